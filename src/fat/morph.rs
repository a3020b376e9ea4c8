//! FATs as morph targets, and back.
//!
//! A morph target is the face deformed to show one table at one known value `V`. A
//! single-interval table `[0, V]` (or `[V, 0]`) is exactly one morph target; a multi-interval
//! table becomes one morph target per non-zero border. Offsets are kept in `f64`: an `f32` rate
//! times an integer value below 2^29 is exact in `f64`, and so is the division back, which is
//! what makes FAT → morph targets → FAT lossless for single-interval tables.

use glam::{DVec3, Vec3};
use serde::{Deserialize, Serialize};

use super::{interval_weights, FaceDefMesh, FaceDefTable, FaceDefTransform, Fat, TableKey};
use super::{FatError, TransformField, HIGH_LEVEL_FULL};
use crate::error::Result;

/// FAP value a low-level translation morph target represents when none is given (half of the
/// face's FAP-unit distance, i.e. 512 units).
pub const DEFAULT_LINEAR_VALUE: f64 = 512.0;

/// FAP value a rotation (AU) morph target represents when none is given: 20 000 AU = 0.2 rad.
pub const DEFAULT_ANGLE_VALUE: f64 = 20_000.0;

/// The value a morph target of `key` represents by default: full strength (63) for visemes and
/// expressions, [`DEFAULT_ANGLE_VALUE`] for angle FAPs, [`DEFAULT_LINEAR_VALUE`] otherwise.
pub fn default_value(key: TableKey) -> f64 {
    match key {
        TableKey::Viseme(_) | TableKey::Expression(_) => HIGH_LEVEL_FULL,
        TableKey::LowLevel(f) if f.info().is_rotation() => DEFAULT_ANGLE_VALUE,
        TableKey::LowLevel(_) => DEFAULT_LINEAR_VALUE,
    }
}

/// The vertices of one mesh as displaced by a morph target.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct MorphMesh {
    /// `DEF` name of the mesh.
    pub mesh: String,
    /// Moved vertices (indices into the mesh's points).
    pub vertices: Vec<u32>,
    /// Displacement from neutral of each moved vertex, at the target's value.
    pub offsets: Vec<DVec3>,
}

impl MorphMesh {
    /// The mesh's points with this target applied to a copy of `neutral`.
    pub fn displaced(&self, neutral: &[Vec3]) -> Vec<Vec3> {
        let mut out = neutral.to_vec();
        for (&v, o) in self.vertices.iter().zip(&self.offsets) {
            if let Some(p) = out.get_mut(v as usize) {
                *p = (p.as_dvec3() + *o).as_vec3();
            }
        }
        out
    }
}

/// The change of one transform field at a morph target's value.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct MorphTransform {
    /// `DEF` name of the `Transform`.
    pub transform: String,
    /// Which field changes.
    pub field: TransformField,
    /// Rotation axis.
    pub rotation_axis: Vec3,
    /// Rotation angle at the target's value (radians).
    pub rotation_angle: f64,
    /// Scale change at the target's value.
    pub scale: DVec3,
    /// Translation change at the target's value.
    pub translation: DVec3,
}

/// One table shown at one value.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct MorphTarget {
    /// Which FAP / viseme / expression.
    pub key: TableKey,
    /// The value it represents (non-zero).
    pub value: f64,
    /// Displaced vertices per mesh.
    pub meshes: Vec<MorphMesh>,
    /// Transform changes.
    pub transforms: Vec<MorphTransform>,
}

/// The morph targets of a FAT: per key (in first-appearance order), one target per non-zero
/// interval border of its meshes (or one at [`default_value`] when it only drives transforms).
pub fn fat_to_morph_targets(fat: &Fat) -> Vec<MorphTarget> {
    let mut out = Vec::new();
    let mut weights = Vec::new();
    for key in keys_in_order(fat) {
        let tables: Vec<&FaceDefTable> = fat.tables.iter().filter(|t| t.key == key).collect();
        let mut values: Vec<f64> = tables
            .iter()
            .flat_map(|t| t.meshes.iter().flat_map(|m| m.interval_borders.iter()))
            .copied()
            .filter(|&b| b != 0.0 && b.is_finite())
            .collect();
        values.sort_by(f64::total_cmp);
        values.dedup();
        if values.is_empty() {
            values.push(default_value(key));
        }
        for &value in &values {
            let mut meshes = Vec::new();
            for m in tables.iter().flat_map(|t| t.meshes.iter()) {
                interval_weights(&m.interval_borders, value, &mut weights);
                let n = weights.len();
                let offsets = (0..m.coord_index.len())
                    .map(|k| {
                        weights
                            .iter()
                            .enumerate()
                            .map(|(j, &w)| m.displacements[k * n + j].as_dvec3() * w)
                            .sum()
                    })
                    .collect();
                meshes.push(MorphMesh {
                    mesh: m.mesh.clone(),
                    vertices: m.coord_index.clone(),
                    offsets,
                });
            }
            let transforms = tables
                .iter()
                .flat_map(|t| t.transforms.iter())
                .map(|t| MorphTransform {
                    transform: t.transform.clone(),
                    field: t.field,
                    rotation_axis: t.rotation_axis,
                    rotation_angle: t.rotation_angle as f64 * value,
                    scale: t.scale.as_dvec3() * value,
                    translation: t.translation.as_dvec3() * value,
                })
                .collect();
            out.push(MorphTarget {
                key,
                value,
                meshes,
                transforms,
            });
        }
    }
    out
}

fn keys_in_order(fat: &Fat) -> Vec<TableKey> {
    let mut keys: Vec<TableKey> = Vec::new();
    for t in &fat.tables {
        if !keys.contains(&t.key) {
            keys.push(t.key);
        }
    }
    keys
}

/// Builds a FAT from morph targets: one table per key (first-appearance order), borders at 0
/// and at every target value of that key, rates = offset differences / border differences.
///
/// Fails on a zero or non-finite value, two targets of one key at the same value, or a
/// target whose vertex and offset lists differ in length.
pub fn fat_from_morph_targets(targets: &[MorphTarget]) -> Result<Fat> {
    let mut keys: Vec<TableKey> = Vec::new();
    for t in targets {
        if !t.value.is_finite() || t.value == 0.0 {
            return Err(FatError::BadMorphValue {
                key: t.key,
                value: t.value,
            }
            .into());
        }
        for m in &t.meshes {
            if m.vertices.len() != m.offsets.len() {
                return Err(FatError::MorphLengths {
                    key: t.key,
                    mesh: m.mesh.clone(),
                    vertices: m.vertices.len(),
                    offsets: m.offsets.len(),
                }
                .into());
            }
        }
        if !keys.contains(&t.key) {
            keys.push(t.key);
        }
    }
    // Tables are independent: built in parallel, kept in key order (and the first key's
    // error reported, as a sequential build would).
    use rayon::prelude::*;
    let tables: Vec<Result<FaceDefTable>> =
        keys.par_iter().map(|&key| table_of(targets, key)).collect();
    let mut fat = Fat::default();
    for t in tables {
        fat.tables.push(t?);
    }
    Ok(fat)
}

/// The table of `key` from its morph targets (module docs of [`fat_from_morph_targets`]).
fn table_of(targets: &[MorphTarget], key: TableKey) -> Result<FaceDefTable> {
    let mut group: Vec<&MorphTarget> = targets.iter().filter(|t| t.key == key).collect();
    group.sort_by(|a, b| a.value.total_cmp(&b.value));
    if let Some(w) = group.windows(2).find(|w| w[0].value == w[1].value) {
        return Err(FatError::DuplicateMorphValue {
            key,
            value: w[0].value,
        }
        .into());
    }
    let mut borders: Vec<f64> = group.iter().map(|t| t.value).collect();
    let zero_at = borders.partition_point(|&b| b < 0.0);
    borders.insert(zero_at, 0.0);

    let mut table = FaceDefTable::new(key);
    for mesh in mesh_names_in_order(&group) {
        table
            .meshes
            .push(mesh_entry(&group, &mesh, &borders, zero_at));
    }
    // Transforms are linear in the value: the first target defines them.
    if let Some(first) = group.first() {
        for t in &first.transforms {
            let v = first.value;
            table.transforms.push(FaceDefTransform {
                transform: t.transform.clone(),
                field: t.field,
                rotation_axis: t.rotation_axis,
                rotation_angle: (t.rotation_angle / v) as f32,
                scale: (t.scale / v).as_vec3(),
                translation: (t.translation / v).as_vec3(),
            });
        }
    }
    Ok(table)
}

fn mesh_names_in_order(group: &[&MorphTarget]) -> Vec<String> {
    let mut names: Vec<String> = Vec::new();
    for t in group {
        for m in &t.meshes {
            if !names.contains(&m.mesh) {
                names.push(m.mesh.clone());
            }
        }
    }
    names
}

fn mesh_entry(group: &[&MorphTarget], mesh: &str, borders: &[f64], zero_at: usize) -> FaceDefMesh {
    // This mesh's entry in each target, with the target's border.
    let entries: Vec<(usize, &MorphMesh)> = group
        .iter()
        .enumerate()
        .flat_map(|(gi, t)| {
            let b = if gi < zero_at { gi } else { gi + 1 };
            t.meshes
                .iter()
                .filter(|m| m.mesh == mesh)
                .map(move |m| (b, m))
        })
        .collect();
    // Vertex order: the first target's order, then any vertex only later targets move.
    let mut slots = VertexSlots::new(entries.iter().map(|(_, m)| m.vertices.as_slice()));
    let mut vertices: Vec<u32> = Vec::new();
    for (_, m) in &entries {
        for &v in &m.vertices {
            if slots.insert(v, vertices.len() as u32) {
                vertices.push(v);
            }
        }
    }
    // offsets[k·nb + b]: offset of vertex k at border b (zero at the zero border).
    let nb = borders.len();
    let mut offsets = vec![DVec3::ZERO; vertices.len() * nb];
    for (b, m) in &entries {
        for (&v, o) in m.vertices.iter().zip(&m.offsets) {
            offsets[slots.get(v) as usize * nb + b] = *o;
        }
    }
    let mut displacements = Vec::with_capacity(vertices.len() * (nb - 1));
    for per_vertex in offsets.chunks_exact(nb.max(1)) {
        for (o, b) in per_vertex.windows(2).zip(borders.windows(2)) {
            displacements.push(((o[1] - o[0]) / (b[1] - b[0])).as_vec3());
        }
    }
    FaceDefMesh {
        mesh: mesh.to_string(),
        interval_borders: borders.to_vec(),
        coord_index: vertices,
        displacements,
    }
}

/// Each vertex's slot in a mesh entry: a table indexed by vertex when the indices are not
/// much larger than the lists holding them (the usual case, no hashing), else a map, so a
/// stray huge index costs no huge table.
enum VertexSlots {
    Dense(Vec<u32>),
    Sparse(std::collections::HashMap<u32, u32>),
}

impl VertexSlots {
    fn new<'a>(lists: impl Iterator<Item = &'a [u32]> + Clone) -> Self {
        let total: usize = lists.clone().map(<[u32]>::len).sum();
        let max = lists.flatten().copied().max();
        match max {
            Some(m) if m as usize > 4 * total + 1024 => VertexSlots::Sparse(Default::default()),
            m => VertexSlots::Dense(vec![u32::MAX; m.map_or(0, |m| m as usize + 1)]),
        }
    }

    /// Gives `v` slot `slot` unless it has one; whether it was new.
    fn insert(&mut self, v: u32, slot: u32) -> bool {
        match self {
            VertexSlots::Dense(t) => {
                let s = &mut t[v as usize];
                let new = *s == u32::MAX;
                if new {
                    *s = slot;
                }
                new
            }
            VertexSlots::Sparse(m) => match m.entry(v) {
                std::collections::hash_map::Entry::Occupied(_) => false,
                std::collections::hash_map::Entry::Vacant(e) => {
                    e.insert(slot);
                    true
                }
            },
        }
    }

    /// The slot of a vertex given one.
    fn get(&self, v: u32) -> u32 {
        match self {
            VertexSlots::Dense(t) => t[v as usize],
            VertexSlots::Sparse(m) => m[&v],
        }
    }
}
