//! Which meshes a feature point given by position may snap to ([`super::attach`]).
//!
//! Snapping to the nearest vertex of *any* mesh lets lashes catch the eyelid points and a
//! hat the top of the head. So the face's skin is found first: the mesh most skin points
//! (every point but the pupils, teeth and tongue) lie nearest to — or are bound to —, with the
//! meshes joined to it (sharing a vertex position: primitives split at UV seams). Skin points
//! snap to the skin only. Part points (3.5, 3.6, 9.8–9.11, 6.x) snap to the nearest vertex of
//! the other meshes — the eye or teeth part —, or to any mesh when the face has its parts in
//! the skin mesh (one-mesh heads) or no other mesh comes within twice the nearest vertex's
//! distance.

use std::collections::{BTreeSet, HashMap};

use glam::Vec3;

use super::vertex_index::FaceVertexIndex;
use super::FaceModel;
use crate::spec::FeaturePointId;

/// Whether the standard puts feature point `id` on a part, not on the skin: the pupils, the
/// teeth and the tongue.
pub fn is_part_point(id: FeaturePointId) -> bool {
    matches!(
        (id.group(), id.index()),
        (3, 5) | (3, 6) | (9, 8..=11) | (6, _)
    )
}

/// Nearest-vertex indices for skin and part points of one face.
pub struct SnapIndex {
    all: FaceVertexIndex,
    skin: Option<FaceVertexIndex>,
    others: Option<FaceVertexIndex>,
}

impl SnapIndex {
    /// The indices for `face`, its skin chosen by the points `positions` (unbound, by position)
    /// and the meshes `bound` (meshes of points bound to vertices).
    pub fn new(face: &FaceModel, positions: &[(FeaturePointId, Vec3)], bound: &[usize]) -> Self {
        let all = FaceVertexIndex::new(face);
        let mut votes = vec![0usize; face.meshes.len()];
        for &m in bound {
            if let Some(v) = votes.get_mut(m) {
                *v += 1;
            }
        }
        for (id, p) in positions {
            if !is_part_point(*id) {
                if let Some((m, _, _)) = all.nearest(*p) {
                    votes[m] += 1;
                }
            }
        }
        let core = (0..face.meshes.len())
            .filter(|&m| votes[m] > 0)
            .max_by_key(|&m| (votes[m], face.meshes[m].mesh.positions.len()));
        let Some(core) = core.filter(|_| face.meshes.len() > 1) else {
            return SnapIndex {
                all,
                skin: None,
                others: None,
            };
        };
        let skin = joined_to(face, core);
        let rest: Vec<usize> = (0..face.meshes.len())
            .filter(|m| !skin.contains(m))
            .collect();
        let skin: Vec<usize> = skin.into_iter().collect();
        SnapIndex {
            all,
            skin: Some(FaceVertexIndex::of_meshes(face, &skin)),
            others: (!rest.is_empty()).then(|| FaceVertexIndex::of_meshes(face, &rest)),
        }
    }

    /// The index a point `id` at `p` snaps with (see the module docs).
    pub fn for_point(&self, id: FeaturePointId, p: Vec3) -> &FaceVertexIndex {
        if !is_part_point(id) {
            return self.skin.as_ref().unwrap_or(&self.all);
        }
        let (Some(others), Some((_, _, d_all))) = (&self.others, self.all.nearest(p)) else {
            return &self.all;
        };
        match others.nearest(p) {
            Some((_, _, d)) if d <= 2.0 * d_all => others,
            _ => &self.all,
        }
    }
}

/// Mesh `core` and the meshes joined to it, directly or through each other, by a shared
/// vertex position (within 1e-5 of the face's size).
fn joined_to(face: &FaceModel, core: usize) -> BTreeSet<usize> {
    let world = face.neutral_world_positions();
    let size = super::attach::face_size(face);
    let q = (size * 1e-5).max(f32::MIN_POSITIVE);
    let key = |p: Vec3| {
        (
            (p.x / q).round() as i64,
            (p.y / q).round() as i64,
            (p.z / q).round() as i64,
        )
    };
    let mut cells: HashMap<(i64, i64, i64), Vec<usize>> = HashMap::new();
    for (mi, ps) in world.iter().enumerate() {
        for p in ps.iter().filter(|p| p.is_finite()) {
            let list = cells.entry(key(*p)).or_default();
            if list.last() != Some(&mi) {
                list.push(mi);
            }
        }
    }
    let mut joined = BTreeSet::from([core]);
    let mut queue = vec![core];
    while let Some(m) = queue.pop() {
        for p in world[m].iter().filter(|p| p.is_finite()) {
            for &o in cells.get(&key(*p)).into_iter().flatten() {
                if joined.insert(o) {
                    queue.push(o);
                }
            }
        }
    }
    joined
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn part_points_are_the_pupils_teeth_and_tongue() {
        let part = |s: &str| is_part_point(s.parse().unwrap());
        assert!(part("3.5") && part("3.6") && part("9.8") && part("9.11") && part("6.2"));
        assert!(!part("3.1") && !part("9.3") && !part("2.1") && !part("9.15"));
    }
}
