//! What `clone`, `play` and `face export` write imports in Blender (issue 19): one Blender run
//! (`blender -b --factory-startup`, `tests/support/blender_import.py`) imports the user's avatar
//! and fbakit's outputs made from it (`.glb`, `.gltf` + `.bin` + image), the ARKit-named
//! export, a new document (`play` on alma) and an OBJ shape set cloned onto an OBJ target,
//! each into an empty scene, and reports its objects, vertex counts, shape keys, bones and
//! actions. The face mesh must keep the vertex count the user's own file imports with, carry
//! the new shape keys under their names, and the armature, camera and clips must be there; the
//! OBJ shapes import with the user's OBJ's vertices, in its order.
//!
//! Needs Blender (`$BLENDER` or `blender` on the path) with numpy. Without it the test prints a
//! note and returns, unless `$BLENDER_REQUIRED` is set (as `.ci/run` does once it installed
//! Blender).

mod support;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde_json::Value;
use support::blender::{import_in_blender, summary};
use support::loader_outputs::{gltf_outputs, json_of, obj_outputs};

fn objects(r: &Value) -> BTreeMap<String, &Value> {
    r["objects"]
        .as_array()
        .unwrap()
        .iter()
        .map(|o| (o["name"].as_str().unwrap().to_string(), o))
        .collect()
}

fn strings(v: &Value) -> Vec<String> {
    v.as_array()
        .unwrap_or_else(|| panic!("not an array: {v}"))
        .iter()
        .map(|s| s.as_str().unwrap().to_string())
        .collect()
}

/// Paths of the action named `name`.
fn action_paths(r: &Value, name: &str) -> Vec<String> {
    let a = r["actions"]
        .as_array()
        .unwrap()
        .iter()
        .find(|a| a["name"] == name)
        .unwrap_or_else(|| panic!("{}: no action {name}: {}", r["file"], r["actions"]));
    strings(&a["paths"])
}

/// The avatar output imports as the user's avatar does (same objects, vertex and polygon
/// counts, armature, camera, image), with the document's target names as shape keys of the
/// face mesh.
fn assert_avatar(input: &Value, r: &Value, json: &Value, played: bool) -> Vec<String> {
    let file = &r["file"];
    let (a, b) = (objects(input), objects(r));
    assert_eq!(
        a.keys().collect::<Vec<_>>(),
        b.keys().collect::<Vec<_>>(),
        "{file}"
    );
    for (name, x) in &a {
        let y = b[name];
        assert_eq!(x["type"], y["type"], "{file}: {name}");
        assert_eq!(x["vertices"], y["vertices"], "{file}: {name} vertices");
        assert_eq!(x["polygons"], y["polygons"], "{file}: {name} polygons");
        assert_eq!(x["armature"], y["armature"], "{file}: {name} armature");
        assert_eq!(x["materials"], y["materials"], "{file}: {name}");
    }
    assert_eq!(
        strings(&b["Armature"]["bones"]),
        ["Root", "Neck", "Head", "Jaw"]
    );
    assert_eq!(b["Camera"]["type"], "CAMERA");
    assert_eq!(r["images"], input["images"], "{file}");
    // The face mesh (all four primitives of Body) and its shape keys: Basis, then the
    // document's target names, the user's Blink first; each new key moves something.
    let face = b
        .values()
        .find(|o| o["type"] == "MESH" && o["armature"] == "Armature")
        .unwrap_or_else(|| panic!("{file}: no skinned mesh"));
    let names = strings(&json["meshes"][0]["extras"]["targetNames"]);
    let keys = strings(&face["shapeKeys"]);
    assert_eq!(keys[0], "Basis");
    assert_eq!(keys[1..], names[..], "{file}");
    assert_eq!(keys[1], "Blink");
    for (k, key) in keys.iter().enumerate().skip(1) {
        assert!(
            face["shapeKeyMax"][k].as_f64().unwrap() > 0.0,
            "{file}: {key} imported as zeros"
        );
    }
    // The user's clip is still there (the head nods, Blink closes); `play` adds fbakit's.
    let mesh_object = face["name"].as_str().unwrap();
    assert!(action_paths(r, "Idle_Armature")
        .contains(&r#"pose.bones["Head"].rotation_quaternion"#.to_string()));
    assert!(action_paths(r, &format!("Idle_{mesh_object}"))
        .contains(&r#"key_blocks["Blink"].value"#.to_string()));
    let actions = r["actions"].as_array().unwrap().len();
    if played {
        let keyed = action_paths(r, &format!("play_{mesh_object}"));
        assert!(
            keyed.contains(&r#"key_blocks["open_jaw#0"].value"#.to_string()),
            "{file}: {keyed:?}"
        );
        assert!(action_paths(r, "play_Armature")
            .contains(&r#"pose.bones["Jaw"].rotation_quaternion"#.to_string()));
    } else {
        assert_eq!(
            actions,
            input["actions"].as_array().unwrap().len(),
            "{file}"
        );
    }
    keys
}

/// The first `n` vertex lines of an OBJ (Blender's OBJ importer turns the axes on the
/// object's matrix, the mesh keeps the file's coordinates).
fn obj_vertices(path: &Path, n: usize) -> Vec<[f64; 3]> {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .filter_map(|l| l.strip_prefix("v "))
        .take(n)
        .map(|l| {
            let v: Vec<f64> = l.split_whitespace().map(|x| x.parse().unwrap()).collect();
            [v[0], v[1], v[2]]
        })
        .collect()
}

fn obj_vertex_count(path: &Path) -> usize {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .filter(|l| l.starts_with("v "))
        .count()
}

#[test]
fn clone_play_export_and_shape_sets_import_in_blender() {
    let dir = tempfile::tempdir().unwrap();
    let o = gltf_outputs(dir.path());
    let obj = obj_outputs(dir.path());
    let neutral = obj.set.join("neutral.obj");
    let mut shapes: Vec<PathBuf> = std::fs::read_dir(&obj.set)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "obj") && *p != neutral)
        .collect();
    shapes.sort();
    assert!(shapes.len() > 10, "{shapes:?}");
    let jaw = shapes
        .iter()
        .find(|p| {
            p.file_name()
                .unwrap()
                .to_string_lossy()
                .contains("open_jaw")
        })
        .unwrap_or_else(|| panic!("no open_jaw shape in {shapes:?}"))
        .clone();
    let files = [
        &o.input_glb,
        &o.clone_glb,
        &o.play_glb,
        &o.input_gltf,
        &o.clone_gltf,
        &o.play_gltf,
        &o.arkit_glb,
        &o.alma_play_glb,
        &obj.target,
        &neutral,
        &jaw,
        &o.rig_glb,
        &o.from_rig_glb,
    ];
    let Some(r) = import_in_blender(&files) else {
        return;
    };
    for (input, i, file, played) in [
        (&r[0], 1, &o.clone_glb, false),
        (&r[0], 2, &o.play_glb, true),
        (&r[3], 4, &o.clone_gltf, false),
        (&r[3], 5, &o.play_gltf, true),
    ] {
        let keys = assert_avatar(input, &r[i], &json_of(file), played);
        assert!(keys.iter().any(|k| k == "open_jaw#0"), "{keys:?}");
    }
    let keys = assert_avatar(&r[0], &r[6], &json_of(&o.arkit_glb), false);
    for n in ["jawOpen", "mouthSmileLeft", "browInnerUp"] {
        assert!(keys.iter().any(|k| k == n), "{n} missing: {keys:?}");
    }

    // A new document: each mesh with the vertices of its glTF mesh and its targets as keys.
    let json = json_of(&o.alma_play_glb);
    let alma = objects(&r[7]);
    let mut checked = 0;
    for m in json["meshes"].as_array().unwrap() {
        let name = m["name"].as_str().unwrap();
        let object = alma
            .values()
            .find(|x| x["type"] == "MESH" && x["name"] == name)
            .unwrap_or_else(|| panic!("no object for mesh {name}"));
        let accessor = m["primitives"][0]["attributes"]["POSITION"]
            .as_u64()
            .unwrap() as usize;
        assert_eq!(
            object["vertices"], json["accessors"][accessor]["count"],
            "{name}"
        );
        let names = m["extras"]["targetNames"]
            .as_array()
            .map(|_| strings(&m["extras"]["targetNames"]))
            .unwrap_or_default();
        let keys = strings(&object["shapeKeys"]);
        if names.is_empty() {
            assert!(keys.is_empty(), "{name}: {keys:?}");
        } else {
            assert_eq!(keys[0], "Basis");
            assert_eq!(keys[1..], names[..], "{name}");
            checked += 1;
        }
    }
    assert!(
        alma.contains_key("skin") && checked >= 3,
        "{}",
        summary(&r[7])
    );
    assert!(r[7]["actions"]
        .as_array()
        .unwrap()
        .iter()
        .any(|a| a["name"] == "play_skin"));

    // The OBJ shape set: one object each, with the user's vertex count and order.
    let count = obj_vertex_count(&obj.target);
    for (k, path) in [(8, &obj.target), (9, &neutral), (10, &jaw)] {
        let list = r[k]["objects"].as_array().unwrap();
        assert_eq!(list.len(), 1, "{}", summary(&r[k]));
        assert_eq!(list[0]["vertices"], count, "{}", path.display());
        let want = obj_vertices(path, 3);
        for (got, want) in list[0]["positions"].as_array().unwrap().iter().zip(&want) {
            for (g, w) in got.as_array().unwrap().iter().zip(want) {
                assert!((g.as_f64().unwrap() - w).abs() < 1e-4, "{got} vs {want:?}");
            }
        }
    }

    // `face from-rig` on the ICT head rig imports as the rig does, its shapes first, the FAT's
    // targets after them.
    let (rig, from_rig) = (objects(&r[11]), objects(&r[12]));
    assert_eq!(
        rig.keys().collect::<Vec<_>>(),
        from_rig.keys().collect::<Vec<_>>()
    );
    let head = rig.values().find(|x| x["type"] == "MESH").unwrap();
    let name = head["name"].as_str().unwrap();
    assert_eq!(from_rig[name]["vertices"], head["vertices"]);
    assert_eq!(from_rig[name]["polygons"], head["polygons"]);
    let json = json_of(&o.from_rig_glb);
    let keys = strings(&from_rig[name]["shapeKeys"]);
    assert_eq!(
        keys[1..],
        strings(&json["meshes"][0]["extras"]["targetNames"])[..]
    );
    let own = strings(&head["shapeKeys"]);
    assert_eq!(keys[..own.len()], own[..]);
    assert!(keys.len() > own.len(), "{keys:?}");
}
