//! Forced alignment of recordings longer than one piece (`fbakit::speech::lipsync::pieces`):
//! a recording of more than two minutes made from Festival's sentences, which the
//! recogniser aligns a piece at a time, meets issue 22's targets with a transcript. Before
//! pieces, recordings over 120 s kept the warp's times (93.4 % closures, 78.7 % agreement,
//! 4.9 % false closures on Festival's voices). Skipped without espeak-ng, PocketSphinx or
//! Festival's kal voice (`.ci/run` installs them).

#[path = "../examples/lipsync_eval.rs"]
mod lipsync_eval;

#[test]
fn a_long_recording_is_aligned_piecewise_and_meets_the_targets() {
    let name = "a_long_recording_is_aligned_piecewise_and_meets_the_targets";
    let c = lipsync_eval::conditions()
        .into_iter()
        .find(|c| c.voice == "kal_diphone")
        .expect("the kal condition");
    if !fbakit::speech::espeak_available()
        || !fbakit::speech::lipsync::forced::available()
        || !lipsync_eval::festival_voice_available(c.voice)
    {
        eprintln!(
            "skip {name}: needs espeak-ng pocketsphinx pocketsphinx-en-us festival \
             festvox-kallpc16k"
        );
        return;
    }
    let r = lipsync_eval::run_long_case(&c, 125.0, 25.0, None).unwrap();
    let s = &r.aligned;
    eprintln!(
        "{:.1} s: closures {:.3}, agreement {:.3}, false closures {:.3}; {:?}",
        r.audio_seconds,
        s.closure_rate(),
        s.agreement(),
        s.false_closure_rate(),
        r.warnings
    );
    assert!(r.audio_seconds > 120.0, "{}", r.audio_seconds);
    assert!(s.closures >= 100, "{s:?}");
    assert!(s.closure_rate() >= 0.95, "{s:?}");
    assert!(s.agreement() >= 0.85, "{s:?}");
    assert!(s.false_closure_rate() <= 0.02, "{s:?}");
    // Every piece fitted.
    assert!(r.warnings.is_empty(), "{:?}", r.warnings);
    // The recogniser gives each phone its own confidence.
    let mut c = r.confidences.clone();
    c.sort_by(f64::total_cmp);
    assert!(c[c.len() / 10] < c[c.len() * 9 / 10], "{:?}", &c[..10]);
}
