//! The low-level FAT of a synthetic face, exact by construction.
//!
//! - **Local translation FAPs** (lips, chin, brows, cheeks, nose, ears, tongue tip/body): every
//!   vertex within radius `R` of the FAP's feature point moves at rate
//!   `direction × FAPU unit × w`, `w = ½(1 + cos(π d / R))` of the Euclidean distance `d`,
//!   so `w = 1` at the feature point and its displacement at value `P` is exactly
//!   `P × FAPU × direction`. Upper-lip FAPs only move vertices above the mouth slit, lower-lip
//!   FAPs only the lower-lip side (slit copies and rows below); left FAPs only `x > 0`, right
//!   FAPs only `x < 0` (their radius is capped at the point's distance to the midline).
//! - **Eyelids** (19–22): lid vertices move with `w = |v| / ρ × falloff(ρ − 1)` in
//!   coordinates normalised to the elliptical opening (`ρ` = 1 on the lid edge), so the lid
//!   edge follows the opening's profile and the eye closes exactly at top + bottom = 1024.
//! - **open_jaw** (3): a rotation of the lower face about the jaw hinge, sampled at borders
//!   `0 512 1024` (two intervals approximating the arc) and scaled by a smooth jaw-region
//!   weight that is 1 at FP 2.1; the angles are chosen so that FP 2.1 drops by exactly
//!   `P × MNS` (it also moves back along the arc, as a real jaw does). `jaw_tf` (lower teeth
//!   and tongue) rotates about the hinge at the mean angular rate.
//! - **thrust_jaw / shift_jaw** (14, 15): the jaw region translates, and `jaw_tf` with it.
//! - **Eyeballs** (23–26): rotations of `eye_l_tf` / `eye_r_tf` about the eyeball centres,
//!   1e-5 rad per unit, axis from [`crate::spec::FapInfo::rotation_axis`]; **thrust** (27, 28):
//!   translations of the same transforms by ES along +z.
//! - **Pupils** (29, 30): pupil-ring vertices move radially so the pupil *diameter* grows by
//!   `P × IRISD` (radius by half that).
//! - **tongue_roll** (47): linearised rotation of each tongue half about the midline: a vertex
//!   at lateral distance `|x|` rises by `|x| × P × 1e-5`.
//! - **Head** (48–50): rotations of `head` about FP 7.1.
//!
//! Interval borders: bidirectional FAPs `-1024 0 1024` with the same rate on both sides,
//! unidirectional `0 1024` (open_jaw `0 512 1024`, tongue_roll `0 20000` AU); beyond the
//! outer borders the outer rate continues (see [`crate::fat::interval_weights`]).

use glam::{DMat3, DVec3, Vec3};

use super::names;
use super::parts::PartsInfo;
use super::skin::{smoothstep, Skin};
use super::SynthFace;
use crate::fat::{FaceDefMesh, FaceDefTable, FaceDefTransform, Fat, TableKey};
use crate::fdp::fapu::Fapu;
use crate::spec::{Directionality, FapId, FapuKind, FeaturePointId, AU_RADIANS};

#[derive(Clone, Copy, PartialEq)]
enum Lip {
    Any,
    Upper,
    Lower,
}

#[derive(Clone, Copy, PartialEq)]
enum Side {
    Both,
    Left,
    Right,
}

/// Which mesh a local FAP deforms.
#[derive(Clone, Copy, PartialEq)]
enum Target {
    Skin,
    Tongue,
}

/// How one low-level FAP is realised.
enum Recipe {
    Local {
        fp: FeaturePointId,
        target: Target,
        /// Radius as a multiple of the FAPU distance `of`.
        radius: f64,
        of: FapuKind,
        lip: Lip,
        side: Side,
    },
    Lid {
        left: bool,
        upper: bool,
    },
    OpenJaw,
    JawTranslate,
    EyeRotate {
        left: bool,
    },
    EyeThrust {
        left: bool,
    },
    Pupil {
        left: bool,
    },
    TongueRoll,
    Head,
}

fn recipe(fap: FapId) -> Recipe {
    use FapuKind::{Ens, Es, Mw};
    let lip = |fp, radius, lip, side| Recipe::Local {
        fp,
        target: Target::Skin,
        radius,
        of: Mw,
        lip,
        side,
    };
    let skin = |fp, radius, of, side| Recipe::Local {
        fp,
        target: Target::Skin,
        radius,
        of,
        lip: Lip::Any,
        side,
    };
    let tongue = |fp, radius| Recipe::Local {
        fp,
        target: Target::Tongue,
        radius,
        of: Mw,
        lip: Lip::Any,
        side: Side::Both,
    };
    use Lip::{Any, Lower, Upper};
    use Side::{Both, Left, Right};
    match fap.number() {
        3 => Recipe::OpenJaw,
        4 | 17 => lip(FeaturePointId::FP_2_2, 0.28, Upper, Both),
        5 | 16 => lip(FeaturePointId::FP_2_3, 0.28, Lower, Both),
        6 | 12 => lip(FeaturePointId::FP_2_4, 0.28, Any, Left),
        7 | 13 => lip(FeaturePointId::FP_2_5, 0.28, Any, Right),
        8 => lip(FeaturePointId::FP_2_6, 0.22, Upper, Left),
        9 => lip(FeaturePointId::FP_2_7, 0.22, Upper, Right),
        10 => lip(FeaturePointId::FP_2_8, 0.22, Lower, Left),
        11 => lip(FeaturePointId::FP_2_9, 0.22, Lower, Right),
        14 | 15 => Recipe::JawTranslate,
        18 => lip(FeaturePointId::FP_2_10, 0.3, Lower, Both),
        19 => Recipe::Lid {
            left: true,
            upper: true,
        },
        20 => Recipe::Lid {
            left: false,
            upper: true,
        },
        21 => Recipe::Lid {
            left: true,
            upper: false,
        },
        22 => Recipe::Lid {
            left: false,
            upper: false,
        },
        23 | 25 => Recipe::EyeRotate { left: true },
        24 | 26 => Recipe::EyeRotate { left: false },
        27 => Recipe::EyeThrust { left: true },
        28 => Recipe::EyeThrust { left: false },
        29 => Recipe::Pupil { left: true },
        30 => Recipe::Pupil { left: false },
        31 | 37 => skin(FeaturePointId::FP_4_1, 0.25, Es, Left),
        32 | 38 => skin(FeaturePointId::FP_4_2, 0.25, Es, Right),
        33 => skin(FeaturePointId::FP_4_3, 0.25, Es, Left),
        34 => skin(FeaturePointId::FP_4_4, 0.25, Es, Right),
        35 => skin(FeaturePointId::FP_4_5, 0.25, Es, Left),
        36 => skin(FeaturePointId::FP_4_6, 0.25, Es, Right),
        39 => skin(FeaturePointId::FP_5_1, 0.3, Es, Left),
        40 => skin(FeaturePointId::FP_5_2, 0.3, Es, Right),
        41 => skin(FeaturePointId::FP_5_3, 0.3, Es, Left),
        42 => skin(FeaturePointId::FP_5_4, 0.3, Es, Right),
        43..=45 => tongue(FeaturePointId::FP_6_1, 0.9),
        46 => tongue(FeaturePointId::FP_6_2, 0.8),
        47 => Recipe::TongueRoll,
        48..=50 => Recipe::Head,
        51 => lip(FeaturePointId::FP_8_1, 0.28, Upper, Both),
        52 => lip(FeaturePointId::FP_8_2, 0.28, Lower, Both),
        53 | 59 => lip(FeaturePointId::FP_8_3, 0.28, Any, Left),
        54 | 60 => lip(FeaturePointId::FP_8_4, 0.28, Any, Right),
        55 => lip(FeaturePointId::FP_8_5, 0.22, Upper, Left),
        56 => lip(FeaturePointId::FP_8_6, 0.22, Upper, Right),
        57 => lip(FeaturePointId::FP_8_7, 0.22, Lower, Left),
        58 => lip(FeaturePointId::FP_8_8, 0.22, Lower, Right),
        61 => skin(FeaturePointId::FP_9_1, 0.2, Ens, Left),
        62 => skin(FeaturePointId::FP_9_2, 0.2, Ens, Right),
        63 | 64 => skin(FeaturePointId::FP_9_3, 0.3, Ens, Both),
        65 => skin(FeaturePointId::FP_10_1, 0.6, Ens, Left),
        66 => skin(FeaturePointId::FP_10_2, 0.6, Ens, Right),
        67 => skin(FeaturePointId::FP_10_3, 0.6, Ens, Left),
        68 => skin(FeaturePointId::FP_10_4, 0.6, Ens, Right),
        n => unreachable!("FAP {n} is not low-level"),
    }
}

/// Raised-cosine falloff: 1 at 0, 0 from `r` on.
fn falloff(d: f64, r: f64) -> f64 {
    if d >= r {
        0.0
    } else {
        0.5 * (1.0 + (std::f64::consts::PI * d / r).cos())
    }
}

fn borders(fap: FapId) -> Vec<f64> {
    match fap.info().directionality {
        Some(Directionality::Unidirectional) => vec![0.0, 1024.0],
        _ => vec![-1024.0, 0.0, 1024.0],
    }
}

/// A FaceDefMesh from per-vertex rates (the same rate in every interval).
fn uniform_mesh(mesh: &str, borders: Vec<f64>, rates: Vec<(u32, DVec3)>) -> FaceDefMesh {
    let n = borders.len() - 1;
    let mut coord_index = Vec::with_capacity(rates.len());
    let mut displacements = Vec::with_capacity(rates.len() * n);
    for (v, r) in rates {
        coord_index.push(v);
        displacements.extend(std::iter::repeat_n(r.as_vec3(), n));
    }
    FaceDefMesh {
        mesh: mesh.into(),
        interval_borders: borders,
        coord_index,
        displacements,
    }
}

struct Ctx<'a> {
    face: &'a SynthFace,
    skin: &'a Skin,
    info: &'a PartsInfo,
    fapu: Fapu,
    tongue: Vec<DVec3>,
}

impl Ctx<'_> {
    fn fp(&self, id: FeaturePointId) -> DVec3 {
        self.face
            .feature_point(id)
            .expect("feature point")
            .position
            .as_dvec3()
    }

    fn unit(&self, kind: FapuKind) -> f64 {
        self.fapu.unit(kind)
    }

    /// Jaw-region weight of every skin vertex: 1 on the lower lip middle, chin and jaw, fading
    /// to 0 at the mouth corners, the jaw line, behind the hinge and down the neck.
    fn jaw_weights(&self) -> Vec<f64> {
        let d = &self.fapu.distances;
        let slit_y = self.fp(FeaturePointId::FP_2_2).y;
        let corner_x = self.fp(FeaturePointId::FP_2_4).x;
        let chin = self.fp(FeaturePointId::FP_2_1);
        let pivot_y = self.fp(FeaturePointId::FP_7_1).y;
        let jaw_x = self.fp(FeaturePointId::FP_2_13).x;
        let hinge = self.info.jaw_hinge;
        let blend_h = 0.5 * d.mns0;
        self.skin
            .positions
            .iter()
            .zip(&self.skin.lower)
            .map(|(p, &lower)| {
                if !lower {
                    return 0.0;
                }
                let a = (slit_y - p.y) / blend_h;
                let h = ((corner_x - p.x.abs()) / (0.3 * corner_x)).max(0.0);
                let l = smoothstep(0.0, 1.0, a + h);
                let fx = 1.0 - smoothstep(0.8 * jaw_x, 1.15 * jaw_x, p.x.abs());
                let fz = smoothstep(hinge.z - 25.0, hinge.z + 5.0, p.z);
                let fy = smoothstep(pivot_y + 0.3 * (chin.y - pivot_y), chin.y, p.y);
                l * fx * fz * fy
            })
            .collect()
    }

    fn table(&self, fap: FapId) -> FaceDefTable {
        let info = fap.info();
        let mut t = FaceDefTable::new(TableKey::LowLevel(fap));
        let dir = info.direction().map(|d| d.as_dvec3());
        let unit = info.fapu.map(|k| self.unit(k)).unwrap_or(0.0);
        match recipe(fap) {
            Recipe::Local {
                fp,
                target,
                radius,
                of,
                lip,
                side,
            } => {
                let centre = self.fp(fp);
                let mut r = radius * self.fapu.distance(of).expect("distance FAPU");
                if side != Side::Both {
                    r = r.min(centre.x.abs());
                }
                let (positions, mesh_name) = match target {
                    Target::Skin => (&self.skin.positions, names::SKIN),
                    Target::Tongue => (&self.tongue, names::TONGUE),
                };
                let rate = dir.expect("translation FAP") * unit;
                let rates = positions
                    .iter()
                    .enumerate()
                    .filter_map(|(v, p)| {
                        if target == Target::Skin {
                            let lower = self.skin.lower[v];
                            let lip_ok = match lip {
                                Lip::Any => true,
                                Lip::Upper => !lower,
                                Lip::Lower => lower,
                            };
                            let side_ok = match side {
                                Side::Both => true,
                                Side::Left => p.x > 0.0,
                                Side::Right => p.x < 0.0,
                            };
                            if !lip_ok || !side_ok {
                                return None;
                            }
                        }
                        let w = falloff(p.distance(centre), r);
                        (w > 0.0).then(|| (v as u32, rate * w))
                    })
                    .collect();
                t.meshes.push(uniform_mesh(mesh_name, borders(fap), rates));
            }
            Recipe::Lid { left, upper } => {
                let rate = dir.expect("translation FAP") * unit;
                let rates = (0..self.skin.positions.len())
                    .filter_map(|v| {
                        let p = self.skin.positions[v];
                        if (left && p.x <= 0.0) || (!left && p.x >= 0.0) {
                            return None;
                        }
                        let e = self.skin.eye_coords[v];
                        if (upper && e.y <= 0.0) || (!upper && e.y >= 0.0) {
                            return None;
                        }
                        let rho = e.length();
                        let w = (e.y.abs() / rho).min(1.0) * falloff((rho - 1.0).max(0.0), 0.9);
                        (w > 0.0).then(|| (v as u32, rate * w))
                    })
                    .collect();
                t.meshes
                    .push(uniform_mesh(names::SKIN, borders(fap), rates));
            }
            Recipe::OpenJaw => self.open_jaw(&mut t),
            Recipe::JawTranslate => {
                let rate = dir.expect("translation FAP") * unit;
                let rates = self
                    .jaw_weights()
                    .into_iter()
                    .enumerate()
                    .filter(|(_, w)| *w > 0.0)
                    .map(|(v, w)| (v as u32, rate * w))
                    .collect();
                t.meshes
                    .push(uniform_mesh(names::SKIN, borders(fap), rates));
                t.transforms
                    .push(FaceDefTransform::translation(names::JAW_TF, rate.as_vec3()));
            }
            Recipe::EyeRotate { left } => {
                let axis = info.rotation_axis().expect("eyeball rotation axis");
                let name = if left {
                    names::EYE_L_TF
                } else {
                    names::EYE_R_TF
                };
                t.transforms
                    .push(FaceDefTransform::rotation(name, axis, AU_RADIANS as f32));
            }
            Recipe::EyeThrust { left } => {
                let name = if left {
                    names::EYE_L_TF
                } else {
                    names::EYE_R_TF
                };
                t.transforms.push(FaceDefTransform::translation(
                    name,
                    (DVec3::Z * unit).as_vec3(),
                ));
            }
            Recipe::Pupil { left } => {
                let (mesh, centre) = if left {
                    (1, self.info.eye_centres[0])
                } else {
                    (2, self.info.eye_centres[1])
                };
                let positions = &self.face.meshes[mesh].positions;
                let rates = self
                    .info
                    .pupil_ring
                    .iter()
                    .map(|&v| {
                        let q = positions[v as usize].as_dvec3() - centre;
                        let radial = DVec3::new(q.x, q.y, 0.0).normalize();
                        (v, radial * 0.5 * unit)
                    })
                    .collect();
                t.meshes.push(uniform_mesh(
                    &self.face.meshes[mesh].name,
                    borders(fap),
                    rates,
                ));
            }
            Recipe::TongueRoll => {
                let mid_x = self.fp(FeaturePointId::FP_6_1).x;
                let rates = self
                    .tongue
                    .iter()
                    .enumerate()
                    .filter(|(_, p)| p.x != mid_x)
                    .map(|(v, p)| (v as u32, DVec3::Y * (p.x - mid_x).abs() * AU_RADIANS))
                    .collect();
                t.meshes
                    .push(uniform_mesh(names::TONGUE, vec![0.0, 20_000.0], rates));
            }
            Recipe::Head => {
                let axis = info.rotation_axis().expect("head rotation axis");
                t.transforms.push(FaceDefTransform::rotation(
                    names::HEAD_TF,
                    axis,
                    AU_RADIANS as f32,
                ));
            }
        }
        t
    }

    fn open_jaw(&self, t: &mut FaceDefTable) {
        let hinge = self.info.jaw_hinge;
        let chin = self.fp(FeaturePointId::FP_2_1) - hinge;
        let mns = self.unit(FapuKind::Mns);
        // Angle at which the chin point has dropped by `drop`.
        let angle_for = |drop: f64| -> f64 {
            let dy = |th: f64| -> f64 { (DMat3::from_rotation_x(th) * chin).y - chin.y };
            let (mut lo, mut hi) = (0.0, 1.0);
            for _ in 0..100 {
                let mid = 0.5 * (lo + hi);
                if -dy(mid) < drop {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            0.5 * (lo + hi)
        };
        let borders = [0.0, 512.0, 1024.0];
        let angles: Vec<f64> = borders.iter().map(|&b| angle_for(b * mns)).collect();
        let weights = self.jaw_weights();
        let mut coord_index = Vec::new();
        let mut displacements = Vec::new();
        for (v, (&p, &w)) in self.skin.positions.iter().zip(&weights).enumerate() {
            if w <= 0.0 {
                continue;
            }
            let rel = p - hinge;
            let offset = |th: f64| (DMat3::from_rotation_x(th) * rel - rel) * w;
            coord_index.push(v as u32);
            for j in 0..2 {
                let rate =
                    (offset(angles[j + 1]) - offset(angles[j])) / (borders[j + 1] - borders[j]);
                displacements.push(rate.as_vec3());
            }
        }
        // FP 2.1 must drop by exactly P × MNS: pin its vertical rate (the rotation gives it up
        // to bisection precision).
        let chin_v = self
            .face
            .feature_point(FeaturePointId::FP_2_1)
            .expect("2.1")
            .vertex;
        if let Some(slot) = coord_index.iter().position(|&v| v == chin_v) {
            for j in 0..2 {
                displacements[2 * slot + j].y = -(mns as f32);
            }
        }
        t.meshes.push(FaceDefMesh {
            mesh: names::SKIN.into(),
            interval_borders: borders.to_vec(),
            coord_index,
            displacements,
        });
        t.transforms.push(FaceDefTransform::rotation(
            names::JAW_TF,
            Vec3::X,
            (angles[2] / 1024.0) as f32,
        ));
    }
}

/// The low-level tables (FAPs 3..=68) of `face`.
pub(super) fn build(face: &SynthFace, skin: &Skin, info: &PartsInfo) -> Fat {
    let tongue_mesh = face.mesh_index(names::TONGUE).expect("tongue");
    let ctx = Ctx {
        face,
        skin,
        info,
        fapu: face.fapu(),
        tongue: face.meshes[tongue_mesh]
            .positions
            .iter()
            .map(|p| p.as_dvec3())
            .collect(),
    };
    Fat {
        tables: FapId::low_level().map(|f| ctx.table(f)).collect(),
    }
}
