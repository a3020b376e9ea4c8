//! A face, and optionally a FAP stream played on it, as **one self-contained HTML page**
//! (`fbakit view`).
//!
//! The page works offline from `file://` and makes no request at view time: everything is
//! inside the one file.
//! - three.js, vendored in `vendor/three/` at a pinned version (MIT licence beside it) and
//!   bundled into one minified script, and the viewer's own script, style and markup
//!   (`src/export/viewer/`), are embedded at build time with `include_str!`.
//! - The face is the animated glb of [`crate::export::gltf::export_face`], inlined as base64.
//! - A JSON [`ViewerModel`] tells the script what the glb cannot: the FAP sliders (grouped as
//!   the standard groups the FAPs, ranges in FAPU), how each FAP value becomes morph weights
//!   and node transforms, the per-frame FAP values of the stream, the feature points, the
//!   FAPU values and where to put the camera.
//!
//! ## Posing from FAP values
//! The page plays the glb's `play` animation with three.js's animation mixer, looping. When a
//! slider is moved, playback pauses and the script poses the face itself from the slider
//! values (which start at the current frame's values), with the same rules as the exporter:
//! - Morph weights: target `(key, borders, interval j, span s)` gets
//!   `interval_weights(borders, P)[j] / s` for the key's value `P` (see the module docs of
//!   [`crate::export::gltf`]).
//! - Transforms: each `FaceDefTransform` entry of a key at value `P` composes a rotation of
//!   `angle × P` about its axis before the accumulated one, and adds `translation × P` and
//!   `scale × P`; the node then gets rotation `ΔR · r`, translation `t + Δt + c` and scale
//!   `s + Δs` (node **A** of the exporter). Entries are listed in table-slot order (FAPs 3..68,
//!   visemes, expressions), the order the player evaluates activations in.
//!
//! A frame's value of a key is the sum of the frame's activations of that key (a viseme pair
//! selecting one viseme twice adds up), as the exporter sums their weights.

use std::collections::BTreeMap;
use std::path::Path;

use glam::{Quat, Vec3};
use serde::Serialize;

use crate::error::Result;
use crate::export::gltf::{export_face_with_units, FaceMorphs};
use crate::face::FaceModel;
use crate::fat::morph::default_value;
use crate::fat::{TableKey, TransformField, HIGH_LEVEL_FULL};
use crate::gltf::container::base64_encode_into;
use crate::gltf::GltfDocument;
use crate::player::AnimationFrame;
use crate::spec::{fap_group_content, Directionality, FapuKind};

/// The page skeleton; markers `<!--FBAKIT:...-->` are replaced by [`ViewerPage::new`].
const PAGE_TEMPLATE: &str = include_str!("viewer/page.html");
/// The page's style sheet.
const PAGE_STYLE: &str = include_str!("viewer/viewer.css");
/// The viewer script (plain JavaScript using the global `FBAKIT_THREE`).
const PAGE_SCRIPT: &str = include_str!("viewer/viewer.js");
/// three.js r187 + GLTFLoader + OrbitControls, bundled and minified (see `vendor/three/`).
const THREE_BUNDLE: &str = include_str!("../../vendor/three/three.min.js");

/// Largest number of stream frames whose FAP values the page embeds (about 2 h at 25 fps);
/// longer animations are refused rather than written as a page no browser can open.
pub const MAX_FRAMES: usize = 200_000;

/// A played stream to put in the page.
#[derive(Clone, Copy, Debug)]
pub struct ViewerAnimation<'a> {
    /// The played frames (from [`crate::player::Player::animation`]).
    pub frames: &'a [AnimationFrame],
    /// Their frame rate.
    pub fps: f64,
    /// A name for the stream, shown in the page (e.g. its file name).
    pub name: &'a str,
}

impl ViewerAnimation<'_> {
    /// Length in seconds: frames / fps, as the player reports it and the clip lasts.
    pub fn duration(&self) -> f64 {
        if self.fps > 0.0 {
            self.frames.len() as f64 / self.fps
        } else {
            0.0
        }
    }
}

/// What the page's script needs besides the glb; embedded as JSON.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ViewerModel {
    /// The face's name.
    pub face: String,
    /// The played stream, if any.
    pub stream: Option<StreamSummary>,
    /// The six FAP units of the face (empty when they cannot be measured).
    pub fapu: Vec<FapuRow>,
    /// Why the FAPU are missing, when they are.
    pub fapu_note: Option<String>,
    /// Where the camera looks.
    pub camera: CameraFrame,
    /// Feature points for the overlay.
    pub feature_points: Vec<FeaturePointMarker>,
    /// FAP sliders, grouped as the standard groups FAPs (groups 1..=10, only keys with a
    /// table; empty groups left out).
    pub groups: Vec<FapGroup>,
    /// Morph targets of each glTF mesh node and how weights follow from FAP values.
    pub meshes: Vec<MeshMorphs>,
    /// Transforms the FAT drives and how.
    pub transforms: Vec<TransformRig>,
    /// Per key with a table that the stream moves: its value at every frame.
    pub tracks: Vec<KeyTrack>,
    /// Eyeballs to paint an iris and pupil on (the exported glb gives a mesh one material).
    pub eyes: Vec<EyePaint>,
    /// Eye layers resting on the lids that the page leaves out
    /// ([`crate::clone::face::lid_resting_layers`]): transparent in the head's own materials,
    /// opaque in the glb's one material per mesh, they would close the eyes.
    pub hidden: Vec<HiddenLayer>,
}

/// Vertices of a glTF mesh node whose triangles the page does not draw.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct HiddenLayer {
    /// glTF node index of the mesh.
    pub node: u32,
    /// The vertices, ascending: a triangle with every corner among them is left out.
    pub vertices: Vec<u32>,
}

/// An eyeball of a glTF mesh node and which of its triangles are iris and pupil (by their
/// centres, as pictures paint them: [`crate::export::picture::eyes`]); the script gives them
/// their own materials.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct EyePaint {
    /// glTF node index of the mesh holding it.
    pub node: u32,
    /// Every vertex of the eyeball, ascending.
    pub vertices: Vec<u32>,
    /// Its iris triangles (corner vertices, any order).
    pub iris: Vec<[u32; 3]>,
    /// Its pupil triangles.
    pub pupil: Vec<[u32; 3]>,
    /// Colours (sRGB) of the eye white, the iris and the pupil.
    pub colours: [[f32; 3]; 3],
}

/// The stream shown by the page.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct StreamSummary {
    /// Its name.
    pub name: String,
    /// Frame rate.
    pub fps: f64,
    /// Number of frames.
    pub frames: usize,
    /// The animation's length in seconds: frames / fps (the clip holds the last frame for
    /// one frame, like every glTF clip fbakit writes).
    pub duration: f64,
}

/// One FAP unit of the face.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FapuRow {
    /// `IRISD`, `ES`, `ENS`, `MNS`, `MW` or `AU`.
    pub name: &'static str,
    /// The neutral distance (`None` for AU).
    pub distance: Option<f64>,
    /// The unit: distance / 1024 in model units, radians for AU.
    pub unit: f64,
}

/// A sphere around the face the camera is framed on (face frame, model units).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct CameraFrame {
    /// Centre.
    pub target: [f32; 3],
    /// Radius.
    pub radius: f32,
    /// Half the size of the box around the same points along the face's own x, y, z (the
    /// camera fits the x-y rectangle to the view, in front of the box).
    pub half_extent: [f32; 3],
    /// The face's own axes in its file: `right` (towards the face's left, x), `up` (y) and
    /// `front` (out of the face, z) — the file's own for a face modelled upright, turned for
    /// one modelled facing −z ([`crate::fdp::FeaturePointSet::upright_turn`]); the camera
    /// starts in front of the face and keeps `up` up.
    pub axes: [[f32; 3]; 3],
}

/// A feature point in the overlay.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FeaturePointMarker {
    /// Label, e.g. `8.1`.
    pub id: String,
    /// Where on the face the standard puts it.
    pub description: &'static str,
    /// Neutral position in the face frame.
    pub position: [f32; 3],
    /// glTF node of the mesh it is bound to, so the marker follows the animation.
    pub node: Option<u32>,
    /// The bound vertices of that mesh (their mean is the point).
    pub vertices: Vec<u32>,
}

/// One standard FAP group and its sliders.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FapGroup {
    /// Group number 1..=10.
    pub number: u8,
    /// What the group moves, e.g. `eyebrows`.
    pub content: &'static str,
    /// Its keys with a table.
    pub keys: Vec<KeyControl>,
}

/// A slider for one table key.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct KeyControl {
    /// The key's name ([`TableKey::name`]: `open_jaw`, `viseme_7`, `joy`).
    pub key: String,
    /// What the slider shows, e.g. `3 open_jaw` or `viseme 7 (t,d)`.
    pub label: String,
    /// The FAPU its value is in (`None` for visemes and expressions, on the 0..63 scale).
    pub fapu: Option<&'static str>,
    /// Slider minimum.
    pub min: f64,
    /// Slider maximum.
    pub max: f64,
}

/// The morph targets of one glTF mesh node.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct MeshMorphs {
    /// glTF node index.
    pub node: u32,
    /// The face mesh's name.
    pub mesh: String,
    /// Its targets in glTF order.
    pub targets: Vec<TargetWeighting>,
}

/// How one morph target's weight follows from its key's value (see the module docs).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TargetWeighting {
    /// The key's name.
    pub key: String,
    /// Interval borders of its `FaceDefMesh` entry.
    pub borders: Vec<f64>,
    /// Which interval.
    pub interval: usize,
    /// The value span the target shows.
    pub span: f64,
}

/// A transform node the FAT drives.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TransformRig {
    /// glTF node index (node **A** of the exporter).
    pub node: u32,
    /// The transform's name.
    pub name: String,
    /// Neutral rotation `r` (x, y, z, w).
    pub rotation: [f32; 4],
    /// Neutral node translation `t + c`.
    pub translation: [f32; 3],
    /// Neutral scale `s`.
    pub scale: [f32; 3],
    /// The FAT entries driving it, in evaluation order.
    pub entries: Vec<TransformEntry>,
}

/// One `FaceDefTransform` entry, per unit of its key's value.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TransformEntry {
    /// The key's name.
    pub key: String,
    /// Which field it drives.
    pub field: TransformField,
    /// Unit rotation axis.
    pub axis: [f32; 3],
    /// Radians per unit.
    pub angle: f32,
    /// Translation per unit.
    pub translation: [f32; 3],
    /// Scale change per unit.
    pub scale: [f32; 3],
}

/// A key's value at every frame of the stream.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct KeyTrack {
    /// The key's name.
    pub key: String,
    /// One value per frame.
    pub values: Vec<f32>,
}

/// A written-out viewer page.
#[derive(Clone, Debug)]
pub struct ViewerPage {
    /// The whole HTML document.
    pub html: String,
    /// Size of the embedded glb in bytes (before base64).
    pub glb_bytes: usize,
    /// What could not be shown exactly (exporter warnings, missing FAPU).
    pub warnings: Vec<crate::error::Diagnostic>,
}

impl ViewerPage {
    /// The page for `face`, playing `animation` if given.
    ///
    /// Errors: the face's structure or FAT is inconsistent (as for the glTF export), the FAT
    /// has non-finite numbers, or the animation is longer than [`MAX_FRAMES`].
    pub fn new(face: &FaceModel, animation: Option<&ViewerAnimation<'_>>) -> Result<ViewerPage> {
        if let Some(a) = animation {
            if a.frames.len() > MAX_FRAMES {
                return Err(super::ExportError::TooManyViewerFrames {
                    frames: a.frames.len(),
                    limit: MAX_FRAMES,
                }
                .into());
            }
        }
        // The page places the camera, the feature points and the FAPU in the face's own
        // units, so the embedded glb keeps them unscaled (factor 1, as if in metres).
        let export = export_face_with_units(
            face,
            animation.map(|a| a.frames),
            Some(crate::face::units::LengthUnit::M),
        )?;
        let mut warnings = export.warnings;
        let model = ViewerModel::new(face, &export.document, animation)?;
        if let Some(note) = &model.fapu_note {
            warnings.push(crate::error::Diagnostic::warning(note.clone()));
        }
        let glb = export.document.to_glb()?;
        let json = serde_json::to_string(&model)
            .map_err(|e| crate::error::EncodeError::new("the viewer data", e))?;
        let html = assemble(&face.name, &json, &glb)?;
        Ok(ViewerPage {
            html,
            glb_bytes: glb.len(),
            warnings,
        })
    }

    /// Writes the page atomically.
    pub fn write(&self, path: &Path) -> Result<()> {
        crate::io::write_atomic(path, self.html.as_bytes())
    }
}

impl ViewerModel {
    /// The data for `face` exported as `document` (whose nodes are found by name, as
    /// [`crate::export::gltf::export_face`] names them), with `animation` if given.
    pub fn new(
        face: &FaceModel,
        document: &GltfDocument,
        animation: Option<&ViewerAnimation<'_>>,
    ) -> Result<ViewerModel> {
        let morphs = FaceMorphs::new(face)?;
        let nodes = &document.root.nodes;
        let mesh_node = |name: &str| {
            nodes
                .iter()
                .position(|n| n.mesh.is_some() && n.name.as_deref() == Some(name))
                .map(|i| i as u32)
        };
        let transform_node = |name: &str| {
            nodes
                .iter()
                .position(|n| n.mesh.is_none() && n.name.as_deref() == Some(name))
                .map(|i| i as u32)
        };

        let mut meshes = Vec::new();
        for (mi, m) in face.meshes.iter().enumerate() {
            let Some(node) = mesh_node(&m.name) else {
                continue;
            };
            let targets = morphs.meshes[mi]
                .iter()
                .map(|p| {
                    finite(&p.borders, &p.key)?;
                    Ok(TargetWeighting {
                        key: p.key.name(),
                        borders: p.borders.clone(),
                        interval: p.interval,
                        span: p.span,
                    })
                })
                .collect::<Result<Vec<_>>>()?;
            meshes.push(MeshMorphs {
                node,
                mesh: m.name.clone(),
                targets,
            });
        }

        let mut rigs: BTreeMap<usize, Vec<(usize, TransformEntry)>> = BTreeMap::new();
        for table in &face.fat.tables {
            let slot = table.key.slot().unwrap_or(usize::MAX);
            for e in &table.transforms {
                let Some(ti) = face.transform_index(&e.transform) else {
                    return Err(crate::fat::FatError::UnknownTransform {
                        key: table.key,
                        transform: e.transform.clone(),
                    }
                    .into());
                };
                let axis = e.rotation_axis.try_normalize().unwrap_or(Vec3::Z);
                let numbers = [
                    e.rotation_angle,
                    e.translation.x,
                    e.translation.y,
                    e.translation.z,
                    e.scale.x,
                    e.scale.y,
                    e.scale.z,
                ];
                if numbers.iter().any(|v| !v.is_finite()) {
                    return Err(super::ExportError::NonFiniteTransform {
                        key: table.key,
                        transform: e.transform.clone(),
                    }
                    .into());
                }
                rigs.entry(ti).or_default().push((
                    slot,
                    TransformEntry {
                        key: table.key.name(),
                        field: e.field,
                        axis: axis.to_array(),
                        angle: e.rotation_angle,
                        translation: e.translation.to_array(),
                        scale: e.scale.to_array(),
                    },
                ));
            }
        }
        let mut transforms = Vec::new();
        for (ti, mut entries) in rigs {
            let t = &face.transforms[ti];
            let Some(node) = transform_node(&t.name) else {
                continue;
            };
            // Stable: tables of one key keep their file order.
            entries.sort_by_key(|(slot, _)| *slot);
            let r: Quat = t.rotation.normalize();
            transforms.push(TransformRig {
                node,
                name: t.name.clone(),
                rotation: r.to_array(),
                translation: (t.translation + t.center).to_array(),
                scale: t.scale.to_array(),
                entries: entries.into_iter().map(|(_, e)| e).collect(),
            });
        }

        let tracks = animation.map_or_else(Vec::new, |a| key_tracks(face, a.frames));
        let groups = fap_groups(face, &tracks);
        let (fapu, fapu_note) = match face.fapu() {
            Ok(f) => (
                FapuKind::ALL
                    .into_iter()
                    .map(|k| FapuRow {
                        name: k.abbreviation(),
                        distance: f.distance(k),
                        unit: f.unit(k),
                    })
                    .collect(),
                None,
            ),
            Err(e) => (Vec::new(), Some(format!("FAP units not shown: {e}"))),
        };
        let stream = animation.map(|a| StreamSummary {
            name: a.name.to_string(),
            fps: a.fps,
            frames: a.frames.len(),
            duration: a.duration(),
        });
        Ok(ViewerModel {
            face: face.name.clone(),
            stream,
            fapu,
            fapu_note,
            camera: camera_frame(face),
            feature_points: feature_point_markers(face, &mesh_node),
            groups,
            meshes,
            transforms,
            tracks,
            eyes: eye_paints(face, &mesh_node),
            hidden: hidden_layers(face, &mesh_node),
        })
    }

    /// Names of every key that has a slider.
    pub fn slider_keys(&self) -> Vec<&str> {
        self.groups
            .iter()
            .flat_map(|g| g.keys.iter().map(|k| k.key.as_str()))
            .collect()
    }
}

fn finite(borders: &[f64], key: &TableKey) -> Result<()> {
    if borders.iter().all(|b| b.is_finite()) {
        Ok(())
    } else {
        Err(super::ExportError::NonFiniteBorders { key: *key }.into())
    }
}

/// Per key with a table that is non-zero in some frame, its summed activation value per frame.
fn key_tracks(face: &FaceModel, frames: &[AnimationFrame]) -> Vec<KeyTrack> {
    let keys = face.fat.keys();
    let mut values: BTreeMap<TableKey, Vec<f32>> = keys
        .iter()
        .map(|&k| (k, vec![0.0f32; frames.len()]))
        .collect();
    for (i, f) in frames.iter().enumerate() {
        for a in &f.activations {
            if !a.value.is_finite() {
                continue;
            }
            if let Some(v) = values.get_mut(&a.key) {
                v[i] += a.value as f32;
            }
        }
    }
    values
        .into_iter()
        .filter(|(_, v)| v.iter().any(|&x| x != 0.0))
        .map(|(k, values)| KeyTrack {
            key: k.name(),
            values,
        })
        .collect()
}

/// Sliders for every key with a table, by FAP group; ranges cover the table's borders, the
/// key's reference value and every value the stream takes.
fn fap_groups(face: &FaceModel, tracks: &[KeyTrack]) -> Vec<FapGroup> {
    let mut groups: BTreeMap<u8, Vec<KeyControl>> = BTreeMap::new();
    for key in face.fat.keys() {
        let seen = tracks
            .iter()
            .find(|t| t.key == key.name())
            .map_or(0.0, |t| {
                t.values
                    .iter()
                    .fold(0.0f64, |m, &v| m.max(f64::from(v).abs()))
            });
        let (group, control) = match key {
            TableKey::LowLevel(f) => {
                let info = f.info();
                let border = face
                    .fat
                    .tables
                    .iter()
                    .filter(|t| t.key == key)
                    .flat_map(|t| t.meshes.iter().flat_map(|m| m.interval_borders.iter()))
                    .filter(|b| b.is_finite())
                    .fold(0.0f64, |m, b| m.max(b.abs()));
                let range = default_value(key).max(border).max(seen.ceil());
                let min = if info.directionality == Some(Directionality::Unidirectional) {
                    0.0
                } else {
                    -range
                };
                (
                    info.group,
                    KeyControl {
                        key: key.name(),
                        label: format!("{} {}", f.number(), f.name()),
                        fapu: info.fapu.map(|k| k.abbreviation()),
                        min,
                        max: range,
                    },
                )
            }
            TableKey::Viseme(v) => (
                1,
                KeyControl {
                    key: key.name(),
                    label: format!("viseme {} ({})", v.number(), v.label()),
                    fapu: None,
                    min: 0.0,
                    max: HIGH_LEVEL_FULL.max(seen.ceil()),
                },
            ),
            TableKey::Expression(e) => (
                1,
                KeyControl {
                    key: key.name(),
                    label: e.name().to_string(),
                    fapu: None,
                    min: 0.0,
                    max: HIGH_LEVEL_FULL.max(seen.ceil()),
                },
            ),
        };
        groups.entry(group).or_default().push(control);
    }
    groups
        .into_iter()
        .map(|(number, keys)| FapGroup {
            number,
            content: fap_group_content(number).unwrap_or("other"),
            keys,
        })
        .collect()
}

/// A sphere around the feature points (the whole head from hairline to chin and ear to
/// ear), or around all vertices when there are fewer than two.
fn camera_frame(face: &FaceModel) -> CameraFrame {
    // Measured in the face's own axes (a face modelled turned is measured stood up).
    let turn = face.feature_points.upright_turn();
    let up = |p: Vec3| turn.map_or(p, |t| t * p);
    let down = |p: Vec3| turn.map_or(p, |t| t.transpose() * p);
    let mut points: Vec<Vec3> = face
        .feature_points
        .iter()
        .filter_map(|p| p.position)
        .filter(|p| p.is_finite())
        .map(up)
        .collect();
    if points.len() < 2 {
        let frames = face.frames();
        points = face
            .meshes
            .iter()
            .enumerate()
            .flat_map(|(i, m)| {
                let w = frames.meshes[i];
                m.mesh.positions.iter().map(move |&p| w.transform_point3(p))
            })
            .filter(|p| p.is_finite())
            .map(up)
            .collect();
    }
    let axes = [Vec3::X, Vec3::Y, Vec3::Z].map(|a| down(a).to_array());
    let Some(first) = points.first().copied() else {
        return CameraFrame {
            target: [0.0; 3],
            radius: 1.0,
            half_extent: [1.0; 3],
            axes,
        };
    };
    let (lo, hi) = points
        .iter()
        .fold((first, first), |(lo, hi), &p| (lo.min(p), hi.max(p)));
    let radius = ((hi - lo).length() * 0.5).max(f32::EPSILON);
    CameraFrame {
        target: down((lo + hi) * 0.5).to_array(),
        radius,
        half_extent: ((hi - lo) * 0.5).max(Vec3::splat(radius * 0.01)).to_array(),
        axes,
    }
}

/// The eye layers of `face` resting on its lids, on their glTF nodes (see [`HiddenLayer`]).
fn hidden_layers(face: &FaceModel, mesh_node: &dyn Fn(&str) -> Option<u32>) -> Vec<HiddenLayer> {
    crate::clone::face::lid_resting_layers(face)
        .into_iter()
        .filter_map(|l| {
            Some(HiddenLayer {
                node: mesh_node(&face.meshes[l.mesh].name)?,
                vertices: l.vertices,
            })
        })
        .collect()
}

/// The eyeballs of `face` on their glTF nodes (see [`EyePaint`]).
fn eye_paints(face: &FaceModel, mesh_node: &dyn Fn(&str) -> Option<u32>) -> Vec<EyePaint> {
    use crate::face::parts::FacePart;
    let neutral = face.neutral_world_positions();
    crate::export::picture::eyes::eyeballs(face, &neutral)
        .into_iter()
        .filter_map(|e| {
            let node = mesh_node(&face.meshes[e.mesh].name)?;
            let positions = &neutral[e.mesh];
            let (mut iris, mut pupil) = (Vec::new(), Vec::new());
            for t in face.meshes[e.mesh].mesh.triangles() {
                if !t.iter().all(|&v| e.contains(v)) {
                    continue;
                }
                let c = t.iter().map(|&v| positions[v as usize]).sum::<Vec3>() / 3.0;
                match e.part_at(c) {
                    FacePart::Pupil => pupil.push(t),
                    FacePart::Iris => iris.push(t),
                    _ => {}
                }
            }
            Some(EyePaint {
                node,
                iris,
                pupil,
                vertices: e.vertices,
                colours: [
                    FacePart::EyeWhite.default_colour(),
                    FacePart::Iris.default_colour(),
                    FacePart::Pupil.default_colour(),
                ],
            })
        })
        .collect()
}

fn feature_point_markers(
    face: &FaceModel,
    mesh_node: &dyn Fn(&str) -> Option<u32>,
) -> Vec<FeaturePointMarker> {
    let frames = face.frames();
    face.feature_points
        .iter()
        .filter_map(|p| {
            let bound = p.binding.as_ref().and_then(|b| {
                let mi = match &b.mesh {
                    Some(name) => face.mesh_index(name)?,
                    None if face.meshes.len() == 1 => 0,
                    None => return None,
                };
                let count = face.meshes[mi].mesh.vertex_count();
                if b.vertices.is_empty() || b.vertices.iter().any(|&v| v as usize >= count) {
                    return None;
                }
                Some((mi, b.vertices.clone()))
            });
            let position = p.position.or_else(|| {
                let (mi, vs) = bound.as_ref()?;
                let sum: Vec3 = vs
                    .iter()
                    .map(|&v| face.vertex_world(&frames, *mi, v).unwrap_or(Vec3::ZERO))
                    .sum();
                Some(sum / vs.len() as f32)
            })?;
            if !position.is_finite() {
                return None;
            }
            let (node, vertices) = match bound {
                Some((mi, vs)) => match mesh_node(&face.meshes[mi].name) {
                    Some(n) => (Some(n), vs),
                    None => (None, Vec::new()),
                },
                None => (None, Vec::new()),
            };
            Some(FeaturePointMarker {
                id: p.id.to_string(),
                description: p.id.info().description,
                position: position.to_array(),
                node,
                vertices,
            })
        })
        .collect()
}

/// The page: template with style, three.js, data, glb and script filled in.
fn assemble(title: &str, json: &str, glb: &[u8]) -> Result<String> {
    let mut glb64 = String::with_capacity(glb.len().div_ceil(3) * 4);
    base64_encode_into(glb, &mut glb64);
    // Inside <script>, only `</script` (any case) and `<!--` end or confuse the element; JSON
    // escapes `<` as \u003c, and the scripts are checked by tests to contain neither.
    let json = json.replace('<', "\\u003c");
    let parts: [(&str, &str); 6] = [
        ("<!--FBAKIT:TITLE-->", &escape_html(title)),
        ("<!--FBAKIT:STYLE-->", PAGE_STYLE),
        ("<!--FBAKIT:DATA-->", &json),
        ("<!--FBAKIT:GLB-->", &glb64),
        ("<!--FBAKIT:THREE-->", THREE_BUNDLE),
        ("<!--FBAKIT:SCRIPT-->", PAGE_SCRIPT),
    ];
    let mut html = String::with_capacity(
        PAGE_TEMPLATE.len() + parts.iter().map(|(_, v)| v.len()).sum::<usize>(),
    );
    let mut rest = PAGE_TEMPLATE;
    // Markers appear in the template in this order, each once (a unit test checks).
    for (marker, value) in parts {
        let Some(at) = rest.find(marker) else {
            return Err(super::ExportError::TemplateMarker {
                marker: marker.to_string(),
            }
            .into());
        };
        html.push_str(&rest[..at]);
        html.push_str(value);
        rest = &rest[at + marker.len()..];
    }
    html.push_str(rest);
    Ok(html)
}

fn escape_html(s: &str) -> String {
    let mut o = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => o.push_str("&amp;"),
            '<' => o.push_str("&lt;"),
            '>' => o.push_str("&gt;"),
            '"' => o.push_str("&quot;"),
            _ => o.push(c),
        }
    }
    o
}

#[cfg(test)]
mod tests;
