//! Reading blendshape rigs: OBJ folders (ICT-FaceKit layout, neutral + shape folder), bad
//! folders, and glTF rigs written by the tests themselves.

use std::path::{Path, PathBuf};

use fbakit::rig::{obj_folder, read_rig};

fn ict_dir() -> Option<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/data/ict-facekit");
    if dir.join("generic_neutral_mesh.obj").is_file() {
        Some(dir)
    } else {
        eprintln!("skipping: {} is absent", dir.display());
        None
    }
}

#[test]
fn ict_folder_reads_as_a_rig() {
    let Some(dir) = ict_dir() else { return };
    let rig = read_rig(&dir).unwrap();
    assert_eq!(rig.name, "ict-facekit");
    assert_eq!(rig.meshes.len(), 1);
    let mesh = &rig.meshes[0].mesh;
    assert_eq!(mesh.vertex_count(), 26_719);
    assert_eq!(mesh.face_count(), 26_384);
    // 12 usemtl groups kept as material groups.
    let materials: std::collections::BTreeSet<_> = mesh
        .groups
        .iter()
        .filter_map(|g| g.material.clone())
        .collect();
    assert_eq!(materials.len(), 12, "{materials:?}");
    assert_eq!(rig.shapes.len(), 57);
    for name in [
        "jawOpen",
        "eyeBlink_L",
        "mouthSmile_R",
        "PupilDilate_L",
        "cheekRaiser_L",
    ] {
        let s = rig.shape(name).unwrap_or_else(|| panic!("no shape {name}"));
        assert!(s.moved_vertex_count() > 0, "{name} moves nothing");
    }
    // jawOpen drops the chin (landmark 9, vertex id from vertex_indices.json) in −y.
    let ids: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("vertex_indices.json")).unwrap())
            .unwrap();
    let chin = ids["idx_to_landmark_verts"][8].as_u64().unwrap() as u32;
    let d = rig.shape("jawOpen").unwrap().offset(0, chin);
    assert!(d.y < -1.0, "chin moves {d} under jawOpen (cm)");
    // The same rig read from its neutral file.
    let again = read_rig(&dir.join("generic_neutral_mesh.obj")).unwrap();
    assert_eq!(again.shapes.len(), 57);
    assert_eq!(again.shapes[3], rig.shapes[3]);
}

fn write(path: &Path, text: &str) {
    std::fs::write(path, text).unwrap();
}

const QUAD: &str = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n";

#[test]
fn neutral_plus_shape_folder() {
    let tmp = tempfile::tempdir().unwrap();
    let shapes = tmp.path().join("shapes");
    std::fs::create_dir(&shapes).unwrap();
    write(&tmp.path().join("head.obj"), QUAD);
    write(
        &shapes.join("jawOpen.obj"),
        "v 0 -1 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n",
    );
    write(&shapes.join("notes.txt"), "not a shape");
    let rig = obj_folder::read_obj_rig_with(&tmp.path().join("head.obj"), &shapes).unwrap();
    assert_eq!(rig.name, "head");
    assert_eq!(rig.shapes.len(), 1);
    assert_eq!(rig.shapes[0].deltas[0].vertices, vec![0]);
    assert_eq!(
        rig.shapes[0].deltas[0].offsets[0],
        glam::Vec3::new(0.0, -1.0, 0.0)
    );
}

#[test]
fn bad_rig_folders_name_the_files() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    write(&dir.join("neutral.obj"), QUAD);
    write(
        &dir.join("short.obj"),
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 3\n",
    );
    let e = read_rig(dir).unwrap_err();
    assert!(e.is_input_error());
    let msg = e.to_string();
    assert!(
        msg.contains("short.obj") && msg.contains("neutral.obj") && msg.contains("3 vertices"),
        "{msg}"
    );
    std::fs::remove_file(dir.join("short.obj")).unwrap();
    write(
        &dir.join("nan.obj"),
        "v 0 0 0\nv 1 0 0\nv 1 nan 0\nv 0 1 0\n",
    );
    let msg = read_rig(dir).unwrap_err().to_string();
    assert!(msg.contains("nan.obj:3:5"), "{msg}");
    std::fs::remove_file(dir.join("nan.obj")).unwrap();
    // A neutral alone is no rig.
    let msg = read_rig(dir).unwrap_err().to_string();
    assert!(msg.contains("no morph targets"), "{msg}");
    // No neutral at all.
    let other = tempfile::tempdir().unwrap();
    write(&other.path().join("a.obj"), QUAD);
    let msg = read_rig(other.path()).unwrap_err().to_string();
    assert!(msg.contains("no neutral OBJ"), "{msg}");
}

#[test]
fn gltf_rig_with_external_buffer_reads_back() {
    use fbakit::rig::gltf_write::rig_to_gltf;
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    write(&dir.join("neutral.obj"), QUAD);
    write(
        &dir.join("smile.obj"),
        "v 0 0 0\nv 1 0.5 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n",
    );
    let rig = read_rig(dir).unwrap();
    // Write as .gltf with an external .bin (move the embedded buffer out).
    let doc = rig_to_gltf(&rig).unwrap();
    let text = doc.to_gltf_string().unwrap();
    let mut json: serde_json::Value = serde_json::from_str(&text).unwrap();
    let uri = json["buffers"][0]["uri"].as_str().unwrap().to_string();
    let b64 = uri.split_once(";base64,").unwrap().1;
    let bin = fbakit::gltf::container::base64_decode(b64).unwrap();
    std::fs::write(dir.join("rig data.bin"), bin).unwrap();
    json["buffers"][0]["uri"] = "rig%20data.bin".into();
    let path = dir.join("rig.gltf");
    std::fs::write(&path, serde_json::to_vec(&json).unwrap()).unwrap();
    let back = read_rig(&path).unwrap();
    assert_eq!(back.shapes.len(), 1);
    assert_eq!(back.shapes[0].name, "smile");
    assert_eq!(back.shapes[0].deltas, rig.shapes[0].deltas);
    assert_eq!(back.meshes[0].mesh.positions, rig.meshes[0].mesh.positions);
    // A missing external buffer is an I/O error naming it.
    std::fs::remove_file(dir.join("rig data.bin")).unwrap();
    let e = read_rig(&path).unwrap_err();
    assert!(e.to_string().contains("rig data.bin"), "{e}");
}
