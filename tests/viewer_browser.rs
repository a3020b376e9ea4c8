//! Loads `fbakit view` pages in a real browser (headless Chromium on SwiftShader) through
//! `tests/support/viewer-check.mjs`, and checks what a viewer sees: the page plays on load,
//! pauses, seeks and scrubs; the mouth region of the rendered canvas changes between two times
//! of the stream and when a FAP slider moves; no console error, no request leaves the file.
//!
//! Needs `node`, the npm package `playwright-core` (found through `$VIEWER_BROWSER_DIR`, an
//! `npm install --prefix` directory, defaulting to `target/viewer-browser`) and Chromium
//! (`$CHROMIUM_PATH` or `/usr/bin/chromium`). Without them the tests print a note and return,
//! unless `$VIEWER_BROWSER_REQUIRED` is set (as `.ci/run` does once it installed both).

mod support;

use std::path::{Path, PathBuf};
use std::process::Command;

use fbakit::export::viewer::{ViewerAnimation, ViewerPage};
use fbakit::fap::{read_stream_file, ReadOptions};
use fbakit::player::{PlayOptions, Player};
use serde_json::Value;
use support::node_check::run_node_check;

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// The check script's report for `page`, or `None` (with a note) when the browser is missing.
fn check_page(page: &Path) -> Option<Value> {
    let mut args = vec![page.as_os_str().to_owned()];
    // Screenshots for a person to look at: `$VIEWER_SCREENSHOTS=DIR` keeps one per page.
    if let Some(dir) = std::env::var_os("VIEWER_SCREENSHOTS") {
        let name = page.file_stem().unwrap_or_default().to_string_lossy();
        args.push(Path::new(&dir).join(format!("{name}.png")).into_os_string());
    }
    let text = run_node_check(
        "viewer-check.mjs",
        args,
        &[("VIEWER_BROWSER_DIR", "target/viewer-browser")],
        "VIEWER_BROWSER_REQUIRED",
        "viewer browser",
    )?;
    eprintln!("{text}");
    Some(serde_json::from_str(text.trim()).unwrap())
}

/// The check script's report for a page of `face` playing `samples/speech.fap`.
fn speech_page_report(face: &fbakit::face::FaceModel, name: &str) -> Option<Value> {
    let (stream, _) =
        read_stream_file(root().join("samples/speech.fap"), &ReadOptions::lenient()).unwrap();
    let player = Player::new(face, &stream, &PlayOptions::default()).unwrap();
    let frames = player.animation().unwrap();
    let anim = ViewerAnimation {
        frames: &frames,
        fps: player.fps(),
        name: "speech.fap",
    };
    let dir = tempfile::tempdir().unwrap();
    let page: PathBuf = dir.path().join(format!("{name}-speech.html"));
    ViewerPage::new(face, Some(&anim))
        .unwrap()
        .write(&page)
        .unwrap();
    check_page(&page)
}

fn f(v: &Value) -> f64 {
    v.as_f64().unwrap_or_else(|| panic!("not a number: {v}"))
}

fn assert_clean(r: &Value) {
    assert_eq!(r["consoleErrors"], Value::Array(vec![]), "console errors");
    assert_eq!(r["pageErrors"], Value::Array(vec![]), "page errors");
    assert_eq!(
        r["foreignRequests"],
        Value::Array(vec![]),
        "requests left the file"
    );
}

fn assert_slider_moves_the_mouth(r: &Value) {
    assert_eq!(r["slider"]["key"], "open_jaw");
    let c = &r["sliderChange"];
    assert!(
        f(&c["opaqueFraction"]) > 0.5,
        "mouth region is not on the face: {c}"
    );
    assert!(
        f(&c["changedFraction"]) > 0.01 && f(&c["meanAbsDiff"]) > 0.5,
        "moving open_jaw did not change the mouth: {c}"
    );
    assert_eq!(r["stateAfterSlider"]["mode"], "pose");
    assert_eq!(r["stateAfterSlider"]["playing"], false);
    let shown = r["sliderOutput"].as_str().unwrap();
    assert!(
        shown.starts_with("1024") && shown.ends_with("MNS"),
        "{shown}"
    );
}

#[test]
fn speech_page_plays_and_poses_in_chromium() {
    let face = fbakit::synth::alma().to_face_model();
    let Some(r) = speech_page_report(&face, "alma") else {
        return;
    };
    assert_clean(&r);
    assert_eq!(r["ready"]["frames"], 75);
    // 75 frames at 25 fps last 3 s (the closing key holds the last frame).
    assert!((f(&r["ready"]["duration"]) - 3.0).abs() < 1e-3);

    // Opens ready to watch: playing the animation, and the clock moves.
    assert_eq!(r["stateOnLoad"]["mode"], "animation");
    assert_eq!(r["stateOnLoad"]["playing"], true);
    assert_eq!(r["timeAdvanced"], true);
    assert_eq!(r["stateAfterPauseClick"]["playing"], false);

    // The mouth region (from 18 projected lip points) differs between frame 0 and a frame
    // where the mouth FAPs differ most from it.
    assert!(f(&r["mouthRegion"]["points"]) >= 8.0);
    let picked = f(&r["pickedFrame"]["time"]);
    assert!(picked > 0.0);
    let c = &r["timeChange"];
    assert!(
        f(&c["opaqueFraction"]) > 0.5,
        "mouth region is not on the face: {c}"
    );
    assert!(
        f(&c["changedFraction"]) > 0.01 && f(&c["meanAbsDiff"]) > 0.5,
        "the mouth did not change between t=0 and t={picked}: {c}"
    );
    assert!((f(&r["stateAfterSeek"]["time"]) - picked).abs() < 1e-3);
    assert!((f(&r["stateAfterScrub"]["time"]) - picked / 2.0).abs() < 0.02);

    assert_slider_moves_the_mouth(&r);
    assert_eyes_and_framing(&r);
}

#[test]
fn neutral_page_from_the_cli_poses_in_chromium() {
    let dir = tempfile::tempdir().unwrap();
    let page = dir.path().join("bruno.html");
    let out = Command::new(env!("CARGO_BIN_EXE_fbakit"))
        .args(["view", "bruno", "-o"])
        .arg(&page)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );

    let Some(r) = check_page(&page) else { return };
    assert_clean(&r);
    assert_eq!(r["ready"]["frames"], 0);
    assert_eq!(r["stateOnLoad"]["mode"], "pose");
    assert_eq!(r["stateOnLoad"]["playing"], false);
    assert_slider_moves_the_mouth(&r);
}

/// The neutral face at the default camera: both pupils drawn dark (an iris and a pupil on the
/// eyeballs, not blank white), the skin lighter, and every feature point — the chin included —
/// above the transport bar and inside the canvas.
fn assert_eyes_and_framing(r: &Value) {
    let v = &r["neutralView"];
    assert!(f(&v["eyes"]) >= 2.0, "no eyeballs to paint: {v}");
    let pupils = v["pupils"].as_array().unwrap();
    assert_eq!(pupils.len(), 2, "{v}");
    let skin: Vec<f64> = v["skin"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| f(&p["luminance"]))
        .collect();
    assert!(!skin.is_empty(), "{v}");
    let skin_mean = skin.iter().sum::<f64>() / skin.len() as f64;
    for p in pupils {
        let l = f(&p["luminance"]);
        assert!(
            l < 70.0 && l < 0.5 * skin_mean,
            "pupil {} not dark: {l} (skin {skin_mean}): {v}",
            p["id"]
        );
    }
    let bar = f(&v["barTop"]);
    assert!(f(&v["chin"]["y"]) < bar, "chin under the control bar: {v}");
    assert!(
        f(&v["lowestPoint"]) < bar,
        "a feature point under the bar: {v}"
    );
    assert!(
        f(&v["highestPoint"]) > 0.0,
        "a feature point above the canvas: {v}"
    );
}

#[test]
fn real_head_page_shows_pupils_above_the_controls_in_chromium() {
    let (face, _) = fbakit::face::BundledFace::Ict.read().unwrap();
    let Some(r) = speech_page_report(&face, "ict") else {
        return;
    };
    assert_clean(&r);
    assert_eq!(r["ready"]["frames"], 75);
    assert_eq!(r["stateOnLoad"]["playing"], true);
    assert_eq!(r["timeAdvanced"], true);
    assert_eq!(r["stateAfterPauseClick"]["playing"], false);
    assert!((f(&r["stateAfterScrub"]["time"]) - f(&r["pickedFrame"]["time"]) / 2.0).abs() < 0.02);
    assert_eyes_and_framing(&r);
}

/// The ICT-FaceKit's whole head (`../shared`): its eye occlusion, tear film and corner blends
/// are left out of the page (transparent in ICT's materials, they covered the eyes in the
/// glb's one material), so both pupils show dark.
#[test]
fn whole_ict_head_page_shows_its_pupils_through_the_eye_layers_in_chromium() {
    let work = tempfile::tempdir().unwrap();
    let Some((_, face)) = support::ict_full_head::ict_full_head(work.path()) else {
        return;
    };
    // No FAT (a page in pose mode): only the neutral view matters here.
    let page = work.path().join("ict-full.html");
    ViewerPage::new(&face, None).unwrap().write(&page).unwrap();
    let Some(r) = check_page(&page) else { return };
    assert_clean(&r);
    assert_eq!(r["stateOnLoad"]["mode"], "pose");
    assert_eyes_and_framing(&r);
}
