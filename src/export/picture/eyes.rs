//! Eyeballs of a face, found from its pupil feature points (3.5 left, 3.6 right), so that
//! pictures and the viewer can paint an iris and a pupil on them.
//!
//! A pupil bound to a mesh named as an eye ([`FacePart::of_mesh_name`]) makes that whole mesh
//! the eyeball. A pupil bound to a vertex of any other mesh — a one-mesh head such as the
//! ICT-FaceKit's, whose eyeballs are loose pieces of the head mesh — makes the connected piece
//! holding that vertex the eyeball, if it is a small piece (not the skin itself). Either way
//! the eyeball's centre is the mean of its neutral vertices and its front the direction from
//! there to the pupil point; the iris and pupil are the caps within [`IRIS_DEGREES`] and
//! [`PUPIL_DEGREES`] of that direction, as [`crate::face::parts`] paints separate eye meshes.

use glam::Vec3;

use crate::face::parts::{FacePart, IRIS_DEGREES, PUPIL_DEGREES};
use crate::face::FaceModel;
use crate::spec::FeaturePointId;

/// Largest share of a mesh's vertices a piece may hold to count as an eyeball inside it.
const MAX_EYEBALL_SHARE: f64 = 0.25;
/// Fewest vertices of an eyeball piece.
const MIN_EYEBALL_VERTICES: usize = 12;

/// One eyeball of a face.
#[derive(Clone, Debug, PartialEq)]
pub struct Eyeball {
    /// Index of the face mesh holding it.
    pub mesh: usize,
    /// Its vertices in that mesh, ascending.
    pub vertices: Vec<u32>,
    /// Centre in the face frame (neutral).
    pub centre: Vec3,
    /// Unit direction from the centre to the pupil point.
    pub front: Vec3,
}

impl Eyeball {
    /// The part a point of the eyeball shows: pupil, iris or eye white, by its angle from
    /// the pupil direction.
    pub fn part_at(&self, p: Vec3) -> FacePart {
        let cos = (p - self.centre).normalize_or_zero().dot(self.front);
        if cos >= PUPIL_DEGREES.to_radians().cos() {
            FacePart::Pupil
        } else if cos >= IRIS_DEGREES.to_radians().cos() {
            FacePart::Iris
        } else {
            FacePart::EyeWhite
        }
    }

    /// Whether vertex `v` of its mesh belongs to it.
    pub fn contains(&self, v: u32) -> bool {
        self.vertices.binary_search(&v).is_ok()
    }
}

/// The eyeballs of `face` (see the module docs), `neutral` being its neutral world positions
/// per mesh ([`FaceModel::neutral_world_positions`]). At most one per pupil point.
pub fn eyeballs(face: &FaceModel, neutral: &[Vec<Vec3>]) -> Vec<Eyeball> {
    let mut out: Vec<Eyeball> = Vec::new();
    let mut pieces: Vec<Option<(Vec<u32>, usize)>> = vec![None; face.meshes.len()];
    for index in [5, 6] {
        let Some(id) = FeaturePointId::new(3, index) else {
            continue;
        };
        let Some(fp) = face.feature_points.get(id) else {
            continue;
        };
        let Some(b) = &fp.binding else { continue };
        let mesh = match &b.mesh {
            Some(name) => face.mesh_index(name),
            None if face.meshes.len() == 1 => Some(0),
            None => None,
        };
        let (Some(mesh), Some(&vertex)) = (mesh, b.vertices.first()) else {
            continue;
        };
        let Some(positions) = neutral.get(mesh) else {
            continue;
        };
        if vertex as usize >= positions.len() {
            continue;
        }
        let vertices: Vec<u32> =
            if FacePart::of_mesh_name(&face.meshes[mesh].name) == FacePart::EyeWhite {
                (0..positions.len() as u32).collect()
            } else {
                let (piece, _) = pieces[mesh].get_or_insert_with(|| {
                    crate::mesh::components::connected_components(&face.meshes[mesh].mesh, &[])
                });
                let label = piece[vertex as usize];
                let members: Vec<u32> = (0..piece.len() as u32)
                    .filter(|&v| piece[v as usize] == label)
                    .collect();
                let small = (members.len() as f64) <= MAX_EYEBALL_SHARE * positions.len() as f64;
                if !small || members.len() < MIN_EYEBALL_VERTICES {
                    continue;
                }
                members
            };
        let pts: Vec<Vec3> = vertices
            .iter()
            .map(|&v| positions[v as usize])
            .filter(|p| p.is_finite())
            .collect();
        if pts.is_empty() {
            continue;
        }
        let centre = pts.iter().copied().sum::<Vec3>() / pts.len() as f32;
        let pupil = fp.position.unwrap_or(positions[vertex as usize]);
        let Some(front) = (pupil - centre).try_normalize() else {
            continue;
        };
        if out.iter().any(|e| e.mesh == mesh && e.vertices == vertices) {
            continue;
        }
        out.push(Eyeball {
            mesh,
            vertices,
            centre,
            front,
        });
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_real_head_has_two_eyeballs_inside_its_one_mesh() {
        let face = crate::face::BundledFace::Ict.read().unwrap().0;
        assert_eq!(face.meshes.len(), 1);
        let neutral = face.neutral_world_positions();
        let eyes = eyeballs(&face, &neutral);
        assert_eq!(eyes.len(), 2, "{:?}", eyes.iter().map(|e| e.vertices.len()));
        for e in &eyes {
            // ICT's sclera pieces (770 vertices each; the iris discs behind are their own).
            assert!(
                (100..2000).contains(&e.vertices.len()),
                "{}",
                e.vertices.len()
            );
            assert!(e.front.z > 0.9, "{:?}", e.front);
            let pupils = e
                .vertices
                .iter()
                .filter(|&&v| e.part_at(neutral[0][v as usize]) == FacePart::Pupil)
                .count();
            assert!(pupils > 0);
        }
        assert!(eyes[0].centre.x * eyes[1].centre.x < 0.0, "one each side");
    }

    #[test]
    fn named_eye_meshes_are_whole_eyeballs() {
        let face = crate::synth::alma().to_face_model();
        let neutral = face.neutral_world_positions();
        let eyes = eyeballs(&face, &neutral);
        assert_eq!(eyes.len(), 2);
        for e in &eyes {
            assert_eq!(
                FacePart::of_mesh_name(&face.meshes[e.mesh].name),
                FacePart::EyeWhite
            );
            assert_eq!(e.vertices.len(), face.meshes[e.mesh].mesh.vertex_count());
        }
        let mut bare = face.clone();
        bare.feature_points = Default::default();
        assert!(eyeballs(&bare, &neutral).is_empty());
    }
}
