//! The files issue 19 says users open in other tools, made by the real `fbakit` binary: the
//! test avatar ([`super::avatar`]) after `clone` and after `play` as `.glb` and as `.gltf` +
//! `.bin` + image, its ARKit-named export, a new document (`play` on alma), the bundled ICT
//! head rig after `face from-rig`, and an OBJ shape set cloned onto an OBJ target. `tests/gltf_loaders.rs` (three.js) and
//! `tests/blender_import.rs` (Blender) load them.

use std::path::{Path, PathBuf};

use super::avatar;
use super::cli::{clone_alma_to, run_ok as run};

/// The written files.
pub struct GltfOutputs {
    /// The avatar as the user's `.glb`.
    pub input_glb: PathBuf,
    /// The avatar as the user's `.gltf` (buffer and texture in files beside it).
    pub input_gltf: PathBuf,
    /// `clone alma avatar.glb -o clone.glb`.
    pub clone_glb: PathBuf,
    /// `play clone.glb lowlevel.fap --jaw-node Jaw -o play.glb`.
    pub play_glb: PathBuf,
    /// `clone alma in/avatar.gltf -o out/clone.gltf` (another folder: `.bin` and image
    /// written beside it).
    pub clone_gltf: PathBuf,
    /// `play out/clone.gltf lowlevel.fap --jaw-node Jaw -o out/play.gltf`.
    pub play_gltf: PathBuf,
    /// `face export clone.glb --names arkit -o arkit.glb`.
    pub arkit_glb: PathBuf,
    /// `play alma speech.fap -o alma-play.glb`: a document fbakit made.
    pub alma_play_glb: PathBuf,
    /// The bundled ICT head rig (`samples/faces/ict-head/ict-head.glb`, 35 ARKit shapes).
    pub rig_glb: PathBuf,
    /// `face from-rig ict-head.glb --fp ict-head-fp.csv -o from-rig.glb`.
    pub from_rig_glb: PathBuf,
}

fn sample(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("samples")
        .join(name)
}

/// Writes the glTF outputs under `dir`.
pub fn gltf_outputs(dir: &Path) -> GltfOutputs {
    let alma = fbakit::face::read("alma").unwrap();
    let fp = avatar::fp_csv(&alma, dir, "");
    let a = avatar::build();
    let input_glb = dir.join("avatar.glb");
    std::fs::write(&input_glb, a.to_glb()).unwrap();
    let input_gltf = a.write_gltf(&dir.join("in"), "avatar");
    std::fs::create_dir_all(dir.join("out")).unwrap();
    let o = GltfOutputs {
        clone_glb: dir.join("clone.glb"),
        play_glb: dir.join("play.glb"),
        clone_gltf: dir.join("out/clone.gltf"),
        play_gltf: dir.join("out/play.gltf"),
        arkit_glb: dir.join("arkit.glb"),
        alma_play_glb: dir.join("alma-play.glb"),
        rig_glb: sample("faces/ict-head/ict-head.glb"),
        from_rig_glb: dir.join("from-rig.glb"),
        input_glb,
        input_gltf,
    };
    let lowlevel = sample("lowlevel.fap");
    let speech = sample("speech.fap");
    for (input, cloned, played) in [
        (&o.input_glb, &o.clone_glb, &o.play_glb),
        (&o.input_gltf, &o.clone_gltf, &o.play_gltf),
    ] {
        clone_alma_to(input, &fp, cloned);
        // The avatar's `Jaw` carries the mouth, not the chin: named, it still takes the jaw
        // FAPs (found by its name alone it would not).
        run(&[
            "play".as_ref(),
            cloned.as_os_str(),
            lowlevel.as_os_str(),
            "--jaw-node".as_ref(),
            "Jaw".as_ref(),
            "-o".as_ref(),
            played.as_os_str(),
        ]);
    }
    run(&[
        "face".as_ref(),
        "export".as_ref(),
        o.clone_glb.as_os_str(),
        "--names".as_ref(),
        "arkit".as_ref(),
        "-o".as_ref(),
        o.arkit_glb.as_os_str(),
    ]);
    run(&[
        "play".as_ref(),
        "alma".as_ref(),
        speech.as_os_str(),
        "-o".as_ref(),
        o.alma_play_glb.as_os_str(),
    ]);
    let rig_fp = sample("faces/ict-head/ict-head-fp.csv");
    run(&[
        "face".as_ref(),
        "from-rig".as_ref(),
        o.rig_glb.as_os_str(),
        "--fp".as_ref(),
        rig_fp.as_os_str(),
        "-o".as_ref(),
        o.from_rig_glb.as_os_str(),
    ]);
    o
}

/// An OBJ target and the shape set cloned onto it.
pub struct ObjOutputs {
    /// The user's OBJ (alma's meshes in one file).
    pub target: PathBuf,
    /// `clone alma head.obj --fp-target head-fp.csv -o set/`: the folder.
    pub set: PathBuf,
}

/// alma as the user's OBJ with its feature points by position (a small head keeps Blender's
/// OBJ importer quick), and alma cloned onto it as an OBJ shape set.
pub fn obj_outputs(dir: &Path) -> ObjOutputs {
    let head = fbakit::face::read("alma").unwrap();
    let target = dir.join("head.obj");
    fbakit::face::write(&target, &head).unwrap();
    let mut csv = String::from("fp,x,y,z\n");
    for p in head.feature_points.iter() {
        let q = p.position.unwrap();
        csv.push_str(&format!("{},{},{},{}\n", p.id, q.x, q.y, q.z));
    }
    let fp = dir.join("head-fp.csv");
    std::fs::write(&fp, csv).unwrap();
    let set = dir.join("set/");
    clone_alma_to(&target, &fp, &set);
    ObjOutputs { target, set }
}

/// Names of the glTF nodes reachable from the shown scene, in index order.
pub fn scene_nodes(json: &serde_json::Value) -> Vec<(usize, String)> {
    let s = json["scene"].as_u64().unwrap_or(0) as usize;
    let mut stack: Vec<u64> = json["scenes"][s]["nodes"]
        .as_array()
        .into_iter()
        .flatten()
        .filter_map(|n| n.as_u64())
        .collect();
    let mut seen = std::collections::BTreeSet::new();
    while let Some(n) = stack.pop() {
        if seen.insert(n as usize) {
            stack.extend(
                json["nodes"][n as usize]["children"]
                    .as_array()
                    .into_iter()
                    .flatten()
                    .filter_map(|c| c.as_u64()),
            );
        }
    }
    seen.into_iter()
        .map(|i| {
            (
                i,
                json["nodes"][i]["name"].as_str().unwrap_or("").to_string(),
            )
        })
        .collect()
}

/// The JSON of a `.glb` or `.gltf` file.
pub fn json_of(path: &Path) -> serde_json::Value {
    let bytes = std::fs::read(path).unwrap();
    if bytes.starts_with(b"glTF") {
        let chunks = fbakit::gltf::parse_glb(&bytes).unwrap();
        serde_json::from_slice(chunks.json).unwrap()
    } else {
        serde_json::from_slice(&bytes).unwrap()
    }
}

/// three.js's view of each file (`GLTFLoader` in headless Chromium, by
/// `tests/support/gltf-loaders-check.mjs`, files served beside each document), one JSON report
/// per file, or `None` (with a note) when a tool is missing and CI did not require it.
pub fn load_in_three_js<P: AsRef<Path>>(files: &[P]) -> Option<Vec<serde_json::Value>> {
    let text = super::node_check::run_node_check(
        "gltf-loaders-check.mjs",
        files.iter().map(|f| f.as_ref()),
        &[
            ("THREE_DIR", "target/gltf-loaders"),
            ("VIEWER_BROWSER_DIR", "target/viewer-browser"),
        ],
        "GLTF_LOADERS_REQUIRED",
        "three.js loader",
    )?;
    let reports: Vec<serde_json::Value> = text
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert_eq!(reports.len(), files.len());
    Some(reports)
}

/// A three.js report with no load error, nothing on the console, no request but the file's
/// own.
pub fn assert_clean(r: &serde_json::Value) {
    let file = &r["file"];
    assert!(r.get("loadError").is_none(), "{file}: {}", r["loadError"]);
    for k in [
        "consoleErrors",
        "consoleWarnings",
        "pageErrors",
        "foreignRequests",
    ] {
        assert_eq!(r[k], serde_json::Value::Array(vec![]), "{file}: {k}");
    }
}
