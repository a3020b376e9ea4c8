//! The target FAT's transform entries: source entries mapped by role onto the target's
//! transforms, and tongue deformations turned into rigid tongue translations.

use std::collections::{BTreeSet, HashSet};

use glam::{Affine3A, DMat3, DVec3};

use super::{tongue_mesh_names, RigidPlan, Role};
use crate::clone::face::{CloneReport, FaceParts, Similarity, SkinSurface};
use crate::error::Diagnostic;
use crate::face::{FaceFrames, FaceModel};
use crate::fat::morph::{MorphMesh, MorphTarget};
use crate::fat::{FaceDefTransform, Fat, TableKey, TransformField};
use crate::fdp::Fapu;
use crate::spec::FapuKind;

/// Both faces with their frames and FAPUs: what mapping a transform entry needs.
struct EntryContext<'a> {
    source: &'a FaceModel,
    sframes: FaceFrames,
    face: &'a FaceModel,
    frames: &'a FaceFrames,
    /// Target → source alignment.
    frame: &'a Similarity,
    sfapu: Option<Fapu>,
    tfapu: &'a Fapu,
}

impl EntryContext<'_> {
    /// Target / source FAPU of `key`'s unit (`fallback` for high-level tables and angles);
    /// the alignment scale when the source has no FAPU.
    fn ratio(&self, key: TableKey, fallback: FapuKind) -> f64 {
        let kind = match key {
            TableKey::LowLevel(f) => f.info().fapu.unwrap_or(fallback),
            _ => fallback,
        };
        let kind = if kind == FapuKind::Au { fallback } else { kind };
        match &self.sfapu {
            Some(s) => self.tfapu.unit(kind) / s.unit(kind),
            None => self.frame.scale,
        }
    }

    /// Source entry `x` of table `key` on source transform `st`, mapped onto target
    /// transform `tt` of `role`.
    fn mapped_entry(
        &self,
        key: TableKey,
        x: &FaceDefTransform,
        st: usize,
        role: Role,
        tt: usize,
    ) -> FaceDefTransform {
        let tname = self.face.transforms[tt].name.clone();
        match x.field {
            TransformField::Rotation => {
                let a = axis_frame(self.source, &self.sframes, st)
                    * x.rotation_axis.as_dvec3().normalize_or_zero();
                let a_t = self.frame.rotation.inverse() * a;
                let local =
                    (axis_frame(self.face, self.frames, tt).inverse() * a_t).normalize_or_zero();
                FaceDefTransform::rotation(tname, local.as_vec3(), x.rotation_angle)
            }
            TransformField::Translation => {
                let fallback = match role {
                    Role::Part(p) => p.unit(),
                    Role::Head => FapuKind::Ens,
                };
                let v = parent_frame(self.source, &self.sframes, st) * x.translation.as_dvec3();
                // Aligned frame = source frame; the ratio uses the aligned target FAPU.
                let v_t = self.frame.inverse_vector(v) * self.ratio(key, fallback);
                let local = parent_frame(self.face, self.frames, tt).inverse() * v_t;
                FaceDefTransform::translation(tname, local.as_vec3())
            }
            TransformField::Scale => FaceDefTransform {
                transform: tname,
                ..x.clone()
            },
        }
    }
}

/// Frame in which a transform's rotation axis lives: parent world · neutral rotation.
fn axis_frame(f: &FaceModel, fr: &FaceFrames, t: usize) -> DMat3 {
    let tf = &f.transforms[t];
    let parent = tf.parent.map_or(Affine3A::IDENTITY, |p| fr.transforms[p]);
    parent.matrix3.as_dmat3() * DMat3::from_quat(tf.rotation.as_dquat())
}

/// Linear part of a transform's parent world matrix (where its translation lives).
fn parent_frame(f: &FaceModel, fr: &FaceFrames, t: usize) -> DMat3 {
    f.transforms[t]
        .parent
        .map_or(DMat3::IDENTITY, |p| fr.transforms[p].matrix3.as_dmat3())
}

impl RigidPlan {
    /// Appends transform entries (mapped source entries and rigid tongue motion) to `fat`.
    #[allow(clippy::too_many_arguments)]
    pub(in crate::clone::face) fn add_entries(
        &self,
        source: &FaceModel,
        sparts: &FaceParts,
        targets: &[MorphTarget],
        face: &FaceModel,
        frames: &FaceFrames,
        frame: &Similarity,
        tsurf: &SkinSurface,
        fat: &mut Fat,
        report: &mut CloneReport,
    ) {
        let ctx = EntryContext {
            source,
            sframes: source.frames(),
            face,
            frames,
            frame,
            sfapu: source.fapu().ok(),
            tfapu: &tsurf.surface.fapu,
        };
        let mapped = self.add_mapped_entries(&ctx, fat, &mut report.warnings);
        let rigid_tongue =
            self.add_rigid_tongue_entries(&ctx, sparts, targets, fat, &mut report.warnings);
        report.rigid.transform_entries = mapped + rigid_tongue;
        report.rigid.rigid_tongue_tables = rigid_tongue;
    }

    /// Maps every source transform entry onto its target transform; warns about source
    /// transforms without one. Returns the entries written.
    fn add_mapped_entries(
        &self,
        ctx: &EntryContext,
        fat: &mut Fat,
        warnings: &mut Vec<Diagnostic>,
    ) -> usize {
        let mut entries = 0;
        let mut dropped_tf: BTreeSet<String> = BTreeSet::new();
        for table in &ctx.source.fat.tables {
            let Some(out) = fat.tables.iter_mut().find(|t| t.key == table.key) else {
                continue;
            };
            for x in &table.transforms {
                let Some(st) = ctx.source.transform_index(&x.transform) else {
                    continue;
                };
                let Some(&(role, tt)) = self.map.get(&st) else {
                    // Head turns onto a face without a head transform are re-made by the
                    // standard step (10), not lost.
                    if !(Some(st) == self.standard_head
                        && super::standard::is_standard_rotation(table.key))
                    {
                        dropped_tf.insert(x.transform.clone());
                    }
                    continue;
                };
                out.transforms
                    .push(ctx.mapped_entry(table.key, x, st, role, tt));
                entries += 1;
            }
        }
        if !dropped_tf.is_empty() {
            warnings.push(Diagnostic::warning(format!(
                "source transforms {} have no counterpart on the target; their motion is dropped",
                dropped_tf.into_iter().collect::<Vec<_>>().join(", ")
            )));
        }
        entries
    }

    /// Turns source deformations of the tongue (no surface method applies to it) into one
    /// rigid translation of the target's tongue transform per table; warns about non-skin
    /// deformations without a rigid equivalent. Returns the entries written.
    fn add_rigid_tongue_entries(
        &self,
        ctx: &EntryContext,
        sparts: &FaceParts,
        targets: &[MorphTarget],
        fat: &mut Fat,
        warnings: &mut Vec<Diagnostic>,
    ) -> usize {
        let source = ctx.source;
        let tongue_meshes = tongue_mesh_names(source, sparts);
        let skin_meshes: HashSet<&str> = sparts
            .skin
            .iter()
            .map(|&m| source.meshes[m].name.as_str())
            .collect();
        let mut dropped: BTreeSet<String> = BTreeSet::new();
        let mut rigid_tongue = 0;
        let mut done: HashSet<TableKey> = HashSet::new();
        // One rigid translation per key, from its largest positive value (transforms are linear).
        let mut order: Vec<&MorphTarget> = targets.iter().collect();
        order.sort_by(|a, b| b.value.total_cmp(&a.value));
        for t in order {
            for mm in &t.meshes {
                let name = mm.mesh.as_str();
                if skin_meshes.contains(name) || mm.offsets.iter().all(|o| *o == DVec3::ZERO) {
                    continue;
                }
                if !tongue_meshes.contains(name) {
                    dropped.insert(format!("{} (mesh `{name}`)", t.key.name()));
                    continue;
                }
                if done.contains(&t.key) {
                    continue;
                }
                let Some(tt) = self.tongue else {
                    dropped.insert(format!("{} (no target tongue)", t.key.name()));
                    continue;
                };
                let Some(mi) = source.mesh_index(name) else {
                    continue;
                };
                let d = tongue_displacement(ctx, mi, t.key, mm);
                let size = mm.offsets.iter().map(|o| o.length()).fold(0.0, f64::max);
                if d.length() <= 1e-3 * size || d.length() == 0.0 {
                    dropped.insert(format!(
                        "{} (tongue motion is no translation)",
                        t.key.name()
                    ));
                    done.insert(t.key);
                    continue;
                }
                let v_t = ctx.frame.inverse_vector(d) * ctx.ratio(t.key, FapuKind::Mns) / t.value;
                let local = parent_frame(ctx.face, ctx.frames, tt).inverse() * v_t;
                if let Some(out) = fat.tables.iter_mut().find(|x| x.key == t.key) {
                    out.transforms.push(FaceDefTransform::translation(
                        ctx.face.transforms[tt].name.clone(),
                        local.as_vec3(),
                    ));
                    rigid_tongue += 1;
                }
                done.insert(t.key);
            }
        }
        if !dropped.is_empty() {
            warnings.push(Diagnostic::warning(format!(
                "non-skin deformations without a rigid equivalent are dropped: {}",
                dropped.into_iter().collect::<Vec<_>>().join(", ")
            )));
        }
        rigid_tongue
    }
}

/// Face-frame displacement of source tongue mesh `mi` under morph mesh `mm` of table `key`:
/// the displacement of the FAP's tongue feature point, else the mean tongue displacement.
fn tongue_displacement(ctx: &EntryContext, mi: usize, key: TableKey, mm: &MorphMesh) -> DVec3 {
    let lin = ctx.sframes.meshes[mi].matrix3.as_dmat3();
    let fp_vertex = match key {
        TableKey::LowLevel(f) => f.info().feature_points.iter().find_map(|&id| {
            ctx.source
                .fp_vertex(id)
                .filter(|(m, _)| *m == mi)
                .map(|x| x.1)
        }),
        _ => None,
    };
    match fp_vertex {
        Some(v) => mm
            .vertices
            .iter()
            .position(|&x| x == v)
            .map_or(DVec3::ZERO, |k| lin * mm.offsets[k]),
        None => mm.offsets.iter().map(|o| lin * *o).sum::<DVec3>() / mm.offsets.len() as f64,
    }
}
