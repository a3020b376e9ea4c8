//! Building the target's FAT (module docs of [`super`], step 8): cloned skin motions back in
//! each mesh's frame, rebuilt into tables, transform entries appended, every number checked.

use std::collections::HashMap;

use super::motions::back_to_meshes;
use super::rigid::RigidPlan;
use super::{CloneReport, FaceParts, Similarity, SkinSurface};
use crate::clone::CloneError;
use crate::clone::SurfaceMotion;
use crate::error::Result;
use crate::face::FaceModel;
use crate::fat::morph::{fat_from_morph_targets, MorphMesh, MorphTarget};
use crate::fat::{Fat, TableKey};

/// The source side of a clone: the face, its parts and its FAT as morph targets.
pub(super) struct SourceMotions<'a> {
    /// The source face.
    pub face: &'a FaceModel,
    /// Its parts.
    pub parts: &'a FaceParts,
    /// Its FAT as morph targets.
    pub targets: &'a [MorphTarget],
}

/// What cloning produced on the target, by source motion (key, value bits): skin motions and
/// the split parts' rigid displacements.
pub(super) struct ClonedMotions<'a> {
    /// Skin motions.
    pub skin: HashMap<(TableKey, u64), &'a SurfaceMotion>,
    /// Part meshes' displacements.
    pub parts: HashMap<(TableKey, u64), Vec<MorphMesh>>,
}

/// The target FAT: one table per source morph target from the `cloned` skin motions (by key
/// and value) and the split parts' rigid motions, plus the rigid plan's transform entries. Fails on any non-finite number.
pub(super) fn assemble_fat(
    source: &SourceMotions,
    cloned: &ClonedMotions,
    face: &FaceModel,
    tsurf: &SkinSurface,
    alignment: &Similarity,
    rigid: &RigidPlan,
    report: &mut CloneReport,
) -> Result<Fat> {
    let frames = face.frames();
    let mut out_targets = Vec::with_capacity(source.targets.len());
    for t in source.targets {
        let mut meshes = Vec::new();
        if let Some(m) = cloned.skin.get(&(t.key, t.value.to_bits())) {
            meshes = back_to_meshes(face, &frames, tsurf, alignment, m);
        }
        if let Some(extra) = cloned.parts.get(&(t.key, t.value.to_bits())) {
            meshes.extend(extra.iter().cloned());
        }
        out_targets.push(MorphTarget {
            key: t.key,
            value: t.value,
            meshes,
            transforms: Vec::new(),
        });
    }
    let mut fat = fat_from_morph_targets(&out_targets)?;
    rigid.add_entries(
        source.face,
        source.parts,
        source.targets,
        face,
        &frames,
        alignment,
        tsurf,
        &mut fat,
        report,
    );
    check_finite(&fat)?;
    Ok(fat)
}

/// Every displacement, border and transform entry of `fat` must be finite.
fn check_finite(fat: &Fat) -> Result<()> {
    for t in &fat.tables {
        for m in &t.meshes {
            if m.displacements.iter().any(|d| !d.is_finite())
                || m.interval_borders.iter().any(|b| !b.is_finite())
            {
                return Err(CloneError::NonFiniteDisplacement {
                    key: t.key,
                    mesh: m.mesh.clone(),
                }
                .into());
            }
        }
        for x in &t.transforms {
            if !x.rotation_axis.is_finite()
                || !x.rotation_angle.is_finite()
                || !x.scale.is_finite()
                || !x.translation.is_finite()
            {
                return Err(CloneError::NonFiniteTransform {
                    key: t.key,
                    transform: x.transform.clone(),
                }
                .into());
            }
        }
    }
    Ok(())
}
