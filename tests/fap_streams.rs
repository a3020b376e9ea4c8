//! FAP stream reading/writing on real third-party files, bundled samples and hostile input.

use std::path::{Path, PathBuf};

use fbakit::error::Severity;
use fbakit::fap::{
    parse_fap, read_fap_file, validate_fap_str, write_fap_string, FapFrame, FapStream, ReadOptions,
};
use fbakit::spec::FapId;

fn shared(dir: &str) -> Option<PathBuf> {
    let p = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../shared/data")).join(dir);
    if p.is_dir() {
        Some(p)
    } else {
        eprintln!("note: {} missing, test skipped", p.display());
        None
    }
}

#[test]
fn xface_files_read_leniently_and_round_trip() {
    let Some(dir) = shared("xface-faps") else {
        return;
    };
    // The backslash name is one token, hence valid; but both files carry negative values of the
    // unidirectional open_jaw, so strict reading stops there.
    for (file, frames, masks, strict_error) in [
        (
            "joy.fap",
            108,
            1,
            "159:4: expected a value >= 0 for unidirectional FAP 3 (open_jaw), found `-5`",
        ),
        (
            "hate.fap",
            107,
            3,
            "17:91: expected a value >= 0 for unidirectional FAP 41 (lift_l_cheek), found `-4`",
        ),
    ] {
        let path = dir.join(file);
        let e = read_fap_file(&path, &ReadOptions::strict())
            .unwrap_err()
            .to_string();
        assert_eq!(e, format!("{}:{strict_error}", path.display()));
        let (s, w) = read_fap_file(&path, &ReadOptions::lenient()).unwrap();
        assert_eq!(w.len(), 1, "{w:?}");
        assert!(w[0].message.starts_with("unidirectional FAP"), "{w:?}");
        assert_eq!(s.name, r"C:\Users\balci\Work\FACE\exml2fap\files\TempFile");
        assert_eq!(s.frame_rate, 25.0);
        assert_eq!(s.frames.len(), frames);
        let mut distinct: Vec<_> = s.frames.iter().map(|f| f.mask()).collect();
        distinct.sort();
        distinct.dedup();
        assert_eq!(distinct.len(), masks, "{file}");
        // write -> read gives the model back.
        let text = write_fap_string(&s);
        let (back, _) = parse_fap(&text, Path::new("out.fap"), &ReadOptions::lenient()).unwrap();
        assert_eq!(back, s, "{file}");
    }
}

#[test]
fn greta_files_read_leniently_and_fail_strictly_with_locations() {
    let Some(dir) = shared("greta-faps") else {
        return;
    };
    let cases = [
        (
            "1-Welcome_1.fap",
            "2:137: expected end of line after 68 mask entries, found `0`",
        ),
        (
            "AU Interpolation_2.fap",
            "1:8: expected the frame rate (the name must be one token without spaces), found `Interpolation_2.fap`",
        ),
        (
            "AU Interpolation_1270.fap",
            "1:8: expected the frame rate (the name must be one token without spaces), found `Interpolation_1270.fap`",
        ),
    ];
    for (file, strict_error) in cases {
        let path = dir.join(file);
        let (s, w) = read_fap_file(&path, &ReadOptions::lenient()).unwrap();
        assert_eq!(s.frames.len(), 1);
        assert!(w.iter().all(|d| d.severity == Severity::Warning));
        assert!(!w.is_empty());
        let e = read_fap_file(&path, &ReadOptions::strict())
            .unwrap_err()
            .to_string();
        assert_eq!(e, format!("{}:{strict_error}", path.display()), "{file}");
    }
    let (s, w) =
        read_fap_file(&dir.join("AU Interpolation_2.fap"), &ReadOptions::lenient()).unwrap();
    assert_eq!(s.name, "AU Interpolation_2.fap");
    let f = &s.frames[0];
    assert_eq!(f.value(FapId::OPEN_JAW), Some(73.0));
    assert_eq!(f.values().len(), 28);
    assert_eq!(f.value(FapId::new(63).unwrap()), Some(0.0));
    assert_eq!(w.len(), 2, "{w:?}");
    let (s, w) = read_fap_file(&dir.join("1-Welcome_1.fap"), &ReadOptions::lenient()).unwrap();
    let v = s.frames[0].viseme().unwrap();
    assert_eq!(v.select1.number(), 0);
    assert_eq!(w.len(), 2, "{w:?}");
    assert!(
        w[1].to_string()
            .contains("3:3: warning: FAP 1 has a single value"),
        "{w:?}"
    );
    let (s, _) = read_fap_file(
        &dir.join("AU Interpolation_1270.fap"),
        &ReadOptions::lenient(),
    )
    .unwrap();
    let eyelids: Vec<f64> = (19..=22)
        .filter_map(|n| s.frames[0].value(FapId::new(n).unwrap()))
        .collect();
    assert_eq!(eyelids, [626.0, 626.0, 133.0, 133.0]);
}

fn text_of(faps: &[(u8, f64)]) -> FapStream {
    let mut f = FapFrame::new(0);
    for &(n, v) in faps {
        f.set(FapId::new(n).unwrap(), v);
    }
    FapStream {
        frames: vec![f],
        ..FapStream::new("x", 25.0)
    }
}

fn strict_err(text: &str) -> String {
    parse_fap(text, Path::new("h.fap"), &ReadOptions::strict())
        .unwrap_err()
        .to_string()
}

#[test]
fn hostile_inputs_are_located_errors() {
    let good = write_fap_string(&text_of(&[(3, 10.0)]));
    let mask = good.lines().nth(1).unwrap();
    assert_eq!(strict_err(""), "h.fap:1:1: expected a header line `<version> <name> <frame_rate> <frame_count>`, found end of input");
    assert_eq!(
        strict_err("2.1 x 25 1000000000000\n"),
        "h.fap:1:10: expected a frame count <= 4294967295, found `1000000000000`"
    );
    assert!(strict_err(&format!("2.1 x 25 1\n{mask}\n0 NaN\n"))
        .starts_with("h.fap:3:3: expected a finite value"));
    assert!(strict_err(&format!("2.1 x 25 1\n{mask}\n0 -inf\n"))
        .starts_with("h.fap:3:3: expected a finite value"));
    assert!(strict_err("2.1 x 0 1\n").starts_with("h.fap:1:7: expected a frame rate"));
    assert!(strict_err("2.1 x -3 1\n").starts_with("h.fap:1:7: expected a frame rate"));
    assert!(strict_err(&format!("2.1 x 25 1\n{mask}"))
        .starts_with("h.fap:2:136: expected the value line"));
    assert!(strict_err("\u{1}\u{2}\u{3}\u{fffd}\u{0}").starts_with("h.fap:1:1: expected a header"));
    // Empty lenient read is still an error.
    assert!(parse_fap("", Path::new("e"), &ReadOptions::lenient()).is_err());
}

#[test]
fn megabyte_single_line_is_read_linearly() {
    // A header followed by a 1 MB line of mask-like entries: one located error, quickly.
    let long = "0 ".repeat(512 * 1024);
    let e = strict_err(&format!("2.1 x 25 1\n{long}\n0\n"));
    assert!(
        e.starts_with("h.fap:2:137: expected end of line after 68 mask entries"),
        "{e}"
    );
    // Leniently the extra (all-zero) entries are ignored with one warning.
    let (s, w) = parse_fap(
        &format!("2.1 x 25 1\n{long}\n0\n"),
        Path::new("h.fap"),
        &ReadOptions::lenient(),
    )
    .unwrap();
    assert_eq!(s.frames.len(), 1);
    assert_eq!(w.len(), 1);
    // A 1 MB header line.
    let e = strict_err(&format!("2.1 {long}25 1\n"));
    assert!(e.contains("expected the frame rate"), "{e}");
    // A 1 MB value line.
    let one = write_fap_string(&text_of(&[(3, 1.0)]));
    let mask = one.lines().nth(1).unwrap();
    let e = strict_err(&format!("2.1 x 25 1\n{mask}\n0 {long}\n"));
    assert!(e.starts_with("h.fap:3:5: expected end of line"), "{e}");
    let all = validate_fap_str(
        &format!("2.1 x 25 1\n{mask}\n0 {long}\n"),
        Path::new("h.fap"),
    );
    assert_eq!(all.len(), 1);
}

mod round_trip {
    use super::*;
    use fbakit::fap::{ExpressionParams, VisemeParams};
    use fbakit::spec::{Expression, Viseme};
    use proptest::prelude::*;

    fn value() -> impl Strategy<Value = f64> {
        prop_oneof![
            (-5000i32..5000).prop_map(f64::from),
            (-1e6f64..1e6).prop_filter("finite", |v| v.is_finite()),
        ]
    }

    type FrameParts = (
        u64,
        Vec<(u8, f64)>,
        Option<VisemeParams>,
        Option<ExpressionParams>,
    );

    fn frame() -> impl Strategy<Value = FrameParts> {
        let viseme = (0u8..15, 0u8..15, 0u8..64, any::<bool>()).prop_map(|(a, b, blend, def)| {
            VisemeParams {
                select1: Viseme::new(a).unwrap(),
                select2: Viseme::new(b).unwrap(),
                blend,
                def,
            }
        });
        let expr = (
            0u8..7,
            0u8..64,
            0u8..7,
            0u8..64,
            any::<bool>(),
            any::<bool>(),
        )
            .prop_map(|(a, i1, b, i2, init_face, def)| ExpressionParams {
                select1: Expression::new(a).unwrap(),
                intensity1: i1,
                select2: Expression::new(b).unwrap(),
                intensity2: i2,
                init_face,
                def,
            });
        (
            1u64..5,
            proptest::collection::vec((3u8..=68, value()), 0..12),
            proptest::option::of(viseme),
            proptest::option::of(expr),
        )
    }

    fn stream() -> impl Strategy<Value = FapStream> {
        (
            "[A-Za-z0-9_.:\\\\/-]{1,12}",
            prop_oneof![Just(25.0), Just(29.97), 1.0f64..120.0],
            proptest::collection::vec(frame(), 0..8),
        )
            .prop_map(|(name, fps, frames)| {
                let mut number = 0u64;
                let frames = frames
                    .into_iter()
                    .map(|(step, faps, v, e)| {
                        number += step;
                        let mut f = FapFrame::new(number);
                        for (n, val) in faps {
                            let id = FapId::new(n).unwrap();
                            // Unidirectional FAPs take only values >= 0.
                            let val = if id.info().accepts(val) { val } else { -val };
                            f.set(id, val);
                        }
                        f.set_viseme(v);
                        f.set_expression(e);
                        f
                    })
                    .collect();
                FapStream {
                    version: "2.1".into(),
                    name,
                    frame_rate: fps,
                    frames,
                }
            })
    }

    proptest! {
        #[test]
        fn write_then_strict_read_is_identity(s in stream()) {
            let text = write_fap_string(&s);
            let (back, w) = parse_fap(&text, Path::new("p.fap"), &ReadOptions::strict()).unwrap();
            prop_assert!(w.is_empty());
            prop_assert_eq!(&back, &s);
            // And the JSON view round-trips too.
            let json = serde_json::to_string(&s).unwrap();
            let from_json: FapStream = serde_json::from_str(&json).unwrap();
            prop_assert_eq!(from_json, s);
        }
    }
}

#[path = "../examples/make_sample_faps.rs"]
mod make_sample_faps;

#[test]
fn committed_samples_match_the_generator() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("samples");
    for (file, text) in [
        ("speech.fap", make_sample_faps::speech()),
        ("lowlevel.fap", make_sample_faps::lowlevel()),
    ] {
        let committed = std::fs::read_to_string(dir.join(file)).unwrap();
        assert_eq!(
            committed, text,
            "{file} drifted: run `cargo run --example make_sample_faps`"
        );
        let (s, w) = parse_fap(&text, Path::new(file), &ReadOptions::strict()).unwrap();
        assert!(w.is_empty());
        // Comments aside, the samples are in canonical form.
        let body: String = text
            .lines()
            .filter(|l| !l.starts_with('#'))
            .map(|l| format!("{l}\n"))
            .collect();
        assert_eq!(write_fap_string(&s), body);
        insta::assert_snapshot!(format!("canonical_{file}"), write_fap_string(&s));
    }
}

/// Replays every input in `tests/fuzz-regressions/fap/` through the fuzz target's checks.
#[test]
fn fuzz_regressions_replay() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fuzz-regressions/fap");
    let mut n = 0;
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        let bytes = std::fs::read(&path).unwrap();
        let Ok(text) = std::str::from_utf8(&bytes) else {
            continue;
        };
        n += 1;
        let p = Path::new("fuzz.fap");
        if let Ok((s, _)) = parse_fap(text, p, &ReadOptions::strict()) {
            let (back, _) = parse_fap(&write_fap_string(&s), p, &ReadOptions::strict()).unwrap();
            assert_eq!(back, s, "{}", path.display());
            assert!(validate_fap_str(text, p).is_empty(), "{}", path.display());
        }
        if let Ok((s, _)) = parse_fap(text, p, &ReadOptions::lenient()) {
            let (back, _) = parse_fap(&write_fap_string(&s), p, &ReadOptions::lenient()).unwrap();
            assert_eq!(back, s, "{}", path.display());
        }
        let _ = validate_fap_str(text, p);
    }
    assert!(n >= 3, "regression inputs present");
}
