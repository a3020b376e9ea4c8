//! An avatar written by Blender's own glTF exporter (issue 19: "checked with avatars made by
//! other tools"): `tests/support/blender_author_avatar.py` rigs the bundled ICT head sample
//! the way an artist hands it over — an armature (Root > Neck > Head > Jaw, LeftEye,
//! RightEye) skinning the face with the chin on `Jaw`, a packed texture, the user's own shape
//! key, a nodding clip, a camera, extras on the node, the mesh and the scene — and Blender
//! splits the vertices at every seam and orders them its own way. Its feature points are
//! given as positions (`fp,x,y,z`, from `face info --points` of the sample).
//!
//! `clone` onto it must hand the document back whole (every node, skin, clip, camera,
//! material, texture, image and extra; each attribute's data unchanged; the user's shape key
//! kept first), with no new Khronos-validator issue; `play` must add one clip that turns the
//! `Jaw` joint for the jaw FAPs (never a joint and a morph for one motion); and Blender must
//! import the result as it imported its own file, with the new shape keys.
//!
//! Needs Blender with numpy (skips with a note otherwise, unless `$BLENDER_REQUIRED`).

mod support;

use std::path::{Path, PathBuf};

use fbakit::gltf::parse_glb;
use serde_json::Value;
use support::blender::{import_in_blender, run_script};
use support::cli::{fbakit, text};
use support::gltf_scenes::{component_count, component_size};

fn sample(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(name)
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn ok(args: &[&str]) -> String {
    let o = fbakit(args);
    assert!(o.status.success(), "{args:?}: {}", text(&o.stderr));
    text(&o.stdout)
}

/// The JSON and binary chunk of a `.glb`.
fn open_glb(path: &Path) -> (Value, Vec<u8>) {
    let bytes = std::fs::read(path).unwrap();
    let chunks = parse_glb(&bytes).unwrap();
    let value: Value = serde_json::from_slice(chunks.json).unwrap();
    (value, chunks.bin.unwrap_or_default().to_vec())
}

/// Accessor `i`: its JSON (without the view, which a patch may move) and its bytes, packed
/// (Blender writes dense, tightly packed accessors).
fn accessor(json: &Value, bin: &[u8], i: &Value) -> (Value, Vec<u8>) {
    let mut a = json["accessors"][i.as_u64().unwrap() as usize].clone();
    assert!(a.get("sparse").is_none());
    let view = &json["bufferViews"][a["bufferView"].as_u64().unwrap() as usize];
    assert!(view.get("byteStride").is_none());
    let start = view["byteOffset"].as_u64().unwrap_or(0) + a["byteOffset"].as_u64().unwrap_or(0);
    let len = a["count"].as_u64().unwrap()
        * component_count(a["type"].as_str().unwrap()) as u64
        * component_size(a["componentType"].as_u64().unwrap() as u32) as u64;
    let bytes = bin[start as usize..(start + len) as usize].to_vec();
    let o = a.as_object_mut().unwrap();
    o.remove("bufferView");
    o.remove("byteOffset");
    (a, bytes)
}

/// `v` without the keys fbakit adds (its own extras record and the morph targets).
fn without_fbakit(mut v: Value) -> Value {
    if let Some(e) = v.get_mut("extras").and_then(Value::as_object_mut) {
        e.remove("fbakit");
    }
    v
}

#[test]
fn a_blender_exported_avatar_comes_back_whole_and_plays_with_its_jaw_joint() {
    let dir = tempfile::tempdir().unwrap();
    let head = sample("samples/faces/ict-head/ict-head.glb");
    let head_fp = sample("samples/faces/ict-head/ict-head-fp.csv");

    // The sample's feature points: JSON for the authoring script, `fp,x,y,z` for fbakit.
    let info: Value = serde_json::from_str(&ok(&[
        "face",
        "info",
        s(&head),
        "--fp",
        s(&head_fp),
        "--json",
    ]))
    .unwrap();
    let fp_json = dir.path().join("fp.json");
    std::fs::write(&fp_json, info["feature_points"]["positions"].to_string()).unwrap();
    let listed = ok(&["face", "info", s(&head), "--fp", s(&head_fp), "--points"]);
    let csv = &listed[listed.find("fp,x,y,z").expect("a positions block")..];
    assert_eq!(csv.lines().count(), 1 + 53, "{csv}");
    let fp_csv = dir.path().join("fp.csv");
    std::fs::write(&fp_csv, csv).unwrap();

    let avatar = dir.path().join("avatar.glb");
    let args = [head.as_path(), fp_json.as_path(), avatar.as_path()];
    if run_script("blender_author_avatar.py", &args).is_none() {
        return;
    }
    let (a_json, a_bin) = open_glb(&avatar);
    assert!(
        a_json["asset"]["generator"]
            .as_str()
            .unwrap()
            .contains("Blender"),
        "{}",
        a_json["asset"]
    );
    let a_prim = &a_json["meshes"][0]["primitives"][0];
    let a_count = a_json["accessors"][a_prim["attributes"]["POSITION"].as_u64().unwrap() as usize]
        ["count"]
        .as_u64()
        .unwrap();

    // The positions snap to the very vertices Blender wrote (no farther than its rounding).
    let read: Value = serde_json::from_str(&ok(&[
        "face",
        "info",
        s(&avatar),
        "--fp",
        s(&fp_csv),
        "--json",
    ]))
    .unwrap();
    let matches = &read["fp_matches"];
    assert_eq!(matches["count"], 53, "{matches}");
    assert!(
        matches["max_distance"].as_f64().unwrap() < 1e-5,
        "{matches}"
    );

    let out = dir.path().join("out.glb");
    let o = fbakit(&[
        "clone",
        "alma",
        s(&avatar),
        "--fp-target",
        s(&fp_csv),
        "-o",
        s(&out),
    ]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let (o_json, o_bin) = open_glb(&out);

    // Everything but the meshes' targets and fbakit's own extras is the user's, unchanged.
    for key in [
        "asset",
        "nodes",
        "skins",
        "animations",
        "cameras",
        "materials",
        "textures",
        "images",
        "samplers",
    ] {
        assert_eq!(a_json[key], o_json[key], "`{key}` changed");
    }
    assert_eq!(
        a_json["scenes"][0],
        without_fbakit(o_json["scenes"][0].clone()),
        "the scene changed"
    );
    assert!(o_json["scenes"][0]["extras"]["fbakit"].is_object());
    // The skin's inverse bind matrices and every attribute keep their data.
    let ibm = &a_json["skins"][0]["inverseBindMatrices"];
    assert_eq!(
        accessor(&a_json, &a_bin, ibm),
        accessor(&o_json, &o_bin, ibm)
    );
    let o_prim = &o_json["meshes"][0]["primitives"][0];
    assert_eq!(a_prim["attributes"], o_prim["attributes"]);
    assert_eq!(a_prim["material"], o_prim["material"]);
    for (name, i) in a_prim["attributes"].as_object().unwrap() {
        assert!(
            accessor(&a_json, &a_bin, i) == accessor(&o_json, &o_bin, i),
            "{name} changed"
        );
    }
    let i = &a_prim["indices"];
    assert!(accessor(&a_json, &a_bin, i) == accessor(&o_json, &o_bin, i));
    // The user's shape key stays first, with its data; fbakit's are appended.
    let names: Vec<&str> = o_json["meshes"][0]["extras"]["targetNames"]
        .as_array()
        .unwrap()
        .iter()
        .map(|n| n.as_str().unwrap())
        .collect();
    assert_eq!(names[0], "UserSmirk");
    assert!(names.iter().any(|n| n.starts_with("open_jaw")), "{names:?}");
    assert_eq!(o_json["meshes"][0]["extras"]["lod"], 0);
    let targets = o_prim["targets"].as_array().unwrap();
    assert_eq!(targets.len(), names.len());
    assert_eq!(
        o_json["meshes"][0]["weights"].as_array().unwrap().len(),
        names.len()
    );
    assert!(
        accessor(&a_json, &a_bin, &a_prim["targets"][0]["POSITION"])
            == accessor(&o_json, &o_bin, &targets[0]["POSITION"]),
        "the user's shape key changed"
    );
    // A new target keeps the vertex count and moves the chin by millimetres (metres here).
    let jaw_target = names
        .iter()
        .position(|n| n.starts_with("open_jaw"))
        .unwrap();
    let jaw = &o_json["accessors"][targets[jaw_target]["POSITION"].as_u64().unwrap() as usize];
    assert_eq!(jaw["count"].as_u64().unwrap(), a_count);
    let reach = |k: &str| {
        jaw[k]
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_f64().unwrap().abs())
            .fold(0.0, f64::max)
    };
    let moved = reach("min").max(reach("max"));
    assert!((1e-3..0.05).contains(&moved), "open_jaw moves {moved} m");

    // play: one clip more, the user's untouched; the Jaw joint turns, the Head node nods
    // with the head FAPs; open_jaw's targets stay at zero weight.
    let played = dir.path().join("played.glb");
    ok(&[
        "play",
        s(&out),
        s(&sample("samples/speech.fap")),
        "-o",
        s(&played),
    ]);
    let (p_json, _) = open_glb(&played);
    let clips = p_json["animations"].as_array().unwrap();
    assert_eq!(clips.len(), 2);
    assert_eq!(clips[0], a_json["animations"][0]);
    let node = |name: &str| {
        a_json["nodes"]
            .as_array()
            .unwrap()
            .iter()
            .position(|n| n["name"] == name)
            .unwrap()
    };
    let channels = clips[1]["channels"].as_array().unwrap();
    let drives = |n: usize, path: &str| {
        channels
            .iter()
            .any(|c| c["target"]["node"] == n && c["target"]["path"] == path)
    };
    assert!(drives(node("Jaw"), "rotation"), "{channels:?}");
    assert!(drives(node("Face"), "weights"), "{channels:?}");

    // The Khronos validator finds nothing the user's own file did not have.
    if let Some(reports) =
        support::validator::validate(&[avatar.clone(), out.clone(), played.clone()])
    {
        let issues = |r: &Value| (r["errors"].clone(), r["warnings"].clone());
        assert_eq!(issues(&reports[0]), issues(&reports[1]), "{}", reports[1]);
        assert_eq!(issues(&reports[0]), issues(&reports[2]), "{}", reports[2]);
    }

    // Blender imports the result as it imported its own file, plus the new shape keys.
    let Some(r) = import_in_blender(&[&avatar, &played]) else {
        return;
    };
    let face = |r: &Value| -> Value {
        r["objects"]
            .as_array()
            .unwrap()
            .iter()
            .find(|o| o["type"] == "MESH")
            .unwrap()
            .clone()
    };
    let (before, after) = (face(&r[0]), face(&r[1]));
    assert_eq!(before["vertices"], after["vertices"]);
    assert_eq!(before["polygons"], after["polygons"]);
    assert_eq!(before["armature"], after["armature"]);
    assert_eq!(before["materials"], after["materials"]);
    let keys = after["shapeKeys"].as_array().unwrap();
    assert_eq!(keys.len(), 1 + names.len(), "{keys:?}"); // Blender's "Basis" first
    assert!(keys.iter().any(|k| k == "UserSmirk"));
    let actions = r[1]["actions"].as_array().unwrap();
    assert!(actions.len() > r[0]["actions"].as_array().unwrap().len());
}
