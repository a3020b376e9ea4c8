//! Trimming a rig: keep some vertices of a mesh, keep some shapes, drop motion too small to
//! see. Used to cut a real rig down to a sample that ships with fbakit, and for anyone who
//! wants a lighter rig (a face without its eyelashes, only the speech shapes).

use super::{Rig, ShapeDelta};
use crate::error::Result;
use crate::mesh::{FaceGroup, Mesh, Polygons};

impl Rig {
    /// Keeps the vertices of mesh `mesh` for which `keep[v]` holds, and the polygons whose
    /// corners are all kept; vertices are renumbered in their old order, shape deltas and
    /// per-vertex attributes (UVs, normals, colours indexed like the positions) follow, and
    /// material groups keep their polygons. Per-corner UVs or normals that cannot follow are
    /// dropped. Returns the new index of every old vertex.
    pub fn retain_vertices(&mut self, mesh: usize, keep: &[bool]) -> Result<Vec<Option<u32>>> {
        let Some(rig_mesh) = self.meshes.get_mut(mesh) else {
            return Err(super::RigError::NoSuchMesh {
                rig: self.name.clone(),
                mesh,
                count: self.meshes.len(),
            }
            .into());
        };
        let old = &rig_mesh.mesh;
        if keep.len() != old.vertex_count() {
            return Err(super::RigError::KeepMaskLength {
                rig: self.name.clone(),
                mesh: rig_mesh.name.clone(),
                vertices: old.vertex_count(),
                mask: keep.len(),
            }
            .into());
        }
        let mut remap = vec![None; keep.len()];
        let mut next = 0u32;
        for (v, &k) in keep.iter().enumerate() {
            if k {
                remap[v] = Some(next);
                next += 1;
            }
        }
        let per_vertex = |attr_polys: &Option<Polygons>, len: usize| {
            attr_polys.as_ref() == Some(&old.polygons) && len == old.vertex_count()
        };
        let keep_uvs = per_vertex(&old.uv_polygons, old.uvs.len());
        let keep_normals = per_vertex(&old.normal_polygons, old.normals.len());
        let mut polygons = Polygons::new();
        let mut groups: Vec<FaceGroup> = Vec::new();
        let mut group_at = old.groups.iter().peekable();
        let mut current: Option<&FaceGroup> = None;
        let mut corners = Vec::new();
        for (f, poly) in old.polygons.iter().enumerate() {
            while let Some(g) = group_at.next_if(|g| g.first_face as usize <= f) {
                current = Some(g);
            }
            corners.clear();
            corners.extend(poly.iter().map_while(|&v| remap[v as usize]));
            if corners.len() != poly.len() {
                continue;
            }
            if let Some(g) = current {
                let same = groups.last().is_some_and(|last| {
                    last.material == g.material
                        && last.groups == g.groups
                        && last.object == g.object
                });
                if !same {
                    groups.push(FaceGroup {
                        first_face: polygons.len() as u32,
                        ..g.clone()
                    });
                }
            }
            polygons.push(&corners);
        }
        let pick = |values: &[glam::Vec3]| -> Vec<glam::Vec3> {
            values
                .iter()
                .zip(keep)
                .filter_map(|(x, &k)| k.then_some(*x))
                .collect()
        };
        let mut trimmed = Mesh {
            name: old.name.clone(),
            positions: pick(&old.positions),
            colors: if old.colors.len() == old.vertex_count() {
                pick(&old.colors)
            } else {
                Vec::new()
            },
            polygons: polygons.clone(),
            uvs: Vec::new(),
            uv_polygons: None,
            normals: Vec::new(),
            normal_polygons: None,
            groups,
            flags: old.flags,
        };
        if keep_uvs {
            trimmed.uvs = old
                .uvs
                .iter()
                .zip(keep)
                .filter_map(|(x, &k)| k.then_some(*x))
                .collect();
            trimmed.uv_polygons = Some(polygons.clone());
        }
        if keep_normals {
            trimmed.normals = pick(&old.normals);
            trimmed.normal_polygons = Some(polygons);
        }
        rig_mesh.mesh = trimmed;
        for shape in &mut self.shapes {
            for d in shape.deltas.iter_mut().filter(|d| d.mesh == mesh) {
                let mut vertices = Vec::with_capacity(d.vertices.len());
                let mut offsets = Vec::with_capacity(d.offsets.len());
                for (&v, &o) in d.vertices.iter().zip(&d.offsets) {
                    if let Some(Some(nv)) = remap.get(v as usize) {
                        vertices.push(*nv);
                        offsets.push(o);
                    }
                }
                *d = ShapeDelta {
                    mesh,
                    vertices,
                    offsets,
                };
            }
            shape.deltas.retain(|d| !d.vertices.is_empty());
        }
        Ok(remap)
    }

    /// Keeps the shapes `keep` accepts (by name), in their order.
    pub fn retain_shapes(&mut self, mut keep: impl FnMut(&str) -> bool) {
        self.shapes.retain(|s| keep(&s.name));
    }

    /// Drops vertex motions no longer than `length` (in the rig's units) from every shape;
    /// returns how many were dropped. Shapes that no longer move anything keep their name.
    pub fn drop_motion_below(&mut self, length: f32) -> usize {
        let mut dropped = 0;
        for shape in &mut self.shapes {
            for d in &mut shape.deltas {
                let before = d.vertices.len();
                (d.vertices, d.offsets) = d
                    .vertices
                    .iter()
                    .zip(&d.offsets)
                    .filter(|(_, o)| o.length() > length)
                    .map(|(&v, &o)| (v, o))
                    .unzip();
                dropped += before - d.vertices.len();
            }
            shape.deltas.retain(|d| !d.vertices.is_empty());
        }
        dropped
    }
}

#[cfg(test)]
mod tests {
    use super::super::{BlendShape, RigMesh};
    use super::*;
    use glam::Vec3;

    /// Two quads side by side (vertices 0-5) in two material groups, one shape moving all.
    fn strip() -> Rig {
        let positions: Vec<Vec3> = (0..6)
            .map(|i| Vec3::new((i % 3) as f32, (i / 3) as f32, 0.0))
            .collect();
        let polygons = Polygons::from_lists([vec![0u32, 1, 4, 3], vec![1, 2, 5, 4]]);
        let mut mesh = Mesh::from_triangles("m", positions, &[]);
        mesh.polygons = polygons;
        mesh.groups = vec![
            FaceGroup {
                first_face: 0,
                object: None,
                groups: Vec::new(),
                smoothing: None,
                material: Some("A".into()),
            },
            FaceGroup {
                first_face: 1,
                object: None,
                groups: Vec::new(),
                smoothing: None,
                material: Some("B".into()),
            },
        ];
        Rig {
            name: "strip".into(),
            meshes: vec![RigMesh {
                name: "m".into(),
                mesh,
            }],
            shapes: vec![BlendShape {
                name: "lift".into(),
                default_weight: 0.0,
                deltas: vec![ShapeDelta {
                    mesh: 0,
                    vertices: (0..6).collect(),
                    offsets: (0..6).map(|i| Vec3::Z * (i as f32 + 1.0) * 0.001).collect(),
                }],
            }],
            warnings: Vec::new(),
            source: None,
        }
    }

    #[test]
    fn retain_vertices_renumbers_polygons_groups_and_deltas() {
        let mut rig = strip();
        // Drop vertex 0: the first quad goes, the second stays with its material.
        let keep = [false, true, true, true, true, true];
        let remap = rig.retain_vertices(0, &keep).unwrap();
        assert_eq!(remap[0], None);
        assert_eq!(remap[1], Some(0));
        let m = &rig.meshes[0].mesh;
        assert_eq!(m.vertex_count(), 5);
        assert_eq!(m.polygons.len(), 1);
        assert_eq!(m.polygons.get(0).unwrap(), &[0, 1, 4, 3]);
        assert_eq!(m.groups.len(), 1);
        assert_eq!(m.groups[0].material.as_deref(), Some("B"));
        assert_eq!(m.groups[0].first_face, 0);
        let d = &rig.shapes[0].deltas[0];
        assert_eq!(d.vertices, vec![0, 1, 2, 3, 4]);
        assert!((d.offsets[0].z - 0.002).abs() < 1e-9);
        rig.check().unwrap();
    }

    #[test]
    fn retain_vertices_checks_its_arguments() {
        let mut rig = strip();
        assert!(rig.retain_vertices(3, &[true; 6]).is_err());
        assert!(rig.retain_vertices(0, &[true; 5]).is_err());
    }

    #[test]
    fn small_motion_and_shapes_are_dropped() {
        let mut rig = strip();
        assert_eq!(rig.drop_motion_below(0.0035), 3);
        assert_eq!(rig.shapes[0].deltas[0].vertices, vec![3, 4, 5]);
        assert_eq!(rig.drop_motion_below(1.0), 3);
        assert!(rig.shapes[0].deltas.is_empty());
        rig.retain_shapes(|n| n != "lift");
        assert!(rig.shapes.is_empty());
    }
}
