//! A whole face subdivided, its animation with it.
//!
//! Every mesh is triangulated and subdivided ([`crate::mesh::subdivide`]); every
//! `FaceDefMesh` rate is carried to the new vertices by the same stencils as the positions.
//! A FAT is linear in its rates, so the subdivided face plays exactly as the original does,
//! sampled finer (midpoint) or smoothed like its neutral (Loop). Feature points bound to
//! vertices keep their vertices (old vertices keep their indices) and are re-derived from
//! the new positions. Transforms and their tables are untouched.
//!
//! What is not carried: texture coordinates and normals (seams make them per corner; they
//! are dropped and normals recomputed by whoever needs them), and the scene the face was
//! read from (its geometry no longer matches; a VRML output is written as a new scene).
//! Material and group runs are kept, moved to the first triangle of their polygon.
//!
//! Used by the cloning benchmarks (CANDIDE-3 made dense) and the real-head ground truth
//! (a subdivided target whose true FAT is known), and by `fbakit face subdivide`.

use std::collections::HashMap;

use glam::Vec3;

use crate::error::Result;
use crate::face::FaceError;
use crate::face::FaceModel;
use crate::fat::FaceDefMesh;
use crate::mesh::geometry::triangulate;
use crate::mesh::subdivide::{subdivide, Scheme, Subdivision};
use crate::mesh::Polygons;

/// Largest vertex count [`subdivide_face`] will make (each round multiplies by about 4).
pub const MAX_SUBDIVIDED_VERTICES: usize = 20_000_000;

/// `face` after `rounds` rounds of `scheme` (module docs). Fails, before any work, when the
/// result would pass [`MAX_SUBDIVIDED_VERTICES`].
pub fn subdivide_face(face: &FaceModel, scheme: Scheme, rounds: usize) -> Result<FaceModel> {
    let vertices: usize = face.meshes.iter().map(|m| m.mesh.positions.len()).sum();
    let estimate = (0..rounds).try_fold(vertices, |v, _| v.checked_mul(4));
    if estimate.is_none_or(|v| v > MAX_SUBDIVIDED_VERTICES) {
        return Err(FaceError::TooManySubdivided {
            face: face.name.clone(),
            rounds,
            vertices,
            max: MAX_SUBDIVIDED_VERTICES,
        }
        .into());
    }
    let mut out = face.clone();
    out.scene = None;
    for _ in 0..rounds {
        let mut by_mesh: HashMap<String, Subdivision> = HashMap::new();
        for fm in &mut out.meshes {
            let mesh = &mut fm.mesh;
            let (triangles, source) = triangulate(&mesh.positions, &mesh.polygons);
            let s = subdivide(mesh.positions.len(), &triangles, scheme);
            mesh.positions = s.apply(&mesh.positions);
            if !mesh.colors.is_empty() {
                mesh.colors = s.apply(&mesh.colors);
            }
            for g in &mut mesh.groups {
                // The first triangle made from the group's first polygon (4 per triangle).
                let first = source.partition_point(|&p| p < g.first_face);
                g.first_face = (4 * first) as u32;
            }
            mesh.polygons = Polygons::from_triangles(&s.triangles);
            mesh.uvs.clear();
            mesh.uv_polygons = None;
            mesh.normals.clear();
            mesh.normal_polygons = None;
            by_mesh.insert(fm.name.clone(), s);
        }
        for table in &mut out.fat.tables {
            for dm in &mut table.meshes {
                if let Some(s) = by_mesh.get(&dm.mesh) {
                    *dm = carry_rates(dm, s);
                }
            }
        }
    }
    out.resolve_feature_points()?;
    Ok(out)
}

/// `dm`'s rates on the subdivided mesh: dense per interval, through the stencils, zeros left
/// out again.
fn carry_rates(dm: &FaceDefMesh, s: &Subdivision) -> FaceDefMesh {
    let intervals = dm.interval_count();
    let mut rates = Vec::with_capacity(dm.coord_index.len() * intervals);
    for j in 0..intervals {
        let mut dense = vec![Vec3::ZERO; s.old_count];
        for (slot, &v) in dm.coord_index.iter().enumerate() {
            if let Some(d) = dense.get_mut(v as usize) {
                *d = dm.displacements[slot * intervals + j];
            }
        }
        rates.push(s.apply(&dense));
    }
    let mut coord_index = Vec::new();
    let mut displacements = Vec::new();
    for v in 0..s.vertex_count() {
        if rates.iter().any(|r| r[v] != Vec3::ZERO) {
            coord_index.push(v as u32);
            displacements.extend(rates.iter().map(|r| r[v]));
        }
    }
    FaceDefMesh {
        mesh: dm.mesh.clone(),
        interval_borders: dm.interval_borders.clone(),
        coord_index,
        displacements,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fat::eval::Activation;
    use crate::fat::morph::fat_to_morph_targets;

    /// Posing the subdivided face equals subdividing the posed face: the FAT is carried
    /// exactly (Loop is linear in positions).
    #[test]
    fn animation_commutes_with_subdivision() {
        let face = crate::synth::alma().to_face_model();
        let sub = subdivide_face(&face, Scheme::Loop, 1).unwrap();
        assert!(sub.meshes[0].mesh.positions.len() > 3 * face.meshes[0].mesh.positions.len());
        assert_eq!(sub.feature_points.len(), face.feature_points.len());
        let targets = fat_to_morph_targets(&face.fat);
        for t in targets
            .iter()
            .filter(|t| t.key.name() == "open_jaw")
            .take(1)
        {
            let a = [Activation {
                key: t.key,
                value: t.value,
            }];
            let posed = face.pose(&a).unwrap();
            let sub_posed = sub.pose(&a).unwrap();
            for (mi, fm) in face.meshes.iter().enumerate() {
                let (tris, _) = triangulate(&fm.mesh.positions, &fm.mesh.polygons);
                let s = subdivide(fm.mesh.positions.len(), &tris, Scheme::Loop);
                let expected = s.apply(&posed[mi]);
                let worst = expected
                    .iter()
                    .zip(&sub_posed[mi])
                    .map(|(a, b)| a.distance(*b))
                    .fold(0.0f32, f32::max);
                assert!(worst < 1e-4, "mesh {}: {worst}", fm.name);
            }
        }
        // Feature points stay on their vertices.
        let fp = sub.feature_points.iter().next().unwrap();
        assert!(fp.position.is_some());
    }

    #[test]
    fn runaway_rounds_are_refused() {
        let face = crate::synth::alma().to_face_model();
        let e = subdivide_face(&face, Scheme::Midpoint, 40).unwrap_err();
        assert!(e.to_string().contains("fewer rounds"), "{e}");
    }
}
