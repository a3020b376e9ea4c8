//! Writing a face in the format its file name asks for: VRML97 (patching the source scene
//! so other nodes survive), gzip VRML, or OBJ (a face read from OBJ: the user's text with only
//! its `v` lines rewritten, [`source_obj_text`]; otherwise all meshes merged in face
//! coordinates, each an `o` span; feature points, transforms and the FAT cannot be held by OBJ and are not
//! written: use VRML for a complete face). glTF output is [`crate::export::gltf`].

use std::path::Path;

use glam::{Affine3A, Vec3};

use super::vrml::face_to_scene;
use super::FaceModel;
use crate::error::Result;
use crate::format::OutputFormat;
use crate::io::gzip;
use crate::mesh::obj::ObjScene;
use crate::mesh::obj_patch::ObjVertexLines;
use crate::mesh::{FaceGroup, Mesh, Polygons};

/// The formats [`write()`] writes.
pub const WRITABLE: &[OutputFormat] =
    &[OutputFormat::Vrml, OutputFormat::VrmlGz, OutputFormat::Obj];

/// Writes a face in the format its extension names (see the module docs), atomically.
pub fn write(path: impl AsRef<Path>, face: &FaceModel) -> Result<()> {
    let path = path.as_ref();
    match OutputFormat::resolve(path, WRITABLE, "a face file")? {
        OutputFormat::Vrml => super::vrml::write_face_file(path, face),
        OutputFormat::VrmlGz => {
            let text = crate::vrml::write_vrml_string(&face_to_scene(face)?);
            crate::io::write_atomic_with(path, |w| gzip(text.as_bytes(), w))
        }
        // `resolve` accepted only WRITABLE: this is OBJ.
        _ => {
            let world: Vec<Vec3> = face.neutral_world_positions().concat();
            if let Some(text) = source_obj_text(face, &world) {
                return crate::io::write_atomic(path, text.as_bytes());
            }
            let scene = ObjScene {
                mesh: merged_mesh(face, &face.frames().meshes, None)?,
                material_libraries: Vec::new(),
            };
            crate::mesh::obj::write_obj_file(&scene, path)
        }
    }
}

/// The OBJ text `face` was read from with its vertices moved to `positions` (face frame, in
/// its vertex order): every other statement as the user wrote it
/// ([`crate::mesh::obj_patch`]). `None` when the face has no OBJ source or no longer has its
/// layout (one mesh with as many vertices and polygons as the text has `v` and `f`
/// statements) — then [`merged_mesh`] is the fallback.
pub fn source_obj_text(face: &FaceModel, positions: &[Vec3]) -> Option<String> {
    source_obj_lines(face)?.with_positions(positions)
}

/// The OBJ text `face` was read from, cut at its `v` statements to write many sets of
/// positions ([`source_obj_text`] for one); `None` as there.
pub fn source_obj_lines(face: &FaceModel) -> Option<ObjVertexLines<'_>> {
    let text = face.obj_source.as_deref()?;
    let [only] = face.meshes.as_slice() else {
        return None;
    };
    let lines = ObjVertexLines::parse(text);
    let layout = lines.layout();
    if layout.vertices != only.mesh.positions.len() || layout.faces != only.mesh.polygons.len() {
        return None;
    }
    Some(lines)
}

/// Many poses of one face written as OBJ files: the user's own text with its `v` lines
/// rewritten where the face still has it ([`source_obj_lines`]), else the merged mesh
/// ([`merged_mesh`]) with the pose's positions. The text is cut once; [`ObjPoses::write`]
/// builds and writes a batch of poses on rayon's threads.
#[derive(Debug)]
pub struct ObjPoses<'f> {
    lines: Option<ObjVertexLines<'f>>,
    merged: Mesh,
}

/// One OBJ file of a pose: its file name in the folder, the name its merged mesh takes (when
/// the face has no OBJ text of its own), and its positions in merged order (face frame).
#[derive(Clone, Debug)]
pub struct ObjPose {
    /// The file's name inside the folder.
    pub file: String,
    /// The mesh name written when the merged mesh is the fallback (`None`: the face's name).
    pub mesh_name: Option<String>,
    /// Every vertex of the face, in merged order.
    pub positions: Vec<Vec3>,
}

impl<'f> ObjPoses<'f> {
    /// Cuts the face's OBJ text (if it has one) and merges its meshes once.
    pub fn new(face: &'f FaceModel) -> Result<Self> {
        Ok(Self {
            lines: source_obj_lines(face),
            merged: merged_mesh(face, &face.frames().meshes, None)?,
        })
    }

    /// How many poses a caller gathers before [`ObjPoses::write`]: a few per thread, so the
    /// threads stay busy and the poses held stay few whatever the FAT's size.
    pub fn batch_len() -> usize {
        2 * rayon::current_num_threads().max(1)
    }

    /// The OBJ text of one pose.
    pub fn text(&self, pose: &ObjPose) -> Result<String> {
        if let Some(text) = self
            .lines
            .as_ref()
            .and_then(|l| l.with_positions(&pose.positions))
        {
            return Ok(text);
        }
        let mut mesh = self.merged.clone();
        mesh.positions.clone_from(&pose.positions);
        if let Some(name) = &pose.mesh_name {
            mesh.name.clone_from(name);
        }
        crate::mesh::obj::write_obj_string(&ObjScene {
            mesh,
            material_libraries: Vec::new(),
        })
    }

    /// Writes `poses` into `dir`, each file atomically, several at once.
    pub fn write(&self, dir: &crate::io::AtomicDir, poses: &[ObjPose]) -> Result<()> {
        use rayon::prelude::*;
        poses.par_iter().try_for_each(|pose| {
            let text = self.text(pose)?;
            dir.write_file(&pose.file, |p| crate::io::write_atomic(p, text.as_bytes()))
        })
    }
}

/// The positions of [`merged_mesh`] alone (no polygons copied): each mesh's vertices
/// displaced by `displacements[i]` and placed by `mesh_frames[i]`, in merged order.
pub fn merged_positions(
    face: &FaceModel,
    mesh_frames: &[Affine3A],
    displacements: Option<&[Vec<Vec3>]>,
) -> Vec<Vec3> {
    let mut out = Vec::with_capacity(face.meshes.iter().map(|m| m.mesh.positions.len()).sum());
    for (mi, fm) in face.meshes.iter().enumerate() {
        let frame = mesh_frames.get(mi).copied().unwrap_or(Affine3A::IDENTITY);
        push_placed(
            &mut out,
            &fm.mesh.positions,
            frame,
            displacements.and_then(|d| d.get(mi)),
        );
    }
    out
}

/// `positions`, each displaced by its entry of `disp` (none: zero) then placed by `frame`,
/// appended to `out`.
fn push_placed(out: &mut Vec<Vec3>, positions: &[Vec3], frame: Affine3A, disp: Option<&Vec<Vec3>>) {
    out.extend(positions.iter().enumerate().map(|(vi, p)| {
        let d = disp.and_then(|d| d.get(vi)).copied().unwrap_or(Vec3::ZERO);
        frame.transform_point3(*p + d)
    }));
}

/// All meshes of `face` merged into one in face coordinates, each mesh placed by
/// `mesh_frames[i]` and, when given, displaced by `displacements[i]` (in its local frame)
/// first. One `o` span per mesh; uvs / normals only when every mesh has them.
pub fn merged_mesh(
    face: &FaceModel,
    mesh_frames: &[Affine3A],
    displacements: Option<&[Vec<Vec3>]>,
) -> Result<Mesh> {
    let mut out = Mesh {
        name: face.name.clone(),
        ..Mesh::default()
    };
    let all_uvs = face
        .meshes
        .iter()
        .all(|m| m.mesh.uv_polygons.is_some() && !m.mesh.uvs.is_empty());
    let all_normals = face
        .meshes
        .iter()
        .all(|m| m.mesh.normal_polygons.is_some() && !m.mesh.normals.is_empty());
    let mut uv_polys = Polygons::new();
    let mut normal_polys = Polygons::new();
    let mut corner = Vec::new();
    for (mi, fm) in face.meshes.iter().enumerate() {
        let m = &fm.mesh;
        let frame = mesh_frames.get(mi).copied().unwrap_or(Affine3A::IDENTITY);
        let base =
            u32::try_from(out.positions.len()).map_err(|_| super::FaceError::TooManyVertices)?;
        let uv_base = out.uvs.len() as u32;
        let n_base = out.normals.len() as u32;
        out.groups.push(FaceGroup {
            first_face: out.polygons.len() as u32,
            object: Some(fm.name.clone()),
            ..FaceGroup::default()
        });
        push_placed(
            &mut out.positions,
            &m.positions,
            frame,
            displacements.and_then(|d| d.get(mi)),
        );
        for poly in m.polygons.iter() {
            corner.clear();
            corner.extend(poly.iter().map(|&i| i + base));
            out.polygons.push(&corner);
        }
        if all_uvs {
            out.uvs.extend_from_slice(&m.uvs);
            if let Some(up) = &m.uv_polygons {
                for poly in up.iter() {
                    corner.clear();
                    corner.extend(poly.iter().map(|&i| i + uv_base));
                    uv_polys.push(&corner);
                }
            }
        }
        if all_normals {
            let nm = glam::Mat3::from(frame.matrix3).inverse().transpose();
            out.normals.extend(
                m.normals
                    .iter()
                    .map(|n| (nm * *n).try_normalize().unwrap_or(*n)),
            );
            if let Some(np) = &m.normal_polygons {
                for poly in np.iter() {
                    corner.clear();
                    corner.extend(poly.iter().map(|&i| i + n_base));
                    normal_polys.push(&corner);
                }
            }
        }
    }
    if all_uvs && !face.meshes.is_empty() {
        out.uv_polygons = Some(uv_polys);
    } else {
        out.uvs.clear();
    }
    if all_normals && !face.meshes.is_empty() {
        out.normal_polygons = Some(normal_polys);
    } else {
        out.normals.clear();
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn merged_mesh_places_meshes_and_spans() {
        let face = crate::synth::alma().to_face_model();
        let frames = face.frames();
        let m = merged_mesh(&face, &frames.meshes, None).unwrap();
        assert_eq!(m.vertex_count(), face.vertex_count());
        assert_eq!(m.groups.len(), face.meshes.len());
        assert!(m.validate().is_valid());
        // The second mesh's first vertex sits where the face frame puts it.
        let off = face.meshes[0].mesh.vertex_count();
        assert_eq!(m.positions[off], face.vertex_world(&frames, 1, 0).unwrap());
    }

    #[test]
    fn writers_round_trip_by_extension() {
        let dir = tempfile::tempdir().unwrap();
        let face = crate::synth::alma().to_face_model();
        for name in ["a.wrl", "a.wrl.gz", "a.wrz"] {
            let p = dir.path().join(name);
            write(&p, &face).unwrap();
            let (back, report) = crate::face::read_with(&p, &Default::default()).unwrap();
            assert!(report.diagnostics.is_empty(), "{name}");
            assert!(back == face, "{name}");
        }
        // OBJ: geometry only, read → write → read equal.
        let p = dir.path().join("a.obj");
        write(&p, &face).unwrap();
        let (obj, _) = crate::face::read_with(&p, &Default::default()).unwrap();
        let q = dir.path().join("b.obj");
        write(&q, &obj).unwrap();
        let (again, _) = crate::face::read_with(&q, &Default::default()).unwrap();
        assert_eq!(again.meshes[0].mesh.positions, obj.meshes[0].mesh.positions);
        assert_eq!(again.meshes[0].mesh.polygons, obj.meshes[0].mesh.polygons);
        assert_eq!(obj.vertex_count(), face.vertex_count());
        assert!(write(dir.path().join("a.txt"), &face).is_err());
    }
}
