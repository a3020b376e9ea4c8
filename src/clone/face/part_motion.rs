//! Motion for target parts the source moves by deformation: a one-mesh source (a rig face
//! such as ICT's, its eyes, teeth, gums and tongue inside the skin mesh) moves its teeth with
//! the jaw through the skin FAT, so no source transform drives the target's split-out teeth.
//! Each such target part (teeth, gums and tongue; eyeballs move by eye rotations only) takes,
//! vertex by vertex, the source displacement where it lies on the source's inner pieces
//! (closest point among the triangles around its nearest inner vertex, barycentric weights;
//! aligned frame, times the FAPU ratio) — module docs of [`super`], step 7.
//!
//! Not reduced to one rigid motion per part: a rig's gums and tongue stretch where the jaw
//! opens (ICT blends them across the lip line), and the part's best rigid motion put
//! open_jaw 7.6 % and thrust_jaw 11.4 % off the ICT identities' true FATs (per vertex: 2.6
//! and 3.1 %). A source part that moves rigidly hands on a motion that is rigid up to its
//! interpolation.
//!
//! Only parts cut out of a one-mesh target are lent such motion. Whole part meshes of a
//! multi-mesh target (alma's and bruno's teeth under their transforms, cloned from ICT) lie
//! within the gap of ICT's inner pieces but on the wrong places of them: lent, alma's lower
//! teeth moved 0.49× its chin under open_jaw (ICT's own lower teeth 0.73× its chin) and
//! 0.43× under thrust_jaw and shift_jaw. They follow the target's cloned chin instead
//! (`jaw_follow`), as do cut parts no inner piece lies under.

use std::collections::HashMap;

use glam::{DMat3, DVec3, Vec3};

use crate::mesh::geometry::barycentric;

use super::{FaceParts, Part, Similarity, SkinSurface, SplitPart};
use crate::clone::SurfaceMotion;
use crate::face::FaceModel;
use crate::fat::morph::MorphMesh;
use crate::fat::TableKey;
use crate::fdp::Fapu;
use crate::mesh::VertexIndex;
use crate::spec::FapuKind;

/// Per source motion (key, value bits), displacements of target part meshes.
pub(super) type PartMeshes = HashMap<(TableKey, u64), Vec<MorphMesh>>;

/// A part's nearest source vertices must lie within this share of the source surface's
/// size (median): the source has the part's geometry in its skin, not just skin nearby.
const MAX_MEDIAN_GAP: f32 = 0.005;

/// A target part mesh the source has no part mesh for.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Undriven {
    /// Its part.
    pub part: Part,
    /// Its mesh index.
    pub mesh: usize,
    /// Whether it was cut out of a one-mesh target (step 1), not a part mesh of its own.
    pub cut: bool,
}

/// The target part meshes the source has no part mesh for, eyeballs left out (they move
/// only by the eye FAPs' rotations, never with a lid: not their neighbours' deformation):
/// parts cut out of a one-mesh target and whole part meshes alike.
pub(super) fn undriven_parts(
    sparts: &FaceParts,
    tparts: &FaceParts,
    split: &[SplitPart],
    face: &FaceModel,
) -> Vec<Undriven> {
    let mut out: Vec<Undriven> = split
        .iter()
        .filter_map(|s| {
            Some(Undriven {
                part: s.part,
                mesh: face.mesh_index(&s.mesh)?,
                cut: true,
            })
        })
        .collect();
    for (&part, meshes) in &tparts.parts {
        for &mesh in meshes {
            if !out.iter().any(|u| u.mesh == mesh) {
                out.push(Undriven {
                    part,
                    mesh,
                    cut: false,
                });
            }
        }
    }
    out.retain(|u| !matches!(u.part, Part::LeftEye | Part::RightEye));
    out.retain(|u| !sparts.parts.contains_key(&u.part));
    out
}

/// Per source motion (key, value bits), the displacements of the target part meshes `todo`
/// (the cut ones of [`undriven_parts`]) that lie on the source's inner pieces; also the
/// meshes so placed (moving or not).
pub(super) fn part_motions(
    todo: &[usize],
    face: &FaceModel,
    ssurf: &SkinSurface,
    tsurf: &SkinSurface,
    frame: &Similarity,
    motions: &[SurfaceMotion],
) -> (PartMeshes, Vec<usize>) {
    let mut out: PartMeshes = HashMap::new();
    let mut placed = Vec::new();
    if todo.is_empty() || motions.is_empty() {
        return (out, placed);
    }
    let src = &ssurf.surface;
    let size = bounds_diagonal(&src.positions);
    // Only the source's inner pieces (not its largest, the face) may lend their motion: a
    // reshaped target's teeth can sit nearer the source's lips than its teeth.
    let inner = inner_vertices(src);
    let index = VertexIndex::new(
        &inner
            .iter()
            .map(|&v| src.positions[v as usize])
            .collect::<Vec<_>>(),
    );
    // Inner triangles around each inner vertex (by its index in `inner`).
    let mut slot = vec![u32::MAX; src.positions.len()];
    for (k, &v) in inner.iter().enumerate() {
        slot[v as usize] = k as u32;
    }
    let mut around: Vec<Vec<u32>> = vec![Vec::new(); inner.len()];
    for (t, tri) in src.triangles.iter().enumerate() {
        if tri
            .iter()
            .all(|&v| slot.get(v as usize).is_some_and(|&k| k != u32::MAX))
        {
            for &v in tri {
                around[slot[v as usize] as usize].push(t as u32);
            }
        }
    }
    let frames = face.frames();
    for &mi in todo {
        let world = frames.meshes[mi];
        let q: Vec<Vec3> = face.meshes[mi]
            .mesh
            .positions
            .iter()
            .map(|&p| frame.point(world.transform_point3(p)))
            .collect();
        let near: Vec<(u32, f32)> = q.iter().filter_map(|&p| index.nearest_vertex(p)).collect();
        if near.len() != q.len() || q.len() < 3 {
            continue;
        }
        let mut gaps: Vec<f32> = near.iter().map(|n| n.1).collect();
        gaps.sort_by(f32::total_cmp);
        if gaps[gaps.len() / 2] > MAX_MEDIAN_GAP * size {
            continue;
        }
        placed.push(mi);
        let places: Vec<Place> = q
            .iter()
            .zip(&near)
            .map(|(&p, &(k, _))| place(p, inner[k as usize], &around[k as usize], src))
            .collect();
        let inv: DMat3 = world.matrix3.as_dmat3().inverse();
        for m in motions {
            let ratio = fapu_ratio(m.key, ssurf, tsurf);
            let offsets: Vec<DVec3> = places
                .iter()
                .map(|pl| {
                    let d: DVec3 = pl
                        .vertices
                        .iter()
                        .zip(&pl.weights)
                        .map(|(&v, &w)| m.offset_at(v).as_dvec3() * f64::from(w))
                        .sum();
                    inv * frame.inverse_vector(d * ratio)
                })
                .collect();
            if offsets.iter().all(|d| *d == DVec3::ZERO) {
                continue;
            }
            out.entry((m.key, m.value.to_bits()))
                .or_default()
                .push(MorphMesh {
                    mesh: face.meshes[mi].name.clone(),
                    vertices: (0..offsets.len() as u32).collect(),
                    offsets,
                });
        }
    }
    (out, placed)
}

/// Where a target vertex lies on the source: up to three source vertices and their weights.
struct Place {
    vertices: [u32; 3],
    weights: [f32; 3],
}

/// `p`'s closest point among the source triangles `tris` around its nearest source vertex
/// `v` (barycentric, clamped to each triangle); `v` itself without such triangles.
fn place(p: Vec3, v: u32, tris: &[u32], src: &crate::clone::CloneSurface) -> Place {
    let mut best = Place {
        vertices: [v; 3],
        weights: [1.0, 0.0, 0.0],
    };
    let mut best_d = src
        .positions
        .get(v as usize)
        .map_or(f32::INFINITY, |q| q.distance(p));
    for &t in tris {
        let Some(tri) = src.triangles.get(t as usize) else {
            continue;
        };
        let [a, b, c] = tri.map(|k| src.positions[k as usize]);
        let w = barycentric(p, a, b, c);
        let d = (a * w[0] + b * w[1] + c * w[2]).distance(p);
        if d < best_d {
            best_d = d;
            best = Place {
                vertices: *tri,
                weights: w,
            };
        }
    }
    best
}

/// Target / source FAPU of the key's unit (MNS for high-level tables and angles: parts in
/// the mouth).
fn fapu_ratio(key: TableKey, s: &SkinSurface, t: &SkinSurface) -> f64 {
    part_fapu_ratio(key, &s.surface.fapu, &t.surface.fapu)
}

/// Target / source FAPU of `key`'s unit for a part (MNS for high-level tables and angles:
/// the parts are in the mouth or move with it); 1 when the source unit is unusable.
pub(super) fn part_fapu_ratio(key: TableKey, s: &Fapu, t: &Fapu) -> f64 {
    let kind = match key {
        TableKey::LowLevel(f) => f.info().fapu.unwrap_or(FapuKind::Mns),
        _ => FapuKind::Mns,
    };
    let kind = if kind == FapuKind::Au {
        FapuKind::Mns
    } else {
        kind
    };
    let su = s.unit(kind);
    if su > 0.0 && su.is_finite() {
        t.unit(kind) / su
    } else {
        1.0
    }
}

/// Vertices of every connected piece of the surface but the largest.
fn inner_vertices(s: &crate::clone::CloneSurface) -> Vec<u32> {
    let n = s.positions.len();
    let mut parent: Vec<usize> = (0..n).collect();
    fn root(p: &mut [usize], mut x: usize) -> usize {
        while p[x] != x {
            p[x] = p[p[x]];
            x = p[x];
        }
        x
    }
    for t in &s.triangles {
        for k in 0..3 {
            let (a, b) = (t[k] as usize, t[(k + 1) % 3] as usize);
            if a < n && b < n {
                let (ra, rb) = (root(&mut parent, a), root(&mut parent, b));
                parent[ra] = rb;
            }
        }
    }
    let roots: Vec<usize> = (0..n).map(|v| root(&mut parent, v)).collect();
    let mut count: HashMap<usize, usize> = HashMap::new();
    for &r in &roots {
        *count.entry(r).or_default() += 1;
    }
    let core = count.iter().max_by_key(|(_, &c)| c).map(|(&r, _)| r);
    (0..n as u32)
        .filter(|&v| Some(roots[v as usize]) != core)
        .collect()
}

fn bounds_diagonal(p: &[Vec3]) -> f32 {
    let lo = p.iter().fold(Vec3::splat(f32::INFINITY), |a, &b| a.min(b));
    let hi = p
        .iter()
        .fold(Vec3::splat(f32::NEG_INFINITY), |a, &b| a.max(b));
    if lo.x <= hi.x {
        (hi - lo).length()
    } else {
        1.0
    }
}
