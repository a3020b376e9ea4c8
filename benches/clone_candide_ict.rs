//! The whole clone of a dense CANDIDE-3 face (Loop-subdivided three times: 5 993 vertices,
//! 46 tables) onto the bundled real head `ict` (24 591 vertices, one mesh), per method.
//! Skipped when `../shared/data/candide3` is absent. Each method's step timings (one run)
//! and the process's peak memory are printed before the measured runs.
//!
//! Figures for `fit` (issue 21's target: ≤ 0.3 s, ≤ 200 MB, release, 2 cores). Stop 31, quiet
//! machine (load < 1.5): 356–362 ms median; step split register ~150, bound 76–84, parts 21,
//! fold 17–22 ms; peak memory 97 MB. Helper `speed5` (the bound step's fills on flat tables
//! and four-lane vectors, a motion's held and spread rounds side by side; outputs bit for bit
//! the same), measured on a machine shared by four sessions, old and new binaries alternated
//! in the same minutes: at load 7.5, 5-sample medians 1.04 / 1.10 / 1.14 s → 0.94 / 0.95 /
//! 0.96 s, the bound step 219 / 209 / 199 → 171 / 155 / 110 ms; with one thread
//! (`RAYON_NUM_THREADS=1`, load ~8, six runs each) the bound step's median 217 → 150 ms.
//! Most of that step's work on this pair is one motion (`open_jaw`: 2 900 vertices
//! re-solved; under load its held rounds 109 ms and its spread rounds, never kept here, 75 ms,
//! of ~250 ms for all twelve motions bounded). Not re-measured on a quiet machine.

use std::path::Path;
use std::sync::OnceLock;

use fbakit::clone::face::{clone_face, CloneOptions, Method};
use fbakit::face::candide::candide_face;
use fbakit::face::subdivide::subdivide_face;
use fbakit::face::FaceModel;
use fbakit::mesh::subdivide::Scheme;

fn main() {
    divan::main();
}

/// Dense CANDIDE and the bundled head.
fn faces() -> Option<&'static (FaceModel, FaceModel)> {
    static F: OnceLock<Option<(FaceModel, FaceModel)>> = OnceLock::new();
    F.get_or_init(|| {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/data/candide3");
        if !dir.join("candide3.wfm").is_file() {
            eprintln!("note: {} not found; skipping", dir.display());
            return None;
        }
        let model = fbakit::candide::read_wfm_file(&dir.join("candide3.wfm")).expect("wfm");
        let fp = fbakit::fdp::csv::read_csv_file(&dir.join("feature-points.csv"))
            .expect("fp")
            .to_set();
        let candide = candide_face(&model, &fp, &[]).expect("candide face");
        let dense = subdivide_face(&candide, Scheme::Loop, 3).expect("subdivide");
        let ict = fbakit::face::read("ict").expect("bundled ict");
        for method in [Method::Fmc, Method::Rbf, Method::Fit] {
            let out = clone_face(&dense, &ict, &opts(method)).expect("clone");
            let steps: Vec<String> = out
                .report
                .timings
                .steps
                .iter()
                .map(|(s, t)| format!("{s} {:.0} ms", t * 1e3))
                .collect();
            eprintln!(
                "{} ({} → {} vertices): {:.0} ms: {}",
                method.name(),
                dense.vertex_count(),
                ict.vertex_count(),
                out.report.timings.total() * 1e3,
                steps.join(", ")
            );
        }
        if let Some(peak) = peak_rss_mb() {
            eprintln!("peak memory so far (faces read, one clone per method run): {peak:.0} MB");
        }
        Some((dense, ict))
    })
    .as_ref()
}

/// The process's peak resident set (Linux `VmHWM`), in MB.
fn peak_rss_mb() -> Option<f64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb / 1024.0)
}

fn opts(method: Method) -> CloneOptions {
    CloneOptions {
        method,
        ..CloneOptions::default()
    }
}

#[divan::bench(args = [Method::Fmc, Method::Rbf, Method::Fit], sample_count = 5)]
fn dense_candide_to_ict(method: Method) {
    let Some((source, target)) = faces() else {
        return;
    };
    divan::black_box(clone_face(source, target, &opts(method)).expect("clone"));
}
