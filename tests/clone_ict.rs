//! Real-head ground truth (tests/support/ict_truth.rs): head A (ICT neutral + its rig FAT,
//! 14 FAPs) cloned onto head B (A smoothly reshaped, B×10 + offset, and B subdivided once)
//! with every method,
//! against B's true FAT, per FAP. Skipped with a note when `../shared/data/ict-facekit` is
//! absent.

#[path = "support/ict_truth.rs"]
mod ict_truth;

use std::sync::OnceLock;

use fbakit::clone::eval::ground_truth_error;
use fbakit::clone::face::{clone_face, CloneOptions, CloneOutcome, Method, Part};
use fbakit::export::picture::strip_fat;
use fbakit::face::FaceModel;
use fbakit::fat::eval::Activation;
use fbakit::fat::morph::fat_to_morph_targets;
use glam::Vec3;

struct Case {
    truth: FaceModel,
    /// fmc, rbf, fit.
    clones: Vec<(Method, CloneOutcome, f64)>,
}

/// Cases `b`, `b10` (B×10 + offset) and `b_sub` (B subdivided once), built and cloned once
/// per test binary.
fn cases() -> Option<&'static [Case; 3]> {
    static C: OnceLock<Option<[Case; 3]>> = OnceLock::new();
    C.get_or_init(|| {
        let dir = ict_truth::ict_dir()?;
        let a = ict_truth::head_a(&dir);
        let (nose, chin) = ict_truth::anchors(&a);
        let b = ict_truth::head_b(&a, |p| ict_truth::reshape(p, nose, chin));
        let offset = Vec3::new(5.0, -3.0, 2.0);
        let b10 = ict_truth::head_b(&a, |p| ict_truth::reshape(p, nose, chin) * 10.0 + offset);
        let run = |truth: FaceModel| {
            let target = strip_fat(&truth);
            let clones = [Method::Fmc, Method::Rbf, Method::Fit]
                .into_iter()
                .map(|m| {
                    let opts = CloneOptions {
                        method: m,
                        ..CloneOptions::default()
                    };
                    let t = std::time::Instant::now();
                    let out = clone_face(&a, &target, &opts).unwrap();
                    (m, out, t.elapsed().as_secs_f64())
                })
                .collect();
            Case { truth, clones }
        };
        let b_sub = ict_truth::subdivide(&b);
        Some([run(b), run(b10), run(b_sub)])
    })
    .as_ref()
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

#[test]
fn head_a_has_the_chosen_faps() {
    let Some(c) = cases() else { return };
    assert!(
        c[0].truth.fat.tables.len() >= 10,
        "{}",
        c[0].truth.fat.tables.len()
    );
}

#[test]
fn both_cloners_against_the_real_head_truth() {
    let Some(cases) = cases() else { return };
    for (ci, case) in cases.iter().enumerate() {
        for (m, out, secs) in &case.clones {
            let r = ground_truth_error(&out.face, &case.truth).unwrap();
            let all: Vec<f64> = r.keys.iter().map(|k| k.all).collect();
            let med = median(all.clone());
            let worst = r
                .keys
                .iter()
                .max_by(|a, b| a.all.total_cmp(&b.all))
                .unwrap();
            eprintln!(
                "case {ci} {m:?}: {secs:.2} s, median {med:.1} %, mean {:.1} %, worst {} {:.1} %, failed {:?}",
                r.mean_all,
                worst.key,
                worst.all,
                out.report
                    .failed_faps
                    .iter()
                    .map(|f| (&f.fap, f.value, f.repaired))
                    .collect::<Vec<_>>()
            );
            for k in &r.keys {
                eprintln!("    {:<22} {:6.1} %", k.key, k.all);
            }
            // The targets are median ≤ 10 % and no FAP above 100 % (fit: ≤ 4 %).
            // Measured (since the split teeth and gums take the source's motion vertex by
            // vertex, not one rigid motion; thrust_jaw was the worst FAP of every method at
            // 13.8–15.9 % before): fmc median 3.2–3.3 %, worst stretch_r_cornerlip 6.5 %; rbf
            // 2.2–2.3 %, worst open_jaw 5.9 %. fit matches B and B×10, one mesh with A,
            // vertex to vertex (0.0 %); on the subdivided B it registers: median 2.3 %, worst
            // open_jaw 5.7 % (2.3 % and 13.8 % before). The limits are those figures with a
            // small margin, to catch regressions.
            let (med_max, worst_max) = match m {
                Method::Fmc => (4.0, 8.0),
                Method::Rbf => (3.0, 7.0),
                Method::Fit if ci < 2 => (0.1, 0.1),
                Method::Fit => (2.6, 7.0),
            };
            assert!(med <= med_max, "{m:?} case {ci}: median {med}");
            assert!(worst.all < worst_max, "{m:?} case {ci}: {worst:?}");
        }
    }
}

#[test]
fn eyeballs_stay_still() {
    let Some(cases) = cases() else { return };
    for case in cases.iter() {
        for (m, out, _) in &case.clones {
            let face = &out.face;
            // The eyeballs are vertices of the head's one mesh (the clone's cut, if it made
            // one, is an internal view; `fit` keeps a head of the source's mesh whole): found
            // by cutting the output the same way.
            let (_, split) = fbakit::clone::face::split_embedded_parts(&strip_fat(face));
            let eye_parts: Vec<&fbakit::clone::face::SplitPart> = split
                .iter()
                .filter(|s| matches!(s.part, Part::LeftEye | Part::RightEye))
                .collect();
            assert_eq!(eye_parts.len(), 2, "{split:?}");
            assert_eq!(face.meshes.len(), 1);
            let eyes: Vec<(usize, usize)> = eye_parts
                .iter()
                .flat_map(|s| s.source_vertices.iter().map(|&v| (0, v as usize)))
                .collect();
            let neutral = face.pose(&[]).unwrap();
            let mut worst: f32 = 0.0;
            for t in fat_to_morph_targets(&case.truth.fat) {
                let posed = face
                    .pose(&[Activation {
                        key: t.key,
                        value: t.value,
                    }])
                    .unwrap();
                let peak = neutral
                    .iter()
                    .flatten()
                    .zip(posed.iter().flatten())
                    .map(|(a, b)| a.distance(*b))
                    .fold(0.0, f32::max);
                let eye = eyes
                    .iter()
                    .map(|&(mi, v)| neutral[mi][v].distance(posed[mi][v]))
                    .fold(0.0, f32::max);
                if peak > 0.0 {
                    worst = worst.max(eye / peak);
                }
            }
            eprintln!("{m:?}: eyeball motion ≤ {:.4} % of the peak", worst * 100.0);
            assert!(worst < 0.01, "{m:?}: eyeballs move {worst}");
        }
    }
}

/// `fit`'s local-frame transfer works on the subdivided head but stays behind the default
/// barycentric transfer there (measured 5.8 % against 3.3 % median): the truth keeps each
/// motion on the face's axes, as MPEG-4 defines FAPs.
#[test]
fn fit_local_frame_transfer_is_measured() {
    let Some(c) = cases() else { return };
    let a = ict_truth::head_a(&ict_truth::ict_dir().unwrap());
    let truth = &c[2].truth;
    let mut opts = CloneOptions::default();
    opts.fit.transfer = fbakit::clone::fit::FitTransfer::LocalFrame;
    let local = clone_face(&a, &strip_fat(truth), &opts).unwrap();
    let gt = ground_truth_error(&local.face, truth).unwrap();
    let base = c[2].clones.iter().find(|x| x.0 == Method::Fit).unwrap();
    let base_gt = ground_truth_error(&base.1.face, truth).unwrap();
    eprintln!(
        "fit on subdivided B: local frames median {:.2} %, barycentric {:.2} %",
        gt.median_all, base_gt.median_all
    );
    assert!(gt.median_all < 10.0, "local frames {}", gt.median_all);
    assert!(base_gt.median_all <= gt.median_all);
}
