//! A face's tables evaluated as motion: the displacement of every vertex, in the face frame,
//! at the values that pin a table down (its non-zero interval borders and its reference
//! value), and the change of every transform there. Diff and snapshot both read faces
//! through this, so they compare and print the same thing: animation, not storage (a sparse
//! VRML table and a dense glTF morph target of the same motion look alike here).

use glam::{Affine3A, DAffine3, DVec3, Mat3, Mat4, Quat, Vec3};

use crate::error::Result;
use crate::face::{FaceModel, FacePose};
use crate::fat::eval::{Activation, FatEvaluator, FatOutput, TransformDelta};
use crate::fat::morph::default_value;
use crate::fat::TableKey;

use super::SnapshotError;

/// A face ready to evaluate one table at one value at a time.
pub(crate) struct FaceMotion<'f> {
    pub face: &'f FaceModel,
    evaluator: FatEvaluator,
    out: FatOutput,
    pose: FacePose,
    /// Each mesh's face-frame matrix at neutral.
    frames: Vec<Affine3A>,
    /// Linear part of each mesh's face-frame matrix; `None` when it is the identity.
    linear: Vec<Option<Mat3>>,
    /// First global vertex index of each mesh (meshes in face order).
    pub offsets: Vec<usize>,
    /// Neutral positions of every vertex in the face frame, meshes in order.
    pub neutral: Vec<DVec3>,
}

impl<'f> FaceMotion<'f> {
    /// Binds `face`'s FAT; a face without tables is refused when `need_fat`.
    pub fn new(face: &'f FaceModel, need_fat: bool) -> Result<Self> {
        if need_fat && face.fat.tables.is_empty() {
            return Err(SnapshotError::NoFat {
                face: face.name.clone(),
            }
            .into());
        }
        let evaluator = face.evaluator()?;
        let out = evaluator.output();
        let frames = face.frames();
        let mut offsets = Vec::with_capacity(face.meshes.len());
        let mut neutral = Vec::with_capacity(face.vertex_count());
        let mut linear = Vec::with_capacity(face.meshes.len());
        for (i, m) in face.meshes.iter().enumerate() {
            offsets.push(neutral.len());
            let frame = frames.meshes[i];
            let frame64 = to_f64(frame);
            neutral.extend(
                m.mesh
                    .positions
                    .iter()
                    .map(|p| frame64.transform_point3(p.as_dvec3())),
            );
            let l = Mat3::from(frame.matrix3);
            linear.push((l != Mat3::IDENTITY).then_some(l));
        }
        Ok(FaceMotion {
            face,
            evaluator,
            out,
            pose: FacePose::default(),
            frames: frames.meshes,
            linear,
            offsets,
            neutral,
        })
    }

    /// Total vertex count.
    pub fn vertex_count(&self) -> usize {
        self.neutral.len()
    }

    /// Keys with a table, sorted (FAPs by number, then visemes, then expressions).
    pub fn keys(&self) -> Vec<TableKey> {
        self.face.fat.keys()
    }

    /// The values that pin `key`'s motion down: every non-zero border of its meshes (the
    /// motion is linear between borders and beyond the outer ones, and zero at zero) and its
    /// reference value ([`default_value`]), sorted.
    pub fn sample_values(&self, key: TableKey) -> Vec<f64> {
        let mut values = vec![default_value(key)];
        for t in self.face.fat.tables.iter().filter(|t| t.key == key) {
            for m in &t.meshes {
                values.extend(
                    m.interval_borders
                        .iter()
                        .copied()
                        .filter(|b| *b != 0.0 && b.is_finite()),
                );
            }
        }
        values.sort_by(f64::total_cmp);
        values.dedup();
        values
    }

    /// The interval borders of `key`'s meshes, merged and sorted.
    pub fn borders(&self, key: TableKey) -> Vec<f64> {
        let mut b: Vec<f64> = self
            .face
            .fat
            .tables
            .iter()
            .filter(|t| t.key == key)
            .flat_map(|t| t.meshes.iter().flat_map(|m| m.interval_borders.iter()))
            .copied()
            .filter(|b| b.is_finite())
            .collect();
        b.sort_by(f64::total_cmp);
        b.dedup();
        b
    }

    /// Names of the transforms `key`'s tables drive, sorted and unique.
    pub fn driven_transforms(&self, key: TableKey) -> Vec<&'f str> {
        let mut names: Vec<&str> = self
            .face
            .fat
            .tables
            .iter()
            .filter(|t| t.key == key)
            .flat_map(|t| t.transforms.iter().map(|x| x.transform.as_str()))
            .collect();
        names.sort_unstable();
        names.dedup();
        names
    }

    /// Evaluates `key` alone at `value`: every vertex's displacement in the face frame into
    /// `into` (resized to the vertex count), through the one posing rule
    /// ([`FaceModel::pose_into`]), so motion a table gives through transforms (eyes, jaw
    /// nodes) counts as vertex motion too. Transform changes are then in
    /// [`FaceMotion::transform_delta`].
    pub fn evaluate(&mut self, key: TableKey, value: f64, into: &mut Vec<DVec3>) {
        self.evaluator
            .evaluate(&[Activation { key, value }], &mut self.out);
        self.face.pose_into(&self.out, &mut self.pose);
        into.clear();
        for (mi, m) in self.face.meshes.iter().enumerate() {
            let d = &self.out.displacements[mi];
            let posed = self.pose.world.meshes[mi];
            if posed == self.frames[mi] {
                // The mesh's frame did not move: its displacements, turned into the face
                // frame (no cancellation against the neutral position).
                match self.linear[mi] {
                    None => into.extend(d.iter().map(|v| v.as_dvec3())),
                    Some(l) => into.extend(d.iter().map(|v| (l * *v).as_dvec3())),
                }
            } else {
                let posed = to_f64(posed);
                let base = self.offsets[mi];
                into.extend(
                    m.mesh
                        .positions
                        .iter()
                        .zip(d)
                        .enumerate()
                        .map(|(k, (p, v))| {
                            posed.transform_point3((*p + *v).as_dvec3()) - self.neutral[base + k]
                        }),
                );
            }
        }
    }

    /// The change of the transform named `name` in the last evaluation (identity when the
    /// face has no such transform).
    pub fn transform_delta(&self, name: &str) -> TransformDelta {
        self.face
            .transform_index(name)
            .and_then(|i| self.out.transforms.get(i).copied())
            .unwrap_or(TransformDelta::IDENTITY)
    }

    /// The face size: the diagonal of the neutral's bounding box in the face frame.
    pub fn size(&self) -> f64 {
        bounding_diagonal(&self.neutral)
    }
}

fn to_f64(a: Affine3A) -> DAffine3 {
    DAffine3::from_mat4(Mat4::from(a).as_dmat4())
}

/// Diagonal of the bounding box of `points` (0 for none; non-finite points skipped).
pub(crate) fn bounding_diagonal(points: &[DVec3]) -> f64 {
    let mut it = points.iter().filter(|p| p.is_finite());
    let Some(first) = it.next() else {
        return 0.0;
    };
    let (lo, hi) = it.fold((*first, *first), |(lo, hi), p| (lo.min(*p), hi.max(*p)));
    (hi - lo).length()
}

/// The angle between two rotations in degrees (0..=180): exactly 0 for equal ones (the
/// vector part of `a⁻¹·b` cancels exactly, where `acos` of a `w` a rounding below 1 would not).
pub(crate) fn rotation_difference_degrees(a: Quat, b: Quat) -> f64 {
    let (a, b) = (a.as_dquat(), b.as_dquat());
    let d = a.conjugate() * b;
    let v = glam::DVec3::new(d.x, d.y, d.z).length();
    (2.0 * v.atan2(d.w.abs())).to_degrees()
}

/// Length of the difference of two vectors, in f64.
pub(crate) fn vec_difference(a: Vec3, b: Vec3) -> f64 {
    (a.as_dvec3() - b.as_dvec3()).length()
}
