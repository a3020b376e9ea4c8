//! A face read from glTF, written back into its own document with ARKit-named morph targets.
//!
//! The 52 ARKit blend shapes are made as [`crate::rig::arkit_export::face_to_arkit_rig`]
//! makes them (each the face posed with its FAP recipe), then patched into the user's
//! document like the FAT targets of [`super::gltf_patch`]: offsets in each primitive's own
//! space through the rest pose it was read with, every primitive of a mesh carrying the same
//! target list (zeros where it does not move), the file's units and everything else kept.
//!
//! The user's own targets stay. A shape whose name the mesh already uses gets `_fbakit`
//! appended (with a warning), unless fbakit wrote that target itself on an earlier run
//! (recorded in the mesh's `extras.fbakit_arkit`): then it is replaced, so exporting twice
//! gives one set. The scene carries the face's feature points and FAPU
//! ([`crate::face::gltf_fat`]), so the file reads back with them.

use std::collections::BTreeMap;

use glam::Vec3;
use serde_json::{json, Map};

use crate::error::{Diagnostic, Result};
use crate::face::FaceModel;
use crate::gltf::patch::{GltfPatch, MeshPatch, PatchedGltf, SparseOffsets};
use crate::gltf::source::GltfSource;
use crate::rig::arkit_export::{face_to_arkit_rig, ArkitExportReport};

/// The mesh extras key listing the ARKit targets fbakit wrote.
pub const RECORD_KEY: &str = "fbakit_arkit";

/// A document with ARKit targets and what was made.
#[derive(Clone, Debug)]
pub struct ArkitPatchExport {
    /// The document to write.
    pub document: PatchedGltf,
    /// Which shapes got a target and which did not.
    pub arkit: ArkitExportReport,
    /// Morph targets added or replaced over all meshes.
    pub morph_targets: usize,
    /// Things that could not be written exactly.
    pub warnings: Vec<Diagnostic>,
}

/// `face` (read from `source`) with its ARKit shapes patched into that document.
pub fn patch_arkit(face: &FaceModel, source: &GltfSource) -> Result<ArkitPatchExport> {
    if face.fat.tables.is_empty() {
        return Err(crate::rig::RigError::NoFat {
            face: face.name.clone(),
        }
        .into());
    }
    let amplitudes = crate::rig::arkit_amplitudes::arkit_amplitudes();
    let (rig, arkit) = face_to_arkit_rig(face, &amplitudes)?;
    let mut warnings = Vec::new();
    // Per glTF mesh: per primitive, per shape, vertex → local offset.
    type PerShape = BTreeMap<usize, BTreeMap<u32, Vec3>>;
    let mut meshes: BTreeMap<usize, BTreeMap<usize, PerShape>> = BTreeMap::new();
    let mut taken: BTreeMap<(usize, usize), &str> = BTreeMap::new();
    for (mi, fm) in face.meshes.iter().enumerate() {
        let moves = rig.shapes.iter().any(|s| s.delta(mi).is_some());
        let Some(part) = source.part(&fm.name) else {
            if moves {
                warnings.push(Diagnostic::warning(format!(
                    "mesh `{}` is not part of {}: its ARKit motion is not written",
                    fm.name,
                    source.path.display()
                )));
            }
            continue;
        };
        if part.vertex_count != fm.mesh.vertex_count() {
            warnings.push(Diagnostic::warning(format!(
                "mesh `{}` has {} vertices but its glTF primitive has {}: its ARKit motion is \
                 not written",
                fm.name,
                fm.mesh.vertex_count(),
                part.vertex_count
            )));
            continue;
        }
        // A glTF mesh shown by several nodes gets one target list, from its first instance.
        if taken
            .insert((part.mesh, part.primitive), &fm.name)
            .is_some()
        {
            continue;
        }
        let prim = meshes
            .entry(part.mesh)
            .or_default()
            .entry(part.primitive)
            .or_default();
        for (si, shape) in rig.shapes.iter().enumerate() {
            let Some(d) = shape.delta(mi) else { continue };
            let slot = prim.entry(si).or_default();
            for (&v, &o) in d.vertices.iter().zip(&d.offsets) {
                *slot.entry(v).or_insert(Vec3::ZERO) += part.rest.to_local(v as usize, o);
            }
        }
    }
    let mut patch = GltfPatch::default();
    let mut morph_targets = 0;
    for (&m, prims) in &meshes {
        // The shapes that move some primitive of this mesh, in ARKit order.
        let shapes: Vec<usize> = (0..rig.shapes.len())
            .filter(|si| prims.values().any(|p| p.contains_key(si)))
            .collect();
        if shapes.is_empty() {
            continue;
        }
        let existing = source.target_names(m);
        let ours = recorded(source, m);
        let mut names = Vec::with_capacity(shapes.len());
        let mut replaces = Vec::with_capacity(shapes.len());
        let mut clashes = Vec::new();
        for &si in &shapes {
            let shape = &rig.shapes[si].name;
            // fbakit's own target for this shape from an earlier run, under its name or a
            // suffixed one.
            let earlier = existing
                .iter()
                .position(|n| ours.contains(n) && n.trim_end_matches("_fbakit") == shape);
            if let Some(i) = earlier {
                names.push(existing[i].clone());
                replaces.push(Some(i));
                continue;
            }
            match existing.iter().position(|n| n == shape) {
                Some(_) => {
                    let mut name = format!("{shape}_fbakit");
                    while existing.contains(&name) {
                        name.push_str("_fbakit");
                    }
                    clashes.push(shape.clone());
                    names.push(name);
                    replaces.push(None);
                }
                None => {
                    names.push(shape.clone());
                    replaces.push(None);
                }
            }
        }
        if !clashes.is_empty() {
            warnings.push(Diagnostic::warning(format!(
                "{}: mesh {m} already has {} targets with ARKit names ({}{}): they are kept, \
                 fbakit's are named `<shape>_fbakit`",
                source.path.display(),
                clashes.len(),
                clashes[..clashes.len().min(3)].join(", "),
                if clashes.len() > 3 { ", …" } else { "" }
            )));
        }
        // fbakit's earlier ARKit targets that this run does not make again move nothing now.
        let zeroed: Vec<usize> = existing
            .iter()
            .enumerate()
            .filter(|(i, n)| ours.contains(*n) && !replaces.contains(&Some(*i)))
            .map(|(i, _)| i)
            .collect();
        morph_targets += shapes.len();
        let primitives = prims
            .iter()
            .map(|(&p, per_shape)| {
                let list = shapes
                    .iter()
                    .map(|si| {
                        let mut s = SparseOffsets::default();
                        for (&v, &o) in per_shape.get(si).into_iter().flatten() {
                            if o != Vec3::ZERO && o.is_finite() {
                                s.vertices.push(v);
                                s.offsets.push(o);
                            }
                        }
                        s
                    })
                    .collect();
                (p, list)
            })
            .collect();
        let mut extras = Map::new();
        let mut record: Vec<String> = ours.into_iter().filter(|n| !names.contains(n)).collect();
        record.extend(names.iter().cloned());
        extras.insert(RECORD_KEY.into(), json!(record));
        patch.meshes.insert(
            m,
            MeshPatch {
                names,
                replaces,
                zeroed,
                primitives,
                extras,
            },
        );
    }
    // Feature points and FAPU travel with the asset; the FAT's own records do not (its
    // tables are not these targets).
    let mut scene = crate::face::gltf_fat::scene_record(face, 1.0, &[]);
    if let Some(record) = scene
        .get_mut(crate::face::gltf_fat::KEY)
        .and_then(|r| r.as_object_mut())
    {
        record.retain(|k, _| matches!(k.as_str(), "version" | "featurePoints" | "fapu"));
    }
    patch.scene_extras = scene;
    let document = patch.apply(source)?;
    warnings.extend(document.warnings.iter().cloned());
    Ok(ArkitPatchExport {
        document,
        arkit,
        morph_targets,
        warnings,
    })
}

/// The ARKit targets fbakit recorded on mesh `m` by an earlier write.
fn recorded(source: &GltfSource, m: usize) -> Vec<String> {
    source.json["meshes"][m]["extras"][RECORD_KEY]
        .as_array()
        .map(|a| {
            a.iter()
                .filter_map(|v| v.as_str().map(str::to_string))
                .collect()
        })
        .unwrap_or_default()
}
