//! Replays the seed corpora of the fuzz targets (`fuzz/seeds/<target>/`) through the same
//! library calls on the stable toolchain, plus truncations and single-byte flips of each
//! seed, and the inputs the targets once crashed on (`tests/fuzz-regressions/<target>/`): no
//! input may panic.

use std::path::{Path, PathBuf};

/// The names the `face` target's first byte picks from.
const FACE_NAMES: [&str; 4] = ["x.wrl", "x.wrl.gz", "x.obj", "x.glb"];

fn seeds(target: &str) -> Vec<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("fuzz/seeds")
        .join(target);
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .map(|d| d.map(|e| e.unwrap().path()).collect())
        .unwrap_or_default();
    files.sort();
    assert!(!files.is_empty(), "seeds in {}", dir.display());
    files
}

/// Each seed, then variants: cut at a few places and with one byte flipped at a few places.
fn variants(bytes: &[u8]) -> Vec<Vec<u8>> {
    let mut out = vec![bytes.to_vec()];
    let n = bytes.len();
    for cut in [1, n / 4, n / 2, n.saturating_sub(3)] {
        out.push(bytes[..cut.min(n)].to_vec());
    }
    for at in [1, n / 3, n / 2, (2 * n) / 3, n.saturating_sub(1)] {
        if at < n {
            let mut v = bytes.to_vec();
            v[at] ^= 0x5A;
            out.push(v);
        }
    }
    out
}

fn replay(target: &str, check: impl Fn(&[u8])) {
    for seed in seeds(target) {
        let bytes = std::fs::read(&seed).unwrap();
        for v in variants(&bytes) {
            check(&v);
        }
    }
    let crashes = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fuzz-regressions")
        .join(target);
    for f in std::fs::read_dir(crashes).into_iter().flatten() {
        check(&std::fs::read(f.unwrap().path()).unwrap());
    }
}

fn face(data: &[u8]) {
    let Some((&pick, content)) = data.split_first() else {
        return;
    };
    let name = FACE_NAMES[usize::from(pick) % FACE_NAMES.len()];
    let _ = fbakit::face::read_bytes(content, name, &fbakit::face::FaceReadOptions::default());
}

#[test]
fn face_seeds() {
    // The unmodified seeds are faces.
    for seed in seeds("face") {
        let bytes = std::fs::read(&seed).unwrap();
        let name = FACE_NAMES[usize::from(bytes[0]) % FACE_NAMES.len()];
        fbakit::face::read_bytes(&bytes[1..], name, &Default::default())
            .unwrap_or_else(|e| panic!("{}: {e}", seed.display()));
    }
    replay("face", face);
}

#[test]
fn gltf_rig_seeds() {
    for seed in seeds("gltf_rig") {
        let bytes = std::fs::read(&seed).unwrap();
        fbakit::rig::gltf_read::read_gltf_bytes(&bytes, &seed)
            .unwrap_or_else(|e| panic!("{}: {e}", seed.display()));
    }
    replay("gltf_rig", |d| {
        let _ = fbakit::rig::gltf_read::read_gltf_bytes(d, Path::new("fuzz.glb"));
    });
}

#[test]
fn landmark_ids_seeds() {
    replay("landmark_ids", |d| {
        let Ok(text) = std::str::from_utf8(d) else {
            return;
        };
        if let Ok(ids) = fbakit::fdp::landmarks::parse_landmark_ids(text, Path::new("fuzz.json")) {
            let _ = ids.check(68, 1000, "iBUG-68 landmarks");
            let _ = ids.check(468, 468, "MediaPipe landmarks");
        }
    });
}

#[test]
fn weights_csv_seeds() {
    for seed in seeds("weights_csv") {
        let text = std::fs::read_to_string(&seed).unwrap();
        fbakit::rig::capture::parse_capture(&text, &seed, None)
            .unwrap_or_else(|e| panic!("{}: {e}", seed.display()));
    }
    replay("weights_csv", |d| {
        let Ok(text) = std::str::from_utf8(d) else {
            return;
        };
        let file = Path::new("fuzz.csv");
        let _ = fbakit::rig::capture::parse_capture(text, file, None);
        let _ = fbakit::rig::capture::parse_capture(text, file, Some(30.0));
    });
}

/// The parser targets' seeds read (each format's own reader), and their cuts and flips
/// neither panic nor break the targets' round trips.
#[test]
fn parser_seeds() {
    fn text(d: &[u8]) -> Option<&str> {
        std::str::from_utf8(d).ok()
    }
    let strict = fbakit::fap::ReadOptions::strict();
    for seed in seeds("fap") {
        let t = std::fs::read_to_string(&seed).unwrap();
        fbakit::fap::parse_fap(&t, &seed, &strict)
            .unwrap_or_else(|e| panic!("{}: {e}", seed.display()));
    }
    replay("fap", |d| {
        let Some(t) = text(d) else { return };
        let p = Path::new("fuzz.fap");
        if let Ok((s, _)) = fbakit::fap::parse_fap(t, p, &strict) {
            let out = fbakit::fap::write_fap_string(&s);
            assert_eq!(fbakit::fap::parse_fap(&out, p, &strict).unwrap().0, s);
        }
    });
    for seed in seeds("vrml") {
        fbakit::vrml::parse_vrml_str(&std::fs::read_to_string(&seed).unwrap())
            .unwrap_or_else(|e| panic!("{}: {e}", seed.display()));
    }
    replay("vrml", |d| {
        if let Some(Ok(scene)) = text(d).map(fbakit::vrml::parse_vrml_str) {
            let written = fbakit::vrml::write_vrml_string(&scene);
            assert_eq!(fbakit::vrml::parse_vrml_str(&written).unwrap(), scene);
        }
    });
    for seed in seeds("obj") {
        let t = std::fs::read_to_string(&seed).unwrap();
        fbakit::mesh::obj::parse_obj(&t, &seed)
            .unwrap_or_else(|e| panic!("{}: {e}", seed.display()));
    }
    replay("obj", |d| {
        if let Some(t) = text(d) {
            let _ = fbakit::mesh::obj::parse_obj(t, Path::new("fuzz.obj"));
        }
    });
    for seed in seeds("wfm") {
        let t = std::fs::read_to_string(&seed).unwrap();
        fbakit::candide::parse_wfm(&t, &seed).unwrap_or_else(|e| panic!("{}: {e}", seed.display()));
    }
    replay("wfm", |d| {
        if let Some(t) = text(d) {
            let _ = fbakit::candide::parse_wfm(t, Path::new("fuzz.wfm"));
        }
    });
    for (target, name) in [
        ("fdp_xml", "f.xml"),
        ("fp_csv", "f.csv"),
        ("xface_fdp", "f.fdp"),
    ] {
        for seed in seeds(target) {
            let t = std::fs::read_to_string(&seed).unwrap();
            fbakit::fdp::parse_feature_points(&t, Path::new(name))
                .unwrap_or_else(|e| panic!("{}: {e}", seed.display()));
        }
        replay(target, |d| {
            if let Some(t) = text(d) {
                let _ = fbakit::fdp::parse_feature_points(t, Path::new(name));
            }
        });
    }
}

fn audio(data: &[u8]) {
    let Ok(mut r) = fbakit::speech::audio::audio_from_bytes(data.to_vec(), Path::new("x.audio"))
    else {
        return;
    };
    let mut samples = 0usize;
    loop {
        match r.next_chunk() {
            Ok(Some(c)) => {
                assert!(c.iter().all(|s| s.is_finite() && s.abs() <= 1.001));
                samples += c.len();
                assert!(samples < 16_000 * 60, "a 0.3 s seed gave a minute of audio");
            }
            Ok(None) => break,
            Err(e) => {
                assert!(e.to_string().contains("x.audio"), "{e}");
                break;
            }
        }
    }
}

#[test]
fn audio_seeds() {
    // The unmodified seeds decode to about 0.3 s each.
    for seed in seeds("audio") {
        let mut r = fbakit::speech::audio::open_audio(&seed)
            .unwrap_or_else(|e| panic!("{}: {e}", seed.display()));
        let mut n = 0;
        while let Some(c) = r.next_chunk().unwrap() {
            n += c.len();
        }
        assert!(
            (4_000..7_000).contains(&n),
            "{}: {n} samples",
            seed.display()
        );
    }
    replay("audio", audio);
}
