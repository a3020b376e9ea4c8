//! Small meshes riding on the skin (module docs of [`super`], step 8): eyelashes, brow cards
//! and the like, given as their own mesh or glTF primitive, hold no feature point and touch
//! no skin vertex, so step 1 leaves them rigid with the head — and a closing lid would slide
//! under its lashes. Each vertex of such a mesh is tied to the closest point of the target's
//! skin surface (a triangle and its barycentric weights; the offset from that point stays
//! fixed), so in every table it moves exactly as the skin under it moves.
//!
//! A mesh is attached when it is small (bounding-box diagonal under [`MAX_SIZE`] of the
//! face's) and lies on the skin (every vertex within [`MAX_GAP`] of the face's size of the
//! skin surface). A hat or hair cap is too large, a prop in front of the face too far; both
//! stay rigid. Eyeballs, teeth and the tongue are parts, never attached.
//!
//! A connected piece of an attached mesh that is a row of lashes (near an eye, on one side
//! of its corners, its root at the lid's margin: [`super::lid_margin`]) is tied to that
//! lid's margin instead of the closest skin point: floating in front of the lid, its closest
//! skin point is often the lid's fold, which hardly moves when the lid closes.

use glam::{DMat3, DVec3, Vec3};
use parry3d::math::Vector as PVec;
use parry3d::shape::{CompositeShapeRef, TriMesh};

use super::lid_margin::{Ball, LidMargins};
use super::parts::face_diagonal;
use super::split::mesh_pieces;
use super::{FaceParts, Similarity, SkinSurface};
use crate::clone::SurfaceMotion;
use crate::face::{FaceFrames, FaceModel};
use crate::fat::morph::MorphMesh;
use crate::mesh::geometry::barycentric;

/// Largest attached mesh: this share of the face's bounding-box diagonal.
pub(super) const MAX_SIZE: f32 = 0.35;

/// Farthest an attached mesh's vertex may lie from the skin surface, as a share of the face's
/// bounding-box diagonal.
pub(super) const MAX_GAP: f32 = 0.05;

/// One mesh tied to the skin: per vertex, the skin surface triangle (welded vertex ids) and
/// the barycentric weights of its closest point.
#[derive(Clone, Debug)]
pub(super) struct AttachedMesh {
    /// Index of the mesh in the face.
    pub mesh: usize,
    /// Per vertex: the triangle's surface vertices.
    pub corners: Vec<[u32; 3]>,
    /// Per vertex: the weights of those corners.
    pub weights: Vec<[f32; 3]>,
    /// Per vertex of a row of lashes: the eyeball it stays out of and its rest position
    /// (aligned frame).
    pub outside: Vec<Option<(Ball, Vec3)>>,
}

/// The face's meshes of neither skin nor a part (`parts.other`) that ride on the skin surface
/// `skin` (built in the `frame` the alignment puts the face in).
pub(super) fn attach_to_skin(
    face: &FaceModel,
    frames: &FaceFrames,
    parts: &FaceParts,
    skin: &SkinSurface,
    frame: &Similarity,
    margins: &LidMargins,
) -> Vec<AttachedMesh> {
    if parts.other.is_empty() || skin.surface.triangles.is_empty() {
        return Vec::new();
    }
    let diag = face_diagonal(face, frames);
    if diag <= 0.0 {
        return Vec::new();
    }
    let surf = &skin.surface;
    let verts: Vec<PVec> = surf
        .positions
        .iter()
        .map(|p| PVec::new(p.x, p.y, p.z))
        .collect();
    let Ok(tri_mesh) = TriMesh::new(verts, surf.triangles.clone()) else {
        return Vec::new();
    };
    // The surface lives in the aligned frame: distances there are scaled by the alignment.
    let gap = MAX_GAP * diag * frame.scale as f32;
    let mut out = Vec::new();
    for &mi in &parts.other {
        // Empty for an unknown mesh: skipped below.
        let world = face.mesh_world(frames, mi);
        if world.is_empty() || bounds_diagonal(&world) > MAX_SIZE * diag {
            continue;
        }
        let mut corners = Vec::with_capacity(world.len());
        let mut weights = Vec::with_capacity(world.len());
        for p in &world {
            let q = frame.point(*p);
            let Some((tri, proj, _)) = CompositeShapeRef(&tri_mesh)
                .project_local_point_and_get_location(PVec::new(q.x, q.y, q.z), gap, false)
            else {
                break;
            };
            let Some(t) = surf.triangles.get(tri as usize) else {
                break;
            };
            let on = Vec3::new(proj.point.x, proj.point.y, proj.point.z);
            let [a, b, c] = t.map(|v| surf.positions[v as usize]);
            corners.push(*t);
            weights.push(barycentric(on, a, b, c));
        }
        if corners.len() == world.len() {
            let (piece, count) = mesh_pieces(&face.meshes[mi].mesh, diag * 1e-6);
            let mut members: Vec<Vec<usize>> = vec![Vec::new(); count];
            for (v, &k) in piece.iter().enumerate() {
                members[k].push(v);
            }
            let mut outside = vec![None; world.len()];
            for vs in &members {
                let pts: Vec<Vec3> = vs.iter().map(|&v| frame.point(world[v])).collect();
                let Some(lid) = margins.row_lid(&pts) else {
                    continue;
                };
                let ball = margins.ball(lid);
                for (&v, &p) in vs.iter().zip(&pts) {
                    (corners[v], weights[v]) = margins.tie(lid, p);
                    outside[v] = ball.map(|b| (b, p));
                }
            }
            out.push(AttachedMesh {
                outside,
                mesh: mi,
                corners,
                weights,
            });
        }
    }
    out
}

/// The cloned skin motion `m` (aligned frame, welded vertices) carried onto the attached
/// meshes, in each mesh's own frame. Meshes that do not move are left out.
pub(super) fn attached_motion(
    face: &FaceModel,
    frames: &FaceFrames,
    attached: &[AttachedMesh],
    skin: &SkinSurface,
    frame: &Similarity,
    m: &SurfaceMotion,
) -> Vec<MorphMesh> {
    if attached.is_empty() || m.offsets.is_empty() {
        return Vec::new();
    }
    let mut dense = vec![Vec3::ZERO; skin.surface.positions.len()];
    for &(w, d) in &m.offsets {
        if let Some(slot) = dense.get_mut(w as usize) {
            *slot = d;
        }
    }
    let mut out = Vec::new();
    for a in attached {
        let inv: DMat3 = frames.meshes[a.mesh].matrix3.as_dmat3().inverse();
        let mut vertices = Vec::new();
        let mut offsets = Vec::new();
        for (v, ((c, w), out)) in a.corners.iter().zip(&a.weights).zip(&a.outside).enumerate() {
            let d: DVec3 = (0..3)
                .map(|k| dense[c[k] as usize].as_dvec3() * f64::from(w[k]))
                .sum();
            let d = match out {
                Some((ball, rest)) => ball.keep_out(*rest, d.as_vec3()).as_dvec3(),
                None => d,
            };
            if d == DVec3::ZERO {
                continue;
            }
            vertices.push(v as u32);
            offsets.push(inv * frame.inverse_vector(d));
        }
        if !vertices.is_empty() {
            out.push(MorphMesh {
                mesh: face.meshes[a.mesh].name.clone(),
                vertices,
                offsets,
            });
        }
    }
    out
}

/// Diagonal of the bounding box of the finite points (0 without any).
fn bounds_diagonal(points: &[Vec3]) -> f32 {
    let mut lo = Vec3::splat(f32::INFINITY);
    let mut hi = Vec3::splat(f32::NEG_INFINITY);
    for p in points.iter().filter(|p| p.is_finite()) {
        lo = lo.min(*p);
        hi = hi.max(*p);
    }
    if lo.x <= hi.x {
        (hi - lo).length()
    } else {
        0.0
    }
}
