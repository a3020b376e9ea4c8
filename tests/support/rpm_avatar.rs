//! A Ready Player Me avatar as users bring them (half body, `.glb`, metres, +z forward, the
//! head about 1.6 m above the floor): a scene root `Armature` holding the joint chain
//! `Hips` → `Spine` → `Spine1` → `Spine2` → `Neck` → `Head` → (`HeadTop_End`, `LeftEye`,
//! `RightEye`) and the skinned meshes, each on a node of the same name with a skin of its own
//! over the same joints:
//!
//! - `Wolf3D_Head`: the face skin, a sphere of 1 519 vertices with the poles and the back seam
//!   duplicated for UVs, with tangents, skinned to `Head`;
//! - `Wolf3D_Teeth`: upper row, lower row and tongue in one primitive, skinned to `Head` (Ready
//!   Player Me has no jaw bone: the jaw is the morph targets');
//! - `EyeLeft` / `EyeRight`: the eyeballs, wholly on `LeftEye` / `RightEye`;
//! - `Wolf3D_Hair` (on `Head`), `Wolf3D_Body` (neck and chest, over the spine and neck joints),
//!   `Wolf3D_Outfit_Top` (on the spine joints): none of them moves with the face.
//!
//! `Wolf3D_Head` and `Wolf3D_Teeth` carry the user's morph targets ([`USER_TARGETS`]: ARKit and
//! Oculus viseme names in `mesh.extras.targetNames`, some sparse, `jawOpen` with normals on the
//! head). Materials use a base-colour PNG (with `KHR_texture_transform`), a normal map, one
//! sampler, `KHR_materials_specular` and `KHR_materials_emissive_strength`; the asset, scene,
//! nodes and meshes carry extras; an animation `Breathe` turns `Spine1`.
//!
//! The head's geometry is [`super::avatar`]'s in metres (head sphere centre `(0, 1.6, 0)`,
//! radius 0.1; eyes, teeth and tongue at the same places), so its feature-point helpers
//! (`fp_csv`) fit.

use glam::{Mat4, Quat, Vec2, Vec3, Vec4};
use serde_json::{json, Value};

use super::avatar::{self, Bin, Prim};

/// The user's morph targets, on `Wolf3D_Head` and `Wolf3D_Teeth` in this order.
pub const USER_TARGETS: [&str; 6] = [
    "jawOpen",
    "eyeBlinkLeft",
    "eyeBlinkRight",
    "mouthSmile",
    "viseme_aa",
    "viseme_O",
];

/// Node indices.
pub const ARMATURE: usize = 0;
pub const HIPS: usize = 1;
pub const SPINE1: usize = 3;
pub const NECK: usize = 5;
pub const HEAD: usize = 6;
pub const LEFT_EYE: usize = 8;
pub const RIGHT_EYE: usize = 9;
/// Mesh nodes, in [`MESHES`]' order.
pub const FIRST_MESH_NODE: usize = 10;

/// Mesh names (and their nodes' names), in mesh order.
pub const MESHES: [&str; 7] = [
    "Wolf3D_Head",
    "Wolf3D_Teeth",
    "EyeLeft",
    "EyeRight",
    "Wolf3D_Hair",
    "Wolf3D_Body",
    "Wolf3D_Outfit_Top",
];

/// Joints of every skin, in slot order.
const JOINTS: [usize; 9] = [1, 2, 3, 4, 5, 6, 7, 8, 9];
const SLOT_SPINE: u8 = 1;
const SLOT_SPINE1: u8 = 2;
const SLOT_SPINE2: u8 = 3;
const SLOT_NECK: u8 = 4;
const SLOT_HEAD: u8 = 5;
const SLOT_LEFT_EYE: u8 = 7;
const SLOT_RIGHT_EYE: u8 = 8;

/// Head sphere centre and radius (m).
pub const HEAD_CENTRE: Vec3 = Vec3::new(0.0, 1.6, 0.0);
pub const HEAD_RADIUS: f32 = 0.1;
/// Eyeball radius (m).
pub const EYE_RADIUS: f32 = 0.012;

/// Names and local translations (m) of the joint chain, parents first (`HeadTop_End` and
/// the eyes are children of `Head`).
fn chain() -> [(&'static str, Vec3); 7] {
    [
        ("Hips", Vec3::new(0.0, 1.0, 0.0)),
        ("Spine", Vec3::new(0.0, 0.1, 0.0)),
        ("Spine1", Vec3::new(0.0, 0.12, 0.0)),
        ("Spine2", Vec3::new(0.0, 0.14, 0.0)),
        ("Neck", Vec3::new(0.0, 0.12, 0.0)),
        ("Head", Vec3::new(0.0, 0.08, 0.0)),
        ("HeadTop_End", Vec3::new(0.0, 0.2, 0.0)),
    ]
}

/// World position of `Head` at rest.
pub fn head_joint_world() -> Mat4 {
    let t: Vec3 = chain()[..6].iter().map(|c| c.1).sum();
    Mat4::from_translation(t)
}

/// An eyeball's centre (m); `left` is the avatar's own left (+x).
pub fn eye_centre(left: bool) -> Vec3 {
    avatar::eye_centre(left) * 0.01
}

/// Rest rotation of an eye joint in `Head`'s frame: Ready Player Me's eye bones point along
/// the gaze with a roll of their own.
fn eye_joint_rotation(left: bool) -> Quat {
    Quat::from_rotation_x(-std::f32::consts::FRAC_PI_2)
        * Quat::from_rotation_y(if left { 0.3 } else { -0.3 })
}

/// World matrix of an eye joint at rest.
pub fn eye_joint_world(left: bool) -> Mat4 {
    let head = head_joint_world();
    let local = head.inverse().transform_point3(eye_centre(left));
    head * Mat4::from_rotation_translation(eye_joint_rotation(left), local)
}

/// World matrices of the skins' joints at rest, in slot order.
fn joint_worlds() -> Vec<Mat4> {
    let mut worlds = Vec::new();
    let mut m = Mat4::IDENTITY;
    for (k, (_, t)) in chain().iter().enumerate() {
        if k == 6 {
            worlds.push(head_joint_world() * Mat4::from_translation(*t));
        } else {
            m *= Mat4::from_translation(*t);
            worlds.push(m);
        }
    }
    worlds.push(eye_joint_world(true));
    worlds.push(eye_joint_world(false));
    worlds
}

/// A UV sphere about `centre` of radius `r` with `grid` = (rings, segments, cap: radians from
/// the pole where it is cut), turned by `orient` (the unturned pole points along +z), skinned
/// wholly to `slot`.
fn sphere_prim(
    name: &'static str,
    centre: Vec3,
    r: f32,
    grid: (usize, usize, f32),
    orient: Quat,
    slot: u8,
) -> Prim {
    let (rings, segs, cap) = grid;
    let (p, n, uv, t) = avatar::sphere(Vec3::ZERO, r, rings, segs, cap);
    let mut out = Prim::empty(name);
    out.positions = p.iter().map(|&x| centre + orient * x).collect();
    out.normals = n.iter().map(|&x| orient * x).collect();
    out.uvs = uv;
    out.triangles = t;
    out.joints = vec![[(slot, 1.0), (0, 0.0)]; out.positions.len()];
    out
}

/// The face skin: pole up, seam at the back, open below the jaw.
pub fn head_prim() -> Prim {
    // +z (the sphere's pole) to +y; the seam meridian (+x) to the back (−z).
    let orient = Quat::from_rotation_y(std::f32::consts::FRAC_PI_2)
        * Quat::from_rotation_x(-std::f32::consts::FRAC_PI_2);
    sphere_prim(
        "Wolf3D_Head",
        HEAD_CENTRE,
        HEAD_RADIUS,
        (30, 48, 2.5),
        orient,
        SLOT_HEAD,
    )
}

/// Teeth rows and tongue ([`avatar::teeth_prim_with_tongue`] in metres), all on `Head`.
pub fn teeth_prim() -> Prim {
    let mut p = avatar::teeth_prim_with_tongue();
    p.name = "Wolf3D_Teeth";
    for x in &mut p.positions {
        *x *= 0.01;
    }
    for j in &mut p.joints {
        *j = [(SLOT_HEAD, 1.0), (0, 0.0)];
    }
    p
}

/// Vertices of [`teeth_prim`]: upper row, lower row, tongue.
pub const UPPER_TEETH: std::ops::Range<usize> = 0..14;
pub const LOWER_TEETH: std::ops::Range<usize> = 14..28;
pub const TONGUE: std::ops::Range<usize> = avatar::TONGUE;

/// An eyeball, pole (pupil) forward, wholly on its eye joint.
pub fn eye_prim(left: bool) -> Prim {
    sphere_prim(
        if left { "EyeLeft" } else { "EyeRight" },
        eye_centre(left),
        EYE_RADIUS,
        (8, 16, std::f32::consts::PI),
        Quat::IDENTITY,
        if left { SLOT_LEFT_EYE } else { SLOT_RIGHT_EYE },
    )
}

/// Hair: a cap over the top and back of the head.
fn hair_prim() -> Prim {
    let orient = Quat::from_rotation_x(-std::f32::consts::FRAC_PI_2 - 0.35);
    sphere_prim(
        "Wolf3D_Hair",
        HEAD_CENTRE + Vec3::new(0.0, 0.004, -0.004),
        HEAD_RADIUS * 1.06,
        (6, 24, 1.1),
        orient,
        SLOT_HEAD,
    )
}

/// An open cylinder (axis y) from `y0` to `y1`, each ring weighted by `slots(y)`.
fn tube(
    name: &'static str,
    radius: f32,
    y0: f32,
    y1: f32,
    rings: usize,
    slots: impl Fn(f32) -> [(u8, f32); 2],
) -> Prim {
    let segs = 24;
    let mut p = Prim::empty(name);
    for i in 0..=rings {
        let y = y0 + (y1 - y0) * i as f32 / rings as f32;
        for j in 0..=segs {
            let a = std::f32::consts::TAU * j as f32 / segs as f32;
            let d = Vec3::new(a.sin(), 0.0, a.cos());
            p.positions.push(Vec3::new(0.0, y, 0.0) + d * radius);
            p.normals.push(d);
            p.uvs
                .push(Vec2::new(j as f32 / segs as f32, i as f32 / rings as f32));
            p.joints.push(slots(y));
        }
    }
    let w = segs as u16 + 1;
    for i in 0..rings as u16 {
        for j in 0..segs as u16 {
            let (a, b, c, d) = (
                i * w + j,
                i * w + j + 1,
                (i + 1) * w + j,
                (i + 1) * w + j + 1,
            );
            p.triangles.push([a, b, c]);
            p.triangles.push([b, d, c]);
        }
    }
    p
}

/// Neck and chest: the neck on `Neck`, the chest blended over the spine joints.
fn body_prim() -> Prim {
    tube("Wolf3D_Body", 0.05, 1.2, 1.53, 8, |y| {
        if y > 1.45 {
            [(SLOT_NECK, 1.0), (0, 0.0)]
        } else if y > 1.3 {
            [(SLOT_SPINE2, 0.6), (SLOT_NECK, 0.4)]
        } else {
            [(SLOT_SPINE1, 0.7), (SLOT_SPINE2, 0.3)]
        }
    })
}

/// The top: over the chest, on the spine joints.
fn outfit_prim() -> Prim {
    tube("Wolf3D_Outfit_Top", 0.16, 1.05, 1.44, 6, |y| {
        if y > 1.3 {
            [(SLOT_SPINE2, 1.0), (0, 0.0)]
        } else {
            [(SLOT_SPINE, 0.5), (SLOT_SPINE1, 0.5)]
        }
    })
}

/// The user's targets of one primitive: per target, offsets of every vertex.
fn user_targets(p: &Prim, teeth: bool) -> Vec<Vec<Vec3>> {
    let mouth_y = 1.558;
    USER_TARGETS
        .iter()
        .map(|name| {
            p.positions
                .iter()
                .enumerate()
                .map(|(v, x)| {
                    let jaw = if teeth {
                        LOWER_TEETH.contains(&v) || TONGUE.contains(&v)
                    } else {
                        x.y < mouth_y && x.z > 0.0
                    };
                    let fall = if teeth {
                        1.0
                    } else {
                        ((mouth_y - x.y) / 0.05).clamp(0.0, 1.0)
                    };
                    match *name {
                        "jawOpen" if jaw => Vec3::new(0.0, -0.012, -0.003) * fall,
                        "viseme_aa" if jaw => Vec3::new(0.0, -0.007, -0.002) * fall,
                        "viseme_O" if !teeth && x.z > 0.06 && (x.y - mouth_y).abs() < 0.02 => {
                            Vec3::new(-0.3 * x.x, 0.0, 0.002)
                        }
                        "mouthSmile" if !teeth && x.z > 0.06 && (x.y - mouth_y).abs() < 0.015 => {
                            Vec3::new(0.2 * x.x, 0.003, 0.0)
                        }
                        "eyeBlinkLeft" | "eyeBlinkRight" if !teeth => {
                            let e = eye_centre(*name == "eyeBlinkLeft");
                            if x.distance(e) < 0.03 && x.y > e.y && x.z > e.z {
                                Vec3::new(0.0, -0.01, 0.0)
                            } else {
                                Vec3::ZERO
                            }
                        }
                        _ => Vec3::ZERO,
                    }
                })
                .collect()
        })
        .collect()
}

/// A morph target POSITION accessor: sparse (only moving vertices stored, one zero entry
/// where none moves) when `sparse`, else dense.
fn target_accessor(b: &mut Bin, offsets: &[Vec3], sparse: bool) -> usize {
    if !sparse {
        return b.vec3(offsets, true);
    }
    let mut moving: Vec<u32> = (0..offsets.len() as u32)
        .filter(|&v| offsets[v as usize] != Vec3::ZERO)
        .collect();
    if moving.is_empty() {
        moving.push(0);
    }
    let ib: Vec<u8> = moving.iter().flat_map(|v| v.to_le_bytes()).collect();
    let iv = b.view(&ib, None);
    let vb: Vec<u8> = moving
        .iter()
        .flat_map(|&v| offsets[v as usize].to_array())
        .flat_map(f32::to_le_bytes)
        .collect();
    let vv = b.view(&vb, None);
    let min = offsets
        .iter()
        .fold(Vec3::splat(f32::INFINITY), |m, p| m.min(*p));
    let max = offsets
        .iter()
        .fold(Vec3::splat(f32::NEG_INFINITY), |m, p| m.max(*p));
    b.acc(json!({
        "componentType": 5126, "count": offsets.len(), "type": "VEC3",
        "min": min.to_array(), "max": max.to_array(),
        "sparse": {"count": moving.len(),
            "indices": {"bufferView": iv, "componentType": 5125},
            "values": {"bufferView": vv}}
    }))
}

/// The avatar's primitives, one per mesh in [`MESHES`]' order.
pub fn prims() -> Vec<Prim> {
    vec![
        head_prim(),
        teeth_prim(),
        eye_prim(true),
        eye_prim(false),
        hair_prim(),
        body_prim(),
        outfit_prim(),
    ]
}

/// Builds the avatar.
pub fn build() -> avatar::Avatar {
    let prims = prims();
    let mut b = Bin {
        bin: Vec::new(),
        views: Vec::new(),
        accessors: Vec::new(),
    };
    let base_colour = b.view(&avatar::png(), None);
    let normal_map = {
        let mut img = fbakit::render::Image::new(4, 4, [128, 128, 255, 255]);
        img.fill_rect(1, 1, 2, 2, [140, 120, 250, 255]);
        let mut out = Vec::new();
        img.encode_png(&mut out).unwrap();
        b.view(&out, None)
    };
    // Materials: skin, teeth, eye, hair, body, outfit.
    let materials = json!([
        {"name": "Wolf3D_Skin", "pbrMetallicRoughness": {
            "baseColorTexture": {"index": 0, "extensions": {"KHR_texture_transform": {"offset": [0.0, 0.0], "scale": [1.0, 1.0]}}},
            "metallicFactor": 0.0, "roughnessFactor": 0.8},
         "normalTexture": {"index": 1},
         "extensions": {"KHR_materials_specular": {"specularFactor": 0.5}}},
        {"name": "Wolf3D_Teeth", "pbrMetallicRoughness": {"baseColorFactor": [0.95, 0.93, 0.9, 1.0], "metallicFactor": 0.0}},
        {"name": "Wolf3D_Eye", "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}, "metallicFactor": 0.0},
         "emissiveFactor": [0.05, 0.05, 0.05],
         "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 1.5}}},
        {"name": "Wolf3D_Hair", "pbrMetallicRoughness": {"baseColorFactor": [0.2, 0.12, 0.05, 1.0], "metallicFactor": 0.0}, "alphaMode": "MASK"},
        {"name": "Wolf3D_Body", "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}, "metallicFactor": 0.0}},
        {"name": "Wolf3D_Outfit_Top", "pbrMetallicRoughness": {"baseColorFactor": [0.1, 0.3, 0.6, 1.0], "metallicFactor": 0.0},
         "extras": {"outfit": "top"}}
    ]);
    let material_of = [0usize, 1, 2, 2, 3, 4, 5];
    let mut meshes = Vec::new();
    for (k, p) in prims.iter().enumerate() {
        let mut primitive = avatar::skinned_primitive(&mut b, p, material_of[k]);
        let mut mesh = json!({"name": MESHES[k], "primitives": []});
        if k == 0 {
            // Tangents along the parallels (+w): the normal map's frame.
            let t: Vec<f32> = p
                .normals
                .iter()
                .flat_map(|n| {
                    let t = Vec3::Y.cross(*n).try_normalize().unwrap_or(Vec3::X);
                    Vec4::new(t.x, t.y, t.z, 1.0).to_array()
                })
                .collect();
            let bytes: Vec<u8> = t.iter().flat_map(|x| x.to_le_bytes()).collect();
            let view = b.view(&bytes, Some(34962));
            let tangents = b.acc(json!({"bufferView": view, "componentType": 5126,
                "count": p.positions.len(), "type": "VEC4"}));
            primitive["attributes"]["TANGENT"] = json!(tangents);
        }
        if k < 2 {
            let teeth = k == 1;
            let targets: Vec<Value> = user_targets(p, teeth)
                .iter()
                .enumerate()
                .map(|(t, offsets)| {
                    // Blinks and smiles sparse (as Ready Player Me's exporter writes small
                    // shapes), the jaw's dense.
                    let sparse = !matches!(USER_TARGETS[t], "jawOpen" | "viseme_aa");
                    let mut target = json!({"POSITION": target_accessor(&mut b, offsets, sparse)});
                    if !teeth && USER_TARGETS[t] == "jawOpen" {
                        let dn: Vec<Vec3> = offsets
                            .iter()
                            .map(|o| Vec3::new(0.0, 0.0, -o.y * 2.0))
                            .collect();
                        target["NORMAL"] = json!(b.vec3(&dn, false));
                    }
                    target
                })
                .collect();
            primitive["targets"] = json!(targets);
            mesh["weights"] = json!(vec![0.0; USER_TARGETS.len()]);
            mesh["extras"] = json!({"targetNames": USER_TARGETS});
        }
        mesh["primitives"] = json!([primitive]);
        meshes.push(mesh);
    }
    // Inverse bind matrices: the meshes sit in the armature's (= world) frame.
    let ibm: Vec<f32> = joint_worlds()
        .iter()
        .flat_map(|w| w.inverse().to_cols_array())
        .collect();
    let ibm = b.floats(&ibm, "MAT4", false);
    let times = b.floats(&[0.0, 1.5, 3.0], "SCALAR", true);
    let lean = Quat::from_rotation_x(0.03);
    let rot = b.floats(
        &[
            0.0, 0.0, 0.0, 1.0, lean.x, lean.y, lean.z, lean.w, 0.0, 0.0, 0.0, 1.0,
        ],
        "VEC4",
        false,
    );
    let mut nodes = vec![json!({"name": "Armature",
        "children": std::iter::once(HIPS).chain((0..MESHES.len()).map(|m| FIRST_MESH_NODE + m)).collect::<Vec<_>>(),
        "extras": {"rpm": "root"}})];
    for (k, (name, t)) in chain().iter().enumerate() {
        let mut node = json!({"name": name, "translation": t.to_array()});
        if k < 5 {
            node["children"] = json!([k + 2]);
        } else if k == 5 {
            node["children"] = json!([7, LEFT_EYE, RIGHT_EYE]);
        }
        nodes.push(node);
    }
    let head_inv = head_joint_world().inverse();
    for left in [true, false] {
        nodes.push(json!({"name": if left { "LeftEye" } else { "RightEye" },
            "translation": head_inv.transform_point3(eye_centre(left)).to_array(),
            "rotation": eye_joint_rotation(left).to_array()}));
    }
    for (k, name) in MESHES.iter().enumerate() {
        nodes.push(json!({"name": name, "mesh": k, "skin": k, "extras": {"part": name}}));
    }
    let skins: Vec<Value> = MESHES
        .iter()
        .map(|_| json!({"joints": JOINTS, "inverseBindMatrices": ibm}))
        .collect();
    let json = json!({
        "asset": {"version": "2.0", "generator": "Ready Player Me (fbakit test fixture)",
            "extras": {"avatarId": "test", "bodyType": "halfbody", "outfitGender": "feminine"}},
        "extensionsUsed": ["KHR_materials_specular", "KHR_materials_emissive_strength", "KHR_texture_transform"],
        "scene": 0,
        "scenes": [{"name": "Scene", "nodes": [ARMATURE], "extras": {"source": "rpm"}}],
        "nodes": nodes,
        "meshes": meshes,
        "skins": skins,
        "materials": materials,
        "textures": [{"source": 0, "sampler": 0}, {"source": 1, "sampler": 0}],
        "samplers": [{"magFilter": 9729, "minFilter": 9987, "wrapS": 10497, "wrapT": 10497}],
        "images": [
            {"bufferView": base_colour, "mimeType": "image/png", "name": "Image_0"},
            {"bufferView": normal_map, "mimeType": "image/png", "name": "Image_1"}
        ],
        "animations": [{"name": "Breathe",
            "samplers": [{"input": times, "output": rot, "interpolation": "LINEAR"}],
            "channels": [{"sampler": 0, "target": {"node": SPINE1, "path": "rotation"}}]}],
        "accessors": b.accessors,
        "bufferViews": b.views,
        "buffers": [{"byteLength": b.bin.len()}]
    });
    let mut bin = b.bin;
    while bin.len() % 4 != 0 {
        bin.push(0);
    }
    avatar::Avatar { json, bin, prims }
}

/// Feature points as `fp,x,y,z` (world metres): `source`'s points fitted onto the head
/// sphere by [`avatar::fp_csv`] (the pupils on the eyeballs' front poles), then the teeth
/// points on the rows' middles.
pub fn fp_csv(source: &fbakit::face::FaceModel, dir: &std::path::Path) -> std::path::PathBuf {
    let mut teeth = String::new();
    let t = teeth_prim();
    let mid = |range: std::ops::Range<usize>, top: bool| {
        // The rows are strips of 7 columns × (bottom, top); column 3 is the middle.
        t.positions[range.start + 6 + usize::from(top)]
    };
    for (id, p) in [
        ("9.8", mid(UPPER_TEETH, false)),
        ("9.10", mid(UPPER_TEETH, true)),
        ("9.9", mid(LOWER_TEETH, true)),
        ("9.11", mid(LOWER_TEETH, false)),
    ] {
        teeth.push_str(&format!("{id},{},{},{}\n", p.x, p.y, p.z));
    }
    avatar::fp_csv(source, dir, &teeth)
}
