//! A real head's FAT cloned onto a face mask made by another tool: MediaPipe's canonical
//! face (468 vertices, no mouth socket, no eyeballs), its feature points placed by
//! `fbakit fp from-landmarks`. The ICT head's mouth socket reaches 6 cm behind its lips; the
//! mask's inner lips must read the lips' motion, not the socket's. The mask is exactly
//! symmetric, so every left FAP must move it as much as its right twin.
//! Skipped with a note when `../shared/data` is absent.

use std::path::{Path, PathBuf};

use glam::Vec3;

mod support;
use support::cli::{fbakit, text};

fn canonical_face() -> Option<PathBuf> {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../shared/data/mediapipe-canonical-face/canonical_face_model.obj");
    if p.exists() {
        Some(p)
    } else {
        eprintln!("note: {} not found; skipping", p.display());
        None
    }
}

fn positions(path: &Path) -> Vec<Vec3> {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .filter_map(|l| l.strip_prefix("v "))
        .map(|l| {
            let v: Vec<f32> = l
                .split_whitespace()
                .take(3)
                .map(|x| x.parse().unwrap())
                .collect();
            Vec3::new(v[0], v[1], v[2])
        })
        .collect()
}

/// The right-side twin of a left shape's file name (`raise_l_cornerlip@474.obj`).
fn right_twin(left: &str) -> Option<String> {
    left.contains("_l_")
        .then(|| left.replace("_l_", "_r_"))
        .or_else(|| left.contains("_l@").then(|| left.replace("_l@", "_r@")))
}

#[test]
fn ict_onto_the_mediapipe_mask_moves_both_lip_corners_alike() {
    let Some(obj) = canonical_face() else {
        return;
    };
    let tmp = tempfile::tempdir().unwrap();
    let fp = tmp.path().join("fp.csv");
    let out = fbakit(&[
        "fp",
        "from-landmarks",
        "--mediapipe468",
        "-o",
        fp.to_str().unwrap(),
        obj.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let dir = tmp.path().join("shapes/");
    let out = fbakit(&[
        "clone",
        "ict",
        obj.to_str().unwrap(),
        "--fp-target",
        fp.to_str().unwrap(),
        "-o",
        dir.to_str().unwrap(),
    ]);
    let stderr = text(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    // No FAP needed the guard: the old code moved the right inner lip corner 0.4–4 % of
    // its FAPU under `stretch_r_cornerlip` and `raise_r_cornerlip` and repaired it by moving
    // the feature point alone (a spike).
    assert!(!stderr.contains("repaired"), "{stderr}");
    let neutral = positions(&dir.join("neutral.obj"));
    assert_eq!(neutral.len(), 468);
    let moved = |name: &str| -> f32 {
        positions(&dir.join(name))
            .iter()
            .zip(&neutral)
            .map(|(a, b)| a.distance(*b))
            .sum()
    };
    let mut names: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    let mut pairs = 0;
    let mut worst = (String::new(), 1.0f32);
    for left in &names {
        let Some(right) = right_twin(left) else {
            continue;
        };
        assert!(names.contains(&right), "{left} has no twin {right}");
        let (l, r) = (moved(left), moved(&right));
        assert!(l > 0.0 && r > 0.0, "{left} {l} {right} {r}");
        let ratio = (r / l).max(l / r);
        eprintln!("{left:34} {l:8.3}  {right:34} {r:8.3}  ratio {ratio:.3}");
        if ratio > worst.1 {
            worst = (left.clone(), ratio);
        }
        pairs += 1;
    }
    eprintln!("{pairs} mirrored pairs, worst {worst:?}");
    assert!(pairs >= 12, "{pairs}");
    // The old code: 25× apart (right inner lip corner).
    assert!(worst.1 < 1.1, "{worst:?}");
}
