//! What `clone`, `play` and `face export` write to `.glb`/`.gltf` loads in three.js (issue 19):
//! each file is loaded by three.js's `GLTFLoader` in headless Chromium through
//! `tests/support/gltf-loaders-check.mjs`, and what three.js made of it is checked: the
//! scene's nodes are the document's, the avatar's body is a `SkinnedMesh` with its bones on
//! every primitive, every primitive of the face mesh has the new morph target names (and
//! their data), the user's clip and fbakit's `play` clip exist and move the morph
//! influences when an `AnimationMixer` plays them.
//!
//! Needs `node`, the npm packages `three` (found through `$THREE_DIR`, an `npm install
//! --prefix` directory, defaulting to `target/gltf-loaders`) and `playwright-core`
//! (`$VIEWER_BROWSER_DIR`, defaulting to `target/viewer-browser`), and Chromium
//! (`$CHROMIUM_PATH` or `/usr/bin/chromium`). Without them the test prints a note and returns,
//! unless `$GLTF_LOADERS_REQUIRED` is set (as `.ci/run` does once it installed them).

mod support;

use std::path::PathBuf;

use serde_json::Value;
use support::avatar;
use support::loader_outputs::{assert_clean, gltf_outputs, json_of, load_in_three_js, scene_nodes};

/// One line per file: what three.js made of it (shown with `--nocapture` or on failure).
fn summary(r: &Value) -> String {
    let list = |k: &str| r[k].as_array().map_or(0, Vec::len);
    let clips: Vec<String> = r["animations"]
        .as_array()
        .into_iter()
        .flatten()
        .map(|a| {
            let moved: Vec<usize> = a["samples"]
                .as_array()
                .unwrap()
                .iter()
                .map(|s| s["changed"].as_array().map_or(0, Vec::len))
                .collect();
            format!(
                "{} {:.2} s, {} tracks, influences changed at 1/4 1/2 3/4: {moved:?}",
                a["name"],
                a["duration"].as_f64().unwrap_or(0.0),
                a["tracks"].as_array().map_or(0, Vec::len)
            )
        })
        .collect();
    let morphs: Vec<String> = r["meshes"]
        .as_array()
        .into_iter()
        .flatten()
        .map(|m| format!("{} {} v/{} t", m["type"], m["vertices"], m["morphTargets"]))
        .collect();
    format!(
        "{}: {} nodes, {} skinned, {} cameras; meshes [{}]; clips [{}]",
        r["file"],
        list("nodes"),
        list("skinned"),
        r["cameras"],
        morphs.join(", "),
        clips.join("; ")
    )
}

fn strings(v: &Value) -> Vec<String> {
    v.as_array()
        .unwrap_or_else(|| panic!("not an array: {v}"))
        .iter()
        .map(|s| s.as_str().unwrap_or_else(|| panic!("{s}")).to_string())
        .collect()
}

/// three.js's nodes are the document's scene nodes, by index and name.
fn assert_nodes(r: &Value, json: &Value) {
    let mut got: Vec<(usize, String)> = r["nodes"]
        .as_array()
        .unwrap()
        .iter()
        .map(|n| {
            (
                n["index"].as_u64().unwrap() as usize,
                n["name"].as_str().unwrap().to_string(),
            )
        })
        .collect();
    got.sort();
    assert_eq!(got, scene_nodes(json), "{}", r["file"]);
}

/// The three.js meshes made from glTF mesh `m`, by primitive.
fn meshes_of(r: &Value, m: usize) -> Vec<&Value> {
    let mut list: Vec<&Value> = r["meshes"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|x| x["mesh"] == m)
        .collect();
    list.sort_by_key(|x| x["primitive"].as_u64());
    list
}

/// Every primitive of mesh `m` has the document's target names, in order, with data.
fn assert_morphs(r: &Value, json: &Value, m: usize) -> Vec<String> {
    let want = strings(&json["meshes"][m]["extras"]["targetNames"]);
    let prims = meshes_of(r, m);
    assert_eq!(
        prims.len(),
        json["meshes"][m]["primitives"].as_array().unwrap().len()
    );
    for p in &prims {
        assert_eq!(strings(&p["names"]), want, "{}: {}", r["file"], p["name"]);
        assert_eq!(p["morphTargets"], want.len(), "{}", p["name"]);
        assert_eq!(p["morphTargetsRelative"], true);
    }
    // Each target moves something on some primitive: three.js read its (sparse) data.
    for (t, name) in want.iter().enumerate() {
        let moved = prims
            .iter()
            .any(|p| p["morphMax"][t].as_f64().unwrap() > 0.0);
        assert!(moved, "{}: target {name} read as zeros", r["file"]);
    }
    want
}

/// The clip named `name`.
fn clip<'a>(r: &'a Value, name: &str) -> &'a Value {
    r["animations"]
        .as_array()
        .unwrap()
        .iter()
        .find(|a| a["name"] == name)
        .unwrap_or_else(|| panic!("{}: no clip {name}: {}", r["file"], r["animations"]))
}

/// Targets whose influence a clip changed at `at` (a fraction of its duration).
fn changed_at(clip: &Value, at: f64) -> Vec<String> {
    let s = clip["samples"]
        .as_array()
        .unwrap()
        .iter()
        .find(|s| s["at"].as_f64() == Some(at))
        .unwrap();
    let mut names: Vec<String> = s["changed"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c["target"].as_str().unwrap_or("?").to_string())
        .collect();
    names.sort();
    names.dedup();
    names
}

/// The avatar after `clone` (and `play`, and the ARKit export): the user's scene, skin, camera,
/// texture and clip, with the new targets on every primitive of `Body`.
fn assert_avatar(r: &Value, input: &Value, output: &Value, played: bool) -> Vec<String> {
    let file = r["file"].clone();
    assert_clean(r);
    assert_nodes(r, output);
    assert_eq!(scene_nodes(input), scene_nodes(output), "{file}");
    assert_eq!(r["cameras"], 1, "{file}");
    // Body: four skinned primitives with the rig's bones and the user's vertex counts.
    let body = meshes_of(r, 0);
    let prims = avatar::body_prims();
    assert_eq!(body.len(), prims.len(), "{file}");
    for (p, want) in body.iter().zip(&prims) {
        assert_eq!(p["type"], "SkinnedMesh", "{file}: {}", p["name"]);
        assert_eq!(
            strings(&p["bones"]),
            ["Root", "Neck", "Head", "Jaw"],
            "{file}"
        );
        assert_eq!(p["vertices"], want.positions.len(), "{file}: {}", p["name"]);
    }
    assert_eq!(strings(&r["skinned"]).len(), 4, "{file}");
    // The skin keeps its base-colour texture (embedded or the copied image file).
    let skin = body.iter().find(|p| p["material"] == "skin").unwrap();
    assert_eq!(skin["textureImage"], serde_json::json!([4, 4]), "{file}");
    // The user's Blink first, the new targets after it, on every primitive.
    let names = assert_morphs(r, output, 0);
    assert_eq!(names[0], "Blink");
    assert!(names.len() > 10, "{file}: {names:?}");
    // The user's clip still nods the head and closes the eyes half way through.
    let idle = clip(r, "Idle");
    assert!(
        strings(&idle["tracks"]).contains(&"Head.quaternion".to_string()),
        "{file}: {idle}"
    );
    assert!(
        changed_at(idle, 0.5).contains(&"Blink".to_string()),
        "{file}: {idle}"
    );
    let clips = r["animations"].as_array().unwrap().len();
    if played {
        assert_eq!(clips, 2, "{file}");
        // fbakit's clip: weights of the face mesh and the jaw joint (open_jaw turns it); half
        // way through, the stream moves fbakit's targets and leaves the user's Blink alone.
        let play = clip(r, "play");
        let tracks = strings(&play["tracks"]);
        assert!(
            tracks.iter().any(|t| t.ends_with(".morphTargetInfluences")),
            "{file}: {tracks:?}"
        );
        assert!(
            tracks.contains(&"Jaw.quaternion".to_string()),
            "{file}: {tracks:?}"
        );
        let moved = changed_at(play, 0.5);
        assert!(
            moved.iter().any(|n| n != "Blink" && names.contains(n)),
            "{file}: {play}"
        );
        assert!(!moved.contains(&"Blink".to_string()), "{file}: {moved:?}");
    } else {
        assert_eq!(clips, 1, "{file}");
    }
    names
}

/// three.js's view of each file, each summarised on stderr.
fn load_in_three(files: &[&PathBuf]) -> Option<Vec<Value>> {
    let reports = load_in_three_js(files)?;
    for r in &reports {
        eprintln!("{}", summary(r));
    }
    Some(reports)
}

#[test]
fn clone_play_and_export_outputs_load_in_three_js() {
    let dir = tempfile::tempdir().unwrap();
    let o = gltf_outputs(dir.path());
    // The harness must see what three.js complains about: target names that do not match the
    // targets are dropped with a console warning.
    let broken = o.clone_gltf.with_file_name("broken.gltf");
    let mut json = json_of(&o.clone_gltf);
    json["meshes"][0]["extras"]["targetNames"]
        .as_array_mut()
        .unwrap()
        .pop();
    std::fs::write(&broken, serde_json::to_vec(&json).unwrap()).unwrap();
    let files = [
        &o.clone_glb,
        &o.play_glb,
        &o.clone_gltf,
        &o.play_gltf,
        &o.arkit_glb,
        &o.alma_play_glb,
        &o.from_rig_glb,
        &broken,
    ];
    let Some(reports) = load_in_three(&files) else {
        return;
    };
    let input = json_of(&o.input_glb);
    let input_gltf = json_of(&o.input_gltf);
    for (r, f, i, played) in [
        (&reports[0], &o.clone_glb, &input, false),
        (&reports[1], &o.play_glb, &input, true),
        (&reports[2], &o.clone_gltf, &input_gltf, false),
        (&reports[3], &o.play_gltf, &input_gltf, true),
    ] {
        let names = assert_avatar(r, i, &json_of(f), played);
        assert!(names.iter().any(|n| n == "open_jaw#0"), "{names:?}");
    }
    // ARKit names on every primitive.
    let names = assert_avatar(&reports[4], &input, &json_of(&o.arkit_glb), false);
    for n in ["jawOpen", "mouthSmileLeft", "browInnerUp"] {
        assert!(names.iter().any(|x| x == n), "{n} missing: {names:?}");
    }

    // A new document: every mesh with its targets, and `play` moves them mid-clip.
    let r = &reports[5];
    let json = json_of(&o.alma_play_glb);
    assert_clean(r);
    assert_nodes(r, &json);
    let mut all = Vec::new();
    for m in 0..json["meshes"].as_array().unwrap().len() {
        if json["meshes"][m]["extras"]["targetNames"].is_array() {
            all.extend(assert_morphs(r, &json, m));
        }
    }
    assert!(all.iter().any(|n| n.starts_with("open_jaw")), "{all:?}");
    let play = clip(r, "play");
    assert!((play["duration"].as_f64().unwrap() - 3.0).abs() < 1e-3);
    assert!(!changed_at(play, 0.5).is_empty(), "{play}");

    // `face from-rig` on the ICT head rig: its nodes and 24 591 vertices, its 35 shapes first,
    // the FAT's targets after them.
    let r = &reports[6];
    let rig = json_of(&o.rig_glb);
    let json = json_of(&o.from_rig_glb);
    assert_clean(r);
    assert_nodes(r, &json);
    assert_eq!(scene_nodes(&rig), scene_nodes(&json));
    let names = assert_morphs(r, &json, 0);
    let own = strings(&rig["meshes"][0]["extras"]["targetNames"]);
    assert_eq!(names[..own.len()], own[..]);
    assert!(names.len() > own.len(), "{names:?}");
    assert_eq!(r["meshes"][0]["vertices"], 24_591);
    assert_eq!(r["animations"], Value::Array(vec![]));

    let r = &reports[7];
    let warned = r["consoleWarnings"].to_string();
    assert!(warned.contains("targetNames"), "{r}");
    // three.js then names the targets by their index.
    assert!(meshes_of(r, 0).iter().all(|p| p["names"][0] == "0"), "{r}");
}
