//! Reading and writing a large, realistic FAP stream (100 000 frames, ~30 FAPs per frame).
//!
//! Run: `cargo bench --bench fap_io`

use std::path::Path;

use divan::counter::BytesCount;
use fbakit::fap::{parse_fap, write_fap_string, FapFrame, FapStream, ReadOptions};
use fbakit::spec::FapId;

fn main() {
    divan::main();
}

/// 100 000 frames; 30 low-level FAPs per frame (jaw, lips, eyelids, brows, head), values a
/// deterministic mix of small and large integers with some decimals.
fn stream() -> FapStream {
    let faps: Vec<FapId> = [
        3u8, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 16, 17, 19, 20, 21, 22, 31, 32, 33, 34, 35, 36, 48,
        49, 50, 51, 52, 53, 54,
    ]
    .into_iter()
    .map(|n| FapId::new(n).unwrap())
    .collect();
    let mut s = FapStream::new("bench", 25.0);
    for n in 0..100_000u64 {
        let mut f = FapFrame::new(n);
        for (k, &id) in faps.iter().enumerate() {
            let raw = ((n * 37 + k as u64 * 101) % 2001) as f64 - 1000.0;
            let v = if id.info().accepts(raw) { raw } else { -raw };
            let v = if k % 10 == 9 { v + 0.5 } else { v };
            let v = if id.number() >= 48 && id.number() <= 50 {
                v * 20.0
            } else {
                v
            };
            f.set(id, v);
        }
        s.frames.push(f);
    }
    s
}

#[divan::bench(sample_count = 10)]
fn read_strict(bencher: divan::Bencher) {
    let text = write_fap_string(&stream());
    bencher.counter(BytesCount::new(text.len())).bench(|| {
        parse_fap(
            divan::black_box(&text),
            Path::new("bench.fap"),
            &ReadOptions::strict(),
        )
        .unwrap()
    });
}

#[divan::bench(sample_count = 10)]
fn read_lenient(bencher: divan::Bencher) {
    let text = write_fap_string(&stream());
    bencher.counter(BytesCount::new(text.len())).bench(|| {
        parse_fap(
            divan::black_box(&text),
            Path::new("bench.fap"),
            &ReadOptions::lenient(),
        )
        .unwrap()
    });
}

#[divan::bench(sample_count = 10)]
fn write(bencher: divan::Bencher) {
    let s = stream();
    let len = write_fap_string(&s).len();
    bencher
        .counter(BytesCount::new(len))
        .bench(|| write_fap_string(divan::black_box(&s)));
}
