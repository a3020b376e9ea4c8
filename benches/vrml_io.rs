//! VRML97 parse throughput and write time on a generated 50 000-vertex face-like file
//! (IndexedFaceSet with ~100 000 triangles plus an FDP whose FaceDefMesh tables carry many
//! displacements). Target: parsing at >= 40 MB/s.

use std::fmt::Write as _;

use divan::counter::BytesCount;
use divan::{black_box, Bencher};
use fbakit::vrml::{parse_vrml_str, write_vrml_string};

fn main() {
    divan::main();
}

/// Deterministic pseudo-random coordinates (no RNG crate needed).
fn coord(i: usize, k: usize) -> f32 {
    let h = (i as u64 * 2_654_435_761 + k as u64 * 40_503).wrapping_mul(0x9E37_79B9) >> 40;
    (h % 200_000) as f32 / 100_000.0 - 1.0
}

fn face_file() -> String {
    const W: usize = 250;
    const H: usize = 200; // 50 000 vertices, 2 x 249 x 199 = 99 102 triangles
    let mut s = String::from("#VRML V2.0 utf8\nDEF Head Transform { children [\n");
    s.push_str(
        "DEF Skin Shape { geometry DEF FaceMesh IndexedFaceSet {\n coord Coordinate { point [\n",
    );
    for i in 0..W * H {
        let _ = writeln!(s, "  {} {} {},", coord(i, 0), coord(i, 1), coord(i, 2));
    }
    s.push_str(" ] }\n coordIndex [\n");
    for y in 0..H - 1 {
        for x in 0..W - 1 {
            let a = y * W + x;
            let _ = writeln!(
                s,
                "  {} {} {} -1, {} {} {} -1,",
                a,
                a + 1,
                a + W,
                a + 1,
                a + W + 1,
                a + W
            );
        }
    }
    s.push_str(" ] } } ] }\n");
    s.push_str("Face { fdp FDP { faceDefTables [\n");
    for fap in 3..=68 {
        let _ = write!(
            s,
            "FaceDefTables {{ fapID {fap} faceDefMesh FaceDefMesh {{ faceSceneGraphNode USE FaceMesh\n intervalBorders [ -1000 0 1000 ]\n coordIndex ["
        );
        for v in 0..300 {
            let _ = write!(s, " {}", (fap * 733 + v * 97) % (W * H));
        }
        s.push_str(" ]\n displacements [\n");
        for v in 0..600 {
            let _ = writeln!(
                s,
                "  {} {} {},",
                coord(v, fap) * 1e-3,
                coord(v, 1) * 1e-3,
                0.0001
            );
        }
        s.push_str(" ] } }\n");
    }
    s.push_str("] } }\n");
    s
}

#[divan::bench(sample_count = 20)]
fn parse(bencher: Bencher) {
    let text = face_file();
    bencher
        .counter(BytesCount::new(text.len()))
        .bench(|| parse_vrml_str(black_box(&text)).unwrap());
}

#[divan::bench(sample_count = 20)]
fn write(bencher: Bencher) {
    let scene = parse_vrml_str(&face_file()).unwrap();
    bencher.bench(|| write_vrml_string(black_box(&scene)));
}
