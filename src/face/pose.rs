//! Posing a face: an evaluated FAT output (vertex displacements and transform changes)
//! turned into mesh positions and face-frame matrices. Every consumer — the player, cloning
//! measures, pictures, exports — poses through these functions, so there is one rule:
//!
//! - mesh vertex `v` of mesh `m` moves to `p_v + d_v` in the mesh's local frame;
//! - transform `t` gets the animated local matrix [`super::FaceTransform::animated_matrix`]
//!   of its FAT delta;
//! - face-frame matrices chain the locals parents first ([`FaceModel::frames_into`]), and a
//!   vertex's world position is its mesh's world matrix applied to its local position.

use glam::{Affine3A, Vec3};

use super::{FaceFrames, FaceModel};
use crate::error::Result;
use crate::fap::{DenseFrame, FapFrame};
use crate::fat::eval::{frame_activations, Activation, FatEvaluator, FatOutput};

/// One pose of a face, in buffers that are refilled without allocating.
#[derive(Clone, Debug, Default)]
pub struct FacePose {
    /// Per mesh, per vertex: neutral + FAT displacement, in the mesh's local frame.
    pub positions: Vec<Vec<Vec3>>,
    /// Per transform: its animated local matrix.
    pub transform_locals: Vec<Affine3A>,
    /// World (face-frame) matrices of every transform and mesh in this pose.
    pub world: FaceFrames,
}

impl FacePose {
    /// Face-frame position of every vertex of mesh `mesh` (empty for an unknown mesh).
    pub fn world_positions(&self, mesh: usize) -> impl ExactSizeIterator<Item = Vec3> + '_ {
        let m = self
            .world
            .meshes
            .get(mesh)
            .copied()
            .unwrap_or(Affine3A::IDENTITY);
        self.positions
            .get(mesh)
            .map_or(&[][..], |p| p.as_slice())
            .iter()
            .map(move |&p| m.transform_point3(p))
    }

    /// Face-frame positions of all meshes, per mesh and vertex.
    pub fn all_world_positions(&self) -> Vec<Vec<Vec3>> {
        let mut out = Vec::new();
        self.world_positions_into(&mut out);
        out
    }

    /// Face-frame positions of all meshes, written into `out` (resized, buffers reused).
    pub fn world_positions_into(&self, out: &mut Vec<Vec<Vec3>>) {
        out.resize_with(self.positions.len(), Vec::new);
        for (i, o) in out.iter_mut().enumerate() {
            o.clear();
            o.extend(self.world_positions(i));
        }
    }
}

impl FaceModel {
    /// Refills `pose` from an evaluated FAT `output` of this face (see the module docs).
    /// Allocates only the first time, when the buffers are sized.
    pub fn pose_into(&self, output: &FatOutput, pose: &mut FacePose) {
        pose.positions.resize_with(self.meshes.len(), Vec::new);
        for (mi, (pos, m)) in pose.positions.iter_mut().zip(&self.meshes).enumerate() {
            pos.clear();
            match output.displacements.get(mi) {
                Some(d) if d.len() == m.mesh.positions.len() => {
                    pos.extend(m.mesh.positions.iter().zip(d).map(|(&p, &d)| p + d))
                }
                _ => pos.extend_from_slice(&m.mesh.positions),
            }
        }
        pose.transform_locals.clear();
        pose.transform_locals
            .extend(self.transforms.iter().enumerate().map(|(i, t)| {
                output
                    .transforms
                    .get(i)
                    .map_or_else(|| t.local_matrix(), |d| t.animated_matrix(d))
            }));
        self.frames_into(&pose.transform_locals, &mut pose.world);
    }

    /// World (face-frame) positions of every mesh with `activations` applied, using a
    /// caller's evaluator and output buffers (for many poses of one face).
    pub fn pose_with(
        &self,
        evaluator: &mut FatEvaluator,
        output: &mut FatOutput,
        activations: &[Activation],
    ) -> Vec<Vec<Vec3>> {
        evaluator.evaluate(activations, output);
        let mut pose = FacePose::default();
        self.pose_into(output, &mut pose);
        let mut world = Vec::new();
        pose.world_positions_into(&mut world);
        world
    }

    /// World positions of every mesh with `activations` applied (one pose; for many, use
    /// [`FaceModel::pose_with`] or the player).
    pub fn pose(&self, activations: &[Activation]) -> Result<Vec<Vec<Vec3>>> {
        let mut evaluator = self.evaluator()?;
        let mut output = evaluator.output();
        Ok(self.pose_with(&mut evaluator, &mut output, activations))
    }

    /// World positions of every mesh for one FAP frame: the FAPs it transmits at their
    /// values, every other FAP at 0 (neutral), its viseme and expression if it has them.
    pub fn pose_frame(&self, frame: &FapFrame) -> Result<Vec<Vec<Vec3>>> {
        let mut state = DenseFrame::NEUTRAL;
        state.apply(frame);
        let mut activations = Vec::new();
        frame_activations(&state, &mut activations);
        self.pose(&activations)
    }

    /// World positions of every mesh at neutral.
    pub fn neutral_world_positions(&self) -> Vec<Vec<Vec3>> {
        let frames = self.frames();
        self.meshes
            .iter()
            .zip(&frames.meshes)
            .map(|(m, w)| {
                m.mesh
                    .positions
                    .iter()
                    .map(|&p| w.transform_point3(p))
                    .collect()
            })
            .collect()
    }

    /// [`FaceModel::frames_with`] into existing buffers (no allocation once they have
    /// capacity). Transforms must come parents first, which readers and builders guarantee.
    pub fn frames_into(&self, locals: &[Affine3A], out: &mut FaceFrames) {
        out.transforms.clear();
        for (i, t) in self.transforms.iter().enumerate() {
            let parent = t
                .parent
                .filter(|&p| p < i)
                .map_or(Affine3A::IDENTITY, |p| out.transforms[p]);
            let local = locals.get(i).copied().unwrap_or(Affine3A::IDENTITY);
            out.transforms.push(parent * local);
        }
        out.meshes.clear();
        for m in &self.meshes {
            let w = m
                .transform
                .and_then(|t| out.transforms.get(t).copied())
                .unwrap_or(Affine3A::IDENTITY);
            out.meshes.push(w);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fat::TableKey;
    use crate::spec::FapId;

    #[test]
    fn one_frame_pose_matches_activations() {
        let face = crate::face::read("alma").unwrap();
        let jaw = FapId::from_name("open_jaw").unwrap();
        let mut frame = FapFrame::new(0);
        frame.set(jaw, 400.0);
        let by_frame = face.pose_frame(&frame).unwrap();
        let by_key = face
            .pose(&[Activation {
                key: TableKey::LowLevel(jaw),
                value: 400.0,
            }])
            .unwrap();
        assert_eq!(by_frame, by_key);
        let neutral = face.neutral_world_positions();
        assert_eq!(face.pose(&[]).unwrap(), neutral);
        assert_ne!(by_key, neutral, "the jaw moved");
    }
}
