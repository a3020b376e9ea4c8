//! End-to-end tests on Candide-3 faces (skipped when `../shared` is absent).

use super::super::fixtures::{candide, CandideFace};
use super::super::quality::{displacement_error, displacement_errors, morph_target_error};
use super::*;
use crate::fat::TableKey;
use crate::spec::FapId;

const VALUE: f64 = 512.0;
const RESHAPE: [(&str, f32); 3] = [
    ("Mouth width", 0.5),
    ("Eyes, width", 0.3),
    ("Head height", 0.2),
];

fn all_finite(r: &SurfaceCloneResult) {
    for m in &r.motions {
        for (v, o) in &m.offsets {
            assert!(o.is_finite(), "{:?} vertex {v}: {o}", m.key);
        }
    }
}

fn run(source: &CandideFace, target: &CandideFace) -> SurfaceCloneResult {
    let r = clone_rbf(
        &source.surface,
        &source.motions,
        &target.surface,
        &RbfOptions::default(),
    )
    .unwrap();
    all_finite(&r);
    assert_eq!(r.motions.len(), source.motions.len());
    for (a, b) in r.motions.iter().zip(&source.motions) {
        assert_eq!((a.key, a.value), (b.key, b.value));
    }
    let names: Vec<&str> = r.timings.steps.iter().map(|s| s.0.as_str()).collect();
    assert_eq!(names, ["contours", "fit", "refine", "map", "deform"]);
    eprintln!("stats {:?}\nwarnings {:?}", r.stats, r.warnings);
    r
}

fn offset_of(r: &SurfaceCloneResult, fap: u8, v: u32) -> Vec3 {
    let key = TableKey::LowLevel(FapId::new(fap).unwrap());
    r.motions
        .iter()
        .find(|m| m.key == key)
        .and_then(|m| m.offsets.iter().find(|o| o.0 == v))
        .map(|o| o.1)
        .unwrap_or(Vec3::ZERO)
}

#[test]
fn candide_contours_follow_the_inner_lips_and_eyes() {
    let Some(face) = candide(&[], 0, VALUE) else {
        return;
    };
    let s = &face.surface;
    let adj = adjacency(s.positions.len(), &s.triangles);
    let mut warnings = Vec::new();
    let c = contours::extract(
        s,
        &adj,
        &VertexTriangles::new(s.positions.len(), &s.triangles),
        "t",
        &mut warnings,
    );
    assert!(warnings.is_empty(), "{warnings:?}");
    // Candide-3: 2.5 = 89, 2.4 = 88; upper 82, 2.2 = 87, 81; lower 84, 2.3 = 40, 83.
    assert_eq!(c.upper_lip.unwrap(), vec![89, 82, 87, 81, 88]);
    assert_eq!(c.lower_lip.unwrap(), vec![89, 84, 40, 83, 88]);
    for (eye, fps) in [
        (c.right_eye, [54, 56, 55, 53]),
        (c.left_eye, [21, 20, 22, 23]),
    ] {
        let eye = eye.unwrap();
        assert!(fps.iter().all(|v| eye.contains(v)), "{eye:?}");
        let mut sorted = eye.clone();
        sorted.sort_unstable();
        sorted.dedup();
        assert_eq!(sorted.len(), eye.len(), "no vertex twice: {eye:?}");
    }
    // Lip regions: 2.2 upper, 2.3 lower, 8.1 (7) upper, 8.2 (8) lower, nose (6) other.
    let (r, _) = lip_regions(
        s,
        &adj,
        &contours::extract(
            s,
            &adj,
            &VertexTriangles::new(s.positions.len(), &s.triangles),
            "t",
            &mut warnings,
        ),
        true,
    );
    assert_eq!(
        [r[87], r[40], r[7], r[8], r[6]],
        [
            Region::Upper,
            Region::Lower,
            Region::Upper,
            Region::Lower,
            Region::Other
        ]
    );
}

#[test]
fn self_cloning_is_exact() {
    let Some(face) = candide(&[], 0, VALUE) else {
        return;
    };
    let r = run(&face, &face);
    let e = morph_target_error(&face.surface.positions, &face.motions, &r.motions);
    let d = displacement_error(face.surface.positions.len(), &face.motions, &r.motions);
    eprintln!("self-clone: formula (1) error {e:.3e} %, displacement error {d:.3e} %");
    // Measured 3.6e-9 % (formula (1)) and 1.7e-7 % (displacements).
    assert!(e < 1e-6, "formula (1) {e} %");
    assert!(d < 1e-4, "displacement {d} %");
    assert_eq!(r.stats["iterations"], 0.0);
}

fn per_fap_report(label: &str, target: &CandideFace, r: &SurfaceCloneResult) -> f64 {
    let n = target.surface.positions.len();
    let errs = displacement_errors(n, &target.motions, &r.motions);
    let line: Vec<String> = errs
        .iter()
        .map(|(k, e)| match k {
            TableKey::LowLevel(f) => format!("{}:{e:.1}", f.number()),
            _ => format!("{k:?}:{e:.1}"),
        })
        .collect();
    let mean = displacement_error(n, &target.motions, &r.motions);
    let f1 = morph_target_error(&target.surface.positions, &target.motions, &r.motions);
    eprintln!("{label}: per-FAP displacement error % {}", line.join(" "));
    eprintln!("{label}: mean displacement error {mean:.2} %, formula (1) {f1:.4} %");
    mean
}

#[test]
fn reshaped_target_error_is_bounded() {
    let (Some(src), Some(tgt)) = (candide(&[], 0, VALUE), candide(&RESHAPE, 0, VALUE)) else {
        return;
    };
    let r = run(&src, &tgt);
    let mean = per_fap_report("reshaped", &tgt, &r);
    // Measured 13.4 %: no FAPU normalisation, see the module doc.
    assert!(mean < 16.0, "mean displacement error {mean} %");
}

#[test]
fn subdivided_target_error_is_bounded() {
    let (Some(src), Some(tgt)) = (candide(&[], 0, VALUE), candide(&RESHAPE, 1, VALUE)) else {
        return;
    };
    let r = run(&src, &tgt);
    let mean = per_fap_report("reshaped+subdivided", &tgt, &r);
    // Map rays that miss both ways fall back to the closest point: rare on a face.
    let fallback = r.stats["ray_misses_fallback"] / tgt.surface.positions.len() as f64;
    eprintln!("map-ray fallbacks {:.2} %", fallback * 100.0);
    assert!(fallback < 0.05, "fallbacks {fallback}");
    // Measured 13.4 %: no FAPU normalisation, see the module doc.
    assert!(mean < 16.0, "mean displacement error {mean} %");
}

#[test]
fn closed_lips_stay_apart() {
    let Some(face) = candide(&[], 0, VALUE) else {
        return;
    };
    let (Some(wide), Some(fine)) = (candide(&RESHAPE, 0, VALUE), candide(&RESHAPE, 1, VALUE))
    else {
        return;
    };
    for target in [&face, &wide, &fine] {
        let r = run(&face, target);
        // FAP 4 lower_t_midlip moves 2.2 (87) down; 2.3 (40) must stay.
        assert!(offset_of(&r, 4, 87).y < 0.0);
        assert_eq!(offset_of(&r, 4, 40), Vec3::ZERO);
        // FAP 5 raise_b_midlip moves 2.3 up; 2.2 must stay.
        assert!(offset_of(&r, 5, 40).y > 0.0);
        assert_eq!(offset_of(&r, 5, 87), Vec3::ZERO);
        // Same for the coincident pairs 81 (upper) / 83 (lower): FAPs 8 and 10.
        assert_eq!(offset_of(&r, 8, 83), Vec3::ZERO);
        assert_eq!(offset_of(&r, 10, 81), Vec3::ZERO);
    }
}

#[test]
fn degenerate_feature_points_are_errors_not_nans() {
    let Some(face) = candide(&[], 0, VALUE) else {
        return;
    };
    // All feature points on one vertex: one distinct correspondence.
    let mut collapsed = face.surface.clone();
    for v in collapsed.fp_vertices.values_mut() {
        *v = 0;
    }
    let opts = RbfOptions::default();
    assert!(clone_rbf(&collapsed, &face.motions, &face.surface, &opts).is_err());
    // Only three feature points shared.
    let mut few = face.surface.clone();
    let keep: Vec<_> = few.fp_vertices.keys().copied().take(3).collect();
    few.fp_vertices.retain(|k, _| keep.contains(k));
    assert!(clone_rbf(&face.surface, &face.motions, &few, &opts).is_err());
    // Every source FP at one position but distinct vertices: coincident, merged, then too few.
    let mut flat = face.surface.clone();
    for &v in flat.fp_vertices.values() {
        flat.positions[v as usize] = Vec3::ZERO;
    }
    let e = clone_rbf(&flat, &face.motions, &face.surface, &opts).unwrap_err();
    assert!(e.to_string().contains("RBF"), "{e}");
    // Broken input.
    let mut nan = face.surface.clone();
    nan.positions[3].x = f32::NAN;
    assert!(clone_rbf(&nan, &face.motions, &face.surface, &opts).is_err());
    let mut bad = face.surface.clone();
    bad.triangles.push([0, 1, 100_000]);
    assert!(clone_rbf(&face.surface, &face.motions, &bad, &opts).is_err());
}

/// Each surface vertex's mirror image across `x = mean x` (the nearest surface vertex to
/// it), or `None` when some vertex has no image within `tol`. Vertices in no triangle
/// (Candide-3's unused duplicates) map to themselves.
fn mirror_map(surface: &CloneSurface, tol: f32) -> Option<Vec<u32>> {
    let mut used = vec![false; surface.positions.len()];
    for &v in surface.triangles.iter().flatten() {
        used[v as usize] = true;
    }
    let pos: Vec<Vec3> = (0..used.len())
        .map(|v| {
            if used[v] {
                surface.positions[v]
            } else {
                Vec3::NAN
            }
        })
        .collect();
    let (sum, n) = pos
        .iter()
        .filter(|p| p.is_finite())
        .fold((0.0, 0), |(s, n), p| (s + f64::from(p.x), n + 1));
    let cx = (sum / f64::from(n)) as f32;
    let index = VertexIndex::new(&pos);
    let adj = adjacency(pos.len(), &surface.triangles);
    let ring =
        |v: usize| adj[v].iter().map(|&n| pos[n as usize]).sum::<Vec3>() / adj[v].len() as f32;
    let flip = |p: Vec3| Vec3::new(2.0 * cx - p.x, p.y, p.z);
    (0..pos.len())
        .map(|v| {
            if !used[v] {
                return Some(v as u32);
            }
            // Coincident vertices (a closed mouth's lips) are told apart by their
            // neighbours.
            let mirrored_ring = flip(ring(v));
            index
                .within(flip(pos[v]), tol)
                .into_iter()
                .min_by(|a, b| {
                    let da = ring(a.0 as usize).distance(mirrored_ring);
                    let db = ring(b.0 as usize).distance(mirrored_ring);
                    da.total_cmp(&db)
                })
                .map(|c| c.0)
        })
        .collect()
}

fn mirrored(m: &SurfaceMotion, map: &[u32]) -> SurfaceMotion {
    let mut offsets: Vec<(u32, Vec3)> = m
        .offsets
        .iter()
        .map(|&(v, d)| (map[v as usize], Vec3::new(-d.x, d.y, d.z)))
        .collect();
    offsets.sort_by_key(|o| o.0);
    SurfaceMotion {
        offsets,
        ..m.clone()
    }
}

/// Mirror-symmetric input gives mirror-symmetric output (measured 0.05 % of the motion; it
/// was 59 % at one eye-corner pair while CANDIDE-3's flipped polygons turned one vertex
/// normal, and its map ray, away from its mirror image's).
#[test]
fn mirror_symmetric_faces_get_mirror_symmetric_motions() {
    let (Some(src), Some(tgt)) = (candide(&[], 0, VALUE), candide(&RESHAPE, 1, VALUE)) else {
        return;
    };
    let tol = 1e-4 * src.surface.fapu.distances.ens0 as f32;
    let (Some(ms), Some(mt)) = (mirror_map(&src.surface, tol), mirror_map(&tgt.surface, tol))
    else {
        panic!("Candide-3 is mirror-symmetric");
    };
    // Every motion and its mirror image, cloned together (one symmetric set of movable
    // vertices): the clone of the mirror image must be the mirror image of the clone.
    // Candide-3's triangulation is not mirror-symmetric everywhere (some quads around the
    // eyes and lips are split the same way on both sides): keep the triangles whose mirror
    // image is a triangle too, so the input is exactly symmetric.
    let symmetric = |face: &CandideFace, map: &[u32]| {
        let key = |t: [u32; 3]| {
            let mut k = t;
            k.sort_unstable();
            k
        };
        let all: std::collections::HashSet<[u32; 3]> =
            face.surface.triangles.iter().map(|&t| key(t)).collect();
        let mut s = face.surface.clone();
        s.triangles
            .retain(|t| all.contains(&key(t.map(|v| map[v as usize]))));
        s
    };
    let (ss, ts) = (symmetric(&src, &ms), symmetric(&tgt, &mt));
    let n = src.motions.len();
    let mut motions = src.motions.clone();
    motions.extend(src.motions.iter().map(|m| mirrored(m, &ms)));
    let r = clone_rbf(&ss, &motions, &ts, &RbfOptions::default()).unwrap();
    let mut worst: f32 = 0.0;
    for i in 0..n {
        let a = mirrored(&r.motions[i], &mt);
        let b = &r.motions[n + i];
        let at = |m: &SurfaceMotion, v: u32| m.offset_at(v);
        let peak = a.offsets.iter().map(|o| o.1.length()).fold(0.0, f32::max);
        let (gv, gap) = (0..tgt.surface.positions.len() as u32)
            .map(|v| (v, at(&a, v).distance(at(b, v))))
            .fold((0, 0.0f32), |acc, x| if x.1 > acc.1 { x } else { acc });
        if peak > 0.0 {
            if gap / peak > 0.01 {
                eprintln!(
                    "{:?} vertex {gv} at {}: {} vs {} (peak {peak})",
                    src.motions[i].key,
                    tgt.surface.positions[gv as usize],
                    at(&a, gv),
                    at(b, gv)
                );
            }
            worst = worst.max(gap / peak);
        }
    }
    eprintln!(
        "mirror asymmetry: worst {:.4} % of the motion; stats {:?} {:?}",
        worst * 100.0,
        r.stats,
        r.warnings
    );
    assert!(worst <= 0.01, "asymmetry {worst}");
}
