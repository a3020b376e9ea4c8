//! Cloning onto damaged targets: holes, duplicated vertices, non-manifold edges, flipped
//! polygons, feature points off the mesh or on top of each other. Each method must give a
//! result with a warning naming the damage, or exit 2 with one error line; never a panic,
//! never a NaN in the output.

mod support;

use std::path::Path;

use fbakit::face::FaceModel;
use fbakit::fdp::FeaturePoint;
use fbakit::spec::FeaturePointId;
use glam::Vec3;
use support::cli::{fbakit, text};

/// The cloning methods under test (add a method here and every case runs with it).
const METHODS: &[&str] = &["fit", "fmc", "rbf"];

/// A clean target: bruno without its FAT, one skin mesh free of UV and normal indices so
/// polygons can be edited.
fn target() -> FaceModel {
    let mut face = fbakit::export::picture::strip_fat(&fbakit::face::read("bruno").unwrap());
    for m in &mut face.meshes {
        m.mesh.uvs.clear();
        m.mesh.uv_polygons = None;
        m.mesh.normals.clear();
        m.mesh.normal_polygons = None;
    }
    face
}

fn skin(face: &mut FaceModel) -> &mut fbakit::mesh::Mesh {
    let i = face.mesh_index("skin").unwrap();
    &mut face.meshes[i].mesh
}

fn polygons(face: &mut FaceModel) -> Vec<Vec<u32>> {
    skin(face).polygons.iter().map(<[u32]>::to_vec).collect()
}

fn set_polygons(face: &mut FaceModel, polys: &[Vec<u32>]) {
    skin(face).polygons = fbakit::mesh::Polygons::from_lists(polys);
}

fn fp(label: &str) -> FeaturePointId {
    label.parse().unwrap()
}

/// Each damage: a name, what the warning or error must mention, and the damaged face.
fn damaged() -> Vec<(&'static str, &'static str, FaceModel)> {
    let mut out = Vec::new();

    // Holes: every ninth skin polygon removed.
    let mut f = target();
    let polys: Vec<Vec<u32>> = polygons(&mut f)
        .into_iter()
        .enumerate()
        .filter(|(k, _)| k % 9 != 4)
        .map(|(_, p)| p)
        .collect();
    set_polygons(&mut f, &polys);
    out.push(("holes", "holes", f));

    // Duplicated vertices: every odd polygon uses copies of its vertices (same positions).
    let mut f = target();
    let n = skin(&mut f).positions.len() as u32;
    let copies = skin(&mut f).positions.clone();
    skin(&mut f).positions.extend(copies);
    let polys: Vec<Vec<u32>> = polygons(&mut f)
        .into_iter()
        .enumerate()
        .map(|(k, p)| {
            if k % 2 == 1 {
                p.iter().map(|v| v + n).collect()
            } else {
                p
            }
        })
        .collect();
    set_polygons(&mut f, &polys);
    out.push(("duplicated vertices", "duplicated vertices", f));

    // Non-manifold edges: a fin on the first edge of every twentieth polygon.
    let mut f = target();
    let mut polys = polygons(&mut f);
    let fins: Vec<Vec<u32>> = polys
        .iter()
        .step_by(20)
        .map(|p| {
            let m = skin(&mut f);
            let tip = (m.positions[p[0] as usize] + m.positions[p[1] as usize]) * 0.5
                + Vec3::new(0.0, 0.0, 5.0);
            m.positions.push(tip);
            vec![p[0], p[1], m.positions.len() as u32 - 1]
        })
        .collect();
    polys.extend(fins);
    set_polygons(&mut f, &polys);
    out.push(("non-manifold edges", "non-manifold", f));

    // Flipped polygons: every third polygon wound the other way.
    let mut f = target();
    let polys: Vec<Vec<u32>> = polygons(&mut f)
        .into_iter()
        .enumerate()
        .map(|(k, mut p)| {
            if k % 3 == 0 {
                p.reverse();
            }
            p
        })
        .collect();
    set_polygons(&mut f, &polys);
    out.push(("flipped polygons", "flipped", f));

    // Feature points off the mesh: three points 300 mm in front of the face, unbound.
    let mut f = target();
    for label in ["2.1", "8.3", "9.3"] {
        let id = fp(label);
        let at = f.feature_points.position(id).unwrap();
        f.feature_points
            .insert(FeaturePoint::at(id, at + Vec3::new(0.0, 0.0, 300.0)));
    }
    out.push(("feature points off the mesh", "off the mesh", f));

    // Coincident feature points: both mouth corners on the left one.
    let mut f = target();
    let left = f.feature_points.get(fp("8.3")).unwrap().clone();
    f.feature_points.insert(FeaturePoint {
        id: fp("8.4"),
        ..left
    });
    out.push(("coincident feature points", "8.4", f));
    out
}

fn itertools_free_unzip<A, B, C>(v: Vec<(A, B, C)>) -> (Vec<A>, Vec<B>, Vec<C>) {
    let mut out = (Vec::new(), Vec::new(), Vec::new());
    for (a, b, c) in v {
        out.0.push(a);
        out.1.push(b);
        out.2.push(c);
    }
    out
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// Every number of a VRML text is finite.
fn no_non_finite(text: &str) -> bool {
    !text
        .split(|c: char| c.is_whitespace() || c == ',' || c == '[' || c == ']')
        .any(|w| {
            let w = w.to_ascii_lowercase();
            w == "nan" || w == "inf" || w == "-inf" || w == "+inf"
        })
}

#[test]
fn damaged_targets_warn_or_are_refused_never_nan() {
    let dir = tempfile::tempdir().unwrap();
    // The undamaged target gets none of the damage warnings.
    let clean = dir.path().join("clean.wrl");
    fbakit::face::vrml::write_face_file(&clean, &target()).unwrap();
    let out = dir.path().join("clean-out.wrl");
    let o = fbakit(&["clone", "alma", s(&clean), "-o", s(&out)]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    let (_, mentions, _): (Vec<_>, Vec<_>, Vec<_>) = itertools_free_unzip(damaged());
    for m in mentions {
        assert!(
            !text(&o.stderr).contains(m),
            "clean target: `{m}`\n{}",
            text(&o.stderr)
        );
    }
    for (name, mention, face) in damaged() {
        let target = dir.path().join(format!("{}.wrl", name.replace(' ', "-")));
        fbakit::face::vrml::write_face_file(&target, &face).unwrap();
        for method in METHODS {
            let case = format!("{name} / {method}");
            let out = dir
                .path()
                .join(format!("{}-{method}.wrl", name.replace(' ', "-")));
            let o = fbakit(&[
                "clone",
                "alma",
                s(&target),
                "--method",
                method,
                "-o",
                s(&out),
            ]);
            let err = text(&o.stderr);
            assert!(!err.contains("panicked"), "{case}: panic\n{err}");
            match o.status.code() {
                Some(0) => {
                    assert!(
                        err.lines()
                            .any(|l| l.starts_with("warning") && l.contains(mention)),
                        "{case}: a warning mentioning `{mention}`\n{err}"
                    );
                    let written = std::fs::read_to_string(&out).unwrap();
                    assert!(no_non_finite(&written), "{case}: non-finite number written");
                    let cloned = fbakit::face::read(&out).unwrap();
                    assert!(!cloned.fat.tables.is_empty(), "{case}: no tables");
                }
                Some(2) => {
                    let errors: Vec<&str> =
                        err.lines().filter(|l| l.starts_with("error:")).collect();
                    assert_eq!(errors.len(), 1, "{case}: one error line\n{err}");
                    assert!(errors[0].contains(mention), "{case}: {}", errors[0]);
                    assert!(!out.exists(), "{case}: output left");
                }
                code => panic!("{case}: exit {code:?}\n{err}"),
            }
        }
    }
}
