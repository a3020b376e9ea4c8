//! Cloning onto a target file keeps every node of it fbakit does not read, also when the
//! clone must add transforms: a face without a head transform (none is added: the head turns
//! become per-vertex tables; eye transforms are added as roots) whose tongue shares the jaw's
//! transform with the lower teeth (a tongue transform is added under the jaw).

mod support;

use std::path::Path;

use fbakit::face::{FaceModel, FaceTransform};
use glam::Vec3;
use support::cli::{fbakit, text};

/// Nodes and declarations fbakit does not interpret, put at the top of the file.
const HEADER_EXTRAS: &str = r#"
PROTO Gadget [ field SFFloat speed 1 ] { Group { } }
EXTERNPROTO Remote [ field SFInt32 level ] [ "remote.wrl#Remote" ]
WorldInfo { title "keep me" info [ "a note" ] }
DEF Cam Viewpoint { position 0 0 900 description "front camera" }
NavigationInfo { type [ "EXAMINE" ] headlight FALSE }
Background { skyColor [ 0.1 0.2 0.3 ] }
DEF Sun DirectionalLight { direction 0 -1 -1 intensity 0.7 }
Inline { url [ "props.wrl" ] }
DEF Spinner MyGadget { speed 3 label "unknown fields" mode 0x1F }
DEF Clock TimeSensor { cycleInterval 4 loop TRUE }
"#;

/// A shape fbakit does not read as a mesh, inside the face's own scene graph.
const GRAPH_EXTRA: &str = r#"DEF Hat Shape { geometry Sphere { radius 12.5 } } "#;

/// Everything above, as it must appear in the output.
const KEPT: [&str; 18] = [
    "PROTO Gadget",
    "EXTERNPROTO Remote",
    "remote.wrl#Remote",
    "\"keep me\"",
    "\"a note\"",
    "DEF Cam Viewpoint",
    "front camera",
    "NavigationInfo",
    "skyColor",
    "DEF Sun DirectionalLight",
    "props.wrl",
    "DEF Spinner MyGadget",
    "\"unknown fields\"",
    "0x1F",
    "DEF Clock TimeSensor",
    "ROUTE Clock.fraction_changed TO Spinner.set_fraction",
    "DEF Hat Shape",
    "radius 12.5",
];

/// bruno without a FAT and without transforms, except one `jaw_tf` root holding the lower
/// teeth and the tongue; the meshes keep their world positions.
fn flat_bruno() -> FaceModel {
    let bruno = fbakit::face::read("bruno").unwrap();
    let frames = bruno.frames();
    let mut face = fbakit::export::picture::strip_fat(&bruno);
    face.transforms = vec![FaceTransform::new("jaw_tf", None, Vec3::ZERO)];
    for (m, mesh) in face.meshes.iter_mut().enumerate() {
        for p in &mut mesh.mesh.positions {
            *p = frames.meshes[m].transform_point3(*p);
        }
        mesh.transform = ["teeth_lower", "tongue"]
            .contains(&mesh.name.as_str())
            .then_some(0);
    }
    face
}

/// The target file: `flat_bruno` with the extras spliced in.
fn target_text() -> String {
    with_extras(&flat_bruno())
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

#[test]
fn cloning_keeps_unknown_nodes_when_it_adds_transforms() {
    let dir = tempfile::tempdir().unwrap();
    let target = dir.path().join("target.wrl");
    std::fs::write(&target, target_text()).unwrap();
    // The target reads as the flat face (the extras are not part of it).
    let (read_target, _) = fbakit::face::read_with(&target, &Default::default()).unwrap();
    assert_eq!(read_target.transforms.len(), 1);
    assert_eq!(read_target.meshes.len(), flat_bruno().meshes.len());

    let out = dir.path().join("cloned.wrl");
    let o = fbakit(&["clone", "alma", s(&target), "-o", s(&out)]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    let err = text(&o.stderr);
    assert!(err.contains("created transforms"), "{err}");
    assert!(!err.contains("new scene"), "{err}");

    let written = std::fs::read_to_string(&out).unwrap();
    for kept in KEPT {
        assert!(written.contains(kept), "`{kept}` lost:\n{written}");
    }
    // Reads back with the new transforms around the old content, in the same places.
    let (cloned, _) = fbakit::face::read_with(&out, &Default::default()).unwrap();
    let names: Vec<&str> = cloned.transforms.iter().map(|t| t.name.as_str()).collect();
    for t in ["jaw_tf", "tongue_tf"] {
        assert!(names.contains(&t), "{t} missing from {names:?}");
    }
    assert!(
        !names.contains(&"head"),
        "a head transform was added: {names:?}"
    );
    let parent = |t: &str| {
        let i = cloned.transform_index(t).unwrap();
        cloned.transforms[i]
            .parent
            .map(|p| cloned.transforms[p].name.as_str())
    };
    assert_eq!(parent("jaw_tf"), None);
    assert_eq!(parent("tongue_tf"), Some("jaw_tf"));
    let tongue = cloned.mesh_index("tongue").unwrap();
    assert_eq!(
        cloned.meshes[tongue].transform,
        cloned.transform_index("tongue_tf")
    );
    assert!(!cloned.fat.tables.is_empty());
    // alma's head transform turns become per-vertex turns of the whole face.
    let head_turns: Vec<_> = cloned
        .fat
        .tables
        .iter()
        .filter(|t| {
            matches!(t.key, fbakit::fat::TableKey::LowLevel(f) if (48..=50).contains(&f.number()))
        })
        .collect();
    assert_eq!(head_turns.len(), 3);
    for t in head_turns {
        assert!(
            t.transforms.is_empty() && !t.meshes.is_empty(),
            "{:?}",
            t.key
        );
    }
    let flat = flat_bruno();
    let (frames, flat_frames) = (cloned.frames(), flat.frames());
    for (m, mesh) in flat.meshes.iter().enumerate() {
        let c = cloned.mesh_index(&mesh.name).unwrap();
        let worst = mesh
            .mesh
            .positions
            .iter()
            .zip(&cloned.meshes[c].mesh.positions)
            .map(|(a, b)| {
                flat_frames.meshes[m]
                    .transform_point3(*a)
                    .distance(frames.meshes[c].transform_point3(*b))
            })
            .fold(0.0f32, f32::max);
        assert!(worst < 1e-3, "{} moved by {worst}", mesh.name);
    }

    // And plays.
    let glb = dir.path().join("speech.glb");
    let stream = Path::new(env!("CARGO_MANIFEST_DIR")).join("samples/speech.fap");
    let o = fbakit(&["play", s(&out), s(&stream), "-o", s(&glb)]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    assert!(glb.exists());
}

/// The target file: `face` (no scene of its own) written fresh with the extras spliced in.
fn with_extras(face: &FaceModel) -> String {
    let base = fbakit::face::vrml::write_face_string(face).unwrap();
    let header_end = base.find('\n').unwrap() + 1;
    let mut text = format!(
        "{}{HEADER_EXTRAS}{}",
        &base[..header_end],
        &base[header_end..]
    );
    let graph = text.find("faceSceneGraph [").expect("a face scene graph") + 16;
    text.insert_str(graph, GRAPH_EXTRA);
    text.push_str("ROUTE Clock.fraction_changed TO Spinner.set_fraction\n");
    text
}

/// A one-mesh head (the bundled `ict`: eyes, teeth and gums inside the skin mesh) is cut
/// into parts only inside the clone: the file comes back with its one mesh, every vertex in
/// its place and order, and everything else it held.
#[test]
fn cloning_a_one_mesh_head_keeps_unknown_nodes() {
    let dir = tempfile::tempdir().unwrap();
    let ict = fbakit::export::picture::strip_fat(&fbakit::face::read("ict").unwrap());
    assert_eq!(ict.meshes.len(), 1);
    let target = dir.path().join("head.wrl");
    std::fs::write(&target, with_extras(&ict)).unwrap();
    let out = dir.path().join("cloned.wrl");
    let o = fbakit(&["clone", "alma", s(&target), "--json", "-o", s(&out)]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let split = v["report"]["split_parts"].as_array().unwrap();
    assert!(split.len() >= 3, "{split:?}");

    let written = std::fs::read_to_string(&out).unwrap();
    for kept in KEPT {
        assert!(written.contains(kept), "`{kept}` lost");
    }
    let (cloned, _) = fbakit::face::read_with(&out, &Default::default()).unwrap();
    assert_eq!(cloned.meshes.len(), 1);
    for p in split {
        let name = p["mesh"].as_str().unwrap();
        assert!(cloned.mesh_index(name).is_none(), "{name} written out");
    }
    // Every vertex is there, in its order, where it was.
    assert_eq!(cloned.meshes[0].name, ict.meshes[0].name);
    assert_eq!(cloned.meshes[0].mesh.polygons, ict.meshes[0].mesh.polygons);
    let before = ict.neutral_world_positions();
    let after = cloned.neutral_world_positions();
    assert_eq!(after[0].len(), before[0].len());
    for (a, b) in after[0].iter().zip(&before[0]) {
        assert!(a.distance(*b) < 1e-5, "vertex moved from {b} to {a}");
    }
    assert!(!cloned.fat.tables.is_empty());
}
