//! Player speed on the synthetic `bruno` face (~27 000 skin vertices, six meshes).
//!
//! - `one_frame_all_faps`: one frame with all 66 low-level FAPs, a viseme blend and an
//!   expression mix, evaluated into reused buffers. Target: < 1 ms (≥ 1 000 frames/s).
//! - `ten_seconds_to_glb`: a 10 s, 25 fps stream (250 frames) played into `.glb` bytes
//!   (morph targets from the FAT, weights and transform channels). Target: < 1 s.
//!
//! Measured (2-core shared machine, release): one frame median 98 µs (≈ 10 000 frames/s);
//! 10 s stream to `.glb` median 17 ms (3 MB).

use fbakit::export::gltf::face_to_gltf;
use fbakit::face::FaceModel;
use fbakit::fap::{ExpressionParams, FapFrame, FapStream, VisemeParams};
use fbakit::player::{PlayOptions, Player};
use fbakit::spec::{Expression, FapId, Viseme};

fn main() {
    divan::main();
}

fn bruno() -> FaceModel {
    fbakit::synth::bruno().to_face_model()
}

/// Frame `n` of a busy stream: every low-level FAP moving, visemes and expressions changing.
fn busy_frame(n: u64) -> FapFrame {
    let mut f = FapFrame::new(n);
    for id in FapId::low_level() {
        let phase = n as f64 * 0.2 + id.number() as f64;
        let amplitude = if id.info().is_rotation() {
            10_000.0
        } else {
            150.0
        };
        let v = amplitude * phase.sin();
        // Unidirectional FAPs only take values >= 0.
        let v = if id.info().accepts(v) { v } else { -v };
        f.set(id, v.round());
    }
    f.set_viseme(Some(VisemeParams {
        select1: Viseme::new((n % 14 + 1) as u8).unwrap(),
        select2: Viseme::new(((n + 5) % 14 + 1) as u8).unwrap(),
        blend: (n * 7 % 64) as u8,
        def: false,
    }));
    f.set_expression(Some(ExpressionParams {
        select1: Expression::new((n % 6 + 1) as u8).unwrap(),
        intensity1: (n * 5 % 64) as u8,
        select2: Expression::new(((n + 2) % 6 + 1) as u8).unwrap(),
        intensity2: 20,
        init_face: false,
        def: false,
    }));
    f
}

fn stream(frames: u64) -> FapStream {
    FapStream {
        frames: (0..frames).map(busy_frame).collect(),
        ..FapStream::new("busy", 25.0)
    }
}

#[divan::bench(sample_count = 50)]
fn one_frame_all_faps(bencher: divan::Bencher) {
    let face = bruno();
    let s = stream(50);
    let mut player = Player::new(&face, &s, &PlayOptions::default()).unwrap();
    let mut frame = player.new_frame();
    let mut n = 0;
    bencher.bench_local(|| {
        player.frame_at(n % 50, &mut frame);
        n += 1;
        divan::black_box(&frame);
    });
}

#[divan::bench(sample_count = 10)]
fn ten_seconds_to_glb(bencher: divan::Bencher) {
    let face = bruno();
    let s = stream(250);
    bencher.bench_local(|| {
        let player = Player::new(&face, &s, &PlayOptions::default()).unwrap();
        let anim = player.animation().unwrap();
        face_to_gltf(&face, Some(&anim)).unwrap().to_glb().unwrap()
    });
}
