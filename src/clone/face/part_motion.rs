//! Rigid motion for target parts the source moves by deformation: a one-mesh source (a rig
//! face such as ICT's, its eyes and teeth inside the skin mesh) moves its teeth with the jaw
//! through the skin FAT, so no source transform drives the target's split-out teeth. Each
//! such target part (teeth and gums; eyeballs move by eye rotations only) takes the source displacements at its nearest source skin vertices
//! (aligned frame, times the FAPU ratio) and keeps only their best rigid motion (module docs
//! of [`super`], step 7).

use std::collections::HashMap;

use glam::{DMat3, DVec3, Vec3};

use super::{FaceParts, Part, Similarity, SkinSurface, SplitPart};
use crate::clone::SurfaceMotion;
use crate::face::FaceModel;
use crate::fat::morph::MorphMesh;
use crate::fat::TableKey;
use crate::fdp::Fapu;
use crate::mesh::VertexIndex;
use crate::spec::FapuKind;

/// A part's nearest source vertices must lie within this share of the source surface's
/// size (median): the source has the part's geometry in its skin, not just skin nearby.
const MAX_MEDIAN_GAP: f32 = 0.005;

/// Per source motion (key, value bits), the rigid displacements of the target's split parts
/// the source has no part mesh for.
pub(super) fn part_motions(
    sparts: &FaceParts,
    split: &[SplitPart],
    face: &FaceModel,
    ssurf: &SkinSurface,
    tsurf: &SkinSurface,
    frame: &Similarity,
    motions: &[SurfaceMotion],
) -> HashMap<(TableKey, u64), Vec<MorphMesh>> {
    let mut out: HashMap<(TableKey, u64), Vec<MorphMesh>> = HashMap::new();
    let todo: Vec<usize> = split
        .iter()
        // Eyeballs move only by the eye FAPs' rotations, never with a lid: not their
        // neighbours' deformation.
        .filter(|s| !matches!(s.part, Part::LeftEye | Part::RightEye))
        .filter(|s| !sparts.parts.contains_key(&s.part))
        .filter_map(|s| face.mesh_index(&s.mesh))
        .collect();
    if todo.is_empty() || motions.is_empty() {
        return out;
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
    let frames = face.frames();
    for mi in todo {
        let world = frames.meshes[mi];
        let q: Vec<Vec3> = face.meshes[mi]
            .mesh
            .positions
            .iter()
            .map(|&p| frame.point(world.transform_point3(p)))
            .collect();
        let near: Vec<(u32, f32)> = q
            .iter()
            .filter_map(|&p| index.nearest_vertex(p))
            .map(|(k, d)| (inner[k as usize], d))
            .collect();
        if near.len() != q.len() || q.len() < 3 {
            continue;
        }
        let mut gaps: Vec<f32> = near.iter().map(|n| n.1).collect();
        gaps.sort_by(f32::total_cmp);
        if gaps[gaps.len() / 2] > MAX_MEDIAN_GAP * size {
            continue;
        }
        let inv: DMat3 = world.matrix3.as_dmat3().inverse();
        let from: Vec<DVec3> = q.iter().map(|p| p.as_dvec3()).collect();
        for m in motions {
            let ratio = fapu_ratio(m.key, ssurf, tsurf);
            let to: Vec<DVec3> = from
                .iter()
                .zip(&near)
                .map(|(p, n)| *p + offset_at(m, n.0).as_dvec3() * ratio)
                .collect();
            if from.iter().zip(&to).all(|(a, b)| a == b) {
                continue;
            }
            let Some(rigid) = rigid_fit(&from, &to) else {
                continue;
            };
            let offsets: Vec<DVec3> = from
                .iter()
                .map(|&p| inv * frame.inverse_vector(rigid_point(&rigid, p) - p))
                .collect();
            out.entry((m.key, m.value.to_bits()))
                .or_default()
                .push(MorphMesh {
                    mesh: face.meshes[mi].name.clone(),
                    vertices: (0..offsets.len() as u32).collect(),
                    offsets,
                });
        }
    }
    out
}

/// Best rotation and translation taking `from` onto `to` (the similarity fit with its scale
/// set to 1: a part does not grow).
fn rigid_fit(from: &[DVec3], to: &[DVec3]) -> Option<Similarity> {
    let mut s = Similarity::fit(from, to).ok()?;
    let n = from.len() as f64;
    let mf = from.iter().sum::<DVec3>() / n;
    let mt = to.iter().sum::<DVec3>() / n;
    s.scale = 1.0;
    s.translation = mt - s.rotation * mf;
    s.translation.is_finite().then_some(s)
}

fn rigid_point(s: &Similarity, p: DVec3) -> DVec3 {
    s.rotation * p * s.scale + s.translation
}

fn offset_at(m: &SurfaceMotion, v: u32) -> Vec3 {
    m.offsets
        .binary_search_by_key(&v, |o| o.0)
        .map_or(Vec3::ZERO, |i| m.offsets[i].1)
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
