//! Test faces for the cloning methods: Candide-3 surfaces (from `../shared/data/candide3`)
//! with shape units applied and optional 1→4 subdivision, whose motions are exact by
//! construction (each FAP unit moves its vertices by value × that face's FAPU × direction;
//! on a subdivided face a new edge vertex moves by the mean of the edge's end points).
//!
//! Test-only; a small reader of just the parts of the `.wfm` format needed here.

use std::collections::{BTreeMap, HashMap};
use std::path::PathBuf;

use glam::Vec3;

use super::{CloneSurface, SurfaceMotion};
use crate::fat::TableKey;
use crate::fdp::{Fapu, FapuDistances};
use crate::spec::{FapId, FapuKind, FeaturePointId};

/// The shared Candide-3 folder, or `None` (tests then skip with a note).
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

struct Unit {
    name: String,
    fap: Option<FapId>,
    fapu: Option<FapuKind>,
    moves: Vec<(u32, Vec3)>,
}

struct Wfm {
    vertices: Vec<Vec3>,
    triangles: Vec<[u32; 3]>,
    animation: Vec<Unit>,
    shape: Vec<Unit>,
}

fn parse_wfm(text: &str) -> Wfm {
    let lines: Vec<&str> = text.lines().map(str::trim).collect();
    let find = |tag: &str| lines.iter().position(|l| l.starts_with(tag)).unwrap() + 1;
    let nums = |l: &str| -> Vec<f32> { l.split_whitespace().map(|t| t.parse().unwrap()).collect() };
    let mut i = find("# VERTEX LIST:");
    let n: usize = lines[i].parse().unwrap();
    let vertices = (0..n)
        .map(|k| {
            let v = nums(lines[i + 1 + k]);
            Vec3::new(v[0], v[1], v[2])
        })
        .collect();
    i = find("# FACE LIST:");
    let n: usize = lines[i].parse().unwrap();
    let triangles = (0..n)
        .map(|k| {
            let v = nums(lines[i + 1 + k]);
            [v[0] as u32, v[1] as u32, v[2] as u32]
        })
        .collect();
    let units = |tag: &str| -> Vec<Unit> {
        let mut i = find(tag);
        let count: usize = lines[i].parse().unwrap();
        i += 1;
        let mut out = Vec::new();
        while out.len() < count {
            // Comment lines name the unit (and for FAPs give the FAPU), then a count line.
            let mut comments = Vec::new();
            while lines[i].is_empty() || lines[i].starts_with('#') {
                if lines[i].starts_with('#') {
                    comments.push(lines[i].trim_start_matches('#').trim());
                }
                i += 1;
            }
            let k: usize = lines[i].parse().unwrap();
            let moves = (0..k)
                .map(|j| {
                    let v = nums(lines[i + 1 + j]);
                    (v[0] as u32, Vec3::new(v[1], v[2], v[3]))
                })
                .collect();
            i += 1 + k;
            let name = comments.first().copied().unwrap_or("").to_string();
            let fap = name
                .strip_prefix("FAP")
                .and_then(|r| r.split_whitespace().next())
                .and_then(|n| n.parse::<u8>().ok())
                .and_then(FapId::new);
            let fapu = comments.get(1).and_then(|c| c.parse::<FapuKind>().ok());
            out.push(Unit {
                name,
                fap,
                fapu,
                moves,
            });
        }
        out
    };
    Wfm {
        vertices,
        triangles,
        animation: units("# ANIMATION UNITS LIST:"),
        shape: units("# SHAPE UNITS LIST:"),
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
    let wfm = parse_wfm(&std::fs::read_to_string(dir.join("candide3.wfm")).ok()?);
    let mut positions = wfm.vertices.clone();
    for (name, v) in shape {
        let unit = wfm
            .shape
            .iter()
            .find(|u| u.name == *name)
            .expect("shape unit");
        for (i, d) in &unit.moves {
            positions[*i as usize] += *d * *v;
        }
    }
    // Feature points: single vertices, or the mean of several (pupils).
    let csv = std::fs::read_to_string(dir.join("feature-points.csv")).ok()?;
    let mut fp_vertices = BTreeMap::new();
    let mut fp_positions = BTreeMap::new();
    for line in csv.lines().skip(1) {
        let f: Vec<&str> = line.splitn(4, ',').collect();
        let id: FeaturePointId = f[0].parse().unwrap();
        let vs: Vec<u32> = f[1]
            .split(';')
            .filter(|s| !s.is_empty())
            .map(|s| s.parse().unwrap())
            .collect();
        match f[2] {
            "single" => {
                fp_vertices.insert(id, vs[0]);
                fp_positions.insert(id, positions[vs[0] as usize]);
            }
            "mean" => {
                let m = vs.iter().map(|&v| positions[v as usize]).sum::<Vec3>() / vs.len() as f32;
                fp_positions.insert(id, m);
            }
            _ => {}
        }
    }
    let fp = |s: &str| fp_positions[&s.parse::<FeaturePointId>().unwrap()];
    let fapu = Fapu::from_distances(FapuDistances {
        irisd0: (fp("3.1").y - fp("3.3").y) as f64,
        es0: (fp("3.5").x - fp("3.6").x) as f64,
        ens0: (fp("3.5").y - fp("9.15").y) as f64,
        mns0: (fp("9.15").y - fp("2.2").y) as f64,
        mw0: (fp("8.3").x - fp("8.4").x) as f64,
    })
    .unwrap();
    let mut motions: Vec<SurfaceMotion> = wfm
        .animation
        .iter()
        .filter_map(|u| {
            let (fap, kind) = (u.fap?, u.fapu?);
            let scale = (value * fapu.unit(kind)) as f32;
            let mut offsets: Vec<(u32, Vec3)> =
                u.moves.iter().map(|(i, d)| (*i, *d * scale)).collect();
            offsets.sort_by_key(|o| o.0);
            Some(SurfaceMotion {
                key: TableKey::LowLevel(fap),
                value,
                offsets,
            })
        })
        .collect();
    let mut triangles = wfm.triangles.clone();
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
        .find(|m| m.key == TableKey::LowLevel(FapId::OPEN_JAW))
        .unwrap();
    let d = jaw.offsets.iter().find(|o| o.0 == 10).unwrap().1;
    let expected = -(512.0 * wide.surface.fapu.unit(FapuKind::Mns)) as f32;
    assert!((d.y - expected).abs() < 1e-6 && d.x == 0.0);
}
