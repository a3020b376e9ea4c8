use std::collections::BTreeMap;

use super::*;
use crate::clone::fixtures::candide;
use crate::spec::FeaturePointId;

#[test]
fn candide_self_clone_is_exact() {
    let Some(face) = candide(&[], 1, 512.0) else {
        return;
    };
    let out = clone_fit(
        &face.surface,
        &face.motions,
        &face.surface,
        &FitOptions::default(),
    )
    .unwrap();
    let mut worst: f32 = 0.0;
    let mut peak: f32 = 0.0;
    for (a, b) in face.motions.iter().zip(&out.motions) {
        let mut dense = vec![Vec3::ZERO; face.surface.positions.len()];
        for &(v, d) in &a.offsets {
            dense[v as usize] = d;
            peak = peak.max(d.length());
        }
        let mut got = vec![Vec3::ZERO; face.surface.positions.len()];
        for &(v, d) in &b.offsets {
            got[v as usize] = d;
        }
        // Candide-3's four vertices no triangle uses are still in its motions.
        let used: std::collections::BTreeSet<u32> =
            face.surface.triangles.iter().flatten().copied().collect();
        for (v, (x, y)) in dense.iter().zip(&got).enumerate() {
            if used.contains(&(v as u32)) {
                worst = worst.max(x.distance(*y));
            }
        }
    }
    assert!(worst <= 1e-5 * peak, "worst {worst} of peak {peak}");
}

const RESHAPE: [(&str, f32); 3] = [
    ("Mouth width", 0.5),
    ("Eyes, width", 0.3),
    ("Head height", 0.2),
];

fn dense(m: &SurfaceMotion, n: usize) -> Vec<Vec3> {
    let mut d = vec![Vec3::ZERO; n];
    for &(v, o) in &m.offsets {
        d[v as usize] = o;
    }
    d
}

/// A face-like height field on an `n × n` grid over [−1, 1]², triangulated mirror
/// symmetrically (each quad's diagonal points away from x = 0), with eye and mouth feature
/// points at grid vertices. Vertex `(i, j)` is `j·n + i`; its mirror image is `(n−1−i, j)`.
fn grid_face(n: usize, bump: f32) -> CloneSurface {
    let at = |i: usize| -1.0 + 2.0 * i as f32 / (n - 1) as f32;
    let mut positions = Vec::new();
    for j in 0..n {
        for i in 0..n {
            // Exactly mirrored coordinates (−1 + 2i/(n−1) is not, in floats).
            let x = if 2 * i < n { at(i) } else { -at(n - 1 - i) };
            let y = at(j);
            let z = 0.6 * (-(x * x + y * y)).exp()
                + bump * (-(x * x) * 4.0 - (y + 0.2).powi(2) * 9.0).exp();
            positions.push(Vec3::new(x, y, z));
        }
    }
    let mut triangles = Vec::new();
    let id = |i: usize, j: usize| (j * n + i) as u32;
    for j in 0..n - 1 {
        for i in 0..n - 1 {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            if 2 * i + 1 >= n - 1 {
                triangles.extend([[a, b, c], [a, c, d]]);
            } else {
                triangles.extend([[a, b, d], [b, c, d]]);
            }
        }
    }
    let vertex = |x: f32, y: f32| {
        let k = |t: f32| (((t + 1.0) / 2.0) * (n - 1) as f32).round() as usize;
        // Mirrored points on mirrored vertices (rounding is not symmetric).
        let i = if x < 0.0 { n - 1 - k(-x) } else { k(x) };
        id(i, k(y))
    };
    let mut fp_vertices = BTreeMap::new();
    for (g, i, x, y) in [
        (3, 1, 0.4, 0.4),
        (3, 2, -0.4, 0.4),
        (3, 3, 0.4, 0.2),
        (3, 4, -0.4, 0.2),
        (3, 7, 0.7, 0.3),
        (3, 8, -0.7, 0.3),
        (3, 11, 0.1, 0.3),
        (3, 12, -0.1, 0.3),
        (2, 2, 0.0, -0.4),
        (2, 3, 0.0, -0.6),
        (2, 4, 0.4, -0.5),
        (2, 5, -0.4, -0.5),
        (9, 3, 0.0, 0.0),
    ] {
        fp_vertices.insert(FeaturePointId::new(g, i).unwrap(), vertex(x, y));
    }
    let fp_positions = fp_vertices
        .iter()
        .map(|(&k, &v)| (k, positions[v as usize]))
        .collect();
    let d = crate::fdp::FapuDistances {
        irisd0: 0.2,
        es0: 0.8,
        ens0: 0.4,
        mns0: 0.3,
        mw0: 0.8,
    };
    CloneSurface {
        positions,
        triangles,
        fp_vertices,
        fp_positions,
        fapu: crate::fdp::Fapu::from_distances(d).unwrap(),
    }
}

#[test]
fn mirror_symmetric_faces_clone_mirror_symmetrically() {
    let (sn, tn) = (31, 45);
    let (s, t) = (grid_face(sn, 0.1), grid_face(tn, 0.25));
    let mirror = |v: usize, n: usize| (v / n) * n + (n - 1 - v % n);
    let flip = |d: Vec3| Vec3::new(-d.x, d.y, d.z);
    let key = crate::fat::TableKey::LowLevel(crate::spec::FapId::new(19).unwrap());
    // An off-centre motion (a lid closing at x = 0.4 with a twist) and its mirror image.
    let field = |p: Vec3| {
        let g = (-((p.x - 0.4).powi(2) + (p.y - 0.35).powi(2)) * 20.0).exp();
        Vec3::new(0.02 * g, -0.05 * g, 0.01 * g * p.x)
    };
    let m = SurfaceMotion {
        key,
        value: 512.0,
        offsets: s
            .positions
            .iter()
            .enumerate()
            .map(|(v, &p)| (v as u32, field(p)))
            .collect(),
    };
    let mut mirrored = SurfaceMotion {
        offsets: Vec::new(),
        ..m.clone()
    };
    for &(v, d) in &m.offsets {
        mirrored
            .offsets
            .push((mirror(v as usize, sn) as u32, flip(d)));
    }
    mirrored.offsets.sort_by_key(|o| o.0);
    let out = clone_fit(&s, &[m, mirrored], &t, &FitOptions::default()).unwrap();
    let (a, b) = (
        dense(&out.motions[0], t.positions.len()),
        dense(&out.motions[1], t.positions.len()),
    );
    let peak = a.iter().map(|x| x.length()).fold(0.0, f32::max);
    assert!(peak > 0.0);
    let worst = (0..t.positions.len())
        .map(|v| a[v].distance(flip(b[mirror(v, tn)])) / peak)
        .fold(0.0, f32::max);
    assert!(worst <= 0.01, "asymmetry {worst} of the peak motion");
}

#[test]
fn no_vertex_outruns_its_fap_in_fapu() {
    let (Some(src), Some(dst)) = (candide(&[], 1, 512.0), candide(&RESHAPE, 2, 512.0)) else {
        return;
    };
    let out = clone_fit(
        &src.surface,
        &src.motions,
        &dst.surface,
        &FitOptions::default(),
    )
    .unwrap();
    for (m, c) in src.motions.iter().zip(&out.motions) {
        let r = transfer::fapu_ratio(m.key, &src.surface, &dst.surface);
        let most = m.offsets.iter().map(|o| o.1.length()).fold(0.0, f32::max);
        for &(_, d) in &c.offsets {
            assert!(d.length() <= 1.5 * most * r + 1e-6, "{:?}", m.key);
        }
    }
}

#[test]
fn bad_targets_warn_and_stay_finite() {
    let (Some(src), Some(dst)) = (candide(&[], 1, 512.0), candide(&RESHAPE, 1, 512.0)) else {
        return;
    };
    let s = &src.surface;
    let check = |t: &CloneSurface, what: &str| {
        let out = clone_fit(s, &src.motions, t, &FitOptions::default()).unwrap();
        assert_eq!(out.motions.len(), src.motions.len());
        for m in &out.motions {
            assert!(m.offsets.iter().all(|o| o.1.is_finite()), "{what}");
            assert!(
                m.offsets.iter().all(|o| (o.0 as usize) < t.positions.len()),
                "{what}"
            );
        }
        assert!(!out.warnings.is_empty(), "{what}: no warning");
    };
    // A hole: every triangle around the mouth corner 8.3 removed.
    let mut holed = dst.surface.clone();
    let corner = holed.fp_vertices[&FeaturePointId::new(8, 3).unwrap()];
    holed.triangles.retain(|t| !t.contains(&corner));
    check(&holed, "hole");
    // Duplicated vertices: every triangle of the forehead's upper half re-pointed to copies.
    let mut dup = dst.surface.clone();
    let n = dup.positions.len() as u32;
    let top = dup
        .positions
        .iter()
        .map(|p| p.y)
        .fold(f32::NEG_INFINITY, f32::max);
    let copies = dup.positions.clone();
    dup.positions.extend(copies);
    for t in &mut dup.triangles {
        if t.iter().all(|&v| dup.positions[v as usize].y > top * 0.5) {
            *t = t.map(|v| v + n);
        }
    }
    check(&dup, "duplicates");
    // Feature points off the mesh: moved far away, and bound to unused vertices.
    let mut off = dst.surface.clone();
    for p in off.fp_positions.values_mut() {
        *p += Vec3::new(100.0, -50.0, 30.0);
    }
    let spare = off.positions.len() as u32;
    off.positions.push(Vec3::splat(1e3));
    for v in off.fp_vertices.values_mut() {
        *v = spare;
    }
    check(&off, "feature points off the mesh");
    // Empty target: an error, not a panic.
    let mut empty = dst.surface.clone();
    empty.triangles.clear();
    assert!(clone_fit(s, &src.motions, &empty, &FitOptions::default()).is_err());
}

#[test]
fn a_source_prepared_ahead_clones_the_same_bits() {
    let (s, t) = (grid_face(31, 0.1), grid_face(45, 0.25));
    let key = crate::fat::TableKey::LowLevel(crate::spec::FapId::new(19).unwrap());
    let m = SurfaceMotion {
        key,
        value: 512.0,
        offsets: s
            .positions
            .iter()
            .enumerate()
            .map(|(v, &p)| (v as u32, Vec3::new(0.02 * p.x, -0.05 * p.y * p.y, 0.01)))
            .collect(),
    };
    let motions = [m];
    let opts = FitOptions::default();
    let bits = |r: SurfaceCloneResult| -> Vec<(u32, [u32; 3])> {
        r.motions
            .iter()
            .flat_map(|m| m.offsets.iter())
            .map(|&(v, d)| (v, d.to_array().map(f32::to_bits)))
            .collect()
    };
    let plain = bits(clone_fit(&s, &motions, &t, &opts).unwrap());
    assert!(!plain.is_empty());
    let run = |prep: Option<SourcePrep>| {
        assert!(prep.is_some());
        bits(clone_fit_prepared(&s, &motions, &t, &opts, prep).unwrap())
    };
    let prep = SourcePrep::new(&s, &opts).unwrap();
    assert!(prep.fits(&s, &opts));
    assert_eq!(run(Some(prep)), plain);
    // A preparation for another membrane weight or another surface is not used.
    let stiff = FitOptions {
        membrane: 1.0,
        ..opts.clone()
    };
    let other = bits(clone_fit(&s, &motions, &t, &stiff).unwrap());
    assert_ne!(other, plain, "the membrane weight changes the clone");
    let reshaped = grid_face(31, 0.3);
    for (prep, what) in [
        (SourcePrep::new(&s, &stiff), "another membrane weight"),
        (SourcePrep::new(&t, &opts), "another surface"),
        (
            SourcePrep::new(&reshaped, &opts),
            "the same triangles elsewhere",
        ),
    ] {
        assert!(!prep.as_ref().unwrap().fits(&s, &opts), "{what}");
        assert_eq!(run(prep), plain, "{what}");
    }
}
