use super::*;
use proptest::prelude::*;

fn read(text: &str) -> (ObjScene, Vec<Diagnostic>) {
    parse_obj(text, Path::new("t.obj")).unwrap()
}

fn read_err(text: &str) -> String {
    parse_obj(text, Path::new("t.obj")).unwrap_err().to_string()
}

#[test]
fn vertex_statement_forms() {
    assert_eq!(
        vertex_statement(" 1 2 3\nx"),
        Ok((
            "x",
            Statement::Vertex {
                position: Vec3::new(1.0, 2.0, 3.0),
                w: None,
                color: None
            }
        ))
    );
    assert_eq!(
        vertex_statement(" 1 2 3 0.5"),
        Ok((
            "",
            Statement::Vertex {
                position: Vec3::new(1.0, 2.0, 3.0),
                w: Some(0.5),
                color: None
            }
        ))
    );
    let Ok((_, Statement::Vertex { color, .. })) = vertex_statement(" 1 2 3 1 0 0.5 # red") else {
        panic!()
    };
    assert_eq!(color, Some(Vec3::new(1.0, 0.0, 0.5)));
    assert!(vertex_statement(" 1 2").is_err());
    assert!(vertex_statement(" 1 2 3 4 5").is_err());
    assert!(vertex_statement(" 1 2 3 4 5 6 7").is_err());
    assert!(vertex_statement(" 1 2 nan").is_err());
    assert!(vertex_statement(" 1 2 3x").is_err());
}

#[test]
fn texcoord_and_normal_statements() {
    assert_eq!(
        texcoord_statement(" 0.5"),
        Ok(("", Statement::TexCoord(Vec2::new(0.5, 0.0))))
    );
    assert_eq!(
        texcoord_statement(" 0.5 1 0\r\n"),
        Ok(("", Statement::TexCoord(Vec2::new(0.5, 1.0))))
    );
    assert!(texcoord_statement("").is_err());
    assert_eq!(
        normal_statement(" 0 0 1"),
        Ok(("", Statement::Normal(Vec3::Z)))
    );
    assert!(normal_statement(" 0 1").is_err());
}

#[test]
fn face_corner_forms() {
    let c = |v, vt, vn| FaceCorner { v, vt, vn };
    assert_eq!(face_corner("3 "), Ok((" ", c(3, None, None))));
    assert_eq!(face_corner("3/4"), Ok(("", c(3, Some(4), None))));
    assert_eq!(face_corner("3//-1"), Ok(("", c(3, None, Some(-1)))));
    assert_eq!(face_corner("-3/4/5"), Ok(("", c(-3, Some(4), Some(5)))));
    assert!(face_corner("/4").is_err());
    assert!(face_corner("3/").is_err());
    assert!(face_corner("3/4/").is_err());
}

#[test]
fn face_statement_needs_three_uniform_corners() {
    let Ok(("", Statement::Face(cs))) = face_statement(" 1 2 3 4") else {
        panic!()
    };
    assert_eq!(cs.len(), 4);
    assert!(face_statement(" 1 2").is_err());
    let e = face_statement(" 1/1 2 3").unwrap_err();
    assert!(
        matches!(e, nom::Err::Error(PErr { expected, .. }) if expected.contains("same index form"))
    );
}

#[test]
fn naming_statements() {
    assert_eq!(
        object_statement(" head mesh  # c\n"),
        Ok(("", Statement::Object("head mesh")))
    );
    assert_eq!(object_statement("\n"), Ok(("", Statement::Object(""))));
    assert_eq!(
        group_statement(" a b\n"),
        Ok(("", Statement::Group(vec!["a", "b"])))
    );
    assert_eq!(
        usemtl_statement(" skin"),
        Ok(("", Statement::UseMaterial("skin")))
    );
    assert_eq!(
        mtllib_statement(" a.mtl b.mtl"),
        Ok(("", Statement::MaterialLibrary("a.mtl b.mtl")))
    );
    assert_eq!(
        smoothing_statement(" off"),
        Ok(("", Statement::Smoothing(None)))
    );
    assert_eq!(
        smoothing_statement(" 0"),
        Ok(("", Statement::Smoothing(None)))
    );
    assert_eq!(
        smoothing_statement(" 2\n"),
        Ok(("", Statement::Smoothing(Some(2))))
    );
    assert!(smoothing_statement(" on").is_err());
    assert!(smoothing_statement(" 99999999999").is_err());
}

#[test]
fn lexical_pieces() {
    assert_eq!(keyword("vt 1"), Ok((" 1", "vt")));
    assert!(keyword(" x").is_err());
    assert_eq!(blank(" \\\n \\\r\n\tx"), Ok(("x", ())));
    assert_eq!(statement_end("  # comment\r\nnext"), Ok(("next", ())));
    assert_eq!(statement_end(""), Ok(("", ())));
    assert!(statement_end(" x").is_err());
}

const CUBE: &str = "\
# a cube of quads
mtllib cube.mtl
o cube
v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
v 0 0 1
v 1 0 1
v 1 1 1
v 0 1 1
g bottom
usemtl grey
s 1
f 1 4 3 2
g sides
f 1 2 6 5
f 2 3 7 6
f 3 4 8 7
f -8 -4 -1 -5
g top
s off
f 5 6 7 8
";

#[test]
fn reads_a_cube_with_groups() {
    let (scene, warnings) = read(CUBE);
    assert!(warnings.is_empty(), "{warnings:?}");
    let m = &scene.mesh;
    assert_eq!(m.name, "t");
    assert_eq!((m.vertex_count(), m.face_count()), (8, 6));
    assert_eq!(
        m.polygons.get(4),
        Some(&[0, 4, 7, 3][..]),
        "negative indices resolved"
    );
    assert_eq!(m.triangles().len(), 12);
    assert_eq!(scene.material_libraries, ["cube.mtl"]);
    let spans: Vec<(u32, &str, Option<u32>)> = m
        .groups
        .iter()
        .map(|g| {
            (
                g.first_face,
                g.groups.first().map_or("", String::as_str),
                g.smoothing,
            )
        })
        .collect();
    assert_eq!(
        spans,
        [
            (0, "bottom", Some(1)),
            (1, "sides", Some(1)),
            (5, "top", None)
        ]
    );
    assert!(m.groups.iter().all(|g| g.object.as_deref() == Some("cube")));
    assert_eq!(m.groups[0].material.as_deref(), Some("grey"));
    assert!(m.validate().is_valid());
}

#[test]
fn writer_output_is_canonical() {
    let (scene, _) = read(CUBE);
    let text = write_obj_string(&scene).unwrap();
    insta::assert_snapshot!(text);
    let (again, _) = read(&text);
    assert_eq!(again, scene);
}

#[test]
fn uvs_normals_colours_crlf_continuations() {
    let text = "v 0 0 0 1 0 0\r\nv 1 0 0 0 1 0\r\nv 0 1 \\\r\n 0 0 0 1\r\nvt 0 0\r\nvt 1 0\r\nvt 0 1\r\nvn 0 0 1\r\nf 1/1/1 2/2/1 3/3/1\r\n";
    let (scene, w) = read(text);
    assert!(w.is_empty(), "{w:?}");
    let m = &scene.mesh;
    assert_eq!(m.positions[2], Vec3::Y);
    assert_eq!(m.colors[2], Vec3::Z);
    assert_eq!(m.uv_polygons.as_ref().unwrap().get(0), Some(&[0, 1, 2][..]));
    assert_eq!(
        m.normal_polygons.as_ref().unwrap().get(0),
        Some(&[0, 0, 0][..])
    );
    let again = read(&write_obj_string(&scene).unwrap()).0;
    assert_eq!(again, scene);
}

#[test]
fn lenient_parts_warn() {
    let text = "v 0 0 0 2\nv 1 0 0\nv 0 1 0 0 0 1\nvt 0 0\nl 1 2\nf 1/1 2/1 3/1\nf 1 2 3\n";
    let (scene, w) = read(text);
    let msgs: Vec<String> = w.iter().map(ToString::to_string).collect();
    assert_eq!(msgs.len(), 4, "{msgs:#?}");
    assert!(
        msgs[0].starts_with("t.obj:1:1: warning: vertex weight w = 2"),
        "{msgs:?}"
    );
    assert!(msgs[1].starts_with("t.obj:5:1: warning: unsupported statement `l`"));
    assert!(msgs[2].contains("only 1 of 3 vertices have colours"));
    assert!(msgs[3].contains("only 1 of 2 faces have texture coordinates"));
    assert!(scene.mesh.colors.is_empty() && scene.mesh.uv_polygons.is_none());
}

#[test]
fn errors_are_located() {
    assert_eq!(
        read_err("v 0 0 0\nv 1 0 0\nf 1 2 3\n"),
        "t.obj:3:7: expected a vertex index in 1..=2 or -2..=-1 (vertices defined so far), found `3`"
    );
    assert_eq!(read_err("v 0 0 0\nf 1 -2 1\n").split(':').nth(1), Some("2"));
    assert!(read_err("v 0 0 0\nf 0 1 1\n").starts_with("t.obj:2:3: expected a vertex index"));
    assert_eq!(
        read_err("v 0 nan 0\n"),
        "t.obj:1:5: expected a number, found `nan 0`"
    );
    assert!(read_err("v 0 1e40 0\n").starts_with("t.obj:1:5: expected a finite number"));
    assert!(read_err("v 0 0 0\nvt 0 0\nf 1/1 1/2 1/1\n")
        .starts_with("t.obj:3:7: expected a texture-coordinate index"));
    assert!(read_err("vn 0 0\n").starts_with("t.obj:1:7: expected 3 numbers"));
    assert!(read_err("f 1 2\n").starts_with("t.obj:1:6: expected at least 3 corners"));
}

#[test]
fn empty_and_comment_only_files() {
    assert_eq!(read("").0.mesh.vertex_count(), 0);
    let (s, w) = read("\u{feff}# nothing\n\n   \n# more");
    assert!(w.is_empty());
    assert_eq!(s.mesh.positions.len(), 0);
}

#[test]
fn writer_refuses_unreadable_meshes() {
    let mut m = Mesh::from_triangles("x", vec![Vec3::ZERO; 3], &[[0, 1, 5]]);
    let scene = |m: &Mesh| ObjScene {
        mesh: m.clone(),
        material_libraries: vec![],
    };
    assert!(write_obj_string(&scene(&m)).is_err());
    m.polygons = Polygons::from_triangles(&[[0, 1, 2]]);
    m.groups.push(FaceGroup {
        object: Some("a\nb".into()),
        ..FaceGroup::default()
    });
    assert!(write_obj_string(&scene(&m)).is_err());
    m.groups.clear();
    m.positions[0].x = f32::NAN;
    assert!(write_obj_string(&scene(&m)).is_err());
}

#[test]
fn mediapipe_canonical_face_round_trips() {
    let path = Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../shared/data/mediapipe-canonical-face/canonical_face_model.obj"
    ));
    if !path.exists() {
        eprintln!("note: {} missing, test skipped", path.display());
        return;
    }
    let (scene, warnings) = read_obj_file(path).unwrap();
    assert!(warnings.is_empty(), "{warnings:?}");
    let m = &scene.mesh;
    assert_eq!(
        (m.vertex_count(), m.face_count(), m.uvs.len()),
        (468, 898, 468)
    );
    assert!(m.uv_polygons.is_some() && m.normal_polygons.is_none());
    // First line of the file, and the first face `f 174/43 156/119 134/220`.
    assert_eq!(m.positions[0], Vec3::new(0.0, -3.406404, 5.979507));
    assert_eq!(m.polygons.get(0), Some(&[173, 155, 133][..]));
    assert_eq!(
        m.uv_polygons.as_ref().unwrap().get(0),
        Some(&[42, 118, 219][..])
    );
    assert!(m.validate().is_valid());
    // Landmark 263 (left eye outer corner) at x = +4.45 per the data README.
    assert!((m.positions[263].x - 4.45).abs() < 0.01);
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("canonical_face_model.obj");
    write_obj_file(&scene, &out).unwrap();
    let (again, _) = read_obj_file(&out).unwrap();
    assert_eq!(again, scene);
}

fn arb_scene() -> impl Strategy<Value = ObjScene> {
    let coord = || {
        prop_oneof![
            -1e6f32..1e6f32,
            Just(0.0f32),
            Just(-0.0f32),
            1e-30f32..1e-20f32
        ]
    };
    let v3 = move || (coord(), coord(), coord()).prop_map(|(x, y, z)| Vec3::new(x, y, z));
    (1usize..12, 1usize..6, 1usize..6)
        .prop_flat_map(move |(nv, nt, nn)| {
            let arity = 3usize..7;
            let face = arity.prop_flat_map(move |k| {
                (
                    prop::collection::vec(0..nv as u32, k),
                    prop::collection::vec(0..nt as u32, k),
                    prop::collection::vec(0..nn as u32, k),
                )
            });
            (
                prop::collection::vec(v3(), nv),
                prop::collection::vec(v3(), nv),
                prop::collection::vec((coord(), coord()).prop_map(|(u, v)| Vec2::new(u, v)), nt),
                prop::collection::vec(v3(), nn),
                prop::collection::vec(face, 0..10),
                (any::<bool>(), any::<bool>(), any::<bool>()),
                prop::collection::vec(
                    (
                        0u32..12,
                        prop::option::of("[a-z]{1,4}"),
                        prop::collection::vec("[a-z]{1,4}", 0..3),
                        prop::option::of(0u32..4),
                        prop::option::of("[a-z]{1,4}"),
                    ),
                    0..4,
                ),
                prop::collection::vec("[a-z]{1,6}\\.mtl", 0..2),
            )
        })
        .prop_map(
            |(pos, cols, uvs, normals, faces, (has_c, has_t, has_n), groups, libs)| {
                let mut m = Mesh {
                    name: "t".into(),
                    positions: pos,
                    uvs,
                    normals,
                    ..Mesh::default()
                };
                if has_c {
                    m.colors = cols;
                }
                let nf = faces.len() as u32;
                m.polygons = Polygons::from_lists(faces.iter().map(|f| f.0.clone()));
                if has_t && nf > 0 {
                    m.uv_polygons = Some(Polygons::from_lists(faces.iter().map(|f| f.1.clone())));
                }
                if has_n && nf > 0 {
                    m.normal_polygons =
                        Some(Polygons::from_lists(faces.iter().map(|f| f.2.clone())));
                }
                let mut starts: Vec<u32> = groups.iter().map(|g| g.0.min(nf)).collect();
                starts.sort_unstable();
                starts.dedup();
                m.groups = starts
                    .iter()
                    .zip(groups)
                    .map(
                        |(&first_face, (_, object, groups, s, material))| FaceGroup {
                            first_face,
                            object,
                            groups,
                            smoothing: s.filter(|&s| s != 0),
                            material,
                        },
                    )
                    .collect();
                ObjScene {
                    mesh: m,
                    material_libraries: libs,
                }
            },
        )
}

proptest! {
    #[test]
    fn write_then_read_is_identity(scene in arb_scene()) {
        prop_assert!(scene.mesh.validate().is_valid());
        let text = write_obj_string(&scene).unwrap();
        let (again, warnings) = parse_obj(&text, Path::new("t.obj")).unwrap();
        prop_assert!(warnings.is_empty(), "{:?}", warnings);
        prop_assert_eq!(again, scene, "{}", text);
    }
}
