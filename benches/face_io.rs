//! Face files and FAT evaluation on a ~55 000-vertex procedural face with a full FAT (the
//! `bruno` generator on a finer grid: 320 × 160 skin quads plus eyes, teeth and tongue;
//! 66 low-level FAPs, 14 visemes, 6 expressions).
//!
//! - `read_vrml`: text → scene → `FaceModel` (throughput in bytes; target ≥ 40 MB/s).
//! - `write_vrml`: `FaceModel` → VRML text.
//! - `read_vrml_gz`: the same face from `.wrl.gz` (decompression + parse).
//! - `evaluate_all_tables`: one frame with every table active (all 66 low-level FAPs, one
//!   viseme pair, one expression pair) on all vertices (target < 1 ms).

use std::sync::LazyLock;

use divan::counter::BytesCount;
use divan::{black_box, Bencher};
use fbakit::face::vrml::{face_from_scene, write_face_string};
use fbakit::face::FaceModel;
use fbakit::fat::eval::Activation;
use fbakit::io::{gunzip_bounded, gzip};
use fbakit::synth::{generate, HeadParams};

fn main() {
    let f = &*FACE;
    eprintln!(
        "face: {} vertices, {} FAT tables, {} FAT vertex entries, VRML {:.1} MB, gzip {:.1} MB",
        f.face.vertex_count(),
        f.face.fat.tables.len(),
        f.face
            .fat
            .tables
            .iter()
            .map(|t| t.moved_vertex_count())
            .sum::<usize>(),
        f.text.len() as f64 / 1e6,
        f.gz.len() as f64 / 1e6
    );
    divan::main();
}

struct Fixture {
    face: FaceModel,
    text: String,
    gz: Vec<u8>,
}

static FACE: LazyLock<Fixture> = LazyLock::new(|| {
    let params = HeadParams {
        name: "bench".into(),
        columns: 320,
        rows: 160,
        ..HeadParams::bruno()
    };
    let face = generate(&params).to_face_model();
    let text = write_face_string(&face).expect("writes");
    let mut gz = Vec::new();
    gzip(text.as_bytes(), &mut gz).expect("compresses");
    Fixture { face, text, gz }
});

#[divan::bench(sample_count = 10)]
fn read_vrml(b: Bencher) {
    let text = &FACE.text;
    b.counter(BytesCount::new(text.len())).bench(|| {
        let scene = fbakit::vrml::parse_vrml_str(black_box(text)).expect("parses");
        face_from_scene(scene, "bench").expect("reads")
    });
}

#[divan::bench(sample_count = 10)]
fn read_vrml_gz(b: Bencher) {
    let gz = &FACE.gz;
    b.counter(BytesCount::new(FACE.text.len())).bench(|| {
        let raw = gunzip_bounded(black_box(gz), 1 << 30).expect("gunzips");
        let text = String::from_utf8(raw).expect("utf-8");
        let scene = fbakit::vrml::parse_vrml_str(&text).expect("parses");
        face_from_scene(scene, "bench").expect("reads")
    });
}

#[divan::bench(sample_count = 10)]
fn write_vrml(b: Bencher) {
    let face = &FACE.face;
    b.counter(BytesCount::new(FACE.text.len()))
        .bench(|| write_face_string(black_box(face)).expect("writes"));
}

#[divan::bench(sample_count = 200)]
fn evaluate_all_tables(b: Bencher) {
    let face = &FACE.face;
    let mut eval = face.evaluator().expect("binds");
    let mut out = eval.output();
    let acts: Vec<Activation> = face
        .fat
        .keys()
        .into_iter()
        .map(|key| Activation { key, value: 200.0 })
        .collect();
    b.bench_local(|| {
        eval.evaluate(black_box(&acts), &mut out);
        black_box(&out);
    });
}
