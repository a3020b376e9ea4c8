//! Any face with a FAT as an ARKit-named blendshape rig: 52-or-fewer morph targets named as
//! Apple spells them (`jawOpen`, `eyeBlinkLeft`, ...), ready for tools that drive ARKit names.
//!
//! Each ARKit shape's **recipe** is its rows of the amplitude table
//! ([`super::arkit_amplitudes`], FAP values in FAP units measured on a real rig): the shape is
//! the face posed with those FAPs at those values ([`FaceModel::pose`], the one posing rule),
//! minus the neutral, in the face frame. Because FAP values are relative to the face's own
//! FAP units, the recipe fits any face.
//!
//! The rig's meshes are the face's meshes in face-frame coordinates (transforms applied, so a
//! FAT that turns an eyeball transform shows as vertex motion). A shape **gets no target**
//! (rather than an empty one) when the table has no recipe for it (`cheekPuff`, `mouthClose`,
//! the `eyeLook*` shapes: ICT-FaceKit moves no eyeball with them) or when the face has no
//! table for any of its FAPs; the report lists those shapes and why.

use serde::Serialize;

use super::arkit_amplitudes::Amplitude;
use super::arkit_names::ARKIT_SHAPES;
use super::{sparse_delta, BlendShape, Rig, RigMesh};
use crate::error::Result;
use crate::face::FaceModel;
use crate::fat::eval::Activation;
use crate::fat::TableKey;

/// An ARKit shape without a target, and why.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct UnmappedShape {
    /// ARKit name.
    pub shape: String,
    /// Why it has no target.
    pub reason: String,
}

/// What [`face_to_arkit_rig`] made.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct ArkitExportReport {
    /// ARKit shapes with a target, in [`ARKIT_SHAPES`] order.
    pub targets: Vec<String>,
    /// ARKit shapes without one.
    pub unmapped: Vec<UnmappedShape>,
    /// `shape: FAP` recipe parts the face has no table for (the rest of the recipe is used).
    pub missing_tables: Vec<String>,
}

/// `face` as a rig of ARKit-named shapes made with `amplitudes` (module docs).
pub fn face_to_arkit_rig(
    face: &FaceModel,
    amplitudes: &[Amplitude],
) -> Result<(Rig, ArkitExportReport)> {
    face.check_structure()?;
    let neutral = face.neutral_world_positions();
    let meshes: Vec<RigMesh> = face
        .meshes
        .iter()
        .zip(&neutral)
        .map(|(m, world)| {
            let mut mesh = m.mesh.clone();
            mesh.positions = world.clone();
            if m.transform.is_some() {
                // Normals were in the mesh's own frame; the writer leaves them out.
                mesh.normals.clear();
                mesh.normal_polygons = None;
            }
            RigMesh {
                name: m.name.clone(),
                mesh,
            }
        })
        .collect();
    let mut report = ArkitExportReport::default();
    let mut shapes = Vec::new();
    let mut evaluator = face.evaluator()?;
    let mut output = evaluator.output();
    for name in ARKIT_SHAPES {
        let recipe: Vec<&Amplitude> = amplitudes.iter().filter(|a| a.shape == name).collect();
        if recipe.is_empty() {
            report.unmapped.push(UnmappedShape {
                shape: name.into(),
                reason: "no FAP recipe in the amplitude table".into(),
            });
            continue;
        }
        let mut acts = Vec::new();
        for a in &recipe {
            let key = TableKey::LowLevel(a.fap);
            if face.fat.table(key).is_some() {
                acts.push(Activation {
                    key,
                    value: a.value,
                });
            } else {
                report
                    .missing_tables
                    .push(format!("{name}: {}", a.fap.name()));
            }
        }
        if acts.is_empty() {
            report.unmapped.push(UnmappedShape {
                shape: name.into(),
                reason: format!(
                    "the face has no table for {}",
                    recipe
                        .iter()
                        .map(|a| a.fap.name())
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
            });
            continue;
        }
        let posed = face.pose_with(&mut evaluator, &mut output, &acts);
        let deltas: Vec<_> = posed
            .iter()
            .zip(&neutral)
            .enumerate()
            .map(|(mi, (p, n))| sparse_delta(mi, n, p))
            .filter(|d| !d.vertices.is_empty())
            .collect();
        if deltas.is_empty() {
            report.unmapped.push(UnmappedShape {
                shape: name.into(),
                reason: "the face's tables for its FAPs move nothing".into(),
            });
            continue;
        }
        report.targets.push(name.into());
        shapes.push(BlendShape {
            name: name.into(),
            default_weight: 0.0,
            deltas,
        });
    }
    let rig = Rig {
        name: face.name.clone(),
        meshes,
        shapes,
        warnings: Vec::new(),
        source: None,
    };
    Ok((rig, report))
}

/// `rig` with every position and offset multiplied by `k` (model units → metres for glTF).
pub fn scale_rig(rig: &mut Rig, k: f32) {
    for m in &mut rig.meshes {
        for p in &mut m.mesh.positions {
            *p *= k;
        }
    }
    for s in &mut rig.shapes {
        for d in &mut s.deltas {
            for o in &mut d.offsets {
                *o *= k;
            }
        }
    }
}

/// Writes `face` as ARKit-named blend shapes to `path` (`.glb` or `.gltf` by extension) with
/// the bundled amplitudes, in metres (`units` is the face's length unit, `None`: guessed),
/// atomically. Returns the report and the warnings (an unguessable unit).
pub fn write_arkit_gltf(
    path: impl AsRef<std::path::Path>,
    face: &FaceModel,
    units: Option<crate::face::units::LengthUnit>,
) -> Result<(ArkitExportReport, Vec<crate::error::Diagnostic>)> {
    if face.fat.tables.is_empty() {
        return Err(super::RigError::NoFat {
            face: face.name.clone(),
        }
        .into());
    }
    let amplitudes = super::arkit_amplitudes::arkit_amplitudes();
    let (mut rig, report) = face_to_arkit_rig(face, &amplitudes)?;
    let (k, unit_warning) = crate::face::units::metres_factor(face, units);
    let warnings = unit_warning
        .into_iter()
        .map(crate::error::Diagnostic::warning)
        .collect();
    scale_rig(&mut rig, k);
    super::gltf_write::write_rig_gltf(&rig, path.as_ref())?;
    Ok((report, warnings))
}
