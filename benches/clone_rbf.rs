//! Speed of `clone::rbf::clone_rbf` on a dense synthetic pair: Candide-3 subdivided three
//! times (source, all its FAP motions) onto a reshaped Candide-3 subdivided five times
//! (target). Target: the whole clone under 1 s on 2 cores. Skips (with a note) when
//! `../shared/data/candide3` is absent.

use fbakit::clone::rbf::{clone_rbf, RbfOptions};

use fbakit::clone::fixtures::{candide, CandideFace};

fn main() {
    divan::main();
}

fn faces() -> Option<(CandideFace, CandideFace)> {
    let source = candide(&[], 3, 512.0)?;
    let target = candide(
        &[
            ("Mouth width", 0.5),
            ("Eyes, width", 0.3),
            ("Head height", 0.2),
        ],
        5,
        512.0,
    )?;
    Some((source, target))
}

#[divan::bench(sample_count = 5)]
fn candide_sub3_to_reshaped_sub5(bencher: divan::Bencher) {
    let Some((source, target)) = faces() else {
        return;
    };
    let opts = RbfOptions::default();
    let once = clone_rbf(&source.surface, &source.motions, &target.surface, &opts).unwrap();
    eprintln!(
        "\nsource {} vertices, {} motions; target {} vertices",
        source.surface.positions.len(),
        source.motions.len(),
        target.surface.positions.len()
    );
    for (step, s) in &once.timings.steps {
        eprintln!("  {step:<9} {:>8.1} ms", s * 1e3);
    }
    eprintln!("  total     {:>8.1} ms", once.timings.total() * 1e3);
    eprintln!("  stats {:?}", once.stats);
    bencher.bench(|| {
        clone_rbf(
            divan::black_box(&source.surface),
            &source.motions,
            &target.surface,
            &opts,
        )
        .unwrap()
    });
}
