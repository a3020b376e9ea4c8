//! Face files of any supported kind, picked by extension: VRML97 (`.wrl`, `.vrml`),
//! gzip-compressed VRML (`.wrl.gz`, `.vrml.gz`, `.wrz`) and Wavefront OBJ (`.obj`).
//!
//! **OBJ faces.** An OBJ file is one mesh (named after the file stem, see
//! [`crate::mesh::obj`]) with no transforms and no FAT. Feature points come from a separate
//! feature-point file (`fp`, any format [`crate::fdp::read_feature_points`] reads): points
//! bound to vertices are placed on the mesh ([`FaceModel::resolve_feature_points`]); points
//! with a position only are bound to the nearest vertex, and the distance is reported in
//! [`FaceReadReport::fp_matches`], as the VRML reader does for files without fbakit's record.
//! The same `fp` file may also be given for a VRML face: its points then replace the file's.
//!
//! **Writing OBJ.** All meshes are merged into one, in face coordinates (each mesh's points
//! through its transform chain at neutral); each mesh becomes an `o` object span named after
//! it. Texture coordinates are kept only when every mesh has them, normals only when every mesh
//! has them (rotated with the mesh). Feature points, transforms and the FAT are not written:
//! OBJ cannot hold them (use VRML for a complete face).
//!
//! **Gzip.** Compressed input is read bounded (the compressed file and the decompressed text
//! are both limited to [`crate::io::DEFAULT_MAX_INPUT_BYTES`]), so a gzip bomb is refused
//! instead of filling memory. Output is compressed at the best level with a zero timestamp,
//! so equal faces give byte-identical files.

use std::io::{Read, Write};
use std::path::Path;

use flate2::read::MultiGzDecoder;
use flate2::write::GzEncoder;
use flate2::Compression;
use glam::{Affine3A, Vec3};

use super::vrml::{face_from_scene, face_to_scene, FaceReadReport, FeaturePointMatch};
use super::{FaceMesh, FaceModel};
use crate::error::{Error, Result};
use crate::fdp::{FeaturePointSet, VertexBinding};
use crate::io::DEFAULT_MAX_INPUT_BYTES;
use crate::mesh::obj::ObjScene;
use crate::mesh::{FaceGroup, Mesh, Polygons, VertexIndex};

/// The face file formats, by extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum FaceFormat {
    /// VRML97 text (`.wrl`, `.vrml`).
    Vrml,
    /// Gzip-compressed VRML97 (`.wrl.gz`, `.vrml.gz`, `.wrz`).
    VrmlGz,
    /// Wavefront OBJ (`.obj`): geometry only.
    Obj,
}

impl FaceFormat {
    /// The format of `path` from its extension (case-insensitive).
    pub fn of_path(path: &Path) -> Result<FaceFormat> {
        let name = path
            .file_name()
            .map(|n| n.to_string_lossy().to_ascii_lowercase())
            .unwrap_or_default();
        if name.ends_with(".wrl.gz") || name.ends_with(".vrml.gz") || name.ends_with(".wrz") {
            Ok(FaceFormat::VrmlGz)
        } else if name.ends_with(".wrl") || name.ends_with(".vrml") {
            Ok(FaceFormat::Vrml)
        } else if name.ends_with(".obj") {
            Ok(FaceFormat::Obj)
        } else {
            Err(Error::Unsupported(format!(
                "{}: unknown face file type (expected .wrl, .vrml, .wrl.gz, .wrz or .obj)",
                path.display()
            )))
        }
    }
}

/// The name a face read from `path` gets: the file name without its face extension.
pub fn face_name(path: &Path) -> String {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "face".into());
    let lower = name.to_ascii_lowercase();
    for ext in [".wrl.gz", ".vrml.gz", ".wrz", ".wrl", ".vrml", ".obj"] {
        if lower.ends_with(ext) && name.len() > ext.len() {
            return name[..name.len() - ext.len()].to_string();
        }
    }
    name
}

/// Reads a face file of any supported format (see the module docs); `fp` is a feature-point
/// file whose points replace the face's own (required to have any points on an OBJ face).
pub fn read_face(path: &Path, fp: Option<&Path>) -> Result<(FaceModel, FaceReadReport)> {
    let name = face_name(path);
    let (mut face, mut report) = match FaceFormat::of_path(path)? {
        FaceFormat::Vrml => {
            let scene = crate::vrml::read_vrml_file(path)?;
            face_from_scene(scene, &name)?
        }
        FaceFormat::VrmlGz => {
            let text = read_gz_text(path, DEFAULT_MAX_INPUT_BYTES)?;
            let scene = crate::vrml::parse_vrml(path, &text)?;
            face_from_scene(scene, &name)?
        }
        FaceFormat::Obj => {
            let (obj, diagnostics) = crate::mesh::obj::read_obj_file(path)?;
            let mut face = FaceModel::new(&name);
            let mut mesh = obj.mesh;
            mesh.name = name.clone();
            face.meshes.push(FaceMesh {
                name: name.clone(),
                transform: None,
                mesh,
                color: None,
            });
            let report = FaceReadReport {
                diagnostics,
                mesh_paths: vec![format!("OBJ {}", path.display())],
                ..FaceReadReport::default()
            };
            (face, report)
        }
    };
    if let Some(fp) = fp {
        let file = crate::fdp::read_feature_points(fp)?;
        let obj_file = path
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        report.fp_matches = attach_feature_points(&mut face, file.points, &[&obj_file])
            .map_err(|e| Error::Invalid(format!("{}: {e}", fp.display())))?;
    }
    Ok((face, report))
}

/// Puts `points` on `face`: bound points are placed on their vertices, position-only points
/// are bound to the nearest vertex (returned with the distance). On a single-mesh face a
/// binding naming no mesh, the mesh itself, or one of `aliases` (e.g. the OBJ file name an
/// Xface `.fdp` refers to) is bound to that mesh; any other mesh name is an error.
pub fn attach_feature_points(
    face: &mut FaceModel,
    mut points: FeaturePointSet,
    aliases: &[&str],
) -> Result<Vec<FeaturePointMatch>> {
    let single = (face.meshes.len() == 1).then(|| face.meshes[0].name.clone());
    let mut bad = Vec::new();
    let ids: Vec<_> = points.iter().map(|p| p.id).collect();
    for id in ids {
        let Some(p) = points.get_mut(id) else {
            continue;
        };
        let Some(b) = p.binding.as_mut() else {
            continue;
        };
        match (&single, b.mesh.as_deref()) {
            (Some(only), None) => b.mesh = Some(only.clone()),
            (Some(only), Some(m)) if m == only || aliases.contains(&m) => {
                b.mesh = Some(only.clone())
            }
            (_, Some(m)) if face.mesh_index(m).is_some() => {}
            (_, m) => bad.push(format!(
                "{id} names mesh {}",
                m.map_or("<none>".to_string(), |m| format!("`{m}`"))
            )),
        }
    }
    if !bad.is_empty() {
        let names: Vec<&str> = face.meshes.iter().map(|m| m.name.as_str()).collect();
        return Err(Error::Invalid(format!(
            "feature points bound to meshes the face does not have ({}); the face's meshes: {}",
            bad.join(", "),
            names.join(", ")
        )));
    }
    face.feature_points = points;
    face.resolve_feature_points()?;

    // Position-only points: bind to the nearest vertex of any mesh.
    let frames = face.frames();
    let mut owners: Vec<(usize, u32)> = Vec::new();
    let mut world: Vec<Vec3> = Vec::new();
    for (mi, m) in face.meshes.iter().enumerate() {
        for (vi, p) in m.mesh.positions.iter().enumerate() {
            owners.push((mi, vi as u32));
            world.push(frames.meshes[mi].transform_point3(*p));
        }
    }
    let index = VertexIndex::new(&world);
    let mut matches = Vec::new();
    let unbound: Vec<_> = face
        .feature_points
        .iter()
        .filter(|p| p.binding.is_none())
        .filter_map(|p| Some((p.id, p.position?)))
        .collect();
    for (id, pos) in unbound {
        if !pos.is_finite() {
            return Err(Error::Invalid(format!(
                "feature point {id} has a non-finite position"
            )));
        }
        let Some((nearest, distance)) = index.nearest_vertex(pos) else {
            continue;
        };
        let (mi, vi) = owners[nearest as usize];
        let mesh = face.meshes[mi].name.clone();
        if let Some(p) = face.feature_points.get_mut(id) {
            p.binding = Some(VertexBinding {
                mesh: Some(mesh.clone()),
                vertices: vec![vi],
            });
        }
        matches.push(FeaturePointMatch {
            id,
            mesh,
            vertex: vi,
            distance,
        });
    }
    Ok(matches)
}

/// Reads a gzip-compressed UTF-8 text file; both the compressed file and the decompressed
/// text are limited to `max_bytes` (a larger output is an error, not an allocation).
pub fn read_gz_text(path: &Path, max_bytes: u64) -> Result<String> {
    let compressed = crate::io::read_bounded(path, max_bytes)?;
    let text = gunzip_bounded(&compressed, max_bytes).map_err(|e| Error::io(path, e))?;
    String::from_utf8(text).map_err(|e| {
        let at = e.utf8_error().valid_up_to();
        let valid = std::str::from_utf8(&e.as_bytes()[..at]).unwrap_or_default();
        Error::Parse(crate::error::ParseError {
            location: crate::error::Location::from_offset(path, valid, at),
            expected: "UTF-8 text (after gzip decompression)".to_string(),
            found: Some(format!("byte 0x{:02X}", e.as_bytes()[at])),
        })
    })
}

/// Decompresses gzip data, refusing output larger than `max_bytes`.
pub fn gunzip_bounded(data: &[u8], max_bytes: u64) -> std::io::Result<Vec<u8>> {
    let mut out = Vec::new();
    MultiGzDecoder::new(data)
        .take(max_bytes.saturating_add(1))
        .read_to_end(&mut out)
        .map_err(|e| std::io::Error::new(std::io::ErrorKind::InvalidData, e))?;
    if out.len() as u64 > max_bytes {
        return Err(std::io::Error::new(
            std::io::ErrorKind::FileTooLarge,
            format!("decompresses to more than the {max_bytes}-byte input limit"),
        ));
    }
    Ok(out)
}

/// Gzip-compresses `data` (best level, zero timestamp: equal input gives equal bytes).
pub fn gzip(data: &[u8], w: &mut dyn Write) -> std::io::Result<()> {
    let mut enc = GzEncoder::new(w, Compression::best());
    enc.write_all(data)?;
    enc.finish()?;
    Ok(())
}

/// Writes a face in the format its extension names (see the module docs), atomically.
pub fn write_face(path: &Path, face: &FaceModel) -> Result<()> {
    match FaceFormat::of_path(path)? {
        FaceFormat::Vrml => super::vrml::write_face_file(path, face),
        FaceFormat::VrmlGz => {
            let text = crate::vrml::write_vrml_string(&face_to_scene(face)?);
            crate::io::write_atomic_with(path, |w| gzip(text.as_bytes(), w))
        }
        FaceFormat::Obj => {
            let scene = ObjScene {
                mesh: merged_mesh(face, &face.frames().meshes, None)?,
                material_libraries: Vec::new(),
            };
            crate::mesh::obj::write_obj_file(&scene, path)
        }
    }
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
        let base = u32::try_from(out.positions.len())
            .map_err(|_| Error::Invalid("too many vertices for one OBJ".into()))?;
        let uv_base = out.uvs.len() as u32;
        let n_base = out.normals.len() as u32;
        out.groups.push(FaceGroup {
            first_face: out.polygons.len() as u32,
            object: Some(fm.name.clone()),
            ..FaceGroup::default()
        });
        let disp = displacements.and_then(|d| d.get(mi));
        for (vi, p) in m.positions.iter().enumerate() {
            let d = disp.and_then(|d| d.get(vi)).copied().unwrap_or(Vec3::ZERO);
            out.positions.push(frame.transform_point3(*p + d));
        }
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
    use crate::fdp::FeaturePoint;
    use crate::spec::FeaturePointId;

    fn fp(s: &str) -> FeaturePointId {
        s.parse().unwrap()
    }

    #[test]
    fn formats_by_extension() {
        let f = |p: &str| FaceFormat::of_path(Path::new(p)).ok();
        assert_eq!(f("a.wrl"), Some(FaceFormat::Vrml));
        assert_eq!(f("a.VRML"), Some(FaceFormat::Vrml));
        assert_eq!(f("a.wrl.gz"), Some(FaceFormat::VrmlGz));
        assert_eq!(f("a.wrz"), Some(FaceFormat::VrmlGz));
        assert_eq!(f("a.obj"), Some(FaceFormat::Obj));
        assert_eq!(f("a.gz"), None);
        assert_eq!(face_name(Path::new("x/alma.wrl.gz")), "alma");
        assert_eq!(face_name(Path::new("x/head.obj")), "head");
    }

    #[test]
    fn gzip_round_trip_and_bomb_refused() {
        let mut z = Vec::new();
        gzip(b"hello hello hello", &mut z).unwrap();
        assert_eq!(gunzip_bounded(&z, 100).unwrap(), b"hello hello hello");
        // Deterministic output.
        let mut z2 = Vec::new();
        gzip(b"hello hello hello", &mut z2).unwrap();
        assert_eq!(z, z2);
        // 1 MB of zeros compresses to ~1 kB; a 64 kB limit refuses it.
        let mut bomb = Vec::new();
        gzip(&vec![0u8; 1 << 20], &mut bomb).unwrap();
        assert!(bomb.len() < 4096);
        let e = gunzip_bounded(&bomb, 1 << 16).unwrap_err();
        assert_eq!(e.kind(), std::io::ErrorKind::FileTooLarge);
        // Garbage is an error, not a panic.
        assert!(gunzip_bounded(b"\x1f\x8b\x08garbage", 100).is_err());
        assert!(gunzip_bounded(&bomb[..bomb.len() / 2], 1 << 30).is_err());
    }

    fn square() -> FaceModel {
        let mut face = FaceModel::new("sq");
        face.meshes.push(FaceMesh {
            name: "sq".into(),
            transform: None,
            mesh: Mesh::from_triangles(
                "sq",
                vec![Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y],
                &[[0, 1, 2], [0, 2, 3]],
            ),
            color: None,
        });
        face
    }

    #[test]
    fn feature_points_bound_or_matched() {
        let mut face = square();
        let mut set = FeaturePointSet::new();
        set.insert(FeaturePoint::bound(
            fp("2.1"),
            VertexBinding {
                mesh: Some("sq.obj".into()),
                vertices: vec![1, 2],
            },
        ));
        set.insert(FeaturePoint::at(fp("9.3"), Vec3::new(0.1, 0.9, 0.0)));
        let m = attach_feature_points(&mut face, set, &["sq.obj"]).unwrap();
        assert_eq!(
            face.feature_points.position(fp("2.1")),
            Some(Vec3::new(1.0, 0.5, 0.0))
        );
        assert_eq!(m.len(), 1);
        assert_eq!((m[0].id, m[0].vertex), (fp("9.3"), 3));
        assert!((m[0].distance - 0.141_421).abs() < 1e-4);
        assert_eq!(face.fp_vertex(fp("9.3")), Some((0, 3)));
        assert_eq!(face.fp_vertex(fp("2.1")), Some((0, 1)));

        // Out-of-range vertex and unknown mesh names are errors.
        let mut set = FeaturePointSet::new();
        set.insert(FeaturePoint::bound(fp("2.1"), VertexBinding::vertex(9)));
        let e = attach_feature_points(&mut square(), set, &[]).unwrap_err();
        assert!(e.to_string().contains("vertex 9"), "{e}");
        let mut set = FeaturePointSet::new();
        set.insert(FeaturePoint::bound(
            fp("2.1"),
            VertexBinding {
                mesh: Some("other".into()),
                vertices: vec![0],
            },
        ));
        let e = attach_feature_points(&mut square(), set, &[]).unwrap_err();
        assert!(e.to_string().contains("`other`"), "{e}");
    }

    #[test]
    fn merged_mesh_places_meshes_and_spans() {
        let face = FaceModel::from_synth(&crate::synth::alma());
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
        let face = FaceModel::from_synth(&crate::synth::alma());
        for name in ["a.wrl", "a.wrl.gz", "a.wrz"] {
            let p = dir.path().join(name);
            write_face(&p, &face).unwrap();
            let (back, report) = read_face(&p, None).unwrap();
            assert!(report.diagnostics.is_empty(), "{name}");
            assert!(back == face, "{name}");
        }
        // OBJ: geometry only, read → write → read equal.
        let p = dir.path().join("a.obj");
        write_face(&p, &face).unwrap();
        let (obj, _) = read_face(&p, None).unwrap();
        let q = dir.path().join("b.obj");
        write_face(&q, &obj).unwrap();
        let (again, _) = read_face(&q, None).unwrap();
        assert_eq!(again.meshes[0].mesh.positions, obj.meshes[0].mesh.positions);
        assert_eq!(again.meshes[0].mesh.polygons, obj.meshes[0].mesh.polygons);
        assert_eq!(obj.vertex_count(), face.vertex_count());
        assert!(write_face(&dir.path().join("a.txt"), &face).is_err());
    }
}
