//! The mouth shape of a pose, measured on the lip feature points, and the shapes the 14
//! visemes must have on any face.
//!
//! ## What is measured ([`MouthShape`])
//! On a posed face (neutral + FAT output), with `p(x)` the posed face-frame position of feature
//! point `x` (the mean of its bound vertices) and MNS0, MW0 the face's neutral mouth-nose
//! separation and mouth width:
//!
//! - **opening** `= (p(2.2) − p(2.3))·y / MNS0`: the inner-lip gap (middle of the inner upper
//!   and lower lip contours), negative when the lips press past each other;
//! - **width** `= |p(8.3) − p(8.4)| / |p₀(8.3) − p₀(8.4)|`: the outer lip corners' distance as a
//!   share of the neutral's;
//! - **protrusion** `= ½ (Δz(8.1) + Δz(8.2)) / MNS0`: how far the outer lip midpoints move
//!   forward (+z, towards the viewer).
//!
//! ## What a viseme must look like ([`viseme_range`])
//! Ranges on those three figures, in the face's own units so they hold on any face: `PP` closes
//! the lips; `FF` brings the lower lip up to the upper lip and teeth (opening ≤ 0.15); `aa` >
//! `E` > `ih` in opening; `oh` and `ou` are rounded (width 70–90 % of neutral) with a modest
//! protrusion (≤ 0.4), `ou` less open than `oh`; `CH`, `SS`, `DD`, `TH`, `nn`, `kk` nearly
//! closed (opening ≤ 0.3). [`viseme_aim`] is one point inside each range that calibrating a
//! face's visemes aims for ([`crate::face::visemes`]). [`viseme_shapes`] measures a face's
//! visemes and [`viseme_problems`] lists what breaks these rules; fbakit's tests hold every
//! bundled face and the rig-built ICT FAT to them.

use glam::Vec3;

use super::pose::FacePose;
use super::FaceModel;
use crate::spec::{FeaturePointId, Viseme};

/// Mouth figures of one pose (module docs): opening and protrusion in MNS0, width as a share of
/// the neutral width.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MouthShape {
    /// Inner-lip gap (2.2 − 2.3)·y / MNS0 (negative: pressed past each other).
    pub opening: f32,
    /// |8.3 − 8.4| over its neutral value.
    pub width: f32,
    /// Mean forward (+z) motion of 8.1 and 8.2 / MNS0.
    pub protrusion: f32,
}

/// What the measure needs of a face: where its lip points are at neutral and which vertices
/// carry them.
#[derive(Clone, Debug)]
pub struct MouthGauge {
    points: [Vec<(usize, u32)>; 6],
    neutral: [Vec3; 6],
    mns0: f32,
    mw0: f32,
}

/// 2.2, 2.3, 8.3, 8.4, 8.1, 8.2: the points the figures use, in this order.
const POINTS: [FeaturePointId; 6] = [
    FeaturePointId::FP_2_2,
    FeaturePointId::FP_2_3,
    FeaturePointId::FP_8_3,
    FeaturePointId::FP_8_4,
    FeaturePointId::FP_8_1,
    FeaturePointId::FP_8_2,
];

impl MouthGauge {
    /// The gauge of `face`, or `None` when a lip point is missing or bound to no vertex, or
    /// the face has no MNS0 (no 9.15).
    pub fn new(face: &FaceModel) -> Option<MouthGauge> {
        let frames = face.frames();
        let mut points: [Vec<(usize, u32)>; 6] = Default::default();
        let mut neutral = [Vec3::ZERO; 6];
        for (k, id) in POINTS.iter().enumerate() {
            let b = face.feature_points.get(*id)?.binding.as_ref()?;
            let mesh = match &b.mesh {
                Some(name) => face.mesh_index(name)?,
                None if face.meshes.len() == 1 => 0,
                None => return None,
            };
            let mut sum = Vec3::ZERO;
            for &v in &b.vertices {
                sum += face.vertex_world(&frames, mesh, v)?;
                points[k].push((mesh, v));
            }
            if points[k].is_empty() {
                return None;
            }
            neutral[k] = sum / points[k].len() as f32;
        }
        let fapu = face.fapu().ok()?;
        let mns0 = fapu.distances.mns0 as f32;
        let mw0 = neutral[2].distance(neutral[3]);
        (mns0 > 0.0 && mw0 > 0.0).then_some(MouthGauge {
            points,
            neutral,
            mns0,
            mw0,
        })
    }

    /// The figures of `pose` (a pose of the face the gauge was made for).
    pub fn measure(&self, pose: &FacePose) -> MouthShape {
        let mut p = [Vec3::ZERO; 6];
        for (k, list) in self.points.iter().enumerate() {
            let mut sum = Vec3::ZERO;
            for &(mesh, v) in list {
                let local = pose.positions[mesh][v as usize];
                sum += pose.world.meshes[mesh].transform_point3(local);
            }
            p[k] = sum / list.len() as f32;
        }
        self.figures(&p)
    }

    /// The figures of the lip points at face-frame positions `p` (in [`MouthGauge::points`]
    /// order): the module docs' formulas, in one place.
    pub(crate) fn figures(&self, p: &[Vec3; 6]) -> MouthShape {
        MouthShape {
            opening: (p[0].y - p[1].y) / self.mns0,
            width: p[2].distance(p[3]) / self.mw0,
            protrusion: 0.5 * ((p[4].z - self.neutral[4].z) + (p[5].z - self.neutral[5].z))
                / self.mns0,
        }
    }

    /// Per lip point (2.2, 2.3, 8.3, 8.4, 8.1, 8.2), the (mesh, vertex) pairs that carry it.
    pub(crate) fn points(&self) -> &[Vec<(usize, u32)>; 6] {
        &self.points
    }

    /// The lip points' neutral face-frame positions, in [`MouthGauge::points`] order.
    pub(crate) fn neutral_points(&self) -> &[Vec3; 6] {
        &self.neutral
    }

    /// The figures of the neutral face.
    pub fn neutral(&self) -> MouthShape {
        MouthShape {
            opening: (self.neutral[0].y - self.neutral[1].y) / self.mns0,
            width: 1.0,
            protrusion: 0.0,
        }
    }
}

/// Allowed ranges of a viseme's figures, `(low, high)` each.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MouthRange {
    /// Opening (MNS0).
    pub opening: (f32, f32),
    /// Width (share of neutral).
    pub width: (f32, f32),
    /// Protrusion (MNS0).
    pub protrusion: (f32, f32),
}

impl MouthRange {
    /// The figures of `shape` outside the range, as `name value (range)` texts.
    pub fn violations(&self, shape: &MouthShape) -> Vec<String> {
        let mut out = Vec::new();
        for (name, v, (lo, hi)) in [
            ("opening", shape.opening, self.opening),
            ("width", shape.width, self.width),
            ("protrusion", shape.protrusion, self.protrusion),
        ] {
            if !(lo..=hi).contains(&v) {
                out.push(format!("{name} {v:.3} outside {lo}..{hi}"));
            }
        }
        out
    }
}

/// The range every face's `viseme` must show alone at full blend (module docs). Ranges not
/// named there are kept loose: a viseme may not turn the mouth inside out (width 0.6–1.35) nor
/// push the lips far (protrusion −0.35..0.5: an open jaw pulls the lower lip back), nor open
/// beyond a wide `aa` (opening ≤ 1.6), nor cross the lips (opening ≥ −0.05, `PP` −0.12: pressed).
pub fn viseme_range(viseme: Viseme) -> MouthRange {
    let loose = MouthRange {
        opening: (-0.05, 1.6),
        width: (0.6, 1.35),
        protrusion: (-0.35, 0.5),
    };
    let nearly_closed = MouthRange {
        opening: (-0.05, 0.3),
        ..loose
    };
    match viseme.label() {
        "PP" => MouthRange {
            opening: (-0.12, 0.05),
            ..loose
        },
        "FF" => MouthRange {
            opening: (-0.1, 0.15),
            ..loose
        },
        "TH" | "DD" | "kk" | "CH" | "SS" | "nn" => nearly_closed,
        "RR" => MouthRange {
            opening: (0.0, 0.45),
            ..loose
        },
        "aa" => MouthRange {
            opening: (0.6, 1.6),
            ..loose
        },
        "E" => MouthRange {
            opening: (0.35, 1.0),
            ..loose
        },
        "ih" => MouthRange {
            opening: (0.15, 0.7),
            ..loose
        },
        "oh" | "ou" => MouthRange {
            width: (0.7, 0.9),
            protrusion: (-0.05, 0.4),
            ..loose
        },
        _ => loose,
    }
}

/// The figures calibration aims for (inside [`viseme_range`]; also `aa` > `E` > `ih` and `ou`
/// less open than `oh`).
pub fn viseme_aim(viseme: Viseme) -> MouthShape {
    let (opening, width, protrusion) = match viseme.label() {
        "PP" => (0.0, 0.97, 0.05),
        "FF" => (0.05, 1.0, 0.0),
        "TH" => (0.2, 1.0, 0.0),
        "DD" => (0.15, 1.02, 0.0),
        "kk" => (0.22, 1.0, 0.0),
        "CH" => (0.15, 0.85, 0.2),
        "SS" => (0.08, 1.08, 0.0),
        "nn" => (0.15, 1.0, 0.0),
        "RR" => (0.2, 0.85, 0.15),
        "aa" => (0.95, 1.0, 0.0),
        "E" => (0.6, 1.1, 0.0),
        "ih" => (0.35, 1.12, 0.0),
        "oh" => (0.6, 0.82, 0.2),
        "ou" => (0.3, 0.76, 0.28),
        _ => (0.0, 1.0, 0.0),
    };
    MouthShape {
        opening,
        width,
        protrusion,
    }
}

/// Each of `face`'s visemes alone at full blend (63), measured: `None` when the face lacks the
/// lip feature points (or their bindings) or its FAT does not evaluate.
pub fn viseme_shapes(face: &FaceModel) -> Option<Vec<(Viseme, MouthShape)>> {
    use crate::fat::eval::Activation;
    use crate::fat::TableKey;
    let gauge = MouthGauge::new(face)?;
    let mut ev = face.evaluator().ok()?;
    let mut out = ev.output();
    let mut pose = FacePose::default();
    Some(
        Viseme::shapes()
            .filter(|v| face.fat.table(TableKey::Viseme(*v)).is_some())
            .map(|v| {
                ev.evaluate(
                    &[Activation {
                        key: TableKey::Viseme(v),
                        value: crate::fat::HIGH_LEVEL_FULL,
                    }],
                    &mut out,
                );
                face.pose_into(&out, &mut pose);
                (v, gauge.measure(&pose))
            })
            .collect(),
    )
}

/// What is wrong with a face's viseme figures ([`viseme_shapes`]) against [`viseme_range`] and
/// the order rules (opening falls from `aa` to `E` to `ih`; `ou` less open than `oh`), one
/// text per problem; empty when they look like speech. Visemes without a table are not judged.
pub fn viseme_problems(shapes: &[(Viseme, MouthShape)]) -> Vec<String> {
    let mut bad = Vec::new();
    for (v, s) in shapes {
        for problem in viseme_range(*v).violations(s) {
            bad.push(format!("{}: {problem}", v.label()));
        }
    }
    let open = |label: &str| {
        shapes
            .iter()
            .find(|(v, _)| v.label() == label)
            .map(|(_, s)| s.opening)
    };
    // Pairs (more open, less open).
    for (more, less) in [("aa", "E"), ("E", "ih"), ("oh", "ou")] {
        if let (Some(a), Some(b)) = (open(more), open(less)) {
            if a <= b {
                bad.push(format!(
                    "{less} ({b:.3}) must be less open than {more} ({a:.3})"
                ));
            }
        }
    }
    bad
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bundled_faces_visemes_look_like_speech() {
        for name in ["alma", "bruno", "ict"] {
            let face = crate::face::read(name).unwrap();
            let shapes = viseme_shapes(&face).expect("lip feature points");
            assert_eq!(shapes.len(), 14, "{name}: 14 viseme tables");
            let table: String = shapes
                .iter()
                .map(|(v, s)| {
                    format!(
                        "\n  {:<3} opening {:.3} width {:.3} protrusion {:.3}",
                        v.label(),
                        s.opening,
                        s.width,
                        s.protrusion
                    )
                })
                .collect();
            let bad = viseme_problems(&shapes);
            assert!(bad.is_empty(), "{name}: {bad:?}{table}");
        }
    }

    #[test]
    fn problems_name_the_viseme_and_the_figure() {
        let pp = Viseme::from_label("PP").unwrap();
        let aa = Viseme::from_label("aa").unwrap();
        let e = Viseme::from_label("E").unwrap();
        let open = |opening| MouthShape {
            opening,
            width: 1.0,
            protrusion: 0.0,
        };
        let bad = viseme_problems(&[(pp, open(0.4)), (aa, open(0.7)), (e, open(0.8))]);
        assert!(
            bad.iter().any(|b| b.starts_with("PP: opening 0.400")),
            "{bad:?}"
        );
        assert!(
            bad.iter()
                .any(|b| b.starts_with("E (0.800) must be less open than aa")),
            "{bad:?}"
        );
        assert!(viseme_problems(&[(pp, open(0.0))]).is_empty());
    }
}
