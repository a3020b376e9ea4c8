//! The triangle BVH of a [`super::surface::QuerySurface`] with what its filters need per
//! node: the union of the side masks below the node and a cone holding the normals of its
//! triangles. A filtered closest-point search then skips a whole subtree whose triangles the
//! filter rejects, where a filter applied per triangle visits every box within the search
//! distance (the normal-compatible searches of registration and correspondence found most
//! nearby triangles facing away, and scanned them all).
//!
//! The tree is parry's own BVH of the mesh, read node by node, and the search is parry's
//! best-first descent ([`parry3d::partitioning::Bvh::find_best`]) step for step: the same
//! children in the same order, the same box and triangle distances, ties kept by the first
//! found. A pruned subtree holds no triangle the filter allows, so it could never have
//! produced a candidate: the search returns exactly what the per-triangle filter returns.
//!
//! Cone test: with `a` the cone's axis, `φ` its half-angle (every triangle normal `t` below
//! the node within `φ` of `a`) and `γ = acos(c)` the widest angle a triangle may make with
//! the query normal `n` (`t·n ≥ c`), every `t` makes at least `∠(a, n) − φ` with `n`, so the
//! subtree is rejected when `∠(a, n) > φ + γ` (that is `a·n < cos(φ + γ)` for `φ + γ < π`),
//! with a margin far above rounding.

use glam::Vec3;
use parry3d::bounding_volume::{Aabb, BoundingVolume};
use parry3d::math::Vector as PVec;
use parry3d::partitioning::{BvhNodeIndex, TraversalAction};
use parry3d::query::{PointProjection, PointQuery, PointQueryWithLocation};
use parry3d::shape::{TriMesh, TrianglePointLocation};

use super::regions::{mask_passes, TriMask};

/// Radians added to the cone test's angle so rounding never rejects an allowed triangle.
const MARGIN: f32 = 1e-3;

/// The mask of a triangle without one: it passes every query bit.
const ALL: TriMask = super::regions::SEEN_BY_ALL | super::regions::FACE_PIECE;

/// One node of the mirror, at parry's node index (`2 × pair + side`).
#[derive(Clone, Copy, Debug)]
struct Node {
    aabb: Aabb,
    /// Leaf: the triangle; inner node: the pair index of its two children.
    child: u32,
    leaf: bool,
    /// Union of the side masks below.
    mask: TriMask,
    /// Unit cone axis (zero: no cone, the node is never rejected by normal).
    axis: Vec3,
    /// Half-angle of the cone, and its cosine and sine.
    half: f32,
    cos_half: f32,
    sin_half: f32,
}

/// A search's normal test, prepared once per query.
#[derive(Clone, Copy)]
pub(crate) struct NormalTest {
    /// The query normal and, on a crease, a second one a triangle may match instead (both
    /// `None`: no normal rejects a subtree).
    normals: [Option<Vec3>; 2],
    /// `γ` (module docs) with the margin, and its cosine and sine.
    gamma: f32,
    cos_gamma: f32,
    sin_gamma: f32,
}

impl NormalTest {
    /// The test `t·n ≥ cos` (or `t·m ≥ cos` for the crease normal `m`). Subtrees are only
    /// rejected by unit normals: the cone test measures angles.
    pub fn new(n: Vec3, crease: Option<Vec3>, cos: f32) -> Self {
        let gamma = cos.clamp(-1.0, 1.0).acos() + MARGIN;
        let unit = |v: Vec3| (v.length_squared() - 1.0).abs() < 1e-4;
        let usable = gamma.is_finite() && unit(n) && crease.is_none_or(unit);
        NormalTest {
            normals: if usable { [Some(n), crease] } else { [None; 2] },
            gamma,
            cos_gamma: gamma.cos(),
            sin_gamma: gamma.sin(),
        }
    }
}

/// The mirrored BVH (module docs).
pub(crate) struct FilterTree {
    nodes: Vec<Node>,
}

impl Node {
    /// Whether no triangle below passes the mask bit and the normal test.
    #[inline]
    fn rejects(&self, bit: TriMask, normal: Option<&NormalTest>) -> bool {
        if !mask_passes(self.mask, bit) {
            return true;
        }
        let Some(test) = normal else {
            return false;
        };
        if self.axis == Vec3::ZERO
            || test.normals[0].is_none()
            || self.half + test.gamma >= std::f32::consts::PI
        {
            return false;
        }
        let limit = self.cos_half * test.cos_gamma - self.sin_half * test.sin_gamma;
        test.normals
            .iter()
            .flatten()
            .all(|n| self.axis.dot(*n) < limit)
    }
}

impl FilterTree {
    /// Mirrors `mesh`'s BVH with the triangles' side `masks` (empty: every triangle seen by
    /// all) and unit `normals` (zero: degenerate). `None` when the tree is not a full pair
    /// of children at the root (a mesh of one triangle) or does not read back consistently.
    pub fn new(mesh: &TriMesh, masks: &[TriMask], normals: &[Vec3]) -> Option<Self> {
        let bvh = mesh.bvh();
        if bvh.leaf_count() < 2 {
            return None;
        }
        // Read each node and, for an inner node, where its children are: parry's traversal
        // from a subtree checks the node, then its two children with their indices.
        let read = |idx: usize| -> Option<(Aabb, u32, bool)> {
            let mut out = None;
            let mut first = true;
            bvh.traverse_indexed(Some(BvhNodeIndex(idx)), |node, i| {
                if first {
                    first = false;
                    out = Some((node.aabb(), node.leaf_data().unwrap_or(0), node.is_leaf()));
                    TraversalAction::Continue
                } else {
                    if let Some(o) = out.as_mut() {
                        o.1 = i.decompose().0 as u32;
                    }
                    TraversalAction::EarlyExit
                }
            });
            out
        };
        let empty = Node {
            aabb: Aabb::new_invalid(),
            child: 0,
            leaf: true,
            mask: 0,
            axis: Vec3::ZERO,
            half: 0.0,
            cos_half: 1.0,
            sin_half: 0.0,
        };
        let mut nodes: Vec<Node> = Vec::new();
        let mut order: Vec<usize> = Vec::new();
        let mut stack = vec![0usize, 1];
        while let Some(idx) = stack.pop() {
            let (aabb, child, leaf) = read(idx)?;
            if nodes.len() <= idx {
                nodes.resize(idx + 1, empty);
            }
            nodes[idx] = Node {
                aabb,
                child,
                leaf,
                ..empty
            };
            order.push(idx);
            if !leaf {
                if child == 0 || order.len() > 4 * masks.len().max(normals.len()) + 4 {
                    return None;
                }
                stack.push(2 * child as usize);
                stack.push(2 * child as usize + 1);
            }
        }
        // Children come after their parent in `order`: fill bottom-up.
        for &idx in order.iter().rev() {
            let node = nodes[idx];
            if node.leaf {
                let t = node.child as usize;
                let mask = masks.get(t).copied().unwrap_or(ALL);
                let n = *normals.get(t)?;
                let cone = if n == Vec3::ZERO {
                    (Vec3::ZERO, 0.0)
                } else {
                    (n, 0.0)
                };
                set(&mut nodes[idx], mask, cone);
            } else {
                let (l, r) = (
                    nodes[2 * node.child as usize],
                    nodes[2 * node.child as usize + 1],
                );
                if !node.aabb.contains(&l.aabb) || !node.aabb.contains(&r.aabb) {
                    return None;
                }
                set(&mut nodes[idx], l.mask | r.mask, merge(&l, &r));
            }
        }
        Some(FilterTree { nodes })
    }

    /// The triangle nearest to `point` that `allowed` accepts, if nearer than `max_dist`:
    /// parry's `project_local_point_and_get_location` on the filtered mesh (not solid),
    /// with subtrees that fail `bit` or `normal` skipped (module docs).
    ///
    /// Within `free` of `point` the normal test is waived: a triangle there that passes
    /// `bit` (`on_side`) is accepted too. The answer is then the nearest point of the side
    /// when that lies within `free`, else the nearest point `allowed` accepts — what a
    /// search of the side within `free` followed by a filtered search would find, in one
    /// walk of the tree (`free` = 0: the plain filtered search; `free` at most `max_dist`).
    #[allow(clippy::too_many_arguments)]
    pub fn closest(
        &self,
        mesh: &TriMesh,
        point: PVec,
        max_dist: f32,
        free: f32,
        bit: TriMask,
        normal: Option<&NormalTest>,
        allowed: impl Fn(u32) -> bool,
        on_side: impl Fn(u32) -> bool,
    ) -> Option<(u32, PointProjection, TrianglePointLocation)> {
        // A node at or beyond the best distance is not entered anyway: the filter test is
        // only needed nearer.
        let cost = |n: &Node, best: f32| -> f32 {
            let d = n.aabb.distance_to_local_point(point, true);
            if d < best && n.rejects(bit, if d <= free { None } else { normal }) {
                f32::MAX
            } else {
                d
            }
        };
        let leaf = |tri: u32| -> Option<(f32, (PointProjection, TrianglePointLocation))> {
            let full = allowed(tri);
            // Neither normal-compatible nor a candidate for the snap on the point's side.
            if !(full || (free > 0.0 && on_side(tri))) {
                return None;
            }
            let proj = mesh
                .triangle(tri)
                .project_local_point_and_get_location(point, false);
            let d = (proj.0.point - point).length();
            (full || d <= free).then_some((d, proj))
        };
        let mut stack: Vec<u32> = Vec::with_capacity(32);
        let mut best: Option<(PointProjection, TrianglePointLocation)> = None;
        let mut best_cost = max_dist;
        let mut best_id = u32::MAX;
        let mut curr = 0u32;
        loop {
            let mut left = &self.nodes[2 * curr as usize];
            let mut right = &self.nodes[2 * curr as usize + 1];
            let mut left_score = cost(left, best_cost);
            let mut right_score = cost(right, best_cost);
            if left_score > right_score {
                std::mem::swap(&mut left_score, &mut right_score);
                std::mem::swap(&mut left, &mut right);
            }
            let mut found_next = false;
            if left_score < best_cost && left_score != f32::MAX {
                if left.leaf {
                    if let Some((c, v)) = leaf(left.child) {
                        if c < best_cost {
                            best = Some(v);
                            best_cost = c;
                            best_id = left.child;
                        }
                    }
                } else {
                    curr = left.child;
                    found_next = true;
                }
            }
            if right_score < best_cost && right_score != f32::MAX {
                if right.leaf {
                    if let Some((c, v)) = leaf(right.child) {
                        if c < best_cost {
                            best = Some(v);
                            best_cost = c;
                            best_id = right.child;
                        }
                    }
                } else if found_next {
                    stack.push(right.child);
                } else {
                    curr = right.child;
                    found_next = true;
                }
            }
            if !found_next {
                match stack.pop() {
                    Some(next) => curr = next,
                    None => return best.map(|(p, l)| (best_id, p, l)),
                }
            }
        }
    }
}

impl FilterTree {
    /// Whether any triangle passes `allowed`, with subtrees that fail `bit` or `normal`
    /// skipped: the answer of a scan over every triangle.
    pub fn any(
        &self,
        bit: TriMask,
        normal: Option<&NormalTest>,
        allowed: impl Fn(u32) -> bool,
    ) -> bool {
        let mut stack = vec![0usize, 1];
        while let Some(i) = stack.pop() {
            let node = &self.nodes[i];
            if node.rejects(bit, normal) {
                continue;
            }
            if node.leaf {
                if allowed(node.child) {
                    return true;
                }
            } else {
                stack.push(2 * node.child as usize);
                stack.push(2 * node.child as usize + 1);
            }
        }
        false
    }
}

/// Stores a node's mask and cone `(axis, half-angle)`.
fn set(node: &mut Node, mask: TriMask, cone: (Vec3, f32)) {
    node.mask = mask;
    node.axis = cone.0;
    node.half = cone.1;
    node.cos_half = cone.1.cos();
    node.sin_half = cone.1.sin();
}

/// A cone holding both children's cones: axis along the sum of theirs, half-angle the
/// largest angle from it to a child's axis plus that child's half-angle. No cone (zero axis)
/// when a child has none or the axes cancel.
fn merge(l: &Node, r: &Node) -> (Vec3, f32) {
    if l.axis == Vec3::ZERO || r.axis == Vec3::ZERO {
        return (Vec3::ZERO, 0.0);
    }
    let axis = (l.axis + r.axis).normalize_or_zero();
    if axis == Vec3::ZERO {
        return (Vec3::ZERO, 0.0);
    }
    let reach = |c: &Node| axis.dot(c.axis).clamp(-1.0, 1.0).acos() + c.half;
    let half = reach(l).max(reach(r));
    if half >= std::f32::consts::PI {
        (Vec3::ZERO, 0.0)
    } else {
        (axis, half)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::clone::fit::regions::FACE_PIECE;
    use crate::clone::tri_filter::FilteredTriMesh;
    use parry3d::shape::CompositeShapeRef;

    /// A bumpy sheet folded over itself (normals of every direction, near surfaces facing
    /// away), with masks varying by triangle.
    fn surface() -> (Vec<Vec3>, Vec<[u32; 3]>, Vec<TriMask>) {
        let k = 24u32;
        let mut positions = Vec::new();
        for j in 0..k {
            for i in 0..k {
                let (u, v) = (i as f32 / (k - 1) as f32, j as f32 / (k - 1) as f32);
                let a = u * 5.0;
                positions.push(Vec3::new(a.cos(), v * 2.0, a.sin() + 0.1 * (9.0 * v).sin()));
            }
        }
        let triangles = crate::clone::fixtures::grid_triangles(k);
        let masks = (0..triangles.len())
            .map(|t| [0b001, 0b010, 0b100 | FACE_PIECE, 0b111 | FACE_PIECE][t % 7 % 4])
            .collect();
        (positions, triangles, masks)
    }

    #[test]
    fn the_pruned_search_finds_what_the_filtered_search_finds() {
        let (positions, triangles, masks) = surface();
        let normals = crate::mesh::geometry::triangle_normals(&positions, &triangles);
        let verts: Vec<PVec> = positions.iter().map(|p| PVec::new(p.x, p.y, p.z)).collect();
        let mesh = TriMesh::new(verts, triangles.clone()).unwrap();
        let tree = FilterTree::new(&mesh, &masks, &normals).expect("tree");
        for q in 0..600u32 {
            let f = q as f32;
            let p = Vec3::new(
                1.6 * (f * 0.37).sin(),
                1.0 + 1.3 * (f * 0.11).cos(),
                1.6 * (f * 0.23).cos(),
            );
            let n = Vec3::new((f * 0.7).sin(), (f * 0.3).cos(), (f * 0.5).sin()).normalize();
            let crease = (q % 5 == 0).then(|| Vec3::new(n.y, -n.x, n.z).normalize());
            let bit = [0b001, 0b010 | FACE_PIECE, 0b100, 0b100 | FACE_PIECE][q as usize % 4];
            let cos = [0.5, 0.0, -0.2, 0.9][(q as usize / 4) % 4];
            let normal = (q % 3 != 0).then(|| NormalTest::new(n, crease, cos));
            let allowed = |i: u32| {
                let t = normals[i as usize];
                mask_passes(masks[i as usize], bit)
                    && normal
                        .is_none_or(|_| t.dot(n) >= cos || crease.is_some_and(|m| t.dot(m) >= cos))
            };
            let max = [f32::MAX, 0.3, 0.05][q as usize % 3];
            let view = FilteredTriMesh {
                mesh: &mesh,
                allowed,
            };
            let pp = PVec::new(p.x, p.y, p.z);
            let want =
                CompositeShapeRef(&view).project_local_point_and_get_location(pp, max, false);
            let got = tree.closest(&mesh, pp, max, 0.0, bit, normal.as_ref(), allowed, |_| {
                false
            });
            assert_eq!(
                want.map(|w| (w.0, w.1.point)),
                got.map(|g| (g.0, g.1.point)),
                "query {q}"
            );
            // With the normal test waived near the point: the side's nearest point when it
            // lies that near, else the filtered search's answer.
            let on_side = |i: u32| mask_passes(masks[i as usize], bit);
            let free = [0.02, 0.1, 0.4][q as usize % 3];
            let side = FilteredTriMesh {
                mesh: &mesh,
                allowed: on_side,
            };
            let near = CompositeShapeRef(&side)
                .project_local_point_and_get_location(pp, free * 1.001, false)
                .filter(|h| (h.1.point - pp).length() <= free);
            let max = max.max(free);
            let want = near.or_else(|| {
                CompositeShapeRef(&view).project_local_point_and_get_location(pp, max, false)
            });
            let got = tree.closest(&mesh, pp, max, free, bit, normal.as_ref(), allowed, on_side);
            assert_eq!(
                want.map(|w| (w.0, w.1.point)),
                got.map(|g| (g.0, g.1.point)),
                "query {q}, free {free}"
            );
        }
        // `any` answers what a scan answers.
        for q in 0..64u32 {
            let f = q as f32;
            let n = Vec3::new((f * 0.7).sin(), (f * 0.3).cos(), (f * 0.5).sin()).normalize();
            let cos = [0.99, 0.999, 0.9999, 0.5][q as usize % 4];
            let bit = [0b001, 0b010 | FACE_PIECE, 0b100][q as usize % 3];
            let test = NormalTest::new(n, None, cos);
            let allowed =
                |i: u32| mask_passes(masks[i as usize], bit) && normals[i as usize].dot(n) >= cos;
            let scan = (0..triangles.len() as u32).any(allowed);
            assert_eq!(tree.any(bit, Some(&test), allowed), scan, "query {q}");
        }
        // The cones do reject: a whole half of the folded sheet faces away from some query.
        let rejected = (0..600u32)
            .filter(|&q| {
                let f = q as f32;
                let n = Vec3::new((f * 0.7).sin(), (f * 0.3).cos(), (f * 0.5).sin()).normalize();
                let test = NormalTest::new(n, None, 0.5);
                tree.nodes
                    .iter()
                    .any(|x| !x.leaf && x.rejects(0b111, Some(&test)))
            })
            .count();
        assert!(rejected > 300, "{rejected}");
    }
}
