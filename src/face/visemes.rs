//! Viseme FAP vectors fitted to one face, so every face's visemes look like speech.
//!
//! A viseme table is built by evaluating a face's low-level FAT at a vector of low-level FAP
//! values ([`crate::synth::viseme_faps`]: the nominal vectors). On a face whose low-level tables
//! are FAP-compliant the nominal vector gives the intended mouth; on a face whose tables are
//! not — a blendshape rig where "push the lips" also opens them (ARKit's `mouthFunnel`), or
//! where the inner and outer corner FAPs both move the whole corner so their narrowing adds
//! up — the same vector can give a duck face. So the vector is corrected on the face itself:
//!
//! With `s(x)` the measured mouth ([`super::mouth::MouthShape`]: opening, width, protrusion)
//! of the nominal vector plus corrections `x` (in FAP units, on four FAP groups: jaw `3`, lip
//! closure `4 = 5 += x₁`, corner stretch `6 = 7 = 53 = 54 += x₂`, lip push `16 = 17 += x₃`;
//! a group the face has no table for, or that the viseme does not use, is held at 0), find
//!
//! ```text
//! x* = argmin ‖W (s(x) − a)‖² + λ ‖x / 1024‖²     subject to   l ≤ x ≤ u
//! ```
//!
//! where `a` is the viseme's aim ([`super::mouth::viseme_aim`]), `W` weighs each figure, `λ`
//! keeps the correction small and the bounds keep the jaw from closing past neutral. `s` is
//! close to linear in `x`, so up to eight Gauss–Newton steps with a finite-difference Jacobian (64
//! FAP units) on the bounded least-squares solver ([`crate::rig::bounded_ls`]) settle it.
//! Only the lip feature points are evaluated, so a 25k-vertex face takes a few milliseconds.

use std::collections::HashMap;

use glam::Vec3;

use super::mouth::{viseme_aim, MouthGauge, MouthShape};
use super::FaceModel;
use crate::fat::{FaceDefMesh, TableKey};
use crate::rig::bounded_ls::solve_box_qp;
use crate::spec::{FapId, Viseme};

/// The correction groups (module docs): FAP numbers moved together.
const GROUPS: [&[u8]; 4] = [&[3], &[4, 5], &[6, 7, 53, 54], &[16, 17]];

/// Tikhonov weight on the correction (per 1024 FAP units).
const LAMBDA: f64 = 0.02;

/// Gauss–Newton steps.
const STEPS: usize = 8;

/// Finite-difference step, FAP units.
const PROBE: f64 = 64.0;

/// The face's low-level displacement of the lip points, evaluated only there; the figures
/// come from the face's [`MouthGauge`].
struct LipModel<'a> {
    gauge: MouthGauge,
    frames: super::FaceFrames,
    /// Per low-level FAP with a table: per lip point, per vertex, its entry and slot.
    entries: HashMap<FapId, Vec<Vec<EntrySlot<'a>>>>,
}

/// Where one vertex is listed in one table: the entry and the vertex's slot in it.
type EntrySlot<'a> = Option<(&'a FaceDefMesh, usize)>;

impl<'a> LipModel<'a> {
    fn new(face: &'a FaceModel) -> Option<LipModel<'a>> {
        let gauge = MouthGauge::new(face)?;
        let mut entries = HashMap::new();
        for t in &face.fat.tables {
            let TableKey::LowLevel(fap) = t.key else {
                continue;
            };
            let per_point = gauge
                .points()
                .iter()
                .map(|list| {
                    list.iter()
                        .map(|&(m, v)| {
                            let name = &face.meshes[m].name;
                            t.meshes.iter().filter(|e| &e.mesh == name).find_map(|e| {
                                e.coord_index.iter().position(|&c| c == v).map(|k| (e, k))
                            })
                        })
                        .collect()
                })
                .collect();
            entries.insert(fap, per_point);
        }
        Some(LipModel {
            gauge,
            frames: face.frames(),
            entries,
        })
    }

    /// The mouth figures of low-level FAP values `faps` (only mesh displacements are used:
    /// the lip points ride on the skin).
    fn shape(&self, faps: &[(FapId, f64)]) -> MouthShape {
        let mut p = *self.gauge.neutral_points();
        for (k, list) in self.gauge.points().iter().enumerate() {
            let mut sum = Vec3::ZERO;
            for (j, &(mesh, _)) in list.iter().enumerate() {
                let mut d = Vec3::ZERO;
                for &(fap, value) in faps {
                    if let Some(Some((entry, slot))) = self.entries.get(&fap).map(|e| e[k][j]) {
                        d += entry.displacement(slot, value);
                    }
                }
                sum += self.frames.meshes[mesh].transform_vector3(d);
            }
            p[k] += sum / list.len() as f32;
        }
        self.gauge.figures(&p)
    }
}

/// Weights of the three figures in the fit: opening, width, protrusion (the last only where
/// the viseme aims at a protrusion: an open jaw pulls the lower lip back, which is right).
fn weights(aim: &MouthShape) -> [f64; 3] {
    [1.0, 1.0, if aim.protrusion > 0.05 { 1.0 } else { 0.0 }]
}

/// The low-level FAP vector of `viseme` fitted to `face` (module docs), or the nominal vector
/// when the face lacks the lip feature points, their bindings or a low-level table the fit
/// could use.
pub fn fitted_viseme_faps(face: &FaceModel, viseme: Viseme) -> Vec<(FapId, f64)> {
    let nominal = crate::synth::viseme_faps(viseme);
    match LipModel::new(face) {
        Some(model) => fit(&model, viseme, nominal),
        None => nominal,
    }
}

/// Every viseme's fitted vector (1..=14), computing the lip model once.
pub fn fitted_visemes(face: &FaceModel) -> Vec<(Viseme, Vec<(FapId, f64)>)> {
    let model = LipModel::new(face);
    Viseme::shapes()
        .map(|v| {
            let nominal = crate::synth::viseme_faps(v);
            let faps = match &model {
                Some(m) => fit(m, v, nominal),
                None => nominal,
            };
            (v, faps)
        })
        .collect()
}

/// Which groups a viseme may correct: the jaw and lip closure always (every viseme has an
/// opening to keep), the corners where it has a width aim or stretches them, the push where
/// it aims at a protrusion.
fn free_groups(nominal: &[(FapId, f64)], aim: &MouthShape) -> [bool; 4] {
    let uses = |g: &[u8]| nominal.iter().any(|(f, _)| g.contains(&f.number()));
    [
        true,
        true,
        uses(GROUPS[2]) || (aim.width - 1.0).abs() > 0.02,
        aim.protrusion > 0.05,
    ]
}

fn apply(nominal: &[(FapId, f64)], x: &[f64; 4]) -> Vec<(FapId, f64)> {
    let mut out: Vec<(FapId, f64)> = nominal.to_vec();
    for (g, &dx) in GROUPS.iter().zip(x) {
        if dx == 0.0 {
            continue;
        }
        for &n in *g {
            let Some(fap) = FapId::new(n) else { continue };
            match out.iter_mut().find(|(f, _)| *f == fap) {
                Some((_, v)) => *v += dx,
                None => out.push((fap, dx)),
            }
        }
    }
    out.retain(|(_, v)| v.abs() > 0.5);
    for (_, v) in &mut out {
        *v = v.round();
    }
    out.sort_by_key(|(f, _)| f.number());
    out
}

fn fit(model: &LipModel, viseme: Viseme, nominal: Vec<(FapId, f64)>) -> Vec<(FapId, f64)> {
    let aim = viseme_aim(viseme);
    let w = weights(&aim);
    let has_table = |g: &[u8]| {
        g.iter()
            .any(|&n| FapId::new(n).is_some_and(|f| model.entries.contains_key(&f)))
    };
    let free = free_groups(&nominal, &aim);
    let jaw = nominal
        .iter()
        .find(|(f, _)| f.number() == 3)
        .map_or(0.0, |(_, v)| *v);
    // Bounds: the jaw never closes past neutral nor opens past 700; the lip closure within ±600, the rest within ±400.
    let lower = [-jaw, -600.0, -400.0, -300.0];
    let upper = [700.0 - jaw, 600.0, 400.0, 400.0];
    let mut x = [0.0f64; 4];
    let residual = |s: &MouthShape| {
        [
            w[0] * (s.opening - aim.opening) as f64,
            w[1] * (s.width - aim.width) as f64,
            w[2] * (s.protrusion - aim.protrusion) as f64,
        ]
    };
    for _ in 0..STEPS {
        let base = model.shape(&apply(&nominal, &x));
        let r0 = residual(&base);
        // Jacobian columns (per 1024 FAP units) of the free groups the face realises.
        let mut cols = [[0.0f64; 3]; 4];
        let mut active = [false; 4];
        for g in 0..4 {
            if !free[g] || !has_table(GROUPS[g]) {
                continue;
            }
            let mut xp = x;
            let step = if x[g] + PROBE <= upper[g] {
                PROBE
            } else {
                -PROBE
            };
            xp[g] += step;
            let r = residual(&model.shape(&apply(&nominal, &xp)));
            for i in 0..3 {
                cols[g][i] = (r[i] - r0[i]) / step * 1024.0;
            }
            active[g] = true;
        }
        // min ‖J y + r0‖² + λ‖y + x/1024‖² over the step y (per 1024 units), in the box.
        let mut q = vec![0.0; 16];
        let mut c = vec![0.0; 4];
        let mut lo = vec![0.0; 4];
        let mut hi = vec![0.0; 4];
        for a in 0..4 {
            for b in 0..4 {
                q[a * 4 + b] = (0..3).map(|i| cols[a][i] * cols[b][i]).sum::<f64>()
                    + if a == b { LAMBDA } else { 0.0 };
            }
            c[a] = -(0..3).map(|i| cols[a][i] * r0[i]).sum::<f64>() - LAMBDA * x[a] / 1024.0;
            if active[a] {
                lo[a] = (lower[a] - x[a]) / 1024.0;
                hi[a] = (upper[a] - x[a]) / 1024.0;
            }
        }
        let y = solve_box_qp(&q, &c, &lo, &hi);
        let mut moved = 0.0f64;
        for a in 0..4 {
            if active[a] && y[a].is_finite() {
                x[a] += y[a] * 1024.0;
                moved = moved.max((y[a] * 1024.0).abs());
            }
        }
        if moved < 1.0 {
            break;
        }
    }
    apply(&nominal, &x)
}
