//! Whole-face cloning: alma (≈7.9k skin vertices, 86 tables) → bruno (≈26.5k), both methods,
//! and self-cloning of bruno. Target: each < 1 s on 2 cores.

use fbakit::clone::eval::self_clone_error;
use fbakit::clone::face::{clone_face, CloneOptions, Method};
use fbakit::face::FaceModel;

fn main() {
    divan::main();
}

fn faces() -> &'static (FaceModel, FaceModel) {
    static F: std::sync::OnceLock<(FaceModel, FaceModel)> = std::sync::OnceLock::new();
    F.get_or_init(|| {
        (
            fbakit::synth::alma().to_face_model(),
            fbakit::synth::bruno().to_face_model(),
        )
    })
}

#[divan::bench(args = [Method::Fmc, Method::Rbf], sample_count = 5)]
fn alma_to_bruno(method: Method) {
    let (a, b) = faces();
    let opts = CloneOptions {
        method,
        ..CloneOptions::default()
    };
    divan::black_box(clone_face(a, b, &opts).expect("clone"));
}

#[divan::bench(args = [Method::Fmc, Method::Rbf], sample_count = 5)]
fn self_clone_bruno(method: Method) {
    let (_, b) = faces();
    divan::black_box(self_clone_error(b, method).expect("self clone"));
}
