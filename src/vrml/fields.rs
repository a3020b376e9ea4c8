//! Field types of the node types the parser knows: VRML97 nodes used by face models and the
//! MPEG-4 face nodes (fact sheet section 8). VRML's text syntax cannot be read without them
//! (`1 0 0` may be an SFVec3f or an SFColor; a bare `5` may be an MFInt32 of one value).

use std::fmt;
use std::sync::OnceLock;

use crate::spec::{bifs_field_name, FapId};

/// The type of a VRML field.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[allow(missing_docs)] // The variants are the standard's type names.
pub enum FieldType {
    SFBool,
    SFInt32,
    SFFloat,
    SFTime,
    SFString,
    SFVec2f,
    SFVec3f,
    SFColor,
    SFRotation,
    SFImage,
    SFNode,
    MFInt32,
    MFFloat,
    MFTime,
    MFString,
    MFVec2f,
    MFVec3f,
    MFColor,
    MFRotation,
    MFNode,
}

impl FieldType {
    /// The standard's name, e.g. `MFVec3f`.
    pub fn name(self) -> &'static str {
        use FieldType::*;
        match self {
            SFBool => "SFBool",
            SFInt32 => "SFInt32",
            SFFloat => "SFFloat",
            SFTime => "SFTime",
            SFString => "SFString",
            SFVec2f => "SFVec2f",
            SFVec3f => "SFVec3f",
            SFColor => "SFColor",
            SFRotation => "SFRotation",
            SFImage => "SFImage",
            SFNode => "SFNode",
            MFInt32 => "MFInt32",
            MFFloat => "MFFloat",
            MFTime => "MFTime",
            MFString => "MFString",
            MFVec2f => "MFVec2f",
            MFVec3f => "MFVec3f",
            MFColor => "MFColor",
            MFRotation => "MFRotation",
            MFNode => "MFNode",
        }
    }
}

impl fmt::Display for FieldType {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// One field declaration of a node type.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FieldDecl {
    /// Field name as written in files.
    pub name: &'static str,
    /// Its type.
    pub ty: FieldType,
}

macro_rules! decls {
    ($($name:literal : $ty:ident),* $(,)?) => {
        &[$(FieldDecl { name: $name, ty: FieldType::$ty }),*]
    };
}

static ANCHOR: &[FieldDecl] = decls!["children": MFNode, "description": SFString,
    "parameter": MFString, "url": MFString, "bboxCenter": SFVec3f, "bboxSize": SFVec3f];
static APPEARANCE: &[FieldDecl] =
    decls!["material": SFNode, "texture": SFNode, "textureTransform": SFNode];
static AUDIO_CLIP: &[FieldDecl] = decls!["description": SFString, "loop": SFBool,
    "pitch": SFFloat, "startTime": SFTime, "stopTime": SFTime, "url": MFString];
static BACKGROUND: &[FieldDecl] = decls!["groundAngle": MFFloat, "groundColor": MFColor,
    "backUrl": MFString, "bottomUrl": MFString, "frontUrl": MFString, "leftUrl": MFString,
    "rightUrl": MFString, "topUrl": MFString, "skyAngle": MFFloat, "skyColor": MFColor];
static BILLBOARD: &[FieldDecl] = decls!["axisOfRotation": SFVec3f, "children": MFNode,
    "bboxCenter": SFVec3f, "bboxSize": SFVec3f];
static BOX: &[FieldDecl] = decls!["size": SFVec3f];
static COLLISION: &[FieldDecl] = decls!["children": MFNode, "collide": SFBool,
    "bboxCenter": SFVec3f, "bboxSize": SFVec3f, "proxy": SFNode];
static COLOR: &[FieldDecl] = decls!["color": MFColor];
static CONE: &[FieldDecl] =
    decls!["bottomRadius": SFFloat, "height": SFFloat, "side": SFBool, "bottom": SFBool];
static COORDINATE: &[FieldDecl] = decls!["point": MFVec3f];
static CYLINDER: &[FieldDecl] = decls!["bottom": SFBool, "height": SFFloat,
    "radius": SFFloat, "side": SFBool, "top": SFBool];
static DIRECTIONAL_LIGHT: &[FieldDecl] = decls!["ambientIntensity": SFFloat, "color": SFColor,
    "direction": SFVec3f, "intensity": SFFloat, "on": SFBool];
static GROUP: &[FieldDecl] = decls!["children": MFNode, "bboxCenter": SFVec3f,
    "bboxSize": SFVec3f];
static IMAGE_TEXTURE: &[FieldDecl] = decls!["url": MFString, "repeatS": SFBool, "repeatT": SFBool];
static INDEXED_FACE_SET: &[FieldDecl] = decls!["color": SFNode, "coord": SFNode,
    "normal": SFNode, "texCoord": SFNode, "ccw": SFBool, "colorIndex": MFInt32,
    "colorPerVertex": SFBool, "convex": SFBool, "coordIndex": MFInt32, "creaseAngle": SFFloat,
    "normalIndex": MFInt32, "normalPerVertex": SFBool, "solid": SFBool, "texCoordIndex": MFInt32];
static INDEXED_LINE_SET: &[FieldDecl] = decls!["color": SFNode, "coord": SFNode,
    "colorIndex": MFInt32, "colorPerVertex": SFBool, "coordIndex": MFInt32];
static INLINE: &[FieldDecl] = decls!["url": MFString, "bboxCenter": SFVec3f, "bboxSize": SFVec3f];
static LOD: &[FieldDecl] = decls!["level": MFNode, "center": SFVec3f, "range": MFFloat];
static MATERIAL: &[FieldDecl] = decls!["ambientIntensity": SFFloat, "diffuseColor": SFColor,
    "emissiveColor": SFColor, "shininess": SFFloat, "specularColor": SFColor,
    "transparency": SFFloat];
static MOVIE_TEXTURE: &[FieldDecl] = decls!["loop": SFBool, "speed": SFFloat,
    "startTime": SFTime, "stopTime": SFTime, "url": MFString, "repeatS": SFBool,
    "repeatT": SFBool];
static NAVIGATION_INFO: &[FieldDecl] = decls!["avatarSize": MFFloat, "headlight": SFBool,
    "speed": SFFloat, "type": MFString, "visibilityLimit": SFFloat];
static NORMAL: &[FieldDecl] = decls!["vector": MFVec3f];
static PIXEL_TEXTURE: &[FieldDecl] = decls!["image": SFImage, "repeatS": SFBool, "repeatT": SFBool];
static POINT_LIGHT: &[FieldDecl] = decls!["ambientIntensity": SFFloat, "attenuation": SFVec3f,
    "color": SFColor, "intensity": SFFloat, "location": SFVec3f, "on": SFBool, "radius": SFFloat];
static POINT_SET: &[FieldDecl] = decls!["color": SFNode, "coord": SFNode];
static SHAPE: &[FieldDecl] = decls!["appearance": SFNode, "geometry": SFNode];
static SPHERE: &[FieldDecl] = decls!["radius": SFFloat];
static SPOT_LIGHT: &[FieldDecl] = decls!["ambientIntensity": SFFloat, "attenuation": SFVec3f,
    "beamWidth": SFFloat, "color": SFColor, "cutOffAngle": SFFloat, "direction": SFVec3f,
    "intensity": SFFloat, "location": SFVec3f, "on": SFBool, "radius": SFFloat];
static SWITCH: &[FieldDecl] = decls!["choice": MFNode, "whichChoice": SFInt32];
static TEXTURE_COORDINATE: &[FieldDecl] = decls!["point": MFVec2f];
static TEXTURE_TRANSFORM: &[FieldDecl] = decls!["center": SFVec2f, "rotation": SFFloat,
    "scale": SFVec2f, "translation": SFVec2f];
static TIME_SENSOR: &[FieldDecl] = decls!["cycleInterval": SFTime, "enabled": SFBool,
    "loop": SFBool, "startTime": SFTime, "stopTime": SFTime];
static TRANSFORM: &[FieldDecl] = decls!["center": SFVec3f, "children": MFNode,
    "rotation": SFRotation, "scale": SFVec3f, "scaleOrientation": SFRotation,
    "translation": SFVec3f, "bboxCenter": SFVec3f, "bboxSize": SFVec3f];
static VIEWPOINT: &[FieldDecl] = decls!["fieldOfView": SFFloat, "jump": SFBool,
    "orientation": SFRotation, "position": SFVec3f, "description": SFString];
static WORLD_INFO: &[FieldDecl] = decls!["info": MFString, "title": SFString];

// MPEG-4 face nodes, in declaration (BIFS coding) order.
static FACE: &[FieldDecl] = decls!["fap": SFNode, "fdp": SFNode, "fit": SFNode,
    "ttsSource": SFNode, "renderedFace": MFNode];
static VISEME: &[FieldDecl] = decls!["viseme_select1": SFInt32, "viseme_select2": SFInt32,
    "viseme_blend": SFInt32, "viseme_def": SFBool];
static EXPRESSION: &[FieldDecl] = decls!["expression_select1": SFInt32,
    "expression_intensity1": SFInt32, "expression_select2": SFInt32,
    "expression_intensity2": SFInt32, "init_face": SFBool, "expression_def": SFBool];
static FDP: &[FieldDecl] = decls!["featurePointsCoord": SFNode, "textureCoord": SFNode,
    "faceDefTables": MFNode, "faceSceneGraph": MFNode, "useOrthoTexture": SFBool];
static FIT: &[FieldDecl] = decls!["FAPs": MFInt32, "Graph": MFInt32, "numeratorExp": MFInt32,
    "denominatorExp": MFInt32, "numeratorImpulse": MFInt32, "numeratorTerms": MFInt32,
    "denominatorTerms": MFInt32, "numeratorCoefs": MFFloat, "denominatorCoefs": MFFloat];
static FACE_DEF_TABLES: &[FieldDecl] = decls!["fapID": SFInt32, "highLevelSelect": SFInt32,
    "faceDefMesh": MFNode, "faceDefTransform": MFNode];
static FACE_DEF_MESH: &[FieldDecl] = decls!["faceSceneGraphNode": SFNode,
    "intervalBorders": MFInt32, "coordIndex": MFInt32, "displacements": MFVec3f];
static FACE_DEF_TRANSFORM: &[FieldDecl] = decls!["faceSceneGraphNode": SFNode,
    "fieldId": SFInt32, "rotationDef": SFRotation, "scaleDef": SFVec3f,
    "translationDef": SFVec3f];

/// The `FAP` node: `viseme`, `expression`, then one SFInt32 per low-level FAP 3..=68 named by
/// its BIFS field name.
fn fap_fields() -> &'static [FieldDecl] {
    static FAP: OnceLock<Vec<FieldDecl>> = OnceLock::new();
    FAP.get_or_init(|| {
        let mut v = vec![
            FieldDecl {
                name: "viseme",
                ty: FieldType::SFNode,
            },
            FieldDecl {
                name: "expression",
                ty: FieldType::SFNode,
            },
        ];
        v.extend(FapId::low_level().map(|id| FieldDecl {
            name: bifs_field_name(id),
            ty: FieldType::SFInt32,
        }));
        v
    })
}

/// Node types the parser reads with typed fields (VRML97 and MPEG-4 face nodes).
pub const KNOWN_NODE_TYPES: &[&str] = &[
    "Anchor",
    "Appearance",
    "AudioClip",
    "Background",
    "Billboard",
    "Box",
    "Collision",
    "Color",
    "Cone",
    "Coordinate",
    "Cylinder",
    "DirectionalLight",
    "Expression",
    "FAP",
    "FDP",
    "FIT",
    "Face",
    "FaceDefMesh",
    "FaceDefTables",
    "FaceDefTransform",
    "Group",
    "ImageTexture",
    "IndexedFaceSet",
    "IndexedLineSet",
    "Inline",
    "LOD",
    "Material",
    "MovieTexture",
    "NavigationInfo",
    "Normal",
    "PixelTexture",
    "PointLight",
    "PointSet",
    "Shape",
    "Sphere",
    "SpotLight",
    "Switch",
    "TextureCoordinate",
    "TextureTransform",
    "TimeSensor",
    "Transform",
    "Viewpoint",
    "Viseme",
    "WorldInfo",
];

/// The field declarations of a known node type, `None` for node types kept generically.
pub fn node_fields(type_name: &str) -> Option<&'static [FieldDecl]> {
    Some(match type_name {
        "Anchor" => ANCHOR,
        "Appearance" => APPEARANCE,
        "AudioClip" => AUDIO_CLIP,
        "Background" => BACKGROUND,
        "Billboard" => BILLBOARD,
        "Box" => BOX,
        "Collision" => COLLISION,
        "Color" => COLOR,
        "Cone" => CONE,
        "Coordinate" => COORDINATE,
        "Cylinder" => CYLINDER,
        "DirectionalLight" => DIRECTIONAL_LIGHT,
        "Expression" => EXPRESSION,
        "FAP" => fap_fields(),
        "FDP" => FDP,
        "FIT" => FIT,
        "Face" => FACE,
        "FaceDefMesh" => FACE_DEF_MESH,
        "FaceDefTables" => FACE_DEF_TABLES,
        "FaceDefTransform" => FACE_DEF_TRANSFORM,
        "Group" => GROUP,
        "ImageTexture" => IMAGE_TEXTURE,
        "IndexedFaceSet" => INDEXED_FACE_SET,
        "IndexedLineSet" => INDEXED_LINE_SET,
        "Inline" => INLINE,
        "LOD" => LOD,
        "Material" => MATERIAL,
        "MovieTexture" => MOVIE_TEXTURE,
        "NavigationInfo" => NAVIGATION_INFO,
        "Normal" => NORMAL,
        "PixelTexture" => PIXEL_TEXTURE,
        "PointLight" => POINT_LIGHT,
        "PointSet" => POINT_SET,
        "Shape" => SHAPE,
        "Sphere" => SPHERE,
        "SpotLight" => SPOT_LIGHT,
        "Switch" => SWITCH,
        "TextureCoordinate" => TEXTURE_COORDINATE,
        "TextureTransform" => TEXTURE_TRANSFORM,
        "TimeSensor" => TIME_SENSOR,
        "Transform" => TRANSFORM,
        "Viewpoint" => VIEWPOINT,
        "Viseme" => VISEME,
        "WorldInfo" => WORLD_INFO,
        _ => return None,
    })
}

/// The type of field `field` of node type `type_name`, if both are known.
pub fn field_type(type_name: &str, field: &str) -> Option<FieldType> {
    node_fields(type_name)?
        .iter()
        .find(|d| d.name == field)
        .map(|d| d.ty)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_known_type_has_a_table_and_unique_fields() {
        for t in KNOWN_NODE_TYPES {
            let fields = node_fields(t).unwrap_or_else(|| panic!("{t} has no table"));
            let mut names: Vec<_> = fields.iter().map(|d| d.name).collect();
            names.sort_unstable();
            names.dedup();
            assert_eq!(names.len(), fields.len(), "{t} repeats a field");
        }
        assert!(node_fields("Script").is_none());
        assert!(node_fields("Unknown").is_none());
    }

    #[test]
    fn fap_node_has_viseme_expression_and_66_low_level_fields() {
        let f = node_fields("FAP").unwrap();
        assert_eq!(f.len(), 68);
        assert_eq!(field_type("FAP", "viseme"), Some(FieldType::SFNode));
        assert_eq!(field_type("FAP", "open_jaw"), Some(FieldType::SFInt32));
        assert_eq!(
            field_type("FAP", "stretch_l_cornerlip"),
            Some(FieldType::SFInt32)
        );
        assert_eq!(f[2 + 50].name, "stretch_l_cornerlip", "FAP 53 by position");
        assert_eq!(field_type("FAP", "nope"), None);
    }

    #[test]
    fn face_node_field_types_match_the_fact_sheet() {
        assert_eq!(
            field_type("FaceDefMesh", "displacements"),
            Some(FieldType::MFVec3f)
        );
        assert_eq!(
            field_type("FaceDefTransform", "rotationDef"),
            Some(FieldType::SFRotation)
        );
        assert_eq!(
            field_type("FIT", "numeratorCoefs"),
            Some(FieldType::MFFloat)
        );
        assert_eq!(
            field_type("FDP", "useOrthoTexture"),
            Some(FieldType::SFBool)
        );
        assert_eq!(
            field_type("Material", "diffuseColor"),
            Some(FieldType::SFColor)
        );
        assert_eq!(FieldType::MFVec3f.to_string(), "MFVec3f");
    }
}
