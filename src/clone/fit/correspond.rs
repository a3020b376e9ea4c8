//! Dense correspondence: every target vertex onto the registered source surface.
//!
//! Each target vertex takes the closest point of the registered source that its slit side
//! allows ([`super::regions`]) among triangles whose normal is within
//! [`FitOptions::normal_degrees`] of the vertex normal — or, for a vertex on a crease (an
//! incident face more than 45° from its vertex normal: a lid margin, a lip's edge), of that
//! face's normal, since a crease has no one normal. Without that condition if no triangle
//! passes, if the vertex already lies on the source, or if it lies within
//! [`FitOptions::fade`]`.0` × ES0 of the source while every compatible point is farther
//! than that beyond the closest one (the normals mislead there: ICT's lid margin
//! triangulated gave its upper-lid point no motion at all);
//! the point is kept as a triangle and barycentric weights. Target vertices the source does
//! not cover (a source mask onto a whole head: the back of the head, the neck) lie far from
//! it; their weight fades from 1 at [`FitOptions::fade`]`.0` × ES0 to 0 at `.1` × ES0, so
//! they stay still instead of copying a border's motion.
//!
//! Seams: a target vertex that coincides with another (an unwelded seam, such as the
//! duplicated midline of CANDIDE-3, whose FAT may move one copy and not the other) picks its
//! source triangle from a point moved a little into its own triangles, then takes its weights
//! at its true position in that triangle. Each copy so lands on the source triangles of its
//! own side of the seam, and a seam vertex of a face cloned onto itself reads exactly its own
//! vertex's motion.

use glam::Vec3;
use rayon::prelude::*;

use super::regions::{own_side_weights, query_bit, Side};
use super::surface::{Filter, QuerySurface};
use super::FitOptions;
use crate::mesh::geometry::{triangle_normals, vertex_normals};
use crate::mesh::spatial::find_coincident_vertices;

/// Points closer than this (× ES0) to the surface match without the normal test.
pub(crate) const SNAP: f32 = 1e-4;

/// Vertices closer than this (× ES0) are copies of one point (a seam).
const SEAM: f32 = 1e-6;

/// How far (as a fraction of the way to the centroid of its triangles) a seam vertex looks
/// into its own side for its source triangle: far enough to leave the seam behind, near
/// enough to stay on the vertex's own triangles of the source.
const SEAM_STEP: f32 = 0.25;

/// How much farther (× ES0) than the closest point a seam vertex's own-side point may lie.
const SEAM_SLACK: f32 = 0.01;

/// For every target vertex that is a copy of another: where it looks for its source triangle
/// (the centroid of its triangles' centroids, [`SEAM_STEP`] of the way from it); `None`
/// elsewhere.
fn seam_probes(target: &[Vec3], triangles: &[[u32; 3]], scale: f32) -> Vec<Option<Vec3>> {
    let mut probes = vec![None; target.len()];
    let clusters = find_coincident_vertices(target, SEAM * scale).clusters;
    if clusters.is_empty() {
        return probes;
    }
    let mut on_seam = vec![false; target.len()];
    for &v in clusters.iter().flatten() {
        if let Some(s) = on_seam.get_mut(v as usize) {
            *s = true;
        }
    }
    let mut sum = vec![(Vec3::ZERO, 0u32); target.len()];
    for t in triangles {
        let Some(c) = t
            .iter()
            .map(|&v| target.get(v as usize).copied())
            .sum::<Option<Vec3>>()
        else {
            continue;
        };
        for &v in t {
            if on_seam[v as usize] {
                let e = &mut sum[v as usize];
                e.0 += c / 3.0;
                e.1 += 1;
            }
        }
    }
    for (v, &(c, n)) in sum.iter().enumerate() {
        if n > 0 {
            let p = target[v];
            probes[v] = Some(p + (c / n as f32 - p) * SEAM_STEP);
        }
    }
    probes
}

/// Incident face normals this far (cosine) from the vertex normal make a vertex a crease.
const CREASE_COS: f32 = 0.7;

/// For every vertex on a crease (module docs), the incident face normal farthest from its
/// vertex normal; `None` elsewhere.
fn crease_normals(
    positions: &[Vec3],
    triangles: &[[u32; 3]],
    normals: &[Vec3],
) -> Vec<Option<Vec3>> {
    let faces = triangle_normals(positions, triangles);
    let mut out: Vec<(f32, Option<Vec3>)> = vec![(CREASE_COS, None); positions.len()];
    for (t, f) in triangles.iter().zip(&faces) {
        if *f == Vec3::ZERO {
            continue;
        }
        for &v in t {
            let (Some(n), Some(o)) = (normals.get(v as usize), out.get_mut(v as usize)) else {
                continue;
            };
            let d = f.dot(*n);
            if d < o.0 {
                *o = (d, Some(*f));
            }
        }
    }
    out.into_iter().map(|o| o.1).collect()
}

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

/// A surface's vertex labels: slit sides and face pieces
/// ([`super::regions::face_pieces`]).
#[derive(Clone, Copy)]
pub(crate) struct Labels<'a> {
    /// Slit side of each vertex.
    pub sides: &'a [Side],
    /// Whether each vertex lies on a face piece.
    pub face: &'a [bool],
    /// Whether each vertex lies in the mouth interior, when both surfaces have one (empty
    /// otherwise: every vertex is outside).
    pub inside: &'a [bool],
}

/// Correspondences of every target vertex (`None`: no allowed source triangle, or beyond
/// the fade) on the registered surface `source` builds. `source_sides`: the slit side of every source vertex.
pub(crate) fn correspond(
    target: &[Vec3],
    target_triangles: &[[u32; 3]],
    labels: Labels,
    source: impl FnOnce() -> QuerySurface + Send,
    (source_triangles, source_sides): (&[[u32; 3]], &[Side]),
    scale: f32,
    opts: &FitOptions,
) -> Vec<Option<Correspondence>> {
    let Labels {
        sides,
        face,
        inside,
    } = labels;
    // The source's BVH is built while the target's normals and seams are found.
    let (source, (normals, creases, probes)) = rayon::join(source, || {
        let normals = vertex_normals(target, target_triangles);
        let creases = crease_normals(target, target_triangles, &normals);
        let probes = seam_probes(target, target_triangles, scale);
        (normals, creases, probes)
    });
    let source = &source;
    let cos = (opts.normal_degrees.to_radians()).cos() as f32;
    let (near, far) = (opts.fade.0 as f32 * scale, opts.fade.1 as f32 * scale);
    let snap = SNAP * scale;
    let far_probe = far * 1.001;
    let seam_slack = SEAM_SLACK * scale;
    target
        .par_iter()
        .enumerate()
        .map(|(i, &p)| {
            let bit = query_bit(
                sides.get(i).copied().unwrap_or(Side::Other),
                face.get(i).copied().unwrap_or(true),
                inside.get(i).copied().unwrap_or(false),
            );
            let nrm = normals.get(i).copied().unwrap_or(Vec3::ZERO);
            // A point on the surface is its own match, whatever the normals at a crease say.
            // Every search is bounded: beyond `far` nothing matches, and a bounded search
            // does not scan the whole source for triangles the filters reject.
            let plain = Filter {
                bit,
                normal: None,
                crease: None,
            };
            // A seam copy takes its own side's triangle (module docs), unless that lies
            // clearly farther than the closest one (the seam opened during registration).
            let seam = probes.get(i).copied().flatten().and_then(|q| {
                let near_p = source.closest_within(p, plain, far_probe)?;
                source
                    .closest_within(q, plain, far_probe)
                    .and_then(|h| source.within(h.triangle, p))
                    .filter(|h| h.point.distance(p) <= near_p.point.distance(p) + seam_slack)
            });
            let hit = if let Some(h) = seam {
                h
            } else if nrm == Vec3::ZERO {
                source.closest_within(p, plain, far_probe)?
            } else {
                let oriented = Filter {
                    bit,
                    normal: Some((nrm, cos)),
                    crease: creases.get(i).copied().flatten(),
                };
                // The side's nearest point within `snap` (a point on the surface), else the
                // compatible one; either is taken below when within `near`.
                let compatible = source.closest_snapping(p, oriented, snap, far_probe);
                // A vertex lying on the source (within `near`) whose compatible points are all
                // farther than `near` beyond its closest point sits where the normals mislead
                // (a lid margin's fold): its closest point stands in.
                // (Searched only when the compatible point is not itself that near.)
                let on_source = || {
                    source
                        .closest_within(p, plain, near * 1.001)
                        .filter(|h| h.point.distance(p) <= near)
                };
                match compatible {
                    Some(h) if h.point.distance(p) <= near => h,
                    Some(h) => match on_source() {
                        Some(c) if h.point.distance(p) > c.point.distance(p) + near => c,
                        _ => h,
                    },
                    None => match on_source() {
                        Some(c) => c,
                        // An oriented point beyond `far` fades to nothing; with no oriented
                        // triangle at all the plain closest point stands in.
                        None if source.any_allowed(oriented) => return None,
                        None => source.closest_within(p, plain, far_probe)?,
                    },
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
            let side = sides.get(i).copied().unwrap_or(Side::Other);
            (fade > 0.0 && fade.is_finite()).then_some(Correspondence {
                vertices: *tri,
                weights: own_side_weights(side, *tri, hit.weights, source_sides),
                fade,
            })
        })
        .collect()
}
