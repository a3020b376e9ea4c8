//! Facial Motion Cloning speed: Candide-3 subdivided to ≥ 5 000 vertices with all its
//! translation-FAP motions, cloned onto a reshaped Candide-3 of ≥ 25 000 vertices.
//! Target: total < 1 s on 2 cores. Needs `../shared/data/candide3` (skips without it).
//!
//! Run: `cargo bench --bench clone_fmc`.

use std::sync::OnceLock;

use fbakit::clone::fixtures::candide;
use fbakit::clone::fmc::{clone_fmc, FmcOptions};
use fbakit::clone::{CloneSurface, SurfaceMotion};
use glam::Vec3;

fn main() {
    if let Some((s, m, t)) = faces() {
        let r = clone_fmc(s, m, t, &FmcOptions::default()).expect("clone");
        eprintln!(
            "source {} vertices, {} motions -> target {} vertices; steps (s): {:?}; total {:.3} s",
            s.positions.len(),
            m.len(),
            t.positions.len(),
            r.timings.steps,
            r.timings.total()
        );
    }
    divan::main();
}

type Faces = (CloneSurface, Vec<SurfaceMotion>, CloneSurface);

fn faces() -> Option<&'static Faces> {
    static FACES: OnceLock<Option<Faces>> = OnceLock::new();
    FACES
        .get_or_init(|| {
            let source = candide(&[], 3, 512.0)?;
            let target = candide(
                &[
                    ("Mouth width", 0.5),
                    ("Eyes, width", 0.3),
                    ("Head height", 0.2),
                ],
                4,
                512.0,
            )?;
            // Four subdivisions give ~23.9k vertices; split some triangles to pass 25k.
            let t = centroid_split(target.surface, 2_000);
            assert!(source.surface.positions.len() >= 5_000 && t.positions.len() >= 25_000);
            Some((source.surface, source.motions, t))
        })
        .as_ref()
}

#[divan::bench(sample_count = 10)]
fn fmc_5k_to_25k(bencher: divan::Bencher) {
    let Some((s, m, t)) = faces() else {
        eprintln!("note: ../shared/data/candide3 not found; skipping");
        return;
    };
    bencher.bench(|| clone_fmc(s, m, t, &FmcOptions::default()).expect("clone"));
}

/// Splits the first `count` triangles at their centroids (adds `count` vertices).
fn centroid_split(mut s: CloneSurface, count: usize) -> CloneSurface {
    let mut out = Vec::with_capacity(s.triangles.len() + 2 * count);
    for (i, t) in s.triangles.iter().enumerate() {
        if i < count {
            let c = t.iter().map(|&v| s.positions[v as usize]).sum::<Vec3>() / 3.0;
            s.positions.push(c);
            let m = s.positions.len() as u32 - 1;
            out.extend([[t[0], t[1], m], [t[1], t[2], m], [t[2], t[0], m]]);
        } else {
            out.push(*t);
        }
    }
    s.triangles = out;
    s
}
