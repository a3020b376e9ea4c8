//! Facial Motion Cloning speed: Candide-3 subdivided to ≥ 5 000 vertices with all its
//! translation-FAP motions, cloned onto a reshaped Candide-3 of ≥ 25 000 vertices.
//! Target: total < 1 s on 2 cores. Needs `../shared/data/candide3` (skips without it).
//!
//! Run: `cargo bench --bench clone_fmc`.

use std::collections::{BTreeMap, HashMap};
use std::path::PathBuf;
use std::sync::OnceLock;

use fbakit::clone::fmc::{clone_fmc, FmcOptions};
use fbakit::clone::{CloneSurface, SurfaceMotion};
use fbakit::fat::TableKey;
use fbakit::fdp::{Fapu, FapuDistances};
use fbakit::spec::{FapId, FapuKind, FeaturePointId};
use glam::Vec3;

fn main() {
    if let Some((s, m, t)) = faces() {
        let r = clone_fmc(s, m, t, &FmcOptions::default()).expect("clone");
        eprintln!(
            "source {} vertices, {} motions -> target {} vertices; steps (s): {:?}; total {:.3} s",
            s.positions.len(),
            m.len(),
            t.positions.len(),
            r.timings.steps,
            r.timings.total()
        );
    }
    divan::main();
}

type Faces = (CloneSurface, Vec<SurfaceMotion>, CloneSurface);

fn faces() -> Option<&'static Faces> {
    static FACES: OnceLock<Option<Faces>> = OnceLock::new();
    FACES
        .get_or_init(|| {
            let dir = PathBuf::from(concat!(
                env!("CARGO_MANIFEST_DIR"),
                "/../shared/data/candide3"
            ));
            let text = std::fs::read_to_string(dir.join("candide3.wfm")).ok()?;
            let csv = std::fs::read_to_string(dir.join("feature-points.csv")).ok()?;
            let (s, m) = candide(&text, &csv, &[], 3);
            let (t, _) = candide(
                &text,
                &csv,
                &[
                    ("Mouth width", 0.5),
                    ("Eyes, width", 0.3),
                    ("Head height", 0.2),
                ],
                4,
            );
            let t = centroid_split(t, 2_000);
            assert!(s.positions.len() >= 5_000 && t.positions.len() >= 25_000);
            Some((s, m, t))
        })
        .as_ref()
}

#[divan::bench(sample_count = 10)]
fn fmc_5k_to_25k(bencher: divan::Bencher) {
    let Some((s, m, t)) = faces() else {
        eprintln!("note: ../shared/data/candide3 not found; skipping");
        return;
    };
    bencher.bench(|| clone_fmc(s, m, t, &FmcOptions::default()).expect("clone"));
}

/// A minimal Candide-3 reader: vertices, faces, shape units, FAP units with a FAPU comment.
fn candide(
    text: &str,
    csv: &str,
    shape: &[(&str, f32)],
    subdivisions: usize,
) -> (CloneSurface, Vec<SurfaceMotion>) {
    let lines: Vec<&str> = text.lines().map(str::trim).collect();
    let find = |tag: &str| lines.iter().position(|l| l.starts_with(tag)).unwrap() + 1;
    let nums = |l: &str| -> Vec<f32> { l.split_whitespace().map(|t| t.parse().unwrap()).collect() };
    let mut i = find("# VERTEX LIST:");
    let n: usize = lines[i].parse().unwrap();
    let mut positions: Vec<Vec3> = (0..n)
        .map(|k| Vec3::from_slice(&nums(lines[i + 1 + k])))
        .collect();
    i = find("# FACE LIST:");
    let n: usize = lines[i].parse().unwrap();
    let mut triangles: Vec<[u32; 3]> = (0..n)
        .map(|k| {
            let v = nums(lines[i + 1 + k]);
            [v[0] as u32, v[1] as u32, v[2] as u32]
        })
        .collect();
    // (comments, moves) of each unit in a list.
    let units = |tag: &str| {
        let mut i = find(tag);
        let count: usize = lines[i].parse().unwrap();
        i += 1;
        let mut out = Vec::new();
        while out.len() < count {
            let mut comments = Vec::new();
            while lines[i].is_empty() || lines[i].starts_with('#') {
                if lines[i].starts_with('#') {
                    comments.push(lines[i].trim_start_matches('#').trim().to_string());
                }
                i += 1;
            }
            let k: usize = lines[i].parse().unwrap();
            let moves: Vec<(u32, Vec3)> = (0..k)
                .map(|j| {
                    let v = nums(lines[i + 1 + j]);
                    (v[0] as u32, Vec3::new(v[1], v[2], v[3]))
                })
                .collect();
            i += 1 + k;
            out.push((comments, moves));
        }
        out
    };
    for (name, value) in shape {
        let shape_units = units("# SHAPE UNITS LIST:");
        let (_, moves) = shape_units.iter().find(|u| u.0[0] == *name).unwrap();
        for (v, d) in moves {
            positions[*v as usize] += *d * *value;
        }
    }
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
    let mut motions: Vec<SurfaceMotion> = units("# ANIMATION UNITS LIST:")
        .into_iter()
        .filter_map(|(comments, moves)| {
            let number = comments
                .first()?
                .strip_prefix("FAP")?
                .split_whitespace()
                .next()?;
            let fap = FapId::new(number.parse().ok()?)?;
            let kind: FapuKind = comments.get(1)?.parse().ok()?;
            let scale = (512.0 * fapu.unit(kind)) as f32;
            let mut offsets: Vec<(u32, Vec3)> =
                moves.iter().map(|(v, d)| (*v, *d * scale)).collect();
            offsets.sort_by_key(|o| o.0);
            Some(SurfaceMotion {
                key: TableKey::LowLevel(fap),
                value: 512.0,
                offsets,
            })
        })
        .collect();
    for _ in 0..subdivisions {
        let mut mid: HashMap<(u32, u32), u32> = HashMap::new();
        let mut next = Vec::with_capacity(triangles.len() * 4);
        let mut edges = Vec::new();
        for t in &triangles {
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
            next.extend([
                [t[0], m[0], m[2]],
                [t[1], m[1], m[0]],
                [t[2], m[2], m[1]],
                m,
            ]);
        }
        triangles = next;
        let first = positions.len() as u32 - edges.len() as u32;
        for motion in &mut motions {
            let moved: HashMap<u32, Vec3> = motion.offsets.iter().copied().collect();
            for (k, (a, b)) in edges.iter().enumerate() {
                let d = moved.get(a).copied().unwrap_or(Vec3::ZERO)
                    + moved.get(b).copied().unwrap_or(Vec3::ZERO);
                if d != Vec3::ZERO {
                    motion.offsets.push((first + k as u32, d * 0.5));
                }
            }
            motion.offsets.sort_by_key(|o| o.0);
        }
    }
    (
        CloneSurface {
            positions,
            triangles,
            fp_vertices,
            fp_positions,
            fapu,
        },
        motions,
    )
}

/// Splits the first `count` triangles at their centroids (to pass 25 000 vertices).
fn centroid_split(mut s: CloneSurface, count: usize) -> CloneSurface {
    let mut out = Vec::with_capacity(s.triangles.len() + 2 * count);
    for (i, t) in s.triangles.iter().enumerate() {
        if i < count {
            let c = t.iter().map(|&v| s.positions[v as usize]).sum::<Vec3>() / 3.0;
            s.positions.push(c);
            let m = s.positions.len() as u32 - 1;
            out.extend([[t[0], t[1], m], [t[1], t[2], m], [t[2], t[0], m]]);
        } else {
            out.push(*t);
        }
    }
    s.triangles = out;
    s
}
