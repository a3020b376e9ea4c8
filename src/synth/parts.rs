//! Eyeballs, teeth and tongue, placed against the skin, and the transform hierarchy.

use glam::{DVec3, Vec3};

use super::names;
use super::skin::Skin;
use super::{HeadParams, PolygonStyle, SynthMesh, SynthTransform};
use crate::spec::FeaturePointId;

/// Geometry facts the FAT builder needs.
pub(super) struct PartsInfo {
    /// Jaw hinge (centre of `jaw_tf`), on the midline.
    pub jaw_hinge: DVec3,
    /// Eyeball centres, left then right.
    pub eye_centres: [DVec3; 2],
    /// Vertices of the pupil ring (same indices in both eye meshes).
    pub pupil_ring: Vec<u32>,
}

pub(super) struct Parts {
    pub transforms: Vec<SynthTransform>,
    /// Meshes after the skin: eye_l, eye_r, teeth_upper, teeth_lower, tongue (mesh indices 1..=5).
    pub meshes: Vec<SynthMesh>,
    /// (point, mesh index, vertex).
    pub feature_points: Vec<(FeaturePointId, usize, u32)>,
    pub info: PartsInfo,
}

/// Positions and polygons of one closed mesh being built.
struct Solid {
    positions: Vec<DVec3>,
    polygons: Vec<Vec<u32>>,
}

impl Solid {
    /// A closed surface of revolution-like topology: a front pole, rings of equal size, a back
    /// pole. Orientation is fixed afterwards by [`Solid::orient_outwards`].
    fn rings(front: DVec3, rings: &[Vec<DVec3>], back: DVec3, style: PolygonStyle) -> Solid {
        let seg = rings[0].len();
        let mut positions = vec![front];
        for r in rings {
            assert_eq!(r.len(), seg);
            positions.extend_from_slice(r);
        }
        positions.push(back);
        let back_i = (positions.len() - 1) as u32;
        let at = |ring: usize, s: usize| (1 + ring * seg + (s % seg)) as u32;
        let mut polygons = Vec::new();
        for s in 0..seg {
            polygons.push(vec![0, at(0, s + 1), at(0, s)]);
            for ring in 0..rings.len() - 1 {
                quad(
                    &mut polygons,
                    [
                        at(ring, s),
                        at(ring, s + 1),
                        at(ring + 1, s + 1),
                        at(ring + 1, s),
                    ],
                    style,
                    (ring + s) % 2 == 0,
                );
            }
            let last = rings.len() - 1;
            polygons.push(vec![at(last, s), at(last, s + 1), back_i]);
        }
        let mut solid = Solid {
            positions,
            polygons,
        };
        solid.orient_outwards();
        solid
    }

    /// Flips every polygon when the enclosed signed volume is negative (the construction is
    /// consistent, so only the global sense can be wrong).
    fn orient_outwards(&mut self) {
        if signed_volume(&self.positions, &self.polygons) < 0.0 {
            for p in &mut self.polygons {
                p.reverse();
            }
        }
    }

    fn into_mesh(self, name: &str, transform: usize, colour: [f32; 3]) -> SynthMesh {
        SynthMesh {
            name: name.into(),
            transform,
            positions: self.positions.iter().map(|p| p.as_vec3()).collect(),
            polygons: self.polygons,
            uvs: None,
            colour,
        }
    }
}

fn quad(out: &mut Vec<Vec<u32>>, q: [u32; 4], style: PolygonStyle, parity: bool) {
    match style {
        PolygonStyle::Quads => out.push(q.to_vec()),
        PolygonStyle::Triangles if parity => {
            out.push(vec![q[0], q[1], q[2]]);
            out.push(vec![q[0], q[2], q[3]]);
        }
        PolygonStyle::Triangles => {
            out.push(vec![q[0], q[1], q[3]]);
            out.push(vec![q[1], q[2], q[3]]);
        }
    }
}

/// Signed volume enclosed by polygons (fan-triangulated); positive when they face outwards.
pub(super) fn signed_volume(positions: &[DVec3], polygons: &[Vec<u32>]) -> f64 {
    let mut v = 0.0;
    for poly in polygons {
        let a = positions[poly[0] as usize];
        for w in poly[1..].windows(2) {
            let b = positions[w[0] as usize];
            let c = positions[w[1] as usize];
            v += a.dot(b.cross(c));
        }
    }
    v / 6.0
}

pub(super) fn build(p: &HeadParams, skin: &Skin) -> Parts {
    use std::f64::consts::{PI, TAU};
    let style = p.polygons;
    let seg = 4 * ((p.columns as f64 / 20.0).round() as usize).max(3);
    let back_rings = (seg / 2).max(8);

    // Eyeballs: the iris ring passes through the lid feature points (lids tangent to the
    // iris), the pupil is a third of the iris, and the ball covers the whole opening.
    let mut eyes = Vec::new();
    let mut eye_centres = [DVec3::ZERO; 2];
    let mut pupil_ring = Vec::new();
    for (side, (top, bottom, outer, inner)) in [
        (
            FeaturePointId::FP_3_1,
            FeaturePointId::FP_3_3,
            FeaturePointId::FP_3_7,
            FeaturePointId::FP_3_11,
        ),
        (
            FeaturePointId::FP_3_2,
            FeaturePointId::FP_3_4,
            FeaturePointId::FP_3_12,
            FeaturePointId::FP_3_8,
        ),
    ]
    .into_iter()
    .enumerate()
    {
        let (t, b) = (skin.fp(top), skin.fp(bottom));
        let half_width = (skin.fp(outer).x - skin.fp(inner).x).abs() / 2.0;
        let iris_r = (t.y - b.y) / 2.0;
        let radius = (1.15 * half_width).max(2.2 * iris_r);
        let lid_z = t.z.min(b.z);
        let centre = DVec3::new(
            (t.x + b.x) / 2.0,
            (t.y + b.y) / 2.0,
            lid_z - (radius * radius - iris_r * iris_r).sqrt(),
        );
        eye_centres[side] = centre;
        let pupil_r = iris_r / 3.0;
        let mut thetas = vec![
            (pupil_r / radius).asin(),
            (2.0 * pupil_r / radius).asin(),
            (iris_r / radius).asin(),
        ];
        let th_i = thetas[2];
        for i in 1..back_rings {
            thetas.push(th_i + (PI - th_i) * i as f64 / back_rings as f64);
        }
        let rings: Vec<Vec<DVec3>> = thetas
            .iter()
            .map(|&th| {
                (0..seg)
                    .map(|s| {
                        let psi = TAU * s as f64 / seg as f64;
                        centre
                            + radius
                                * DVec3::new(th.sin() * psi.cos(), th.sin() * psi.sin(), th.cos())
                    })
                    .collect()
            })
            .collect();
        let solid = Solid::rings(
            centre + DVec3::Z * radius,
            &rings,
            centre - DVec3::Z * radius,
            style,
        );
        pupil_ring = (0..seg as u32).map(|s| 1 + s).collect();
        eyes.push(solid);
    }

    // Teeth: two arches (closed bent slabs) meeting at the slit height, behind the lips.
    let slit = skin.fp(FeaturePointId::FP_2_2);
    let lip_thickness = 0.35 * (p.upper_lip_height + p.lower_lip_height);
    let z_front = slit.z - lip_thickness;
    let arch_w = 0.8 * p.mouth_half_width;
    let arch_d = 0.9 * p.mouth_half_width;
    let thickness = 5.0;
    let tooth_h = 8.0;
    let samples = 2 * (seg / 3) + 1; // odd: the middle sample is on the midline
    let arch = |y0: f64, y1: f64| -> Solid {
        let psi_max = 1.35;
        let mut positions = Vec::new();
        for i in 0..samples {
            let psi = -psi_max + 2.0 * psi_max * i as f64 / (samples - 1) as f64;
            let c = DVec3::new(
                arch_w * psi.sin(),
                0.0,
                z_front - arch_d * (1.0 - psi.cos()),
            );
            let n = DVec3::new(arch_d * psi.sin(), 0.0, arch_w * psi.cos()).normalize();
            let inner = c - thickness * n;
            let mut c = c;
            if i == (samples - 1) / 2 {
                c.x = 0.0;
            }
            positions.extend([
                DVec3::new(c.x, y0, c.z),
                DVec3::new(c.x, y1, c.z),
                DVec3::new(inner.x, y1, inner.z),
                DVec3::new(inner.x, y0, inner.z),
            ]);
        }
        let mut polygons = Vec::new();
        for i in 0..samples - 1 {
            let a = (4 * i) as u32;
            let b = a + 4;
            for side in 0..4u32 {
                let s1 = (side + 1) % 4;
                quad(
                    &mut polygons,
                    [a + side, b + side, b + s1, a + s1],
                    style,
                    (i as u32 + side) % 2 == 0,
                );
            }
        }
        let last = (4 * (samples - 1)) as u32;
        quad(&mut polygons, [0, 1, 2, 3], style, true);
        quad(
            &mut polygons,
            [last + 3, last + 2, last + 1, last],
            style,
            true,
        );
        let mut s = Solid {
            positions,
            polygons,
        };
        s.orient_outwards();
        s
    };
    let teeth_upper = arch(slit.y, slit.y + tooth_h);
    let teeth_lower = arch(slit.y - tooth_h, slit.y);
    let mid = (4 * ((samples - 1) / 2)) as u32;

    // Tongue: a flat ellipsoid lying on the floor of the mouth, its top level with the teeth
    // boundary and its tip (front pole) just behind the lower front teeth.
    let t_rings = 2 * (seg / 6) + 1; // odd: a ring at the equator (theta = pi/2)
    let (rx, ry, rz) = (0.6 * p.mouth_half_width, 3.5, 0.9 * p.mouth_half_width);
    let t_centre = DVec3::new(0.0, slit.y - ry, z_front - thickness - 1.0 - rz);
    let t_seg = 4 * (seg / 4);
    let rings: Vec<Vec<DVec3>> = (1..=t_rings)
        .map(|i| {
            let th = PI * i as f64 / (t_rings + 1) as f64;
            (0..t_seg)
                .map(|s| {
                    let psi = TAU * s as f64 / t_seg as f64;
                    let mut q = t_centre
                        + DVec3::new(
                            rx * th.sin() * psi.cos(),
                            ry * th.sin() * psi.sin(),
                            rz * th.cos(),
                        );
                    if s == t_seg / 4 || s == 3 * t_seg / 4 {
                        q.x = 0.0;
                    }
                    q
                })
                .collect()
        })
        .collect();
    let tongue = Solid::rings(
        t_centre + DVec3::Z * rz,
        &rings,
        t_centre - DVec3::Z * rz,
        style,
    );
    let eq = (t_rings - 1) / 2; // ring index of the equator
    let tongue_at = |s: usize| (1 + eq * t_seg + s) as u32;

    let hinge = DVec3::new(
        0.0,
        p.ear_y - 0.25 * p.ear_half_height,
        p.ear_z + p.ear_half_depth + 6.0,
    );
    let tf = |name: &str, parent: Option<usize>, center: DVec3| SynthTransform {
        name: name.into(),
        parent,
        translation: Vec3::ZERO,
        rotation_axis: Vec3::Z,
        rotation_angle: 0.0,
        scale: Vec3::ONE,
        center: center.as_vec3(),
    };
    let transforms = vec![
        tf(names::HEAD_TF, None, skin.fp(FeaturePointId::FP_7_1)),
        tf(names::EYE_L_TF, Some(0), eye_centres[0]),
        tf(names::EYE_R_TF, Some(0), eye_centres[1]),
        tf(
            names::TEETH_UPPER_TF,
            Some(0),
            teeth_upper.positions[mid as usize],
        ),
        tf(names::JAW_TF, Some(0), hinge),
    ];
    let mut eyes = eyes.into_iter();
    let eye_colour = [0.95, 0.95, 0.93];
    let teeth_colour = [0.96, 0.94, 0.86];
    let meshes = vec![
        eyes.next()
            .expect("left")
            .into_mesh(names::EYE_L, 1, eye_colour),
        eyes.next()
            .expect("right")
            .into_mesh(names::EYE_R, 2, eye_colour),
        teeth_upper.into_mesh(names::TEETH_UPPER, 3, teeth_colour),
        teeth_lower.into_mesh(names::TEETH_LOWER, 4, teeth_colour),
        tongue.into_mesh(names::TONGUE, 4, [0.80, 0.36, 0.40]),
    ];
    let feature_points = vec![
        (FeaturePointId::FP_3_5, 1, 0),
        (FeaturePointId::FP_3_6, 2, 0),
        (FeaturePointId::FP_9_8, 3, mid + 1),
        (FeaturePointId::FP_9_10, 3, mid),
        (FeaturePointId::FP_9_9, 4, mid),
        (FeaturePointId::FP_9_11, 4, mid + 1),
        (FeaturePointId::FP_6_1, 5, 0),
        (FeaturePointId::FP_6_2, 5, tongue_at(t_seg / 4)),
        (FeaturePointId::FP_6_3, 5, tongue_at(0)),
        (FeaturePointId::FP_6_4, 5, tongue_at(t_seg / 2)),
    ];
    Parts {
        transforms,
        meshes,
        feature_points,
        info: PartsInfo {
            jaw_hinge: hinge,
            eye_centres,
            pupil_ring,
        },
    }
}
