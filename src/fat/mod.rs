//! Facial Animation Tables (FATs): for each FAP (or viseme / expression), how the vertices and
//! transforms of one face move.
//!
//! The model mirrors the MPEG-4 nodes: a [`Fat`] is the list of `FaceDefTables`
//! ([`FaceDefTable`]), each holding [`FaceDefMesh`] entries (piecewise-linear vertex motion) and
//! [`FaceDefTransform`] entries (rotation / scale / translation of a `Transform` node). Meshes
//! and transforms are referred to by their `DEF` name, exactly as the VRML `USE` does.
//!
//! Evaluation ([`eval`]) turns FAP values into per-vertex displacements and transform changes;
//! [`morph`] converts between FATs and morph targets; [`bake`] turns a motion of some vertices
//! (a transform's, a rigid part's) into displacement entries.
//!
//! ## Units
//! The value `P` a table is evaluated at is the raw FAP value for low-level FAPs (so the face's
//! FAPU is baked into the displacements: a FAT is model specific). For the high-level tables it
//! is the blend or intensity on the standard's 0..=63 scale: viseme `select1` is evaluated at
//! `blend`, `select2` at `63 - blend`; expression `select1` at `intensity1`, `select2` at
//! `intensity2` (the two terms are added). A table whose only interval is `[0, 63]` therefore
//! shows its full morph target at `P = 63`.

pub mod bake;
mod error;
pub mod eval;
pub mod morph;
pub mod validate;

pub use error::FatError;

use std::fmt;

use glam::Vec3;
use serde::{Deserialize, Serialize};

use crate::spec::{Expression, FapId, Viseme};

/// Value of the high-level FAPs' blend / intensity that means "full strength".
pub const HIGH_LEVEL_FULL: f64 = 63.0;

/// What a table animates: one low-level FAP, one viseme or one expression.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum TableKey {
    /// A low-level FAP (3..=68).
    LowLevel(FapId),
    /// FAP 1 with `highLevelSelect` = viseme number (1..=14).
    Viseme(Viseme),
    /// FAP 2 with `highLevelSelect` = expression number (1..=6).
    Expression(Expression),
}

impl TableKey {
    /// The key of a `FaceDefTables` node from its `fapID` and `highLevelSelect` fields.
    pub fn from_node_fields(fap_id: i64, high_level_select: i64) -> Result<TableKey, String> {
        let fap = u8::try_from(fap_id)
            .ok()
            .and_then(FapId::new)
            .ok_or_else(|| format!("fapID {fap_id} is outside 1..=68"))?;
        match fap.number() {
            1 => u8::try_from(high_level_select)
                .ok()
                .filter(|&n| n >= 1)
                .and_then(Viseme::new)
                .map(TableKey::Viseme)
                .ok_or_else(|| {
                    format!("highLevelSelect {high_level_select} is not a viseme 1..=14")
                }),
            2 => u8::try_from(high_level_select)
                .ok()
                .filter(|&n| n >= 1)
                .and_then(Expression::new)
                .map(TableKey::Expression)
                .ok_or_else(|| {
                    format!("highLevelSelect {high_level_select} is not an expression 1..=6")
                }),
            _ => Ok(TableKey::LowLevel(fap)),
        }
    }

    /// `(fapID, highLevelSelect)` as written in a `FaceDefTables` node (`highLevelSelect` is 1,
    /// the node default, for low-level tables).
    pub fn node_fields(self) -> (u8, u8) {
        match self {
            TableKey::LowLevel(f) => (f.number(), 1),
            TableKey::Viseme(v) => (1, v.number()),
            TableKey::Expression(e) => (2, e.number()),
        }
    }

    /// Dense slot 0..83 (66 low-level FAPs, 14 visemes, 6 expressions), for lookup arrays;
    /// `None` for viseme 0 / neutral, which never have tables.
    pub fn slot(self) -> Option<usize> {
        match self {
            TableKey::LowLevel(f) if !f.is_high_level() => Some(f.index() - 2),
            TableKey::LowLevel(_) => None,
            TableKey::Viseme(v) if v.number() > 0 => Some(66 + v.number() as usize - 1),
            TableKey::Expression(e) if e.number() > 0 => Some(80 + e.number() as usize - 1),
            _ => None,
        }
    }

    /// Short name: the FAP name, `viseme_N` or the expression name (used for morph file names).
    pub fn name(self) -> String {
        match self {
            TableKey::LowLevel(f) => f.name().to_string(),
            TableKey::Viseme(v) => format!("viseme_{}", v.number()),
            TableKey::Expression(e) => e.name().to_string(),
        }
    }

    /// The key named like [`TableKey::name`] produces (`open_jaw`, `viseme_7`, `joy`).
    pub fn from_name(name: &str) -> Option<TableKey> {
        if let Some(f) = FapId::from_name(name).filter(|f| !f.is_high_level()) {
            return Some(TableKey::LowLevel(f));
        }
        if let Some(rest) = name.strip_prefix("viseme_") {
            return rest
                .parse::<u8>()
                .ok()
                .filter(|&n| n >= 1)
                .and_then(Viseme::new)
                .map(TableKey::Viseme);
        }
        Expression::from_name(name)
            .filter(|e| *e != Expression::Neutral && e.name() == name.to_ascii_lowercase())
            .map(TableKey::Expression)
    }

    /// Number of distinct slots.
    pub const SLOTS: usize = 66 + 14 + 6;
}

impl fmt::Display for TableKey {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            TableKey::LowLevel(id) => write!(f, "FAP {} {}", id.number(), id.name()),
            TableKey::Viseme(v) => write!(f, "viseme {} ({})", v.number(), v.label()),
            TableKey::Expression(e) => write!(f, "expression {} ({})", e.number(), e.name()),
        }
    }
}

/// Vertex motion of one mesh for one FAP: a `FaceDefMesh` node.
///
/// `interval_borders` `b0 < b1 < … < bn` split the FAP value axis into `n` intervals; each
/// listed vertex has one displacement *per unit of FAP value* for each interval, stored
/// vertex-major (all intervals of the first listed vertex, then the next).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FaceDefMesh {
    /// `DEF` name of the `IndexedFaceSet` being deformed.
    pub mesh: String,
    /// Strictly increasing borders; one of them is 0.
    pub interval_borders: Vec<f64>,
    /// Indices into the mesh's `Coordinate` points.
    pub coord_index: Vec<u32>,
    /// `coord_index.len() × intervals` rates, vertex-major.
    pub displacements: Vec<Vec3>,
}

impl FaceDefMesh {
    /// Number of intervals (`borders − 1`, or 0 for fewer than two borders).
    pub fn interval_count(&self) -> usize {
        self.interval_borders.len().saturating_sub(1)
    }

    /// The rate of listed vertex `slot` in interval `j`.
    pub fn rate(&self, slot: usize, interval: usize) -> Vec3 {
        self.displacements[slot * self.interval_count() + interval]
    }

    /// How much of each interval the value `p` covers: the signed length of `[0, p]` that lies
    /// in each interval, with the outermost intervals extended to ±∞ so their rate continues
    /// beyond the outer borders. The displacement of a vertex is `Σ weight_j × rate_j`.
    ///
    /// `weights` is cleared and refilled (no allocation once it has the capacity).
    pub fn interval_weights(&self, p: f64, weights: &mut Vec<f64>) {
        interval_weights(&self.interval_borders, p, weights);
    }

    /// Displacement of listed vertex `slot` at value `p` (allocates; for tests and tools —
    /// the evaluator uses [`FaceDefMesh::interval_weights`] once per table instead).
    pub fn displacement(&self, slot: usize, p: f64) -> Vec3 {
        let mut w = Vec::new();
        self.interval_weights(p, &mut w);
        w.iter()
            .enumerate()
            .map(|(j, &wj)| self.rate(slot, j) * wj as f32)
            .sum()
    }
}

/// See [`FaceDefMesh::interval_weights`].
pub fn interval_weights(borders: &[f64], p: f64, weights: &mut Vec<f64>) {
    weights.clear();
    let n = borders.len().saturating_sub(1);
    for j in 0..n {
        // Interval j spans [lo, hi]; the first reaches down to -inf, the last up to +inf.
        let lo = if j == 0 {
            f64::NEG_INFINITY
        } else {
            borders[j]
        };
        let hi = if j + 1 == n {
            f64::INFINITY
        } else {
            borders[j + 1]
        };
        let w = if p >= 0.0 {
            (p.min(hi) - lo.max(0.0)).max(0.0)
        } else {
            -(hi.min(0.0) - p.max(lo)).max(0.0)
        };
        weights.push(w);
    }
}

/// Which field of a `Transform` a [`FaceDefTransform`] drives.
///
/// The numeric `fieldId` coding is not confirmed by an accessible source; fbakit reads and
/// writes 1 = rotation, 2 = scale, 3 = translation (the order of the `rotationDef`,
/// `scaleDef`, `translationDef` fields, and the node default 1 = the first of them).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum TransformField {
    /// `rotation`: axis of `rotationDef`, angle `rotationDef.angle × P`.
    Rotation,
    /// `scale`: neutral scale `+ P × scaleDef` (the literal reading; see the module docs).
    Scale,
    /// `translation`: neutral translation `+ P × translationDef`.
    Translation,
}

impl TransformField {
    /// The `fieldId` number written in files.
    pub const fn field_id(self) -> i32 {
        match self {
            TransformField::Rotation => 1,
            TransformField::Scale => 2,
            TransformField::Translation => 3,
        }
    }

    /// The field for a `fieldId` number.
    pub fn from_field_id(id: i64) -> Option<TransformField> {
        match id {
            1 => Some(TransformField::Rotation),
            2 => Some(TransformField::Scale),
            3 => Some(TransformField::Translation),
            _ => None,
        }
    }
}

/// Motion of one `Transform` node for one FAP: a `FaceDefTransform` node.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FaceDefTransform {
    /// `DEF` name of the `Transform` being driven.
    pub transform: String,
    /// Which field is driven.
    pub field: TransformField,
    /// Axis (need not be unit length in files; normalised on use) and angle per FAP unit.
    pub rotation_axis: Vec3,
    /// Radians per unit of FAP value.
    pub rotation_angle: f32,
    /// Scale change per unit of FAP value.
    pub scale: Vec3,
    /// Translation per unit of FAP value.
    pub translation: Vec3,
}

impl FaceDefTransform {
    /// A rotation entry: `angle_per_unit` radians about `axis` per unit of FAP value.
    pub fn rotation(transform: impl Into<String>, axis: Vec3, angle_per_unit: f32) -> Self {
        FaceDefTransform {
            transform: transform.into(),
            field: TransformField::Rotation,
            rotation_axis: axis,
            rotation_angle: angle_per_unit,
            scale: Vec3::ONE,
            translation: Vec3::ZERO,
        }
    }

    /// A translation entry: `per_unit` per unit of FAP value.
    pub fn translation(transform: impl Into<String>, per_unit: Vec3) -> Self {
        FaceDefTransform {
            transform: transform.into(),
            field: TransformField::Translation,
            rotation_axis: Vec3::Z,
            rotation_angle: 0.0,
            scale: Vec3::ONE,
            translation: per_unit,
        }
    }
}

/// One `FaceDefTables` node: everything one FAP / viseme / expression moves.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FaceDefTable {
    /// What the table animates.
    pub key: TableKey,
    /// Vertex motion, one entry per mesh.
    pub meshes: Vec<FaceDefMesh>,
    /// Transform motion, one entry per driven transform field.
    pub transforms: Vec<FaceDefTransform>,
}

impl FaceDefTable {
    /// An empty table for `key`.
    pub fn new(key: TableKey) -> Self {
        FaceDefTable {
            key,
            meshes: Vec::new(),
            transforms: Vec::new(),
        }
    }

    /// Number of vertex entries over all meshes.
    pub fn moved_vertex_count(&self) -> usize {
        self.meshes.iter().map(|m| m.coord_index.len()).sum()
    }
}

/// A face's Facial Animation Tables: the `faceDefTables` of its `FDP` node.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Fat {
    /// The tables in file order.
    pub tables: Vec<FaceDefTable>,
}

impl Fat {
    /// The first table for `key`, if any.
    pub fn table(&self, key: TableKey) -> Option<&FaceDefTable> {
        self.tables.iter().find(|t| t.key == key)
    }

    /// The tables in fbakit's canonical order, for documents fbakit generates (so equal
    /// FATs read in any order write the same bytes): by key (FAPs by number, then visemes,
    /// then expressions; tables of one key keep their order), each table's entries by mesh
    /// name and by transform name and field.
    pub fn canonical_tables(&self) -> Vec<FaceDefTable> {
        let mut tables = self.tables.clone();
        tables.sort_by_key(|t| t.key);
        for t in &mut tables {
            t.meshes.sort_by(|a, b| a.mesh.cmp(&b.mesh));
            t.transforms.sort_by(|a, b| {
                (a.transform.as_str(), a.field.field_id())
                    .cmp(&(b.transform.as_str(), b.field.field_id()))
            });
        }
        tables
    }

    /// Keys that have at least one table, sorted.
    pub fn keys(&self) -> Vec<TableKey> {
        let mut k: Vec<TableKey> = self.tables.iter().map(|t| t.key).collect();
        k.sort();
        k.dedup();
        k
    }
}

#[cfg(test)]
mod tests;
