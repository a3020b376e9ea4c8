//! glTF output is in metres whatever the face's unit: the bundled faces are in millimetres,
//! `--units` overrides the guess.

use std::process::Command;

/// Height (y extent) of all POSITION accessors of a .glb, from their min/max.
fn glb_height(path: &std::path::Path) -> f64 {
    let bytes = std::fs::read(path).unwrap();
    let n = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
    let json: serde_json::Value = serde_json::from_slice(&bytes[20..20 + n]).unwrap();
    let (mut lo, mut hi) = (f64::MAX, f64::MIN);
    for mesh in json["meshes"].as_array().unwrap() {
        for prim in mesh["primitives"].as_array().unwrap() {
            let a = &json["accessors"][prim["attributes"]["POSITION"].as_u64().unwrap() as usize];
            lo = lo.min(a["min"][1].as_f64().unwrap());
            hi = hi.max(a["max"][1].as_f64().unwrap());
        }
    }
    hi - lo
}

fn export(args: &[&str]) {
    let out = Command::new(env!("CARGO_BIN_EXE_fbakit"))
        .args(args)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

#[test]
fn bundled_face_exports_head_sized_in_metres() {
    let tmp = tempfile::tempdir().unwrap();
    let glb = tmp.path().join("alma.glb");
    export(&["face", "export", "alma", "-o", glb.to_str().unwrap()]);
    let h = glb_height(&glb);
    assert!((0.15..0.35).contains(&h), "alma is {h} m tall");
    // Declared centimetres: ten times larger.
    let cm = tmp.path().join("alma-cm.glb");
    export(&[
        "face",
        "export",
        "alma",
        "--units",
        "cm",
        "-o",
        cm.to_str().unwrap(),
    ]);
    let ratio = glb_height(&cm) / h;
    assert!((ratio - 10.0).abs() < 1e-3, "{ratio}");
}
