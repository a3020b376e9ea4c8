//! Evaluating a FAT for given FAP values.
//!
//! A [`FatEvaluator`] is built once per face: it resolves mesh and transform names to indices and
//! checks every index, so evaluating a frame is a tight loop with no allocation and no lookups.
//! Effects of all active tables are summed on the neutral face, as the standard says.

use glam::{Quat, Vec3};

use super::{interval_weights, Fat, FatError, TableKey, TransformField, HIGH_LEVEL_FULL};
use crate::error::Result;
use crate::fap::DenseFrame;
use crate::spec::{Expression, FapId, Viseme};

/// One table to apply at one value (`P` in the module docs of [`crate::fat`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Activation {
    /// Which table.
    pub key: TableKey,
    /// The value it is evaluated at.
    pub value: f64,
}

/// The activations of one held FAP state, into `out` (cleared): every low-level FAP at its
/// value, then the viseme pair and the expression pair — what a frame asks of a FAT.
pub fn frame_activations(state: &DenseFrame, out: &mut Vec<Activation>) {
    out.clear();
    for id in FapId::low_level() {
        out.push(Activation {
            key: TableKey::LowLevel(id),
            value: state.value(id),
        });
    }
    let v = &state.viseme;
    out.extend(viseme_activations(v.select1, v.select2, f64::from(v.blend)));
    let e = &state.expression;
    out.extend(expression_activations(
        e.select1,
        f64::from(e.intensity1),
        e.select2,
        f64::from(e.intensity2),
    ));
}

/// The two activations of a viseme blend: `select1` at `blend`, `select2` at `63 − blend`
/// (viseme 0, "none", has no table and contributes nothing).
pub fn viseme_activations(select1: Viseme, select2: Viseme, blend: f64) -> [Activation; 2] {
    [
        Activation {
            key: TableKey::Viseme(select1),
            value: blend,
        },
        Activation {
            key: TableKey::Viseme(select2),
            value: HIGH_LEVEL_FULL - blend,
        },
    ]
}

/// The two activations of an expression mix: each selected expression at its own intensity
/// (the terms add; they are not normalised).
pub fn expression_activations(
    select1: Expression,
    intensity1: f64,
    select2: Expression,
    intensity2: f64,
) -> [Activation; 2] {
    [
        Activation {
            key: TableKey::Expression(select1),
            value: intensity1,
        },
        Activation {
            key: TableKey::Expression(select2),
            value: intensity2,
        },
    ]
}

/// Change of one `Transform` relative to its neutral values.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TransformDelta {
    /// Rotation composed onto the neutral rotation.
    pub rotation: Quat,
    /// Added to the neutral scale.
    pub scale: Vec3,
    /// Added to the neutral translation.
    pub translation: Vec3,
}

impl TransformDelta {
    /// No change.
    pub const IDENTITY: TransformDelta = TransformDelta {
        rotation: Quat::IDENTITY,
        scale: Vec3::ZERO,
        translation: Vec3::ZERO,
    };
}

/// Result buffers of one evaluation; reuse them across frames.
#[derive(Clone, Debug, PartialEq)]
pub struct FatOutput {
    /// Per mesh (in the evaluator's mesh order), per vertex displacement from neutral.
    pub displacements: Vec<Vec<Vec3>>,
    /// Per transform (in the evaluator's transform order).
    pub transforms: Vec<TransformDelta>,
}

#[derive(Clone, Debug)]
struct CompiledMesh {
    mesh: usize,
    borders: Vec<f64>,
    coord_index: Vec<u32>,
    /// Rates, vertex-major, as in the node.
    rates: Vec<Vec3>,
}

#[derive(Clone, Debug)]
struct CompiledTransform {
    transform: usize,
    field: TransformField,
    axis: Vec3,
    angle: f32,
    scale: Vec3,
    translation: Vec3,
}

#[derive(Clone, Debug, Default)]
struct CompiledTable {
    meshes: Vec<CompiledMesh>,
    transforms: Vec<CompiledTransform>,
}

/// A FAT bound to a face's meshes and transforms, ready to evaluate frames.
#[derive(Clone, Debug)]
pub struct FatEvaluator {
    vertex_counts: Vec<usize>,
    transform_count: usize,
    /// Indexed by [`TableKey::slot`]; several `FaceDefTables` for one key are merged.
    tables: Vec<CompiledTable>,
    weights: Vec<f64>,
}

impl FatEvaluator {
    /// Binds `fat` to meshes (DEF name, vertex count) and transforms (DEF name).
    ///
    /// Fails with a message naming the table when a mesh or transform name is unknown, a
    /// coordinate index is out of range, or a displacement count does not match
    /// `coordIndex × intervals` (run [`super::validate`] for a full report).
    pub fn new(fat: &Fat, meshes: &[(&str, usize)], transforms: &[&str]) -> Result<Self> {
        let mut tables = vec![CompiledTable::default(); TableKey::SLOTS];
        for table in &fat.tables {
            let Some(slot) = table.key.slot() else {
                return Err(FatError::NeutralTable { key: table.key }.into());
            };
            for m in &table.meshes {
                let mesh = meshes
                    .iter()
                    .position(|(name, _)| *name == m.mesh)
                    .ok_or_else(|| FatError::UnknownMesh {
                        key: table.key,
                        mesh: m.mesh.clone(),
                    })?;
                let count = meshes[mesh].1;
                if let Some(bad) = m.coord_index.iter().find(|&&i| i as usize >= count) {
                    return Err(FatError::CoordIndexOutOfRange {
                        key: table.key,
                        mesh: m.mesh.clone(),
                        index: *bad,
                        vertex_count: count,
                    }
                    .into());
                }
                if m.displacements.len() != m.coord_index.len() * m.interval_count() {
                    return Err(FatError::DisplacementCount {
                        key: table.key,
                        mesh: m.mesh.clone(),
                        found: m.displacements.len(),
                        coord_index: m.coord_index.len(),
                        intervals: m.interval_count(),
                    }
                    .into());
                }
                tables[slot].meshes.push(CompiledMesh {
                    mesh,
                    borders: m.interval_borders.clone(),
                    coord_index: m.coord_index.clone(),
                    rates: m.displacements.clone(),
                });
            }
            for t in &table.transforms {
                let transform = transforms
                    .iter()
                    .position(|name| *name == t.transform)
                    .ok_or_else(|| FatError::UnknownTransform {
                        key: table.key,
                        transform: t.transform.clone(),
                    })?;
                tables[slot].transforms.push(CompiledTransform {
                    transform,
                    field: t.field,
                    axis: t.rotation_axis.try_normalize().unwrap_or(Vec3::Z),
                    angle: t.rotation_angle,
                    scale: t.scale,
                    translation: t.translation,
                });
            }
        }
        let max_intervals = fat
            .tables
            .iter()
            .flat_map(|t| t.meshes.iter().map(|m| m.interval_count()))
            .max()
            .unwrap_or(0);
        Ok(FatEvaluator {
            vertex_counts: meshes.iter().map(|(_, n)| *n).collect(),
            transform_count: transforms.len(),
            tables,
            weights: Vec::with_capacity(max_intervals),
        })
    }

    /// Fresh zeroed output buffers sized for this face.
    pub fn output(&self) -> FatOutput {
        FatOutput {
            displacements: self
                .vertex_counts
                .iter()
                .map(|&n| vec![Vec3::ZERO; n])
                .collect(),
            transforms: vec![TransformDelta::IDENTITY; self.transform_count],
        }
    }

    /// True when the face has a table for `key`.
    pub fn has_table(&self, key: TableKey) -> bool {
        key.slot().is_some_and(|s| {
            let t = &self.tables[s];
            !t.meshes.is_empty() || !t.transforms.is_empty()
        })
    }

    /// Evaluates `activations` into `out` (cleared first). Activations whose key has no table
    /// are skipped; use [`FatEvaluator::has_table`] to count them. No allocation happens here
    /// once `out` came from [`FatEvaluator::output`].
    pub fn evaluate(&mut self, activations: &[Activation], out: &mut FatOutput) {
        for d in &mut out.displacements {
            d.fill(Vec3::ZERO);
        }
        out.transforms.fill(TransformDelta::IDENTITY);
        for a in activations {
            if a.value == 0.0 || !a.value.is_finite() {
                continue;
            }
            let Some(slot) = a.key.slot() else { continue };
            let table = &self.tables[slot];
            for m in &table.meshes {
                interval_weights(&m.borders, a.value, &mut self.weights);
                let n = self.weights.len();
                let target = &mut out.displacements[m.mesh];
                if n == 1 {
                    // The common single-interval table: one multiply-add per vertex.
                    let w = self.weights[0] as f32;
                    for (&vi, rate) in m.coord_index.iter().zip(&m.rates) {
                        target[vi as usize] += *rate * w;
                    }
                } else {
                    for (k, &vi) in m.coord_index.iter().enumerate() {
                        let rates = &m.rates[k * n..(k + 1) * n];
                        let mut d = Vec3::ZERO;
                        for (r, &w) in rates.iter().zip(&self.weights) {
                            d += *r * w as f32;
                        }
                        target[vi as usize] += d;
                    }
                }
            }
            for t in &table.transforms {
                let delta = &mut out.transforms[t.transform];
                let p = a.value as f32;
                match t.field {
                    TransformField::Rotation => {
                        delta.rotation =
                            Quat::from_axis_angle(t.axis, t.angle * p) * delta.rotation;
                    }
                    TransformField::Scale => delta.scale += t.scale * p,
                    TransformField::Translation => delta.translation += t.translation * p,
                }
            }
        }
    }
}
