//! VRM avatars (`.vrm`, VRoid Studio and VRM 1.0 exporters): a binary glTF with the VRM
//! extension. `clone`, `play` and `face export` write one back as `.vrm` with the extension's
//! data as the user wrote it and the avatar's own morph targets (which its expressions name by
//! index) where they were; a document that is no VRM avatar is refused as `.vrm` (exit 2,
//! nothing written).

mod support;

use std::path::Path;

use serde_json::{json, Value};
use support::avatar;
use support::cli::{clone_alma_to, command, play_to, text};
use support::glb::floats;

/// The JSON of a `.glb` / `.vrm` file.
fn json_of(path: &Path) -> Value {
    let bytes = std::fs::read(path).unwrap();
    let chunks = fbakit::gltf::parse_glb(&bytes).unwrap();
    serde_json::from_slice(chunks.json).unwrap()
}

fn run(args: &[&std::ffi::OsStr]) -> std::process::Output {
    command().args(args).output().unwrap()
}

/// The test avatar as a VRM 1.0 avatar: a humanoid, meta and a `blink` expression bound to
/// its own `Blink` morph target (mesh 0's target 0, on node `Body`).
fn vrm_avatar() -> (Value, Vec<u8>) {
    let mut a = avatar::build();
    let body = a.json["nodes"]
        .as_array()
        .unwrap()
        .iter()
        .position(|n| n["name"] == "Body")
        .unwrap();
    a.json["extensionsUsed"] = json!(["VRMC_vrm"]);
    a.json["extensions"] = json!({"VRMC_vrm": {
        "specVersion": "1.0",
        "meta": {"name": "test avatar", "authors": ["fbakit tests"], "licenseUrl": "https://vrm.dev/licenses/1.0/"},
        "humanoid": {"humanBones": {"head": {"node": 3}}},
        "expressions": {"preset": {"blink": {"morphTargetBinds": [{"node": body, "index": 0, "weight": 1.0}]}}}
    }});
    let bytes = a.to_glb();
    (a.json, bytes)
}

#[test]
fn a_vrm_avatar_comes_back_as_vrm_with_its_expressions() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let (json, bytes) = vrm_avatar();
    let input = d.join("avatar.vrm");
    std::fs::write(&input, bytes).unwrap();
    let alma = fbakit::face::read("alma").unwrap();
    let fp = avatar::fp_csv(&alma, d, "");
    let cloned = d.join("cloned.vrm");
    clone_alma_to(&input, &fp, &cloned);
    let out = json_of(&cloned);
    assert_eq!(
        out["extensions"]["VRMC_vrm"],
        json["extensions"]["VRMC_vrm"]
    );
    assert!(out["extensionsUsed"]
        .as_array()
        .unwrap()
        .contains(&json!("VRMC_vrm")));
    // The user's own target keeps index 0 (the `blink` expression's bind), fbakit's follow.
    let names = out["meshes"][0]["extras"]["targetNames"]
        .as_array()
        .unwrap();
    assert_eq!(names[0], "Blink");
    assert!(names.len() > 10, "{names:?}");
    assert!(
        names
            .iter()
            .any(|n| n.as_str().is_some_and(|n| n.starts_with("open_jaw"))),
        "{names:?}"
    );

    // Played and exported with ARKit names, it stays a VRM avatar.
    let played = d.join("played.vrm");
    let speech = Path::new(env!("CARGO_MANIFEST_DIR")).join("samples/speech.fap");
    play_to(&cloned, &speech, &played);
    let p = json_of(&played);
    assert_eq!(p["extensions"]["VRMC_vrm"], json["extensions"]["VRMC_vrm"]);
    assert!(!p["animations"].as_array().unwrap().is_empty());
    let arkit = d.join("arkit.vrm");
    let o = run(&[
        "face".as_ref(),
        "export".as_ref(),
        cloned.as_os_str(),
        "-o".as_ref(),
        arkit.as_os_str(),
        "--names".as_ref(),
        "arkit".as_ref(),
    ]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let k = json_of(&arkit);
    assert_eq!(k["extensions"]["VRMC_vrm"], json["extensions"]["VRMC_vrm"]);
    assert_eq!(k["meshes"][0]["extras"]["targetNames"][0], "Blink");
}

#[test]
fn what_is_no_vrm_avatar_is_not_written_as_vrm() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let plain = d.join("avatar.glb");
    std::fs::write(&plain, avatar::build().to_glb()).unwrap();
    let alma = fbakit::face::read("alma").unwrap();
    let fp = avatar::fp_csv(&alma, d, "");
    let out = d.join("out.vrm");
    let speech = Path::new(env!("CARGO_MANIFEST_DIR")).join("samples/speech.fap");
    let cases: [(Vec<&std::ffi::OsStr>, &str); 2] = [
        (
            vec![
                "clone".as_ref(),
                "alma".as_ref(),
                plain.as_os_str(),
                "--fp-target".as_ref(),
                fp.as_os_str(),
            ],
            "the face's own glTF has no VRM extension",
        ),
        (
            vec!["play".as_ref(), "alma".as_ref(), speech.as_os_str()],
            "a new glTF document has no VRM extension",
        ),
    ];
    for (args, expect) in cases {
        let mut args = args.clone();
        args.extend(["-o".as_ref(), out.as_os_str()]);
        let o = run(&args);
        let err = text(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{err}");
        assert!(
            err.contains(expect) && err.contains("write .glb instead"),
            "{err}"
        );
        assert_eq!(
            err.lines().filter(|l| l.starts_with("error")).count(),
            1,
            "{err}"
        );
        assert!(!out.exists());
    }
}

/// A VRM 0.x avatar faces −z in its file. The test avatar turned round so (its root turned
/// half a turn about y, its feature points with it) clones and plays as the avatar facing
/// +z: the same morph weights, and the same turns of its `Head` and `Jaw` joints in their
/// parents' frames (head pitch about the face's own x, not the file's).
#[test]
fn an_avatar_facing_back_plays_as_the_one_facing_front() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let alma = fbakit::face::read("alma").unwrap();
    let fp = avatar::fp_csv(&alma, d, "");
    let fp_text = std::fs::read_to_string(&fp).unwrap();
    let mut round_fp = String::from("fp,x,y,z\n");
    for line in fp_text.lines().skip(1) {
        let f: Vec<&str> = line.split(',').collect();
        let c: Vec<f32> = f[1..4].iter().map(|v| v.parse().unwrap()).collect();
        round_fp.push_str(&format!("{},{},{},{}\n", f[0], -c[0], c[1], -c[2]));
    }
    let fp_round = d.join("round-fp.csv");
    std::fs::write(&fp_round, round_fp).unwrap();
    let front = avatar::build();
    let mut round = avatar::build();
    round.json["nodes"][0]["rotation"] = json!([0.0, 1.0, 0.0, 0.0]);
    let speech = Path::new(env!("CARGO_MANIFEST_DIR")).join("samples/lowlevel.fap");
    let played = |name: &str, a: &avatar::Avatar, fp: &Path| {
        let input = d.join(format!("{name}.glb"));
        std::fs::write(&input, a.to_glb()).unwrap();
        let cloned = d.join(format!("{name}-cloned.glb"));
        clone_alma_to(&input, fp, &cloned);
        let out = d.join(format!("{name}-played.glb"));
        play_to(&cloned, &speech, &out);
        let (json, bin) = support::glb::open(&out);
        let play = support::glb::play_animation(&json);
        // (node, path) → sampler output values.
        let mut channels: Vec<((u64, String), Vec<f64>)> = play["channels"]
            .as_array()
            .unwrap()
            .iter()
            .map(|c| {
                let s = &play["samplers"][c["sampler"].as_u64().unwrap() as usize];
                let values: Vec<f64> = floats(&json, &bin, s["output"].as_u64().unwrap() as usize)
                    .into_iter()
                    .map(f64::from)
                    .collect();
                (
                    (
                        c["target"]["node"].as_u64().unwrap(),
                        c["target"]["path"].as_str().unwrap().to_string(),
                    ),
                    values,
                )
            })
            .collect();
        channels.sort_by(|a, b| a.0.cmp(&b.0));
        channels
    };
    let (a, b) = (
        played("front", &front, &fp),
        played("round", &round, &fp_round),
    );
    let keys = |c: &[((u64, String), Vec<f64>)]| c.iter().map(|x| x.0.clone()).collect::<Vec<_>>();
    assert_eq!(keys(&a), keys(&b));
    assert!(
        a.iter().any(|((n, p), _)| *n == 3 && p == "rotation"),
        "the Head joint turns: {:?}",
        keys(&a)
    );
    for ((key, x), (_, y)) in a.iter().zip(&b) {
        assert_eq!(x.len(), y.len(), "{key:?}");
        let worst = x
            .iter()
            .zip(y)
            .map(|(p, q)| (p - q).abs())
            .fold(0.0f64, f64::max);
        assert!(worst < 2e-3, "{key:?}: off by {worst}");
    }
}
