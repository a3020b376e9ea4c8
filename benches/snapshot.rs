//! `fbakit::snapshot` on the bundled `ict` head (a 24.6k-vertex glTF rig read with its FAT
//! built from its shapes), faces already in memory: `diff` against a copy with every table
//! perturbed, and `snapshot`. The budgets: diff under 0.1 s, snapshot under 0.05 s
//! (release).

use std::sync::OnceLock;

use fbakit::face::FaceModel;
use fbakit::snapshot::{diff, snapshot, DiffOptions, SnapshotOptions};

fn main() {
    divan::main();
}

fn faces() -> &'static (FaceModel, FaceModel) {
    static FACES: OnceLock<(FaceModel, FaceModel)> = OnceLock::new();
    FACES.get_or_init(|| {
        let a = fbakit::face::read("ict").unwrap();
        let mut b = a.clone();
        for t in &mut b.fat.tables {
            for m in &mut t.meshes {
                for d in m.displacements.iter_mut().step_by(7) {
                    *d *= 1.001;
                }
            }
        }
        (a, b)
    })
}

#[divan::bench(sample_count = 20)]
fn diff_ict(bencher: divan::Bencher) {
    let (a, b) = faces();
    bencher.bench(|| diff(a, b, &DiffOptions::default()));
}

#[divan::bench(sample_count = 20)]
fn snapshot_ict(bencher: divan::Bencher) {
    let (a, _) = faces();
    bencher.bench(|| snapshot(a, &SnapshotOptions::default()));
}
