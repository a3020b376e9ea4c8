//! Cloning against faces whose true FAT is known, every method: self-clones, a CANDIDE-3
//! shape change (its own shape units), a ×10 + offset copy, and a dense → sparse pair (the
//! face midpoint-subdivided, which keeps its shape and carries its FAT exactly, cloned back
//! onto the original). Per FAP: relative displacement error over every vertex
//! ([`fbakit::clone::eval::ground_truth_error`]). CANDIDE cases are skipped with a note when
//! `../shared/data/candide3` is absent; alma is built in.

#[path = "support/ict_truth.rs"]
mod ict_truth;

use std::sync::OnceLock;

use fbakit::clone::eval::{clone_against_truth, GroundTruthReport};
use fbakit::clone::face::{CloneOptions, Method};
use fbakit::face::subdivide::subdivide_face;
use fbakit::face::FaceModel;
use fbakit::mesh::subdivide::Scheme;
use glam::Vec3;

#[path = "support/candide.rs"]
mod candide_data;
use candide_data::{candide, SHAPE};

const METHODS: [Method; 3] = [Method::Fmc, Method::Rbf, Method::Fit];

/// One case: its name and every method's report.
struct Case {
    name: &'static str,
    reports: Vec<(Method, GroundTruthReport)>,
}

fn run(name: &'static str, source: &FaceModel, truth: &FaceModel) -> Case {
    let reports = METHODS
        .into_iter()
        .map(|method| {
            let opts = CloneOptions {
                method,
                ..CloneOptions::default()
            };
            let r = clone_against_truth(source, truth, &opts)
                .unwrap_or_else(|e| panic!("{name} {}: {e}", method.name()))
                .report;
            let worst = r.worst.clone().unwrap_or_default();
            eprintln!(
                "{name:>22} {:>3}: median {:5.2} %, after best scale {:5.2} %, worst {} {:.2} %",
                method.name(),
                r.median_all,
                r.median_scaled,
                worst.0,
                worst.1
            );
            (method, r)
        })
        .collect();
    Case { name, reports }
}

/// Every case, cloned once per test binary.
fn cases() -> &'static [Case] {
    static C: OnceLock<Vec<Case>> = OnceLock::new();
    C.get_or_init(|| {
        let mut out = Vec::new();
        let alma = fbakit::synth::alma().to_face_model();
        out.push(run("alma self", &alma, &alma));
        let alma_mid = subdivide_face(&alma, Scheme::Midpoint, 1).unwrap();
        out.push(run("alma dense > sparse", &alma_mid, &alma));
        if let Some(c) = candide(&[]) {
            out.push(run("candide self", &c, &c));
            let shaped = candide(&SHAPE).unwrap();
            out.push(run("candide shape change", &c, &shaped));
            let big = ict_truth::head_b(&c, |p| p * 10.0 + Vec3::new(5.0, -3.0, 2.0));
            out.push(run("candide x10 + offset", &c, &big));
            let dense = subdivide_face(&c, Scheme::Midpoint, 2).unwrap();
            out.push(run("candide dense > sparse", &dense, &c));
            out.push(run("candide dense > shaped", &dense, &shaped));
            let shaped_dense = subdivide_face(&shaped, Scheme::Midpoint, 2).unwrap();
            out.push(run("candide sparse > dense shaped", &c, &shaped_dense));
        }
        out
    })
}

fn report(case: &Case, method: Method) -> &GroundTruthReport {
    &case.reports.iter().find(|(m, _)| *m == method).unwrap().1
}

/// Self-clones are exact for every method, FAP by FAP (unused copies of CANDIDE's midline
/// points stay still, the tongue and the pupils bend as on the source).
#[test]
fn every_self_clone_is_exact_per_fap() {
    for case in cases().iter().filter(|c| c.name.ends_with("self")) {
        for (method, r) in &case.reports {
            for k in &r.keys {
                assert!(
                    k.all <= 0.01,
                    "{} {}: {} {:.4} %",
                    case.name,
                    method.name(),
                    k.key,
                    k.all
                );
            }
        }
    }
}

/// `fit` without the one-mesh shortcut (registration and closest points) on the CANDIDE
/// shape change and its ×10 + offset copy.
#[test]
fn fit_by_registration_on_one_mesh_pairs() {
    let Some(c) = candide(&[]) else { return };
    let shaped = candide(&SHAPE).unwrap();
    let mut opts = CloneOptions::default();
    opts.fit.shared_topology = false;
    let r = clone_against_truth(&c, &shaped, &opts).unwrap().report;
    let mut keys = r.keys.clone();
    keys.sort_by(|a, b| b.all.total_cmp(&a.all));
    eprintln!(
        "registration only: median {:.2} %, worst {:?}",
        r.median_all,
        &keys[..3]
    );
    assert!(r.median_all <= 5.0);
}

/// Cases that change one thing (shape, size and place, or mesh density).
fn single_change(case: &Case) -> bool {
    !case.name.contains("shaped")
}

/// `fit` on the known-FAT pairs: median ≤ 5 % everywhere; every FAP ≤ 8 % where one thing
/// changes and ≤ 25 % (issue 21's bound for CANDIDE's coarse lids) where shape and density
/// change at once (CANDIDE dense → shaped and back: its worst FAPs are the eyelids, measured
/// 13.4 % and 15.0 %; 17.8 % and 13.8 % before the registration's stiff steps were doubled,
/// 43 % and 81 % before the slit handling of `fit::regions`).
#[test]
fn fit_meets_the_known_fat_targets() {
    for case in cases() {
        let r = report(case, Method::Fit);
        assert!(
            r.median_all <= 5.0,
            "{}: median {}",
            case.name,
            r.median_all
        );
        let (key, worst) = r.worst.clone().unwrap_or_default();
        let limit = if single_change(case) { 8.0 } else { 25.0 };
        assert!(worst <= limit, "{}: worst {key} {worst:.2} %", case.name);
    }
}

/// `fit` is never worse than either paper's method by median.
#[test]
fn fit_is_not_beaten_by_the_papers() {
    for case in cases() {
        let fit = report(case, Method::Fit).median_all;
        for m in [Method::Fmc, Method::Rbf] {
            let other = report(case, m).median_all;
            assert!(
                fit <= other + 0.5,
                "{}: fit {fit:.2} % vs {} {other:.2} %",
                case.name,
                m.name()
            );
        }
    }
}
