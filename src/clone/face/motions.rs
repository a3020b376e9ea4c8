//! Motions between a face's skin meshes and its [`SkinSurface`]: source morph targets onto
//! the welded surface (step 4), cloned surface motions back to per-mesh offsets (step 8).

use std::collections::HashMap;

use glam::{DMat3, DVec3, Vec3};

use super::{Similarity, SkinSurface};
use crate::clone::SurfaceMotion;
use crate::face::{FaceFrames, FaceModel};
use crate::fat::morph::{MorphMesh, MorphTarget};

/// Source morph targets as motions on a skin surface (face frame, welded).
pub(super) fn surface_motions(
    face: &FaceModel,
    skin: &SkinSurface,
    targets: &[MorphTarget],
) -> Vec<SurfaceMotion> {
    let frames = face.frames();
    let slot: HashMap<&str, usize> = skin
        .meshes
        .iter()
        .enumerate()
        .map(|(k, &m)| (face.meshes[m].name.as_str(), k))
        .collect();
    let n = skin.surface.positions.len();
    targets
        .iter()
        .map(|t| {
            let mut sum: HashMap<u32, (DVec3, u32)> = HashMap::new();
            for mm in &t.meshes {
                let Some(&k) = slot.get(mm.mesh.as_str()) else {
                    continue;
                };
                let mi = skin.meshes[k];
                let lin = frames.meshes[mi].matrix3.as_dmat3();
                let len = face.meshes[mi].mesh.positions.len();
                for (&v, o) in mm.vertices.iter().zip(&mm.offsets) {
                    if (v as usize) < len {
                        let w = skin.welded[skin.starts[k] + v as usize];
                        let e = sum.entry(w).or_insert((DVec3::ZERO, 0));
                        e.0 += lin * *o;
                        e.1 += 1;
                    }
                }
            }
            let mut offsets: Vec<(u32, Vec3)> = sum
                .into_iter()
                .filter(|(w, _)| (*w as usize) < n)
                .map(|(w, (s, c))| (w, (s / c as f64).as_vec3()))
                .filter(|(_, d)| *d != Vec3::ZERO)
                .collect();
            offsets.sort_by_key(|o| o.0);
            SurfaceMotion {
                key: t.key,
                value: t.value,
                offsets,
            }
        })
        .collect()
}

/// A cloned surface motion as per-mesh offsets in each target skin mesh's local frame.
pub(super) fn back_to_meshes(
    face: &FaceModel,
    frames: &FaceFrames,
    skin: &SkinSurface,
    frame: &Similarity,
    m: &SurfaceMotion,
) -> Vec<MorphMesh> {
    let inv: Vec<DMat3> = skin
        .meshes
        .iter()
        .map(|&mi| frames.meshes[mi].matrix3.as_dmat3().inverse())
        .collect();
    let mut per_mesh: Vec<Vec<(u32, DVec3)>> = vec![Vec::new(); skin.meshes.len()];
    for &(w, d) in &m.offsets {
        if w as usize >= skin.surface.positions.len() {
            continue;
        }
        let face_d = frame.inverse_vector(d.as_dvec3());
        for &c in skin.duplicates(w) {
            if !skin.referenced.get(c as usize).copied().unwrap_or(false) {
                continue;
            }
            let k = skin.starts.partition_point(|&s| s <= c as usize) - 1;
            let local = c - skin.starts[k] as u32;
            per_mesh[k].push((local, inv[k] * face_d));
        }
    }
    per_mesh
        .into_iter()
        .enumerate()
        .filter(|(_, l)| !l.is_empty())
        .map(|(k, mut l)| {
            l.sort_by_key(|x| x.0);
            MorphMesh {
                mesh: face.meshes[skin.meshes[k]].name.clone(),
                vertices: l.iter().map(|x| x.0).collect(),
                offsets: l.iter().map(|x| x.1).collect(),
            }
        })
        .collect()
}
