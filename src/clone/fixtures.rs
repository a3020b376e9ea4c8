//! CANDIDE-3 test faces for the cloning methods, from `../shared/data/candide3`: shape units
//! applied, optional 1→4 subdivision, and motions that are exact by construction (each FAP
//! unit moves its vertices by value × that face's FAPU × direction; on a subdivided face a new
//! edge vertex moves by the mean of the edge's end points). Used by tests and benchmarks;
//! every function returns `None` (after a note on stderr) when the shared data is absent.

use std::collections::{BTreeMap, HashMap};
use std::path::PathBuf;

use glam::Vec3;

use super::{CloneSurface, SurfaceMotion};
use crate::fat::TableKey;
use crate::fdp::{Fapu, FapuDistances};

/// FAP units whose every distance is 1: synthetic test surfaces measured in them directly.
pub fn unit_fapu() -> Fapu {
    let d = FapuDistances {
        irisd0: 1.0,
        es0: 1.0,
        ens0: 1.0,
        mns0: 1.0,
        mw0: 1.0,
    };
    Fapu::from_distances(d).expect("unit distances are valid FAP units")
}

/// The shared Candide-3 folder, or `None` (callers then skip).
pub fn candide_dir() -> Option<PathBuf> {
    let p = PathBuf::from(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../shared/data/candide3"
    ));
    if p.join("candide3.wfm").exists() {
        Some(p)
    } else {
        eprintln!("note: ../shared/data/candide3 not found; skipping");
        None
    }
}

/// A Candide-3 test face: surface plus exact motions of its FAP units at `value`.
pub struct CandideFace {
    /// The surface.
    pub surface: CloneSurface,
    /// One motion per FAP unit that has a FAPU (translation FAPs), at the value given.
    pub motions: Vec<SurfaceMotion>,
}

/// Candide-3 with shape units (`(name, value)`) applied, `subdivisions` rounds of 1→4
/// triangle subdivision, and its translation-FAP motions at `value`.
pub fn candide(shape: &[(&str, f32)], subdivisions: usize, value: f64) -> Option<CandideFace> {
    let dir = candide_dir()?;
    let model = crate::candide::read_wfm_file(&dir.join("candide3.wfm"))
        .ok()?
        .with_shape(shape)
        .ok()?;
    let mut positions = model.vertices.clone();
    let mut points = crate::fdp::csv::read_csv_file(&dir.join("feature-points.csv"))
        .ok()?
        .to_set();
    let n = positions.len();
    points
        .resolve_positions(|_, v| positions.get(v as usize).copied())
        .ok()?;
    // Points made of one vertex are surface vertices; the others (pupils) positions only.
    let mut fp_vertices = BTreeMap::new();
    let mut fp_positions = BTreeMap::new();
    for p in points.iter() {
        if let Some(b) = p.binding.as_ref().filter(|b| b.vertices.len() == 1) {
            if (b.vertices[0] as usize) < n {
                fp_vertices.insert(p.id, b.vertices[0]);
            }
        }
        if let Some(pos) = p.position {
            fp_positions.insert(p.id, pos);
        }
    }
    let fapu: Fapu = Fapu::from_feature_points(&points).ok()?;
    let mut motions: Vec<SurfaceMotion> = model
        .animation_units
        .iter()
        .filter_map(|u| {
            let (fap, kind) = (u.fap?, u.fapu?);
            let scale = (value * fapu.unit(kind)) as f32;
            let mut offsets: Vec<(u32, Vec3)> = u
                .displacements
                .iter()
                .map(|(i, d)| (*i, *d * scale))
                .collect();
            offsets.sort_by_key(|o| o.0);
            Some(SurfaceMotion {
                key: TableKey::LowLevel(fap),
                value,
                offsets,
            })
        })
        .collect();
    let mut triangles = model.triangles.clone();
    for _ in 0..subdivisions {
        subdivide(&mut positions, &mut triangles, &mut motions);
    }
    Some(CandideFace {
        surface: CloneSurface {
            positions,
            triangles,
            fp_vertices,
            fp_positions,
            fapu,
        },
        motions,
    })
}

/// 1→4 subdivision: a new vertex at each edge midpoint; motions follow linearly.
fn subdivide(
    positions: &mut Vec<Vec3>,
    triangles: &mut Vec<[u32; 3]>,
    motions: &mut [SurfaceMotion],
) {
    let mut mid: HashMap<(u32, u32), u32> = HashMap::new();
    let mut new_tris = Vec::with_capacity(triangles.len() * 4);
    let mut edges = Vec::new();
    for t in triangles.iter() {
        let mut m = [0u32; 3];
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            let key = (a.min(b), a.max(b));
            m[k] = *mid.entry(key).or_insert_with(|| {
                positions.push((positions[a as usize] + positions[b as usize]) * 0.5);
                edges.push(key);
                positions.len() as u32 - 1
            });
        }
        new_tris.push([t[0], m[0], m[2]]);
        new_tris.push([t[1], m[1], m[0]]);
        new_tris.push([t[2], m[2], m[1]]);
        new_tris.push(m);
    }
    *triangles = new_tris;
    let first_new = positions.len() as u32 - edges.len() as u32;
    for motion in motions.iter_mut() {
        let moved: HashMap<u32, Vec3> = motion.offsets.iter().copied().collect();
        for (k, (a, b)) in edges.iter().enumerate() {
            let da = moved.get(a).copied().unwrap_or(Vec3::ZERO);
            let db = moved.get(b).copied().unwrap_or(Vec3::ZERO);
            if da != Vec3::ZERO || db != Vec3::ZERO {
                motion.offsets.push((first_new + k as u32, (da + db) * 0.5));
            }
        }
        motion.offsets.sort_by_key(|o| o.0);
    }
}

/// Triangles of a `k × k` vertex grid numbered row by row, two per cell (unit-test
/// surfaces).
#[cfg(test)]
pub(crate) fn grid_triangles(k: u32) -> Vec<[u32; 3]> {
    let mut triangles = Vec::new();
    for j in 0..k.saturating_sub(1) {
        for i in 0..k - 1 {
            let v = j * k + i;
            triangles.push([v, v + 1, v + k + 1]);
            triangles.push([v, v + k + 1, v + k]);
        }
    }
    triangles
}

#[cfg(test)]
#[test]
fn candide_fixture_is_consistent() {
    let Some(face) = candide(&[], 0, 512.0) else {
        return;
    };
    assert_eq!(face.surface.positions.len(), 113);
    assert_eq!(face.surface.triangles.len(), 184);
    assert_eq!(
        face.motions.len(),
        46,
        "translation FAP units with a FAPU comment"
    );
    let mw = face.surface.fapu.distances.mw0;
    assert!((mw - 0.492).abs() < 1e-3, "MW0 {mw}");
    let Some(wide) = candide(&[("Mouth width", 0.5)], 1, 512.0) else {
        return;
    };
    assert!(wide.surface.fapu.distances.mw0 > mw);
    assert_eq!(wide.surface.triangles.len(), 184 * 4);
    // open_jaw moves FP 2.1 (vertex 10) down by 512 MNS units exactly.
    let jaw = wide
        .motions
        .iter()
        .find(|m| m.key == TableKey::LowLevel(crate::spec::FapId::OPEN_JAW))
        .unwrap();
    let d = jaw.offsets.iter().find(|o| o.0 == 10).unwrap().1;
    let expected = -(512.0 * wide.surface.fapu.unit(crate::spec::FapuKind::Mns)) as f32;
    assert!((d.y - expected).abs() < 1e-6 && d.x == 0.0);
}
