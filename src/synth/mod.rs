//! Deterministic procedural faces: bundled models made by fbakit's own code, for demos, tests on
//! a fresh machine, and as ground truth for FAT cloning (their FATs are exact by construction).
//!
//! [`generate`] builds a [`SynthFace`] from [`HeadParams`]; [`alma`] (about 8 000 skin vertices,
//! triangles) and [`bruno`] (about 27 000 skin vertices, quads, other proportions) are the two
//! presets. Everything is plain data (positions, polygons, feature points, a [`Fat`]); the face
//! layer converts it into its mesh model and VRML.
//!
//! ## Frame and scene graph
//! MPEG-4 frame: +x is the face's own left, +y up, +z towards the viewer; units are roughly
//! millimetres, origin near the centre of the head. The neutral face has the mouth closed (lips
//! touching along a slit whose upper and lower vertices coincide), eyelids tangent to the iris,
//! teeth closed and the tongue tip at the boundary between the teeth.
//!
//! Transforms (VRML `Transform` semantics): `head` (centre = FP 7.1) holds `skin`, `eye_l_tf`,
//! `eye_r_tf` (centres = eyeball centres), `teeth_upper_tf` and `jaw_tf` (centre = jaw hinge,
//! holding `teeth_lower` and `tongue`). **Every neutral transform is the identity** (zero
//! translation, no rotation, unit scale); only `center` is set. Mesh positions are therefore
//! face coordinates, whatever the hierarchy, and FAT transform entries animate about the
//! centres.
//!
//! ## Determinism
//! No randomness: geometry is a closed-form function of the parameters (f64 arithmetic, stored
//! as f32). The left half is computed and mirrored, so the faces are exactly symmetric.
//!
//! ## FAT
//! The private `fat` submodule documents how each FAP is defined. Every low-level FAP 3..=68 has a table;
//! translation FAPs move their feature point by exactly `P × FAPU × direction`.

mod fat;
mod highlevel;
mod parts;
mod skin;

use glam::Vec3;
use serde::{Deserialize, Serialize};

use glam::Quat;

use crate::face::{FaceMesh, FaceModel, FaceTransform};
use crate::fat::Fat;
use crate::fdp::fapu::{Fapu, FapuDistances};
use crate::fdp::{FeaturePoint, FeaturePointSet, VertexBinding};
use crate::mesh::{Mesh, Polygons};
use crate::spec::FeaturePointId;

pub use highlevel::{expression_faps, viseme_faps};

/// A VRML `Transform` of a synthetic face.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SynthTransform {
    /// `DEF` name.
    pub name: String,
    /// Index of the parent transform in [`SynthFace::transforms`] (`None` for the root).
    pub parent: Option<usize>,
    /// Neutral translation (always zero here).
    pub translation: Vec3,
    /// Neutral rotation axis (unit).
    pub rotation_axis: Vec3,
    /// Neutral rotation angle in radians (always zero here).
    pub rotation_angle: f32,
    /// Neutral scale (always one here).
    pub scale: Vec3,
    /// Centre of rotation and scaling, face coordinates.
    pub center: Vec3,
}

/// One `IndexedFaceSet` of a synthetic face.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SynthMesh {
    /// `DEF` name.
    pub name: String,
    /// Index of the parent transform in [`SynthFace::transforms`].
    pub transform: usize,
    /// Vertex positions in face coordinates (all neutral transforms are the identity).
    pub positions: Vec<Vec3>,
    /// Polygons (triangles or quads), counter-clockwise seen from outside.
    pub polygons: Vec<Vec<u32>>,
    /// Texture coordinates, one per vertex, if any (none of the presets has them).
    pub uvs: Option<Vec<[f32; 2]>>,
    /// Diffuse colour for rendering.
    pub colour: [f32; 3],
}

/// A feature point: a vertex of one mesh.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SynthFeaturePoint {
    /// Which point.
    pub id: FeaturePointId,
    /// Index in [`SynthFace::meshes`].
    pub mesh: usize,
    /// Vertex index in that mesh.
    pub vertex: u32,
    /// Its position (equal to the vertex position), face coordinates.
    pub position: Vec3,
}

/// A generated face model: scene graph, meshes, feature points and a full FAT.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SynthFace {
    /// Model name (`alma`, `bruno`, …).
    pub name: String,
    /// Transforms; index 0 is `head`, the root.
    pub transforms: Vec<SynthTransform>,
    /// Meshes; index 0 is `skin`.
    pub meshes: Vec<SynthMesh>,
    /// Feature points in the standard's label order (every point the face has).
    pub feature_points: Vec<SynthFeaturePoint>,
    /// Facial Animation Tables (mesh / transform names are the `DEF` names above).
    pub fat: Fat,
}

/// Polygon layout of the generated meshes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum PolygonStyle {
    /// Every grid quad split into two triangles, diagonals alternating in a checkerboard.
    Triangles,
    /// Grid quads kept as quads (pole caps are triangles).
    Quads,
}

/// Proportions and resolution of a generated head. Lengths are in model units (≈ mm),
/// heights are `y` values in the face frame (origin near the head centre).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct HeadParams {
    /// Model name.
    pub name: String,
    /// Skin grid columns around the head (a multiple of 4).
    pub columns: usize,
    /// Skin grid latitude intervals from the bottom pole to the top pole (even).
    pub rows: usize,
    /// How much the columns crowd onto the face (0 = uniform, < 1).
    pub column_crowding: f64,
    /// How much the rows crowd towards the middle height (0 = uniform, < 1).
    pub row_crowding: f64,
    /// Polygon layout.
    pub polygons: PolygonStyle,
    /// Half the head width (x radius).
    pub head_half_width: f64,
    /// Height of the skull top above the origin.
    pub head_top: f64,
    /// Depth of the head bottom (neck cut) below the origin.
    pub head_bottom: f64,
    /// Front z radius.
    pub face_depth: f64,
    /// Back z radius.
    pub back_depth: f64,
    /// x scale of the head at the chin relative to the cheeks (< 1 narrows the jaw).
    pub jaw_ratio: f64,
    /// Height of the eye centres.
    pub eye_y: f64,
    /// Distance between the eye centres (target for ES0).
    pub eye_separation: f64,
    /// Half width of the eye opening.
    pub eye_half_width: f64,
    /// Half height of the eye opening (≈ iris radius).
    pub eye_half_height: f64,
    /// Height of the eyebrows above the eye centres.
    pub brow_height: f64,
    /// Height of the bottom of the nose (FP 9.15).
    pub nose_bottom_y: f64,
    /// How far the nose tip stands out of the face.
    pub nose_length: f64,
    /// Half width of the nose at the nostrils.
    pub nose_half_width: f64,
    /// Height of the mouth slit.
    pub mouth_y: f64,
    /// Half the mouth width.
    pub mouth_half_width: f64,
    /// Height of the upper lip (slit to outer contour).
    pub upper_lip_height: f64,
    /// Height of the lower lip.
    pub lower_lip_height: f64,
    /// How far the lips stand out.
    pub lip_protrusion: f64,
    /// Height of the bottom of the chin (FP 2.1).
    pub chin_y: f64,
    /// Height of the ear centres.
    pub ear_y: f64,
    /// z of the ear centres.
    pub ear_z: f64,
    /// Half height of the ears.
    pub ear_half_height: f64,
    /// Half depth (front to back) of the ears.
    pub ear_half_depth: f64,
    /// How far the ears stand out sideways.
    pub ear_protrusion: f64,
    /// Height of the hairline on the forehead (FP 11.1).
    pub hairline_y: f64,
}

impl HeadParams {
    /// `alma`: a narrow, oval head, about 8 000 skin vertices in triangles.
    pub fn alma() -> HeadParams {
        HeadParams {
            name: "alma".into(),
            columns: 112,
            rows: 72,
            column_crowding: 0.5,
            row_crowding: 0.45,
            polygons: PolygonStyle::Triangles,
            head_half_width: 74.0,
            head_top: 112.0,
            head_bottom: 118.0,
            face_depth: 90.0,
            back_depth: 100.0,
            jaw_ratio: 0.72,
            eye_y: 30.0,
            eye_separation: 62.0,
            eye_half_width: 12.5,
            eye_half_height: 5.5,
            brow_height: 14.0,
            nose_bottom_y: -12.0,
            nose_length: 19.0,
            nose_half_width: 15.0,
            mouth_y: -33.0,
            mouth_half_width: 24.0,
            upper_lip_height: 8.0,
            lower_lip_height: 9.0,
            lip_protrusion: 4.0,
            chin_y: -78.0,
            ear_y: 12.0,
            ear_z: -8.0,
            ear_half_height: 30.0,
            ear_half_depth: 14.0,
            ear_protrusion: 11.0,
            hairline_y: 78.0,
        }
    }

    /// `bruno`: wider face, longer nose, wider mouth, eyes further apart, rounder skull, and
    /// a finer quad grid (about 27 000 skin vertices).
    pub fn bruno() -> HeadParams {
        HeadParams {
            name: "bruno".into(),
            columns: 232,
            rows: 116,
            column_crowding: 0.42,
            row_crowding: 0.38,
            polygons: PolygonStyle::Quads,
            head_half_width: 84.0,
            head_top: 106.0,
            head_bottom: 124.0,
            face_depth: 95.0,
            back_depth: 98.0,
            jaw_ratio: 0.82,
            eye_y: 26.0,
            eye_separation: 70.0,
            eye_half_width: 13.5,
            eye_half_height: 6.0,
            brow_height: 15.0,
            nose_bottom_y: -20.0,
            nose_length: 25.0,
            nose_half_width: 18.0,
            mouth_y: -42.0,
            mouth_half_width: 29.0,
            upper_lip_height: 7.0,
            lower_lip_height: 10.0,
            lip_protrusion: 5.0,
            chin_y: -88.0,
            ear_y: 6.0,
            ear_z: -6.0,
            ear_half_height: 33.0,
            ear_half_depth: 16.0,
            ear_protrusion: 13.0,
            hairline_y: 74.0,
        }
    }
}

/// Builds the face described by `params`. Deterministic: equal parameters give equal faces.
///
/// Panics only on nonsensical parameters (too few columns or rows for the features); the
/// presets are covered by tests.
pub fn generate(params: &HeadParams) -> SynthFace {
    let skin = skin::build(params);
    let parts = parts::build(params, &skin);
    let mut face = SynthFace {
        name: params.name.clone(),
        transforms: parts.transforms,
        meshes: Vec::new(),
        feature_points: Vec::new(),
        fat: Fat::default(),
    };
    face.meshes.push(SynthMesh {
        name: names::SKIN.into(),
        transform: 0,
        positions: skin.positions.iter().map(|p| p.as_vec3()).collect(),
        polygons: skin.polygons.clone(),
        uvs: None,
        colour: [0.88, 0.71, 0.60],
    });
    face.meshes.extend(parts.meshes);
    let mut fps: Vec<SynthFeaturePoint> = skin
        .feature_points
        .iter()
        .map(|&(id, v)| SynthFeaturePoint {
            id,
            mesh: 0,
            vertex: v,
            position: face.meshes[0].positions[v as usize],
        })
        .collect();
    for &(id, mesh, v) in &parts.feature_points {
        fps.push(SynthFeaturePoint {
            id,
            mesh,
            vertex: v,
            position: face.meshes[mesh].positions[v as usize],
        });
    }
    fps.sort_by_key(|f| f.id.ordinal());
    face.feature_points = fps;
    face.fat = fat::build(&face, &skin, &parts.info);
    highlevel::add_tables(&mut face);
    face
}

/// The `alma` preset face.
pub fn alma() -> SynthFace {
    generate(&HeadParams::alma())
}

/// The `bruno` preset face.
pub fn bruno() -> SynthFace {
    generate(&HeadParams::bruno())
}

/// `DEF` names used by every synthetic face.
pub mod names {
    /// Skin mesh.
    pub const SKIN: &str = "skin";
    /// Left eyeball mesh.
    pub const EYE_L: &str = "eye_l";
    /// Right eyeball mesh.
    pub const EYE_R: &str = "eye_r";
    /// Upper teeth mesh.
    pub const TEETH_UPPER: &str = "teeth_upper";
    /// Lower teeth mesh.
    pub const TEETH_LOWER: &str = "teeth_lower";
    /// Tongue mesh.
    pub const TONGUE: &str = "tongue";
    /// Root transform (centre FP 7.1).
    pub const HEAD_TF: &str = "head";
    /// Left eyeball transform.
    pub const EYE_L_TF: &str = "eye_l_tf";
    /// Right eyeball transform.
    pub const EYE_R_TF: &str = "eye_r_tf";
    /// Upper teeth transform.
    pub const TEETH_UPPER_TF: &str = "teeth_upper_tf";
    /// Jaw transform (lower teeth and tongue).
    pub const JAW_TF: &str = "jaw_tf";
}

impl SynthFace {
    /// This face as a [`FaceModel`] (meshes under their transforms, bound feature points,
    /// the FAT).
    pub fn to_face_model(&self) -> FaceModel {
        let face = self;
        let transforms = face
            .transforms
            .iter()
            .map(|t| FaceTransform {
                name: t.name.clone(),
                parent: t.parent,
                translation: t.translation,
                rotation: Quat::from_axis_angle(
                    t.rotation_axis.try_normalize().unwrap_or(Vec3::Z),
                    t.rotation_angle,
                ),
                scale: t.scale,
                scale_orientation: Quat::IDENTITY,
                center: t.center,
            })
            .collect();
        let meshes = face
            .meshes
            .iter()
            .map(|m| {
                let mut mesh = Mesh {
                    name: m.name.clone(),
                    positions: m.positions.clone(),
                    polygons: Polygons::from_lists(m.polygons.iter().map(|p| p.as_slice())),
                    ..Mesh::default()
                };
                if let Some(uvs) = &m.uvs {
                    mesh.uvs = uvs.iter().map(|&[u, v]| glam::Vec2::new(u, v)).collect();
                    mesh.uv_polygons = Some(mesh.polygons.clone());
                }
                FaceMesh {
                    name: m.name.clone(),
                    transform: Some(m.transform),
                    mesh,
                    color: Some(m.colour),
                }
            })
            .collect();
        let mut feature_points = FeaturePointSet::new();
        for fp in &face.feature_points {
            let mut point = FeaturePoint::at(fp.id, fp.position);
            point.binding = Some(VertexBinding {
                mesh: Some(face.meshes[fp.mesh].name.clone()),
                vertices: vec![fp.vertex],
            });
            feature_points.insert(point);
        }
        FaceModel {
            name: face.name.clone(),
            transforms,
            meshes,
            feature_points,
            fat: face.fat.clone(),
            scene: None,
            obj_source: None,
            obj_path: None,
            gltf_source: None,
        }
    }

    /// The feature point `id`, if the face has it.
    pub fn feature_point(&self, id: FeaturePointId) -> Option<&SynthFeaturePoint> {
        self.feature_points.iter().find(|f| f.id == id)
    }

    /// Index of the mesh named `name`.
    pub fn mesh_index(&self, name: &str) -> Option<usize> {
        self.meshes.iter().position(|m| m.name == name)
    }

    /// (DEF name, vertex count) of every mesh, as [`crate::fat::eval::FatEvaluator::new`] and
    /// [`crate::fat::validate::validate_fat`] take them.
    pub fn mesh_sizes(&self) -> Vec<(&str, usize)> {
        self.meshes
            .iter()
            .map(|m| (m.name.as_str(), m.positions.len()))
            .collect()
    }

    /// DEF names of every transform.
    pub fn transform_names(&self) -> Vec<&str> {
        self.transforms.iter().map(|t| t.name.as_str()).collect()
    }

    /// The FAP units measured on the feature points exactly as the standard defines them:
    /// IRISD0 = 3.1.y − 3.3.y, ES0 = 3.5.x − 3.6.x, ENS0 = 3.5.y − 9.15.y,
    /// MNS0 = 9.15.y − 2.2.y, MW0 = 8.3.x − 8.4.x.
    pub fn fapu(&self) -> Fapu {
        let p = |id: FeaturePointId| -> glam::DVec3 {
            self.feature_point(id)
                .map(|f| f.position.as_dvec3())
                .expect("synthetic faces have every FAPU feature point")
        };
        Fapu::from_distances(FapuDistances {
            irisd0: p(FeaturePointId::FP_3_1).y - p(FeaturePointId::FP_3_3).y,
            es0: p(FeaturePointId::FP_3_5).x - p(FeaturePointId::FP_3_6).x,
            ens0: p(FeaturePointId::FP_3_5).y - p(FeaturePointId::FP_9_15).y,
            mns0: p(FeaturePointId::FP_9_15).y - p(FeaturePointId::FP_2_2).y,
            mw0: p(FeaturePointId::FP_8_3).x - p(FeaturePointId::FP_8_4).x,
        })
        .expect("synthetic FAPU distances are positive")
    }

    /// Number of vertices of the skin mesh.
    pub fn skin_vertex_count(&self) -> usize {
        self.meshes[0].positions.len()
    }
}

#[cfg(test)]
mod tests;
