//! Eye layers resting on the lids: the thin shells a production head lays over its
//! eyeballs — an eye occlusion (a shadow shell in the eye opening), a lacrimal film along the
//! lower lid, blends at the corners (all three in the ICT-FaceKit's head). Their materials
//! are transparent, so a renderer that draws every triangle opaque shows them as skin
//! closing the eye. The cloning takes them for skin (they move with the lids,
//! [`super::split`]); pictures leave them out ([`crate::export::picture`]).
//!
//! A piece (connected by polygon edges alone: ICT's occlusion and tear film share vertex
//! positions with the lids, so joining coincident vertices would weld them into the skin) is
//! such a layer when every vertex lies on one eyeball — within
//! [`EYE_LAYER_REACH`](super::eyeball::EYE_LAYER_REACH) radii of its centre
//! ([`super::eyeball`]) and in front of it, on the pupil's side —, and its open border comes
//! within [`LID_CLEARANCE`](super::split::LID_CLEARANCE) radii of the skin, as the split view
//! sorts eye layers. An eye's own layers (an iris cap, a highlight) float clear of the lids,
//! lashes reach past the eyeball and the eyeball itself wraps round behind its centre, so
//! none of these is one.

use glam::Vec3;

use super::eyeball::eyeballs;
use super::parts::face_diagonal;
use super::split::{ball_under, open_edge_vertices, LidSurface, LID_CLEARANCE};
use super::Part;
use crate::face::FaceModel;
use crate::mesh::components::connected_components;
use crate::spec::FeaturePointId;

/// Vertices of one mesh that belong to eye layers resting on the lids.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct LidRestingLayer {
    /// Index of the mesh in the face.
    pub mesh: usize,
    /// The layers' vertices in that mesh, ascending.
    pub vertices: Vec<u32>,
}

/// The eye layers of `face` that rest on its lids (module docs), one entry per mesh holding
/// any; empty when the face has no pupil points (3.5, 3.6) or no eyeball is found.
pub fn lid_resting_layers(face: &FaceModel) -> Vec<LidRestingLayer> {
    let Ok(fapu) = face.fapu() else {
        return Vec::new();
    };
    let frames = face.frames();
    let diag = face_diagonal(face, &frames);
    let eps = diag * 1e-6;
    let balls: Vec<(Part, Vec3, f32)> = eyeballs(face, &frames, diag, fapu.distances.es0 as f32)
        .into_iter()
        .map(|b| (b.part, b.centre, b.radius))
        .collect();
    // Each eye's front: towards its pupil point.
    let front = |part: Part| {
        let id = match part {
            Part::LeftEye => FeaturePointId::FP_3_5,
            _ => FeaturePointId::FP_3_6,
        };
        let centre = balls.iter().find(|b| b.0 == part)?.1;
        (face.feature_points.position(id)? - centre).try_normalize()
    };
    let fronts: Vec<(Part, Vec3, f32, Vec3)> = balls
        .iter()
        .filter_map(|&(part, c, r)| Some((part, c, r, front(part)?)))
        .collect();
    if fronts.is_empty() {
        return Vec::new();
    }
    let on_ball = |q: Vec3| ball_under(&balls, q);
    // In front of the eye it lies on: the pupil's side of the ball's centre.
    let over_eye = |q: Vec3| {
        let part = on_ball(q)?;
        let &(_, c, _, f) = fronts.iter().find(|b| b.0 == part)?;
        ((q - c).dot(f) > 0.0).then_some(part)
    };
    // The lids' surface is built at the first piece that lies wholly over an eye.
    let mut lids: Option<Option<LidSurface>> = None;
    let mut out = Vec::new();
    for (mi, m) in face.meshes.iter().enumerate() {
        if m.mesh.polygons.is_empty() {
            continue;
        }
        let world = face.mesh_world(&frames, mi);
        let (piece, count) = connected_components(&m.mesh, &[]);
        // Per piece: the one eye all its vertices lie over (`None` once one lies elsewhere).
        let mut eye: Vec<Option<Option<Part>>> = vec![None; count];
        for (&k, &q) in piece.iter().zip(&world) {
            let k = k as usize;
            let here = over_eye(q);
            eye[k] = match eye[k] {
                None => Some(here),
                Some(seen) if seen == here => Some(here),
                Some(_) => Some(None),
            };
        }
        if !eye.iter().any(|e| matches!(e, Some(Some(_)))) {
            continue;
        }
        let Some(lids) =
            lids.get_or_insert_with(|| LidSurface::of(face, &frames, eps, &on_ball, None))
        else {
            return Vec::new();
        };
        let mut resting = vec![false; count];
        for v in open_edge_vertices(&m.mesh, |v| v) {
            let (Some(&k), Some(&q)) = (piece.get(v as usize), world.get(v as usize)) else {
                continue;
            };
            let k = k as usize;
            let Some(Some(part)) = eye[k] else { continue };
            let radius = balls.iter().find(|b| b.0 == part).map_or(0.0, |b| b.2);
            if !resting[k] && lids.within(q, LID_CLEARANCE * radius) {
                resting[k] = true;
            }
        }
        let vertices: Vec<u32> = (0..piece.len() as u32)
            .filter(|&v| resting[piece[v as usize] as usize])
            .collect();
        if !vertices.is_empty() {
            out.push(LidRestingLayer { mesh: mi, vertices });
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_bundled_real_head_has_no_layer_over_its_eyes() {
        // The bundled ICT head keeps eyeballs and irises but not the occlusion, tear film
        // and blends: nothing to leave out, and the eyeballs are not taken for layers.
        let face = crate::face::BundledFace::Ict.read().unwrap().0;
        assert_eq!(lid_resting_layers(&face), Vec::new());
    }
}
