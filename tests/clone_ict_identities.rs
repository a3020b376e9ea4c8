//! Real heads from ICT-FaceKit's identity model (tests/support/ict_truth.rs): head A (ICT
//! neutral + its rig FAT, 14 FAPs) cloned onto other identities (±2–3 standard deviations of
//! two principal components), one of them ×10 + offset and one 4× denser (one round of
//! midpoint subdivision), against each head's true FAT. Every method in its default mode and
//! fmc and rbf in their papers' modes; per case the median over FAPs and the worst FAP are
//! printed, and the default modes' targets asserted. Skipped with a note when
//! `../shared/data/ict-facekit` is absent.

#[path = "support/ict_truth.rs"]
mod ict_truth;

use std::sync::OnceLock;

use fbakit::clone::eval::ground_truth_error;
use fbakit::clone::face::{clone_face, CloneOptions, Method};
use fbakit::clone::fmc::{FmcCorrespondence, FmcOptions, NormalisationMode};
use fbakit::clone::rbf::RbfOptions;
use fbakit::export::picture::strip_fat;
use fbakit::face::subdivide::subdivide_face;
use fbakit::face::FaceModel;
use fbakit::mesh::subdivide::Scheme;
use glam::Vec3;

/// A method and its options: the default modes, and fmc's and rbf's paper modes.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Mode {
    Fmc,
    /// fmc's default mode before dense correspondence (the paper's alignment).
    FmcProjected,
    FmcPaper,
    Rbf,
    /// rbf's default mode before dense correspondence (the paper's rays and transport
    /// through the morph, with the FAPU rescale).
    RbfRays,
    RbfPaper,
    Fit,
}

impl Mode {
    fn options(self) -> CloneOptions {
        let mut o = CloneOptions::default();
        match self {
            Mode::Fmc => o.method = Method::Fmc,
            Mode::FmcPaper => {
                o.method = Method::Fmc;
                o.fmc = FmcOptions {
                    normalisation: NormalisationMode::Paper,
                    correspondence: FmcCorrespondence::Paper,
                    ..FmcOptions::default()
                };
            }
            Mode::FmcProjected => {
                o.method = Method::Fmc;
                o.fmc.correspondence = FmcCorrespondence::Paper;
            }
            Mode::Rbf => o.method = Method::Rbf,
            Mode::RbfRays => {
                o.method = Method::Rbf;
                o.rbf = RbfOptions::default();
            }
            Mode::RbfPaper => {
                o.method = Method::Rbf;
                o.rbf = RbfOptions {
                    max_iterations: 3,
                    ..RbfOptions::default()
                };
                o.rbf_fapu_rescale = false;
            }
            Mode::Fit => o.method = Method::Fit,
        }
        o
    }
}

const MODES: [Mode; 7] = [
    Mode::Fmc,
    Mode::FmcProjected,
    Mode::FmcPaper,
    Mode::Rbf,
    Mode::RbfRays,
    Mode::RbfPaper,
    Mode::Fit,
];

struct Row {
    mode: Mode,
    secs: f64,
    median: f64,
    worst: (String, f64),
}

struct Case {
    name: &'static str,
    rows: Vec<Row>,
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        (v[n / 2 - 1] + v[n / 2]) / 2.0
    }
}

fn cases() -> Option<&'static Vec<Case>> {
    static C: OnceLock<Option<Vec<Case>>> = OnceLock::new();
    C.get_or_init(|| {
        let dir = ict_truth::ict_dir()?;
        let a = ict_truth::head_a(&dir);
        let one = [("identity003", 2.5), ("identity033", -3.0)];
        let two = [("identity003", -2.5), ("identity033", 3.0)];
        let offset = Vec3::new(5.0, -3.0, 2.0);
        let i1 = ict_truth::identity_head(&a, &dir, &one, 1.0, offset * 0.0);
        let heads: Vec<(&'static str, FaceModel)> = vec![
            ("id +2.5/-3", i1.clone()),
            (
                "id -2.5/+3",
                ict_truth::identity_head(&a, &dir, &two, 1.0, Vec3::ZERO),
            ),
            (
                "id +2.5/-3 x10+off",
                ict_truth::identity_head(&a, &dir, &one, 10.0, offset),
            ),
            (
                "id +2.5/-3 4x dense",
                subdivide_face(&i1, Scheme::Midpoint, 1).unwrap(),
            ),
        ];
        let cases = heads
            .into_iter()
            .map(|(name, truth)| {
                let target = strip_fat(&truth);
                let rows = MODES
                    .iter()
                    .map(|&mode| {
                        let t = std::time::Instant::now();
                        let out = clone_face(&a, &target, &mode.options()).unwrap();
                        let secs = t.elapsed().as_secs_f64();
                        let r = ground_truth_error(&out.face, &truth).unwrap();
                        let med = median(r.keys.iter().map(|k| k.all).collect());
                        let w = r
                            .keys
                            .iter()
                            .max_by(|x, y| x.all.total_cmp(&y.all))
                            .unwrap();
                        eprintln!(
                            "{name:<20} {:<9} {secs:6.2} s  median {med:5.1} %  worst {} {:.1} %",
                            format!("{mode:?}"),
                            w.key,
                            w.all
                        );
                        for k in &r.keys {
                            eprintln!("        {:<22} {:6.1} %", k.key, k.all);
                        }
                        Row {
                            mode,
                            secs,
                            median: med,
                            worst: (w.key.clone(), w.all),
                        }
                    })
                    .collect();
                Case { name, rows }
            })
            .collect();
        Some(cases)
    })
    .as_ref()
}

#[test]
fn every_mode_on_identity_heads() {
    let Some(cases) = cases() else { return };
    eprintln!("case | mode | s | median % | worst FAP %");
    for c in cases {
        for r in &c.rows {
            eprintln!(
                "| {} | {:?} | {:.2} | {:.1} | {} {:.1} |",
                c.name, r.mode, r.secs, r.median, r.worst.0, r.worst.1
            );
        }
    }
    // Issue 21's targets for the default modes: median ≤ 8 % on every real-head case
    // (measured 4.1–4.3 % fmc, worst FAP 5.4 %; 2.6–2.9 % rbf, worst 3.8 %, since `fit`'s
    // registration, whose correspondence both use, holds ICT's landmarks harder and takes
    // its stiff steps twice: 4.4–4.6 % and 3.2–3.4 %, worst 5.9 % and 4.3 %, before; 5.2–5.4 %
    // and 3.5–3.6 %, worst thrust_jaw 11.5 %, before the split teeth and gums took the
    // source's motion vertex by vertex). fit: the identities of the source's own mesh are
    // matched vertex to vertex (0.0 %); the 4× denser head goes through the registration:
    // median 2.9 %, worst stretch_r_cornerlip 3.7 % (3.4 % and 4.2 % before that
    // registration change, 3.6 % and thrust_jaw 11.2 % before the split parts). The issue
    // asks median ≤ 3 % and no FAP over 15 %. The papers' modes stay as printed: far behind
    // (26–31 %).
    for c in cases {
        for r in &c.rows {
            assert!(r.median.is_finite() && r.worst.1.is_finite());
            match r.mode {
                Mode::Fmc | Mode::Rbf | Mode::Fit => {
                    let (med, worst) = match r.mode {
                        Mode::Fmc => (4.6, 6.0),
                        Mode::Rbf => (3.2, 4.3),
                        _ if c.name.contains("dense") => (2.95, 4.0),
                        _ => (0.1, 0.1),
                    };
                    assert!(
                        r.median <= med && r.worst.1 <= worst,
                        "{} {:?}: median {}, worst {:?}",
                        c.name,
                        r.mode,
                        r.median,
                        r.worst
                    )
                }
                Mode::FmcPaper | Mode::RbfPaper => {
                    assert!(
                        r.median < 40.0,
                        "{} {:?}: median {}",
                        c.name,
                        r.mode,
                        r.median
                    )
                }
                _ => {}
            }
        }
    }
}
