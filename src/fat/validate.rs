//! Consistency checks of a FAT against the meshes and transforms of its face.
//!
//! Every problem names the table (by position and key) and the entry inside it, so the face
//! layer can attach the scene-graph path and line of the node it came from.

use serde::Serialize;

use super::{Fat, TableKey};

/// Which part of a table a [`FatProblem`] is about.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum FatEntry {
    /// The table node itself.
    Table,
    /// Its `faceDefMesh` entry at this position.
    Mesh(usize),
    /// Its `faceDefTransform` entry at this position.
    Transform(usize),
}

/// One finding of [`validate_fat`].
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FatProblem {
    /// Position of the table in [`Fat::tables`].
    pub table: usize,
    /// The table's key.
    pub key: TableKey,
    /// Entry within the table.
    pub entry: FatEntry,
    /// What is wrong.
    pub message: String,
}

/// Checks: interval borders strictly increasing, finite, with exactly one border equal to 0
/// and at least two borders; displacement count = `coordIndex × intervals`; coordinate
/// indices in range of the named mesh; mesh and transform names known; rotation axes
/// non-zero; all numbers finite. `meshes` lists (DEF name, vertex count), `transforms` DEF names.
pub fn validate_fat(fat: &Fat, meshes: &[(&str, usize)], transforms: &[&str]) -> Vec<FatProblem> {
    let mut problems = Vec::new();
    for (ti, table) in fat.tables.iter().enumerate() {
        let mut report = |entry, message: String| {
            problems.push(FatProblem {
                table: ti,
                key: table.key,
                entry,
                message,
            })
        };
        if table.key.slot().is_none() {
            report(
                FatEntry::Table,
                "viseme 0 / the neutral expression cannot have a table".to_string(),
            );
        }
        for (mi, m) in table.meshes.iter().enumerate() {
            let entry = FatEntry::Mesh(mi);
            let b = &m.interval_borders;
            if b.len() < 2 {
                report(
                    entry,
                    format!(
                        "intervalBorders has {} value(s); at least two are needed",
                        b.len()
                    ),
                );
            }
            if b.iter().any(|x| !x.is_finite()) {
                report(entry, "intervalBorders contains a non-finite value".into());
            }
            if let Some(w) = b.windows(2).find(|w| w[0] >= w[1]) {
                report(
                    entry,
                    format!(
                        "intervalBorders must increase strictly, but {} is followed by {}",
                        w[0], w[1]
                    ),
                );
            }
            let zeros = b.iter().filter(|&&x| x == 0.0).count();
            if zeros != 1 && b.len() >= 2 {
                report(
                    entry,
                    format!("intervalBorders must contain 0 exactly once; it does {zeros} time(s)"),
                );
            }
            let expected = m.coord_index.len() * m.interval_count();
            if m.displacements.len() != expected {
                report(
                    entry,
                    format!(
                        "{} displacements, expected {expected} (coordIndex {} × intervals {})",
                        m.displacements.len(),
                        m.coord_index.len(),
                        m.interval_count()
                    ),
                );
            }
            if m.displacements.iter().any(|d| !d.is_finite()) {
                report(entry, "displacements contain a non-finite value".into());
            }
            match meshes.iter().find(|(name, _)| *name == m.mesh) {
                None => report(
                    entry,
                    format!("faceSceneGraphNode `{}` is not a mesh of this face", m.mesh),
                ),
                Some((_, count)) => {
                    let bad: Vec<u32> = m
                        .coord_index
                        .iter()
                        .copied()
                        .filter(|&i| i as usize >= *count)
                        .collect();
                    if let Some(first) = bad.first() {
                        report(
                            entry,
                            format!(
                                "{} coordIndex value(s) out of range for `{}` with {count} vertices (first: {first})",
                                bad.len(),
                                m.mesh
                            ),
                        );
                    }
                }
            }
            let mut seen = std::collections::HashSet::new();
            if let Some(dup) = m.coord_index.iter().find(|&&i| !seen.insert(i)) {
                report(
                    entry,
                    format!("coordIndex lists vertex {dup} more than once"),
                );
            }
        }
        for (xi, t) in table.transforms.iter().enumerate() {
            let entry = FatEntry::Transform(xi);
            if !transforms.contains(&t.transform.as_str()) {
                report(
                    entry,
                    format!(
                        "faceSceneGraphNode `{}` is not a Transform of this face",
                        t.transform
                    ),
                );
            }
            let finite = t.rotation_axis.is_finite()
                && t.rotation_angle.is_finite()
                && t.scale.is_finite()
                && t.translation.is_finite();
            if !finite {
                report(
                    entry,
                    "a non-finite value in rotationDef, scaleDef or translationDef".into(),
                );
            }
            if t.field == super::TransformField::Rotation && t.rotation_axis.length_squared() == 0.0
            {
                report(entry, "rotationDef has a zero axis".into());
            }
        }
    }
    problems
}
