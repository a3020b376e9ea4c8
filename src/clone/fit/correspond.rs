//! Dense correspondence: every target vertex onto the registered source surface.
//!
//! Each target vertex takes the closest point of the registered source that its slit side
//! allows ([`super::regions`]) among triangles whose normal is within
//! [`FitOptions::normal_degrees`] of the vertex normal (without that condition if none is,
//! or if the vertex already lies on the source: creases have no one normal);
//! the point is kept as a triangle and barycentric weights. Target vertices the source does
//! not cover (a source mask onto a whole head: the back of the head, the neck) lie far from
//! it; their weight fades from 1 at [`FitOptions::fade`]`.0` × ES0 to 0 at `.1` × ES0, so
//! they stay still instead of copying a border's motion.

use glam::Vec3;
use rayon::prelude::*;

use super::regions::{query_bit, Side};
use super::surface::{Filter, QuerySurface};
use super::FitOptions;
use crate::mesh::geometry::vertex_normals;

/// Points closer than this (× ES0) to the surface match without the normal test.
pub(crate) const SNAP: f32 = 1e-4;

/// Where one target vertex lies on the source.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Correspondence {
    /// Source triangle's vertices.
    pub vertices: [u32; 3],
    /// Barycentric weights in that triangle.
    pub weights: [f32; 3],
    /// How much of the source motion the vertex takes (distance fade, 0 to 1).
    pub fade: f32,
}

/// Correspondences of every target vertex (`None`: no allowed source triangle, or beyond
/// the fade).
pub(crate) fn correspond(
    target: &[Vec3],
    target_triangles: &[[u32; 3]],
    sides: &[Side],
    source: &QuerySurface,
    source_triangles: &[[u32; 3]],
    scale: f32,
    opts: &FitOptions,
) -> Vec<Option<Correspondence>> {
    let normals = vertex_normals(target, target_triangles);
    let cos = (opts.normal_degrees.to_radians()).cos() as f32;
    let (near, far) = (opts.fade.0 as f32 * scale, opts.fade.1 as f32 * scale);
    let snap = SNAP * scale;
    let far_probe = far * 1.001;
    target
        .par_iter()
        .enumerate()
        .map(|(i, &p)| {
            let bit = query_bit(sides.get(i).copied().unwrap_or(Side::Other));
            let nrm = normals.get(i).copied().unwrap_or(Vec3::ZERO);
            // A point on the surface is its own match, whatever the normals at a crease say.
            // Every search is bounded: beyond `far` nothing matches, and a bounded search
            // does not scan the whole source for triangles the filters reject.
            let plain = Filter { bit, normal: None };
            let hit = if nrm == Vec3::ZERO {
                source.closest_within(p, plain, far_probe)?
            } else if let Some(h) = source
                .closest_within(p, plain, snap * 1.001)
                .filter(|h| h.point.distance(p) <= snap)
            {
                h
            } else {
                let oriented = Filter {
                    bit,
                    normal: Some((nrm, cos)),
                };
                match source.closest_within(p, oriented, far_probe) {
                    Some(h) => h,
                    // An oriented point beyond `far` fades to nothing; with no oriented
                    // triangle at all the plain closest point stands in.
                    None if source.any_allowed(oriented) => return None,
                    None => source.closest_within(p, plain, far_probe)?,
                }
            };
            let d = hit.point.distance(p);
            let fade = if d <= near {
                1.0
            } else if d >= far || far <= near {
                0.0
            } else {
                1.0 - (d - near) / (far - near)
            };
            let tri = source_triangles.get(hit.triangle as usize)?;
            (fade > 0.0 && fade.is_finite()).then_some(Correspondence {
                vertices: *tri,
                weights: hit.weights,
                fade,
            })
        })
        .collect()
}
