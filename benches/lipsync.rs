//! Lip sync's own work on 10 s of audio (espeak-ng's synthesis left out, so the bench runs
//! without it): MFCC features of a 16 kHz recording, the coarse-to-fine warp between
//! two 10 s feature sequences that differ in speed, and the search for lip closures in the
//! sound (lip sync without a transcript). Real-time factor = 10 s / the sum.
//!
//! Run: `cargo bench --bench lipsync`

use fbakit::speech::lipsync::alignment::warp;
use fbakit::speech::lipsync::features::{normalise, FeatureExtractor};

fn main() {
    divan::main();
}

/// 10 s of a speech-like signal at 16 kHz: a buzz whose pitch and formant-like
/// resonance wander, in syllable-sized bursts.
fn signal(speed: f32) -> Vec<f32> {
    (0..160_000)
        .map(|n| {
            let t = n as f32 / 16_000.0 * speed;
            let envelope = (t * 2.0 * std::f32::consts::PI * 4.0).sin().max(0.0);
            let pitch = 120.0 + 30.0 * (t * 0.7).sin();
            let formant = 700.0 + 500.0 * (t * 3.1).sin();
            envelope
                * ((t * pitch * 2.0 * std::f32::consts::PI).sin() * 0.3
                    + (t * formant * 2.0 * std::f32::consts::PI).sin() * 0.2)
        })
        .collect()
}

fn features(x: &[f32]) -> Vec<fbakit::speech::lipsync::features::FeatureFrame> {
    let mut fx = FeatureExtractor::new();
    for c in x.chunks(8_192) {
        fx.push(c);
    }
    fx.finish()
}

#[divan::bench]
fn features_10s(bencher: divan::Bencher) {
    let x = signal(1.0);
    bencher.bench(|| features(divan::black_box(&x)));
}

#[divan::bench]
fn warp_10s(bencher: divan::Bencher) {
    let a = normalise(&features(&signal(1.0)));
    let b = normalise(&features(&signal(1.2)));
    bencher.bench(|| warp(divan::black_box(&a), divan::black_box(&b), 12, 1.0));
}

#[divan::bench]
fn acoustic_closures_10s(bencher: divan::Bencher) {
    let f = features(&signal(1.0));
    bencher
        .bench(|| fbakit::speech::lipsync::closures::acoustic_closures(divan::black_box(&f), &[]));
}
