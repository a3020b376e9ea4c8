//! A test avatar as artists hand them over: one skinned mesh `Body` with four primitives
//! (skin, mouth, eyes, lashes) in centimetres under a 0.01-scaled `Armature` node (the FBX
//! habit), a joint hierarchy (`Root` → `Neck` → `Head` → `Jaw`) with an animation, a
//! base-colour texture (an embedded PNG), a camera, a `Hat` mesh on the head, one morph
//! target of the user's own (`Blink`, animated), a material extension and extras on the
//! asset, nodes and materials.
//!
//! A variant ([`build_with`], [`Options::teeth`]) adds a fifth primitive `teeth`: an upper and a
//! lower row of teeth in one primitive behind the lips (the upper row on the head joint, the
//! lower on the jaw), with feature points 9.8–9.11 on them ([`teeth_fp_lines`]), and
//! optionally a tongue after the rows ([`Options::tongue`]).
//!
//! Other variants move the eyeballs onto nodes of their own ([`Options::eye_nodes`]) or skin
//! them to eye joints ([`Options::skinned_eyes`]), or keep both eyeballs in `Body`'s `eyes`
//! primitive skinned to two eye joints, the VRM / VRoid layout ([`Options::vrm_eyes`]), with
//! an iris and a highlight primitive in front as VRoid has them ([`Options::vroid_eyes`]).
//!
//! The jaw's inverse bind matrix was taken half a centimetre higher than the jaw rests, so the
//! mouth's vertices (weighted to jaw and head) are placed per vertex at rest; the other joints
//! agree and place their vertices with the armature's one matrix.

use glam::{Mat4, Vec2, Vec3};
use serde_json::{json, Value};

/// Centre of the head sphere, in the armature's centimetres.
pub const HEAD_CENTRE: Vec3 = Vec3::new(0.0, 160.0, 0.0);
/// Head sphere radius (cm).
pub const HEAD_RADIUS: f32 = 10.0;
/// Offset between the jaw's rest and bind positions (cm).
pub const JAW_BIND_OFFSET: f32 = 0.5;

/// One primitive's data.
pub struct Prim {
    pub name: &'static str,
    pub positions: Vec<Vec3>,
    pub normals: Vec<Vec3>,
    pub uvs: Vec<Vec2>,
    pub triangles: Vec<[u16; 3]>,
    /// Per vertex (joint slot, weight) pairs (at most 4).
    pub joints: Vec<[(u8, f32); 2]>,
}

impl Prim {
    /// A primitive named `name` with nothing in it yet.
    pub fn empty(name: &'static str) -> Prim {
        Prim {
            name,
            positions: vec![],
            normals: vec![],
            uvs: vec![],
            triangles: vec![],
            joints: vec![],
        }
    }
}

/// The avatar: JSON and its binary buffer.
pub struct Avatar {
    pub json: Value,
    pub bin: Vec<u8>,
    pub prims: Vec<Prim>,
}

pub fn sphere(
    centre: Vec3,
    r: f32,
    rings: usize,
    segs: usize,
    cap: f32,
) -> (Vec<Vec3>, Vec<Vec3>, Vec<Vec2>, Vec<[u16; 3]>) {
    let (mut p, mut n, mut uv, mut t) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for i in 0..=rings {
        let th = cap * i as f32 / rings as f32;
        for j in 0..=segs {
            let ph = std::f32::consts::TAU * j as f32 / segs as f32;
            // +z is the face's front: the pole points forward.
            let d = Vec3::new(th.sin() * ph.cos(), th.sin() * ph.sin(), th.cos());
            p.push(centre + d * r);
            n.push(d);
            uv.push(Vec2::new(j as f32 / segs as f32, i as f32 / rings as f32));
        }
    }
    let w = segs + 1;
    for i in 0..rings {
        for j in 0..segs {
            let a = (i * w + j) as u16;
            let b = (i * w + j + 1) as u16;
            let c = ((i + 1) * w + j) as u16;
            let d = ((i + 1) * w + j + 1) as u16;
            if i > 0 {
                t.push([a, c, b]);
            }
            t.push([b, c, d]);
        }
    }
    (p, n, uv, t)
}

/// What the avatar has besides its four primitives.
#[derive(Clone, Copy, Debug, Default)]
pub struct Options {
    /// A fifth primitive `teeth`: both rows of teeth in one primitive.
    pub teeth: bool,
    /// With [`Options::teeth`]: a tongue in the `teeth` primitive too, after the rows
    /// ([`TONGUE`]), on the jaw joint: ReadyPlayerMe's `Wolf3D_Teeth` holds both rows and the
    /// tongue so.
    pub tongue: bool,
    /// The eyeballs on their own nodes `LeftEye` and `RightEye` (nodes [`LEFT_EYE_NODE`] and
    /// [`RIGHT_EYE_NODE`], meshes 2 and 3) instead of `Body`'s `eyes` primitive.
    pub eye_nodes: bool,
    /// The eyeballs as meshes of their own (`LeftEyeMesh`, `RightEyeMesh`: meshes 2 and 3 on
    /// nodes [`LEFT_EYE_MESH_NODE`], [`RIGHT_EYE_MESH_NODE`]) skinned to eye joints
    /// `LeftEye` and `RightEye` ([`LEFT_EYE_JOINT`], [`RIGHT_EYE_JOINT`], under `Head`, turned
    /// rest frames, skin slots 4 and 5) instead of `Body`'s `eyes` primitive, as
    /// ReadyPlayerMe and Mixamo avatars have them: `Some(share)` weights each eyeball vertex
    /// to its eye joint by `share`, the rest to `Head`. Not with [`Options::eye_nodes`].
    pub skinned_eyes: Option<f32>,
    /// Both eyeballs stay in `Body`'s `eyes` primitive, each skinned to its own eye joint
    /// `LeftEye` / `RightEye` ([`LEFT_EYE_JOINT`], [`RIGHT_EYE_JOINT`]: the same joints as
    /// [`Options::skinned_eyes`], skin slots 4 and 5), as VRM / VRoid avatars hold them:
    /// `Some(share)` weights each eyeball vertex to its eye joint by `share`, the rest to
    /// `Head`. Not with the other eye options.
    pub vrm_eyes: Option<f32>,
    /// As [`Options::vrm_eyes`] with both eyeballs wholly on their eye joints, and two eye
    /// layers in front of them as VRoid builds eyes: an `iris` primitive of `Body` (a cap
    /// just outside each eye white) and a `highlight` (a small cap further out, above the
    /// pupil), each holding both eyes and skinned to the same joints. Not with the other eye
    /// options.
    pub vroid_eyes: Option<VroidEyes>,
    /// With [`Options::vroid_eyes`]: the eye whites (`Body`'s `eyes` primitive) weighted
    /// wholly to `Head`, not to the eye joints, as VRoid's `EyeWhite` is; only the irises
    /// (and highlights) are skinned to the eye joints.
    pub white_on_head: bool,
    /// The eye nodes `LeftEye` / `RightEye` (as [`Options::eye_nodes`]: nodes
    /// [`LEFT_EYE_NODE`], [`RIGHT_EYE_NODE`] under `Eyes`) hold iris caps (meshes `LeftIris`,
    /// `RightIris`: 2 and 3) while the eye whites sit elsewhere: in `Body`'s `eyes` primitive
    /// on `Head`, or ([`IrisNodes::white_nodes`]) on nodes of their own. Not with the other
    /// eye options.
    pub iris_nodes: Option<IrisNodes>,
}

/// Where the eye whites of [`Options::iris_nodes`] are.
#[derive(Clone, Copy, Debug, Default)]
pub struct IrisNodes {
    /// On nodes `LeftEyeWhite` / `RightEyeWhite` of their own under `Head`
    /// ([`LEFT_WHITE_NODE`], [`RIGHT_WHITE_NODE`]; meshes 4 and 5) instead of `Body`'s `eyes`
    /// primitive.
    pub white_nodes: bool,
}

/// With [`IrisNodes::white_nodes`]: the eye whites' nodes.
pub const LEFT_WHITE_NODE: usize = 11;
pub const RIGHT_WHITE_NODE: usize = 12;

/// The pole of an iris cap of [`Options::vroid_eyes`] or [`Options::iris_nodes`] (cm,
/// armature frame): where an artist puts the pupil.
pub fn iris_pole(left: bool) -> Vec3 {
    eye_centre(left) + Vec3::Z * IRIS_RADIUS
}

/// Radius of the eye white (cm).
pub const EYE_WHITE_RADIUS: f32 = 1.2;

/// The eye layers of [`Options::vroid_eyes`].
#[derive(Clone, Copy, Debug)]
pub struct VroidEyes {
    /// The highlight as a mesh `EyeHighlight` of its own (mesh 2, node [`HIGHLIGHT_NODE`],
    /// skinned to the same joints) instead of a primitive of `Body`.
    pub highlight_node: bool,
    /// Share of each iris vertex's weight on its eye joint (the rest on `Head`).
    pub iris_share: f32,
}

/// With [`VroidEyes::highlight_node`]: the highlight's node.
pub const HIGHLIGHT_NODE: usize = 10;

/// Eye layers of [`Options::vroid_eyes`]: radius (cm) of the iris and the highlight about
/// the eye's centre (the eye white's is 1.2), and their caps' half angles (rad).
const IRIS_RADIUS: f32 = 1.22;
const IRIS_HALF_ANGLE: f32 = 0.5;
const HIGHLIGHT_RADIUS: f32 = 1.27;
const HIGHLIGHT_HALF_ANGLE: f32 = 0.12;

/// The highlight's turn off the gaze: up and towards the face's right.
fn highlight_tilt() -> glam::Quat {
    glam::Quat::from_rotation_x(-0.3) * glam::Quat::from_rotation_y(-0.2)
}

/// An eye layer of [`Options::vroid_eyes`] named `name`: per eye (right, then left, as
/// `eyes`), a cap of `half_angle` on a sphere of `radius` about the eye's centre, its pole
/// turned by `tilt` off the gaze, weighted to the eye's joint by `share` (the rest to `Head`).
pub fn eye_layer(
    name: &'static str,
    radius: f32,
    half_angle: f32,
    tilt: glam::Quat,
    share: f32,
) -> Prim {
    let mut layer = Prim::empty(name);
    for (left, slot) in [(false, 5u8), (true, 4u8)] {
        let (p, n, uv, t) = sphere(Vec3::ZERO, radius, 2, 8, half_angle);
        let base = layer.positions.len() as u16;
        layer
            .triangles
            .extend(t.iter().map(|tr| tr.map(|i| i + base)));
        // A joint of zero weight is slot 0, as the validator asks.
        let rest = if share < 1.0 { 2 } else { 0 };
        layer.joints.extend(std::iter::repeat_n(
            [(slot, share), (rest, 1.0 - share)],
            p.len(),
        ));
        layer
            .positions
            .extend(p.iter().map(|&x| eye_centre(left) + tilt * x));
        layer.normals.extend(n.iter().map(|&x| tilt * x));
        layer.uvs.extend(uv);
    }
    layer
}

/// The highlight layer of [`Options::vroid_eyes`].
pub fn highlight_layer() -> Prim {
    eye_layer(
        "highlight",
        HIGHLIGHT_RADIUS,
        HIGHLIGHT_HALF_ANGLE,
        highlight_tilt(),
        1.0,
    )
}

/// With [`Options::skinned_eyes`]: the eye joints and the nodes of the eye meshes (indices).
pub const LEFT_EYE_JOINT: usize = 8;
pub const RIGHT_EYE_JOINT: usize = 9;
pub const LEFT_EYE_MESH_NODE: usize = 10;
pub const RIGHT_EYE_MESH_NODE: usize = 11;

/// Rest rotation of an eye joint in `Head`'s frame: a bone along the gaze (its +y forward),
/// rolled differently on each side, as rigging tools leave them.
fn eye_joint_rotation(left: bool) -> glam::Quat {
    glam::Quat::from_rotation_x(std::f32::consts::FRAC_PI_2)
        * glam::Quat::from_rotation_y(if left { 0.5 } else { -0.2 })
}

/// An eye joint's translation in `Head`'s frame (cm): the eyeball's centre, the right one
/// 0.2 cm off it (a pivot an artist placed by eye).
fn eye_joint_translation(left: bool) -> Vec3 {
    eye_centre(left) - HEAD_CENTRE
        + if left {
            Vec3::ZERO
        } else {
            Vec3::new(0.0, 0.2, -0.2)
        }
}

/// World matrix (file units: the armature's 0.01 applied) of an eye joint at rest.
pub fn eye_joint_world(left: bool) -> Mat4 {
    joint_worlds()[2]
        * Mat4::from_rotation_translation(eye_joint_rotation(left), eye_joint_translation(left))
}

/// With [`Options::eye_nodes`]: the `Eyes` node and the eye nodes (indices).
pub const EYES_NODE: usize = 8;
pub const LEFT_EYE_NODE: usize = 9;
pub const RIGHT_EYE_NODE: usize = 10;

/// Centre of an eyeball (cm, armature frame); `left` is the face's own left (+x).
pub fn eye_centre(left: bool) -> Vec3 {
    HEAD_CENTRE + Vec3::new(if left { 3.2 } else { -3.2 }, 2.0, 7.5)
}

/// Rest rotations of the `Eyes` node and of each eye node (their own frames differ from
/// the face's).
fn eyes_node_rotation() -> glam::Quat {
    glam::Quat::from_rotation_x(-std::f32::consts::FRAC_PI_2)
}
fn eye_node_rotation(left: bool) -> glam::Quat {
    glam::Quat::from_rotation_z(if left { 0.3 } else { -0.4 })
}
/// `Eyes`' translation in the `Head` joint's frame (cm), and each eye's in `Eyes`' frame.
const EYES_OFFSET: Vec3 = Vec3::new(0.0, 2.0, 7.0);
fn eye_node_translation(left: bool) -> Vec3 {
    // The eye's centre relative to `Eyes`, in `Eyes`' turned frame; the right eye's node
    // sits 0.3 cm off its centre (a pivot an artist placed by eye).
    let off = eye_centre(left) - HEAD_CENTRE - EYES_OFFSET
        + if left {
            Vec3::ZERO
        } else {
            Vec3::new(0.0, 0.0, -0.3)
        };
    eyes_node_rotation().inverse() * off
}

/// World matrix (armature cm) of an eye node at rest.
pub fn eye_node_world(left: bool) -> Mat4 {
    let head = Mat4::from_translation(HEAD_CENTRE);
    head * Mat4::from_rotation_translation(eyes_node_rotation(), EYES_OFFSET)
        * Mat4::from_rotation_translation(eye_node_rotation(left), eye_node_translation(left))
}

/// One eyeball sphere as the `eyes` primitive has it.
fn eyeball(left: bool) -> (Vec<Vec3>, Vec<Vec3>, Vec<Vec2>, Vec<[u16; 3]>) {
    sphere(
        eye_centre(left),
        EYE_WHITE_RADIUS,
        4,
        8,
        std::f32::consts::PI,
    )
}

/// One iris cap of [`Options::iris_nodes`] about the eye's centre.
fn iris_cap(left: bool) -> (Vec<Vec3>, Vec<Vec3>, Vec<Vec2>, Vec<[u16; 3]>) {
    sphere(eye_centre(left), IRIS_RADIUS, 2, 8, IRIS_HALF_ANGLE)
}

/// Lip line height and front of the teeth rows (cm, armature frame): just behind the lips
/// [`fp_csv`] puts on the head sphere.
const LIP_Y: f32 = 155.8;
const TEETH_Z: f32 = 8.2;
/// Half width and height of a row of teeth (cm).
const TEETH_HALF_WIDTH: f32 = 1.5;
const TEETH_HEIGHT: f32 = 0.7;
/// Gap between the rows and the lip line (cm).
const TEETH_GAP: f32 = 0.1;

/// One row of teeth: a strip curving back at its ends, from `y0` to `y1`.
fn teeth_row(y0: f32, y1: f32) -> (Vec<Vec3>, Vec<Vec2>, Vec<[u16; 3]>) {
    let (mut p, mut uv, mut t) = (Vec::new(), Vec::new(), Vec::new());
    let n = 6;
    for i in 0..=n {
        let u = i as f32 / n as f32;
        let x = (2.0 * u - 1.0) * TEETH_HALF_WIDTH;
        let z = HEAD_CENTRE.z + TEETH_Z - 0.4 * x * x;
        for (k, y) in [y0, y1].into_iter().enumerate() {
            p.push(Vec3::new(x, y, z));
            uv.push(Vec2::new(u, k as f32));
        }
    }
    for i in 0..n as u16 {
        let (a, b, c, d) = (2 * i, 2 * i + 1, 2 * i + 2, 2 * i + 3);
        t.push([a, c, b]);
        t.push([b, c, d]);
    }
    (p, uv, t)
}

/// The `teeth` primitive of [`Options::teeth`]: upper row (vertices 0..14, head joint), then
/// the lower row (14..28, jaw joint).
pub fn teeth_prim() -> Prim {
    let (head, jaw) = (2u8, 3u8);
    let mut prim = Prim::empty("teeth");
    let rows = [
        (LIP_Y + TEETH_GAP, LIP_Y + TEETH_GAP + TEETH_HEIGHT, head),
        (LIP_Y - TEETH_GAP - TEETH_HEIGHT, LIP_Y - TEETH_GAP, jaw),
    ];
    for (y0, y1, joint) in rows {
        let (p, uv, t) = teeth_row(y0, y1);
        let base = prim.positions.len() as u16;
        prim.triangles
            .extend(t.iter().map(|tr| tr.map(|i| i + base)));
        prim.joints
            .extend(std::iter::repeat_n([(joint, 1.0), (0, 0.0)], p.len()));
        prim.normals.extend(std::iter::repeat_n(Vec3::Z, p.len()));
        prim.positions.extend(p);
        prim.uvs.extend(uv);
    }
    prim
}

/// The tongue's vertices in the `teeth` primitive of [`Options::tongue`].
pub const TONGUE: std::ops::Range<usize> = 28..28 + 5 * 9;

/// [`teeth_prim`] with a tongue after the rows: a flattened dome on the floor of the mouth
/// behind the lower row, below the lip line, skinned to the jaw.
pub fn teeth_prim_with_tongue() -> Prim {
    let mut prim = teeth_prim();
    let centre = Vec3::new(0.0, LIP_Y - 0.55, HEAD_CENTRE.z + TEETH_Z - 1.4);
    let (p, n, uv, t) = sphere(Vec3::ZERO, 1.0, 4, 8, std::f32::consts::FRAC_PI_2);
    let scale = Vec3::new(1.1, 0.35, 1.2);
    // The dome's pole points forward (+z); lay it down so it bulges up.
    let lay = glam::Quat::from_rotation_x(-std::f32::consts::FRAC_PI_2);
    let base = prim.positions.len() as u16;
    assert_eq!(base as usize, TONGUE.start);
    prim.triangles
        .extend(t.iter().map(|tr| tr.map(|i| i + base)));
    prim.joints
        .extend(std::iter::repeat_n([(3u8, 1.0), (0, 0.0)], p.len()));
    prim.normals.extend(n.iter().map(|d| lay * *d));
    prim.positions
        .extend(p.iter().map(|q| centre + lay * (*q * scale)));
    prim.uvs.extend(uv);
    assert_eq!(prim.positions.len(), TONGUE.end);
    prim
}

/// Feature points 9.8–9.11 on the [`teeth_prim`] rows, as `fp,x,y,z` lines in the file's
/// world frame (metres, at rest): 9.8 and 9.10 on the upper row's lower and upper middle, 9.9 and 9.11
/// on the lower row's upper and lower middle.
pub fn teeth_fp_lines() -> String {
    let z = HEAD_CENTRE.z + TEETH_Z;
    let at = |id: &str, y: f32| format!("{id},0,{},{}\n", y * 0.01, z * 0.01);
    [
        at("9.8", LIP_Y + TEETH_GAP),
        at("9.10", LIP_Y + TEETH_GAP + TEETH_HEIGHT),
        // The jaw joint places the lower row JAW_BIND_OFFSET lower than modelled.
        at("9.9", LIP_Y - TEETH_GAP - JAW_BIND_OFFSET),
        at("9.11", LIP_Y - TEETH_GAP - TEETH_HEIGHT - JAW_BIND_OFFSET),
    ]
    .concat()
}

/// The primitives of `Body` with `opts`.
pub fn body_prims_with(opts: &Options) -> Vec<Prim> {
    let mut prims = body_prims();
    let vrm_share = opts.vrm_eyes.or(opts.vroid_eyes.map(|_| 1.0));
    if let Some(share) = vrm_share.filter(|_| !opts.white_on_head) {
        // `eyes` holds the right eyeball, then the left ([`body_prims`]).
        let eyes = &mut prims[2];
        let half = eyes.positions.len() / 2;
        for (v, j) in eyes.joints.iter_mut().enumerate() {
            let slot = if v < half { 5u8 } else { 4u8 };
            *j = [(slot, share), (2, 1.0 - share)];
        }
    }
    if let Some(v) = opts.vroid_eyes {
        let iris = eye_layer(
            "iris",
            IRIS_RADIUS,
            IRIS_HALF_ANGLE,
            glam::Quat::IDENTITY,
            v.iris_share,
        );
        prims.push(iris);
        if !v.highlight_node {
            prims.push(highlight_layer());
        }
    }
    if opts.teeth {
        prims.push(if opts.tongue {
            teeth_prim_with_tongue()
        } else {
            teeth_prim()
        });
    }
    prims
}

/// The four primitives of `Body`.
pub fn body_prims() -> Vec<Prim> {
    let head = 2u8; // joint slots: 0 Root, 1 Neck, 2 Head, 3 Jaw
    let jaw = 3u8;
    let (p, n, uv, t) = sphere(HEAD_CENTRE, HEAD_RADIUS, 10, 16, std::f32::consts::PI);
    let skin_joints = vec![[(head, 1.0), (0, 0.0)]; p.len()];
    let skin = Prim {
        name: "skin",
        positions: p,
        normals: n,
        uvs: uv,
        triangles: t,
        joints: skin_joints,
    };
    let mouth_c = HEAD_CENTRE + Vec3::new(0.0, -4.0, 7.0);
    let (p, n, uv, t) = sphere(mouth_c, 2.0, 3, 8, 1.2);
    let mouth_joints = vec![[(jaw, 0.7), (head, 0.3)]; p.len()];
    let mouth = Prim {
        name: "mouth",
        positions: p,
        normals: n,
        uvs: uv,
        triangles: t,
        joints: mouth_joints,
    };
    let mut eyes = Prim::empty("eyes");
    for left in [false, true] {
        let (p, n, uv, t) = eyeball(left);
        let base = eyes.positions.len() as u16;
        eyes.triangles
            .extend(t.iter().map(|tr| tr.map(|i| i + base)));
        eyes.joints
            .extend(std::iter::repeat_n([(head, 1.0), (0, 0.0)], p.len()));
        eyes.positions.extend(p);
        eyes.normals.extend(n);
        eyes.uvs.extend(uv);
    }
    let mut lashes = Prim::empty("lashes");
    for x in [-3.2f32, 3.2] {
        let base = lashes.positions.len() as u16;
        for k in 0..4 {
            let dx = (k as f32 - 1.5) * 0.8;
            for h in [0.0f32, 0.4] {
                lashes
                    .positions
                    .push(HEAD_CENTRE + Vec3::new(x + dx, 3.3 + h, 8.6));
                lashes.normals.push(Vec3::Z);
                lashes.uvs.push(Vec2::new(k as f32 / 3.0, h / 0.4));
            }
        }
        for k in 0..3u16 {
            let (a, b, c, d) = (
                base + 2 * k,
                base + 2 * k + 1,
                base + 2 * k + 2,
                base + 2 * k + 3,
            );
            lashes.triangles.push([a, c, b]);
            lashes.triangles.push([b, c, d]);
        }
        lashes
            .joints
            .extend(std::iter::repeat_n([(head, 1.0), (0, 0.0)], 8));
    }
    vec![skin, mouth, eyes, lashes]
}

/// A binary buffer being written with its buffer views and accessors.
pub struct Bin {
    pub bin: Vec<u8>,
    pub views: Vec<Value>,
    pub accessors: Vec<Value>,
}

impl Bin {
    pub fn view(&mut self, bytes: &[u8], target: Option<u32>) -> usize {
        while self.bin.len() % 4 != 0 {
            self.bin.push(0);
        }
        let mut v = json!({"buffer": 0, "byteOffset": self.bin.len(), "byteLength": bytes.len()});
        if let Some(t) = target {
            v["target"] = json!(t);
        }
        self.bin.extend_from_slice(bytes);
        self.views.push(v);
        self.views.len() - 1
    }
    pub fn acc(&mut self, a: Value) -> usize {
        self.accessors.push(a);
        self.accessors.len() - 1
    }
    pub fn vec3(&mut self, v: &[Vec3], minmax: bool) -> usize {
        let bytes: Vec<u8> = v
            .iter()
            .flat_map(|p| p.to_array())
            .flat_map(f32::to_le_bytes)
            .collect();
        let view = self.view(&bytes, Some(34962));
        let mut a =
            json!({"bufferView": view, "componentType": 5126, "count": v.len(), "type": "VEC3"});
        if minmax {
            let min = v.iter().fold(Vec3::splat(f32::INFINITY), |m, p| m.min(*p));
            let max = v
                .iter()
                .fold(Vec3::splat(f32::NEG_INFINITY), |m, p| m.max(*p));
            a["min"] = json!(min.to_array());
            a["max"] = json!(max.to_array());
        }
        self.acc(a)
    }
    pub fn floats(&mut self, v: &[f32], ty: &str, minmax: bool) -> usize {
        let bytes: Vec<u8> = v.iter().flat_map(|x| x.to_le_bytes()).collect();
        let view = self.view(&bytes, None);
        let per = match ty {
            "SCALAR" => 1,
            "VEC2" => 2,
            "VEC4" => 4,
            "MAT4" => 16,
            _ => 3,
        };
        let mut a =
            json!({"bufferView": view, "componentType": 5126, "count": v.len() / per, "type": ty});
        if minmax {
            let min = v.iter().copied().fold(f32::INFINITY, f32::min);
            let max = v.iter().copied().fold(f32::NEG_INFINITY, f32::max);
            a["min"] = json!([min]);
            a["max"] = json!([max]);
        }
        self.acc(a)
    }
}

/// A skinned primitive of `p` (positions, normals, UVs, joints and weights, indices) with
/// `material`, its data appended to `b`.
pub fn skinned_primitive(b: &mut Bin, p: &Prim, material: usize) -> Value {
    let pos = b.vec3(&p.positions, true);
    let nrm = b.vec3(&p.normals, false);
    let uv_bytes: Vec<u8> = p
        .uvs
        .iter()
        .flat_map(|v| v.to_array())
        .flat_map(f32::to_le_bytes)
        .collect();
    let uv_view = b.view(&uv_bytes, Some(34962));
    let uv = b.acc(
        json!({"bufferView": uv_view, "componentType": 5126, "count": p.uvs.len(), "type": "VEC2"}),
    );
    let jb: Vec<u8> = p
        .joints
        .iter()
        .flat_map(|j| [j[0].0, j[1].0, 0, 0])
        .collect();
    let jv = b.view(&jb, Some(34962));
    let joints = b.acc(
        json!({"bufferView": jv, "componentType": 5121, "count": p.joints.len(), "type": "VEC4"}),
    );
    let wf: Vec<f32> = p
        .joints
        .iter()
        .flat_map(|j| [j[0].1, j[1].1, 0.0, 0.0])
        .collect();
    let wb: Vec<u8> = wf.iter().flat_map(|x| x.to_le_bytes()).collect();
    let wv = b.view(&wb, Some(34962));
    let weights = b.acc(
        json!({"bufferView": wv, "componentType": 5126, "count": p.joints.len(), "type": "VEC4"}),
    );
    let ib: Vec<u8> = p
        .triangles
        .iter()
        .flatten()
        .flat_map(|i| i.to_le_bytes())
        .collect();
    let iv = b.view(&ib, Some(34963));
    let idx = b.acc(json!({"bufferView": iv, "componentType": 5123, "count": p.triangles.len() * 3, "type": "SCALAR"}));
    json!({
        "attributes": {"POSITION": pos, "NORMAL": nrm, "TEXCOORD_0": uv, "JOINTS_0": joints, "WEIGHTS_0": weights},
        "indices": idx,
        "material": material
    })
}

/// A 4×4 checker PNG.
pub fn png() -> Vec<u8> {
    let mut img = fbakit::render::Image::new(4, 4, [200, 160, 140, 255]);
    img.fill_rect(0, 0, 2, 2, [120, 80, 60, 255]);
    let mut out = Vec::new();
    img.encode_png(&mut out).unwrap();
    out
}

/// Local matrices of the nodes (cm): Armature (0.01), Root, Neck, Head, Jaw.
fn joint_worlds() -> [Mat4; 4] {
    let armature = Mat4::from_scale(Vec3::splat(0.01));
    let root = armature;
    let neck = root * Mat4::from_translation(Vec3::new(0.0, 150.0, 0.0));
    let head = neck * Mat4::from_translation(Vec3::new(0.0, 10.0, 0.0));
    let jaw = head * Mat4::from_translation(Vec3::new(0.0, -3.0, 2.0));
    [root, neck, head, jaw]
}

/// Builds the avatar.
pub fn build() -> Avatar {
    build_with(&Options::default())
}

/// Builds the avatar with `opts`.
pub fn build_with(opts: &Options) -> Avatar {
    let prims = body_prims_with(opts);
    let mut b = Bin {
        bin: Vec::new(),
        views: Vec::new(),
        accessors: Vec::new(),
    };
    let png = png();
    let image_view = b.view(&png, None);
    let mut primitives = Vec::new();
    for (k, p) in prims.iter().enumerate() {
        let white_apart = opts.iris_nodes.is_some_and(|i| i.white_nodes);
        if (opts.eye_nodes || opts.skinned_eyes.is_some() || white_apart) && p.name == "eyes" {
            continue;
        }
        let mut primitive = skinned_primitive(&mut b, p, k);
        // The user's own `Blink`: lashes move down, every other primitive stays (dense zeros).
        let blink: Vec<Vec3> = p
            .positions
            .iter()
            .map(|_| {
                if p.name == "lashes" {
                    Vec3::new(0.0, -0.6, 0.0)
                } else {
                    Vec3::ZERO
                }
            })
            .collect();
        let blink = b.vec3(&blink, true);
        primitive["targets"] = json!([{"POSITION": blink}]);
        primitive["extras"] = json!({"part": p.name});
        primitives.push(primitive);
    }
    // Hat: a square pyramid above the head (not skinned, under the Head joint).
    let hat_p = vec![
        Vec3::new(-8.0, 8.0, -8.0),
        Vec3::new(8.0, 8.0, -8.0),
        Vec3::new(8.0, 8.0, 8.0),
        Vec3::new(-8.0, 8.0, 8.0),
        Vec3::new(0.0, 20.0, 0.0),
    ];
    let hat_pos = b.vec3(&hat_p, true);
    let hat_i: Vec<u8> = [0u16, 4, 1, 1, 4, 2, 2, 4, 3, 3, 4, 0]
        .iter()
        .flat_map(|i| i.to_le_bytes())
        .collect();
    let hat_iv = b.view(&hat_i, Some(34963));
    let hat_idx =
        b.acc(json!({"bufferView": hat_iv, "componentType": 5123, "count": 12, "type": "SCALAR"}));
    // The eye meshes of `Options::eye_nodes`: each sphere in its node's own frame.
    let mut eye_meshes = Vec::new();
    assert!(
        !(opts.eye_nodes && opts.iris_nodes.is_some()),
        "eye nodes or iris nodes, not both"
    );
    if opts.eye_nodes || opts.iris_nodes.is_some() {
        let irises = opts.iris_nodes.is_some();
        for left in [true, false] {
            let (p, n, uv, t) = if irises {
                iris_cap(left)
            } else {
                eyeball(left)
            };
            let to_local = eye_node_world(left).inverse();
            let p: Vec<Vec3> = p.iter().map(|&x| to_local.transform_point3(x)).collect();
            let n: Vec<Vec3> = n
                .iter()
                .map(|&x| to_local.transform_vector3(x).normalize())
                .collect();
            let pos = b.vec3(&p, true);
            let nrm = b.vec3(&n, false);
            let uv_bytes: Vec<u8> = uv
                .iter()
                .flat_map(|v| v.to_array())
                .flat_map(f32::to_le_bytes)
                .collect();
            let uv_view = b.view(&uv_bytes, Some(34962));
            let uv = b.acc(json!({"bufferView": uv_view, "componentType": 5126, "count": p.len(), "type": "VEC2"}));
            let ib: Vec<u8> = t.iter().flatten().flat_map(|i| i.to_le_bytes()).collect();
            let iv = b.view(&ib, Some(34963));
            let idx = b.acc(json!({"bufferView": iv, "componentType": 5123, "count": t.len() * 3, "type": "SCALAR"}));
            let name = match (irises, left) {
                (false, true) => "LeftEyeMesh",
                (false, false) => "RightEyeMesh",
                (true, true) => "LeftIris",
                (true, false) => "RightIris",
            };
            eye_meshes.push(json!({
                "name": name,
                "primitives": [{"attributes": {"POSITION": pos, "NORMAL": nrm, "TEXCOORD_0": uv}, "indices": idx, "material": 2}]
            }));
        }
    }
    // The eye whites of `IrisNodes::white_nodes`: each sphere about its node's origin (the
    // eye's centre, in `Head`'s frame).
    if opts.iris_nodes.is_some_and(|i| i.white_nodes) {
        for left in [true, false] {
            let (p, n, uv, t) = eyeball(left);
            let p: Vec<Vec3> = p.iter().map(|&x| x - eye_centre(left)).collect();
            let pos = b.vec3(&p, true);
            let nrm = b.vec3(&n, false);
            let uv_bytes: Vec<u8> = uv
                .iter()
                .flat_map(|v| v.to_array())
                .flat_map(f32::to_le_bytes)
                .collect();
            let uv_view = b.view(&uv_bytes, Some(34962));
            let uv = b.acc(json!({"bufferView": uv_view, "componentType": 5126, "count": p.len(), "type": "VEC2"}));
            let ib: Vec<u8> = t.iter().flatten().flat_map(|i| i.to_le_bytes()).collect();
            let iv = b.view(&ib, Some(34963));
            let idx = b.acc(json!({"bufferView": iv, "componentType": 5123, "count": t.len() * 3, "type": "SCALAR"}));
            eye_meshes.push(json!({
                "name": if left { "LeftEyeWhite" } else { "RightEyeWhite" },
                "primitives": [{"attributes": {"POSITION": pos, "NORMAL": nrm, "TEXCOORD_0": uv}, "indices": idx, "material": 2}]
            }));
        }
    }
    // The eye meshes of `Options::skinned_eyes`: each sphere in the armature's centimetres
    // like `Body`, weighted to its eye joint (slot 4 left, 5 right) and the head (slot 2).
    assert!(
        (opts.vrm_eyes.is_none() && opts.vroid_eyes.is_none())
            || !(opts.eye_nodes || opts.skinned_eyes.is_some()),
        "one eye layout"
    );
    if let Some(share) = opts.skinned_eyes {
        assert!(!opts.eye_nodes, "eye nodes or skinned eyes, not both");
        for (left, slot) in [(true, 4u8), (false, 5u8)] {
            let (p, n, uv, t) = eyeball(left);
            let pos = b.vec3(&p, true);
            let nrm = b.vec3(&n, false);
            let uv_bytes: Vec<u8> = uv
                .iter()
                .flat_map(|v| v.to_array())
                .flat_map(f32::to_le_bytes)
                .collect();
            let uv_view = b.view(&uv_bytes, Some(34962));
            let uv = b.acc(json!({"bufferView": uv_view, "componentType": 5126, "count": p.len(), "type": "VEC2"}));
            let jb: Vec<u8> = p.iter().flat_map(|_| [slot, 2, 0, 0]).collect();
            let jv = b.view(&jb, Some(34962));
            let joints = b.acc(
                json!({"bufferView": jv, "componentType": 5121, "count": p.len(), "type": "VEC4"}),
            );
            let wb: Vec<u8> = p
                .iter()
                .flat_map(|_| [share, 1.0 - share, 0.0, 0.0])
                .flat_map(f32::to_le_bytes)
                .collect();
            let wv = b.view(&wb, Some(34962));
            let weights = b.acc(
                json!({"bufferView": wv, "componentType": 5126, "count": p.len(), "type": "VEC4"}),
            );
            let ib: Vec<u8> = t.iter().flatten().flat_map(|i| i.to_le_bytes()).collect();
            let iv = b.view(&ib, Some(34963));
            let idx = b.acc(json!({"bufferView": iv, "componentType": 5123, "count": t.len() * 3, "type": "SCALAR"}));
            eye_meshes.push(json!({
                "name": if left { "LeftEyeMesh" } else { "RightEyeMesh" },
                "primitives": [{"attributes": {"POSITION": pos, "NORMAL": nrm, "TEXCOORD_0": uv,
                    "JOINTS_0": joints, "WEIGHTS_0": weights}, "indices": idx, "material": 2}]
            }));
        }
    }
    // The highlight mesh of `VroidEyes::highlight_node`, in the armature's centimetres like
    // `Body`.
    if opts.vroid_eyes.is_some_and(|v| v.highlight_node) {
        let primitive = skinned_primitive(&mut b, &highlight_layer(), 2);
        eye_meshes.push(json!({"name": "EyeHighlight", "primitives": [primitive]}));
    }
    // Inverse bind matrices: each joint's world inverse times the armature (the mesh's bind
    // frame); the jaw's bind half a centimetre above its rest.
    let worlds = joint_worlds();
    let armature = Mat4::from_scale(Vec3::splat(0.01));
    let mut ibm = Vec::new();
    for (k, w) in worlds.iter().enumerate() {
        let bind = if k == 3 {
            *w * Mat4::from_translation(Vec3::new(0.0, JAW_BIND_OFFSET, 0.0))
        } else {
            *w
        };
        ibm.extend((bind.inverse() * armature).to_cols_array());
    }
    if opts.skinned_eyes.is_some() || opts.vrm_eyes.is_some() || opts.vroid_eyes.is_some() {
        for left in [true, false] {
            ibm.extend((eye_joint_world(left).inverse() * armature).to_cols_array());
        }
    }
    let ibm = b.floats(&ibm, "MAT4", false);
    // The user's animation: the head nods, Blink closes and opens.
    let times = b.floats(&[0.0, 0.5, 1.0], "SCALAR", true);
    let nod = glam::Quat::from_rotation_x(0.2);
    let rot = b.floats(
        &[
            0.0, 0.0, 0.0, 1.0, nod.x, nod.y, nod.z, nod.w, 0.0, 0.0, 0.0, 1.0,
        ],
        "VEC4",
        false,
    );
    let blinkw = b.floats(&[0.0, 1.0, 0.0], "SCALAR", false);
    let mat = |name: &str, tex: bool| {
        let mut m = json!({"name": name, "pbrMetallicRoughness": {"baseColorFactor": [1.0, 0.9, 0.8, 1.0], "metallicFactor": 0.0}, "extras": {"shader": name}});
        if tex {
            m["pbrMetallicRoughness"]["baseColorTexture"] = json!({"index": 0});
        }
        m
    };
    let mut emissive = mat("eyes", false);
    emissive["emissiveFactor"] = json!([0.1, 0.1, 0.1]);
    emissive["extensions"] = json!({"KHR_materials_emissive_strength": {"emissiveStrength": 2.0}});
    let mut materials = vec![
        mat("skin", true),
        mat("mouth", false),
        emissive,
        mat("lashes", false),
    ];
    materials.extend(prims[4..].iter().map(|p| mat(p.name, false)));
    let hat_material = materials.len();
    materials.push(mat("hat", false));
    let mut json = json!({
        "asset": {"version": "2.0", "generator": "fbakit test avatar", "extras": {"author": "tests", "licence": "CC0"}},
        "extensionsUsed": ["KHR_materials_emissive_strength"],
        "scene": 0,
        "scenes": [{"name": "Scene", "nodes": [0, 7], "extras": {"lighting": "studio"}}],
        "nodes": [
            {"name": "Armature", "scale": [0.01, 0.01, 0.01], "children": [1, 5], "extras": {"fbx": true}},
            {"name": "Root", "children": [2]},
            {"name": "Neck", "translation": [0.0, 150.0, 0.0], "children": [3]},
            {"name": "Head", "translation": [0.0, 10.0, 0.0], "children": [4, 6], "extras": {"bone": "head"}},
            {"name": "Jaw", "translation": [0.0, -3.0, 2.0]},
            {"name": "Body", "mesh": 0, "skin": 0, "extras": {"lod": 0}},
            {"name": "Hat", "mesh": 1, "extras": {"removable": true}},
            {"name": "Camera", "camera": 0, "translation": [0.0, 1.6, 0.6]}
        ],
        "meshes": [
            {"name": "Body", "primitives": primitives, "weights": [0.0], "extras": {"targetNames": ["Blink"], "note": "user mesh"}},
            {"name": "Hat", "primitives": [{"attributes": {"POSITION": hat_pos}, "indices": hat_idx, "material": hat_material}]}
        ],
        "skins": [{"name": "Rig", "joints": [1, 2, 3, 4], "skeleton": 1, "inverseBindMatrices": ibm}],
        "materials": materials,
        "textures": [{"source": 0, "sampler": 0}],
        "samplers": [{"magFilter": 9729, "minFilter": 9987, "wrapS": 33071, "wrapT": 33071}],
        "images": [{"bufferView": image_view, "mimeType": "image/png", "name": "skin_basecolor"}],
        "cameras": [{"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.01, "zfar": 100.0, "aspectRatio": 1.5}, "name": "Cam"}],
        "animations": [{
            "name": "Idle",
            "samplers": [
                {"input": times, "output": rot, "interpolation": "LINEAR"},
                {"input": times, "output": blinkw, "interpolation": "LINEAR"}
            ],
            "channels": [
                {"sampler": 0, "target": {"node": 3, "path": "rotation"}},
                {"sampler": 1, "target": {"node": 5, "path": "weights"}}
            ]
        }],
        "accessors": b.accessors,
        "bufferViews": b.views,
        "buffers": [{"byteLength": b.bin.len()}]
    });
    if opts.eye_nodes || opts.iris_nodes.is_some() {
        json["nodes"][3]["children"] = json!([4, 6, EYES_NODE]);
        let white_nodes = opts.iris_nodes.is_some_and(|i| i.white_nodes);
        if white_nodes {
            json["nodes"][3]["children"] =
                json!([4, 6, EYES_NODE, LEFT_WHITE_NODE, RIGHT_WHITE_NODE]);
        }
        let nodes = json["nodes"].as_array_mut().unwrap();
        let q = |q: glam::Quat| json!(q.to_array());
        nodes.push(
            json!({"name": "Eyes", "translation": EYES_OFFSET.to_array(),
            "rotation": q(eyes_node_rotation()), "children": [LEFT_EYE_NODE, RIGHT_EYE_NODE]}),
        );
        for (left, name, mesh) in [(true, "LeftEye", 2), (false, "RightEye", 3)] {
            nodes.push(json!({"name": name, "mesh": mesh,
                "translation": eye_node_translation(left).to_array(),
                "rotation": q(eye_node_rotation(left))}));
        }
        if white_nodes {
            for (left, name, mesh) in [(true, "LeftEyeWhite", 4), (false, "RightEyeWhite", 5)] {
                nodes.push(json!({"name": name, "mesh": mesh,
                    "translation": (eye_centre(left) - HEAD_CENTRE).to_array()}));
            }
        }
        json["meshes"].as_array_mut().unwrap().extend(eye_meshes);
    } else if opts.skinned_eyes.is_some() {
        json["nodes"][3]["children"] = json!([4, 6, LEFT_EYE_JOINT, RIGHT_EYE_JOINT]);
        json["nodes"][0]["children"] = json!([1, 5, LEFT_EYE_MESH_NODE, RIGHT_EYE_MESH_NODE]);
        json["skins"][0]["joints"] = json!([1, 2, 3, 4, LEFT_EYE_JOINT, RIGHT_EYE_JOINT]);
        let nodes = json["nodes"].as_array_mut().unwrap();
        for (left, name) in [(true, "LeftEye"), (false, "RightEye")] {
            nodes.push(json!({"name": name,
                "translation": eye_joint_translation(left).to_array(),
                "rotation": eye_joint_rotation(left).to_array()}));
        }
        for (mesh, name) in [(2, "LeftEyeMesh"), (3, "RightEyeMesh")] {
            nodes.push(json!({"name": name, "mesh": mesh, "skin": 0}));
        }
        json["meshes"].as_array_mut().unwrap().extend(eye_meshes);
    } else if opts.vrm_eyes.is_some() || opts.vroid_eyes.is_some() {
        assert!(
            opts.vrm_eyes.is_none() || opts.vroid_eyes.is_none(),
            "one eye layout"
        );
        json["nodes"][3]["children"] = json!([4, 6, LEFT_EYE_JOINT, RIGHT_EYE_JOINT]);
        json["skins"][0]["joints"] = json!([1, 2, 3, 4, LEFT_EYE_JOINT, RIGHT_EYE_JOINT]);
        let nodes = json["nodes"].as_array_mut().unwrap();
        for (left, name) in [(true, "LeftEye"), (false, "RightEye")] {
            nodes.push(json!({"name": name,
                "translation": eye_joint_translation(left).to_array(),
                "rotation": eye_joint_rotation(left).to_array()}));
        }
        if !eye_meshes.is_empty() {
            nodes.push(json!({"name": "EyeHighlight", "mesh": 2, "skin": 0}));
            json["nodes"][0]["children"] = json!([1, 5, HIGHLIGHT_NODE]);
            json["meshes"].as_array_mut().unwrap().extend(eye_meshes);
        }
    }
    let mut bin = b.bin;
    while bin.len() % 4 != 0 {
        bin.push(0);
    }
    Avatar { json, bin, prims }
}

impl Avatar {
    /// The avatar as `.glb` bytes.
    pub fn to_glb(&self) -> Vec<u8> {
        super::glb::pack(&self.json, &self.bin)
    }

    /// Writes `dir/NAME.gltf` with its buffer in `dir/NAME.bin` and the texture as
    /// `dir/textures/skin.png` (external files, as exporters write them).
    pub fn write_gltf(&self, dir: &std::path::Path, name: &str) -> std::path::PathBuf {
        let mut json = self.json.clone();
        json["buffers"][0] = json!({"byteLength": self.bin.len(), "uri": format!("{name}.bin")});
        // The image moves out of the buffer into a file (its view stays, unused by images).
        let view = json["images"][0]["bufferView"].as_u64().unwrap() as usize;
        let v = &json["bufferViews"][view];
        let (o, l) = (
            v["byteOffset"].as_u64().unwrap() as usize,
            v["byteLength"].as_u64().unwrap() as usize,
        );
        std::fs::create_dir_all(dir.join("textures")).unwrap();
        std::fs::write(dir.join("textures/skin.png"), &self.bin[o..o + l]).unwrap();
        json["images"][0] = json!({"uri": "textures/skin.png", "name": "skin_basecolor"});
        std::fs::write(dir.join(format!("{name}.bin")), &self.bin).unwrap();
        let path = dir.join(format!("{name}.gltf"));
        std::fs::write(&path, serde_json::to_string_pretty(&json).unwrap()).unwrap();
        path
    }
}

/// Feature points for the avatar as a positions CSV: the source face's points, scaled so its
/// pupils land on the avatar's, then pushed onto the head sphere (the pupils onto the eyes'
/// front poles). Teeth and tongue points are left out (the avatar's mouth is no teeth).
/// `extra` lines are appended as they are.
pub fn fp_csv(
    source: &fbakit::face::FaceModel,
    dir: &std::path::Path,
    extra: &str,
) -> std::path::PathBuf {
    let s = &source.feature_points;
    let (l, r) = (
        s.position("3.5".parse().unwrap()).unwrap(),
        s.position("3.6".parse().unwrap()).unwrap(),
    );
    // +x is the face's own left: 3.5 on the +x eye.
    let (al, ar) = (
        Vec3::new(0.032, 1.62, 0.087),
        Vec3::new(-0.032, 1.62, 0.087),
    );
    let scale = al.distance(ar) / l.distance(r);
    let mid = (l + r) / 2.0;
    let amid = (al + ar) / 2.0;
    let mut body = String::from("fp,x,y,z\n");
    for p in s.iter() {
        let id = p.id.to_string();
        if id.starts_with("9.8")
            || ["9.9", "9.10", "9.11"].contains(&id.as_str())
            || id.starts_with("6.")
        {
            continue;
        }
        let q = match id.as_str() {
            "3.5" => al,
            "3.6" => ar,
            _ => {
                let q = amid + (s.position(p.id).unwrap() - mid) * scale;
                // The head sphere in the file's world frame (metres: the armature's 0.01).
                let c = Vec3::new(0.0, 1.6, 0.0);
                c + (q - c).normalize() * 0.1
            }
        };
        body.push_str(&format!("{id},{},{},{}\n", q.x, q.y, q.z));
    }
    body.push_str(extra);
    let path = dir.join("avatar-fp.csv");
    std::fs::write(&path, body).unwrap();
    path
}

/// `face diff` of a clone onto an avatar without a head transform (`cloned`, whose head turns
/// are per-vertex tables: the clone creates no transform) and the file written from it
/// (`back`, whose head turns are one rotation each of a root above every mesh, shown by the
/// avatar's head node). Checks that shape of the head tables, then compares the rest.
pub fn same_fat_head_on_node(
    cloned: &fbakit::face::FaceModel,
    back: &fbakit::face::FaceModel,
) -> fbakit::snapshot::FaceDiff {
    use fbakit::fat::TableKey;
    let is_head =
        |k: TableKey| matches!(k, TableKey::LowLevel(f) if (48..=50).contains(&f.number()));
    let (mut cloned, mut back) = (cloned.clone(), back.clone());
    for f in 48u8..=50 {
        let key = TableKey::LowLevel(fbakit::spec::FapId::new(f).unwrap());
        let c = cloned.fat.table(key).expect("the clone turns the head");
        assert!(c.transforms.is_empty() && !c.meshes.is_empty(), "FAP {f}");
        let b = back.fat.table(key).expect("the file turns the head");
        assert!(b.meshes.is_empty(), "FAP {f} is also a morph");
        assert_eq!(b.transforms.len(), 1, "FAP {f}");
        let t = back.transform_index(&b.transforms[0].transform).unwrap();
        assert!(back.transforms[t].parent.is_none(), "the head is a root");
    }
    cloned.fat.tables.retain(|t| !is_head(t.key));
    back.fat.tables.retain(|t| !is_head(t.key));
    // The root above everything that the file's head node shows, its rest the identity.
    let head = back
        .transforms
        .iter()
        .position(|t| t.parent.is_none() && cloned.transform_index(&t.name).is_none())
        .expect("a head transform in the file");
    back.transforms.remove(head);
    let shift = |i: usize| if i > head { i - 1 } else { i };
    for x in &mut back.transforms {
        x.parent = x.parent.filter(|&p| p != head).map(shift);
    }
    for m in &mut back.meshes {
        m.transform = m.transform.filter(|&p| p != head).map(shift);
    }
    fbakit::snapshot::diff(&cloned, &back, &fbakit::snapshot::DiffOptions::default())
}
