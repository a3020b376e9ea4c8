//! Where each eye's eyeball is, for the eye layers ([`super::split`]): the ball the eye
//! turns about. Usually the piece holding the pupil (3.5, 3.6) is that ball. Many avatars
//! instead put the pupil on an iris or cornea cap (the mesh an artist or
//! `fp from-landmarks` marks) in front of a bigger eye-white ball holding no feature point:
//! then the eye white is the eyeball, and the cap one of its layers.

use glam::Vec3;

use super::parts::fp_mesh_vertex;
use super::split::mesh_pieces;
use super::Part;
use crate::face::{FaceFrames, FaceModel};
use crate::spec::FeaturePointId;

/// Largest eyeball radius an eye layer is looked for around, in ES0 (an eyeball is about
/// 0.2 ES0: a pupil on a bigger piece is on the skin, as on CANDIDE-3).
pub(super) const EYEBALL_MAX_RADIUS: f32 = 0.5;

/// Farthest a vertex of an eye layer may lie from its eyeball's centre, in eyeball radii.
pub(super) const EYE_LAYER_REACH: f32 = 1.3;

/// Smallest ratio of a ball's shortest to longest bounding-box side (an open shell such as
/// an eye occlusion is half as deep as it is wide).
const BALL_ASPECT: f32 = 0.75;

/// Largest spread of a ball's vertices about its radius (a coarse UV sphere's bounding box
/// cuts its equator a little).
const BALL_SPREAD: f32 = 0.2;

/// Nearest the pupil may lie to an eye white's centre, in its radii (an iris cap sits on
/// the ball's surface, a cornea bulges out of it).
const PUPIL_DEPTH: f32 = 0.75;

/// A mesh's world positions, the connected piece of each vertex and the piece count.
type MeshPieces = (Vec<Vec3>, Vec<usize>, usize);

/// One eye's eyeball (face frame).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Eyeball {
    /// The eye.
    pub part: Part,
    /// The ball's centre (bounding-box centre).
    pub centre: Vec3,
    /// Its radius (half the bounding box's longest side).
    pub radius: f32,
}

/// Bounding-box centre and half longest side of points.
fn bounds(points: impl Iterator<Item = Vec3>) -> Option<(Vec3, f32)> {
    let (lo, hi) = points.fold(
        (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
        |(lo, hi), q| (lo.min(q), hi.max(q)),
    );
    (lo.x <= hi.x).then(|| ((lo + hi) / 2.0, ((hi - lo) / 2.0).max_element()))
}

/// A piece's points as a ball (centre, radius): its bounding box near cubic and every point
/// within [`BALL_SPREAD`] of the radius from the box's centre.
fn as_ball(points: &[Vec3]) -> Option<(Vec3, f32)> {
    if points.len() < 8 {
        return None;
    }
    let (lo, hi) = points.iter().fold(
        (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
        |(lo, hi), &q| (lo.min(q), hi.max(q)),
    );
    let side = hi - lo;
    if !(side.max_element() > 0.0 && side.min_element() >= BALL_ASPECT * side.max_element()) {
        return None;
    }
    let centre = (lo + hi) / 2.0;
    let radius = side.max_element() / 2.0;
    points
        .iter()
        .all(|q| (q.distance(centre) - radius).abs() <= BALL_SPREAD * radius)
        .then_some((centre, radius))
}

/// Each eye's eyeball: the largest ball-shaped connected piece of any mesh (under
/// [`EYEBALL_MAX_RADIUS`] ES0, `es`) that the pupil lies on (from [`PUPIL_DEPTH`] to
/// [`EYE_LAYER_REACH`] radii of its centre) and whose reach holds the whole piece holding the
/// pupil: an eye white behind an iris cap, or that piece itself. Without such a ball, the
/// bounding box of the piece holding the pupil (when under the largest radius). An eye whose
/// pupil lies on a bigger piece (the skin) has none.
pub(super) fn eyeballs(face: &FaceModel, frames: &FaceFrames, diag: f32, es: f32) -> Vec<Eyeball> {
    let eps = diag * 1e-6;
    // Per mesh: world positions and connected pieces, found once.
    let mut meshes: Vec<Option<MeshPieces>> = vec![None; face.meshes.len()];
    let mut of_mesh = |mi: usize| {
        meshes[mi]
            .get_or_insert_with(|| {
                let world = face.mesh_world(frames, mi);
                let (piece, count) = mesh_pieces(&face.meshes[mi].mesh, eps);
                (world, piece, count)
            })
            .clone()
    };
    let mut out = Vec::new();
    for (part, id) in [
        (Part::LeftEye, FeaturePointId::FP_3_5),
        (Part::RightEye, FeaturePointId::FP_3_6),
    ] {
        let Some((mi, v)) = fp_mesh_vertex(face, frames, id, diag * 1e-4) else {
            continue;
        };
        let (world, piece, _) = of_mesh(mi);
        let (Some(&k), Some(&pupil)) = (piece.get(v as usize), world.get(v as usize)) else {
            continue;
        };
        let holder: Vec<Vec3> = piece
            .iter()
            .zip(&world)
            .filter(|(p, _)| **p == k)
            .map(|(_, &q)| q)
            .collect();
        let Some((c0, r0)) = bounds(holder.iter().copied()) else {
            continue;
        };
        if !(r0 > 0.0 && r0 < EYEBALL_MAX_RADIUS * es) {
            continue;
        }
        let mut best = (c0, r0);
        let mut found = false;
        for other in 0..face.meshes.len() {
            let (world, piece, count) = of_mesh(other);
            let mut members: Vec<Vec<Vec3>> = vec![Vec::new(); count];
            for (&p, &q) in piece.iter().zip(&world) {
                members[p].push(q);
            }
            for pts in &members {
                let Some((c, r)) = as_ball(pts) else { continue };
                let d = pupil.distance(c);
                let fits = r < EYEBALL_MAX_RADIUS * es
                    && (PUPIL_DEPTH * r..=EYE_LAYER_REACH * r).contains(&d)
                    && holder.iter().all(|q| q.distance(c) <= EYE_LAYER_REACH * r);
                if fits && (!found || r > best.1) {
                    best = (c, r);
                    found = true;
                }
            }
        }
        out.push(Eyeball {
            part,
            centre: best.0,
            radius: best.1,
        });
    }
    out
}

/// The points of an eye's part meshes (`meshes`, face frame) its turn's centre is fitted to:
/// the connected piece with the largest bounding box — the eye white, not the iris,
/// cornea or highlight caps in front of it, which sit on spheres of their own and would
/// pull a fit over all of them forward.
pub(super) fn eye_white_points(
    face: &FaceModel,
    frames: &FaceFrames,
    meshes: &[usize],
) -> Vec<Vec3> {
    let diag = super::parts::face_diagonal(face, frames);
    let mut best: (f32, Vec<Vec3>) = (-1.0, Vec::new());
    for &mi in meshes {
        let world = face.mesh_world(frames, mi);
        let (piece, count) = mesh_pieces(&face.meshes[mi].mesh, diag * 1e-6);
        let mut members: Vec<Vec<Vec3>> = vec![Vec::new(); count];
        for (&k, &q) in piece.iter().zip(&world) {
            members[k].push(q);
        }
        for pts in members {
            let r = bounds(pts.iter().copied()).map_or(-1.0, |b| b.1);
            if r > best.0 {
                best = (r, pts);
            }
        }
    }
    best.1
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sphere(c: Vec3, r: f32, rings: usize, segs: usize, cap: f32) -> Vec<Vec3> {
        let mut out = Vec::new();
        for i in 0..=rings {
            let th = cap * i as f32 / rings as f32;
            for j in 0..segs {
                let ph = std::f32::consts::TAU * j as f32 / segs as f32;
                out.push(c + r * Vec3::new(th.sin() * ph.cos(), th.sin() * ph.sin(), th.cos()));
            }
        }
        out
    }

    #[test]
    fn a_ball_is_round_all_round_and_a_shell_or_cap_is_not() {
        let c = Vec3::new(1.0, 2.0, 3.0);
        let (bc, r) = as_ball(&sphere(c, 1.2, 4, 8, std::f32::consts::PI)).unwrap();
        assert!(bc.distance(c) < 1e-5 && (r - 1.2).abs() < 1e-5, "{bc} {r}");
        // An odd segment count: the box cuts the equator, still a ball.
        assert!(as_ball(&sphere(c, 1.0, 7, 9, std::f32::consts::PI)).is_some());
        // An occlusion shell (a hemisphere) and an iris cap are no balls.
        assert!(as_ball(&sphere(c, 1.0, 6, 12, std::f32::consts::FRAC_PI_2)).is_none());
        assert!(as_ball(&sphere(c, 1.0, 3, 12, 0.5)).is_none());
    }
}
