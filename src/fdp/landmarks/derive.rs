//! Placing a preset's points: landmark rows first, then the rules that derive points from the
//! mesh in the face frame (see [`Rule`] for each rule's definition).
//!
//! Lengths are relative to the face: `es` (distance between the eye-corner centres), `ens`
//! (eyes to nose bottom) and the eye width `w`, so the rules work in any unit. The constants
//! follow the proportions of the bundled procedural faces (`synth`), which place the same
//! points by hand.

use std::collections::BTreeMap;

use glam::Vec3;

use super::surface::{fit_sphere, FaceFrame, Skin};
use super::{
    AbsentPoint, LandmarkFeaturePoints, LandmarkScheme, PlacedPoint, PresetRow, Provenance, Rule,
};
use crate::mesh::Mesh;
use crate::spec::{FeaturePointId, Side};

/// The order rules run in: later rules use the points of earlier ones.
const ORDER: [Rule; 12] = [
    Rule::Landmark,
    Rule::ArcMidpoint,
    Rule::Pupil,
    Rule::UpperLidMargin,
    Rule::LowerLidMargin,
    Rule::ChinBoss,
    Rule::Cheek,
    Rule::Cheekbone,
    Rule::NostrilBorder,
    Rule::NoseBump,
    Rule::TopOfSkull,
    Rule::BackOfSkull,
];

/// One eye's labels.
struct Eye {
    inner: FeaturePointId,
    outer: FeaturePointId,
    upper: FeaturePointId,
    lower: FeaturePointId,
    pupil: FeaturePointId,
    name: &'static str,
}

fn eye(side: Side) -> Eye {
    match side {
        Side::Left => Eye {
            inner: FeaturePointId::FP_3_11,
            outer: FeaturePointId::FP_3_7,
            upper: FeaturePointId::FP_3_1,
            lower: FeaturePointId::FP_3_3,
            pupil: FeaturePointId::FP_3_5,
            name: "left",
        },
        _ => Eye {
            inner: FeaturePointId::FP_3_8,
            outer: FeaturePointId::FP_3_12,
            upper: FeaturePointId::FP_3_2,
            lower: FeaturePointId::FP_3_4,
            pupil: FeaturePointId::FP_3_6,
            name: "right",
        },
    }
}

/// +1 on the face's left, −1 on its right, 0 on the midline.
fn sign(side: Side) -> f32 {
    match side {
        Side::Left => 1.0,
        Side::Right => -1.0,
        Side::Middle => 0.0,
    }
}

type RuleResult = Result<(Vec<u32>, String), String>;

struct Ctx<'a> {
    mesh: &'a Mesh,
    skin: Skin,
    scheme: LandmarkScheme,
    landmarks: &'a [u32],
    placed: BTreeMap<FeaturePointId, PlacedPoint>,
    /// Pupils found on an eyeball (their eye's lids use the pupil's column).
    eyeball_pupils: Vec<FeaturePointId>,
    notes: Vec<String>,
    /// Vertices of every component, by component.
    members: Vec<Vec<u32>>,
}

pub(super) fn place(
    mesh: &Mesh,
    scheme: LandmarkScheme,
    landmarks: &[u32],
) -> Result<LandmarkFeaturePoints, String> {
    let rows = scheme.preset();
    let landmark_of = |id: FeaturePointId| -> Result<Vec3, String> {
        rows.iter()
            .find(|r| r.fp == id && r.rule == Rule::Landmark)
            .map(|r| mesh.positions[landmarks[r.landmarks[0]] as usize])
            .ok_or_else(|| format!("the {scheme} preset has no landmark for {id}"))
    };
    let left_eye =
        (landmark_of(FeaturePointId::FP_3_7)? + landmark_of(FeaturePointId::FP_3_11)?) * 0.5;
    let right_eye =
        (landmark_of(FeaturePointId::FP_3_8)? + landmark_of(FeaturePointId::FP_3_12)?) * 0.5;
    let mouth = (landmark_of(FeaturePointId::FP_8_3)? + landmark_of(FeaturePointId::FP_8_4)?) * 0.5;
    let frame = FaceFrame::from_points(
        left_eye,
        right_eye,
        mouth,
        landmark_of(FeaturePointId::FP_9_3)?,
    )
    .map_err(|e| format!("{scheme} landmarks: {e}"))?;
    let skin = Skin::new(mesh, &frame, landmarks);
    let mut members = vec![Vec::new(); skin.component_count];
    for (v, &c) in skin.component.iter().enumerate() {
        members[c as usize].push(v as u32);
    }
    let mut ctx = Ctx {
        mesh,
        skin,
        scheme,
        landmarks,
        placed: BTreeMap::new(),
        eyeball_pupils: Vec::new(),
        notes: Vec::new(),
        members,
    };
    let mut absent = Vec::new();
    for rule in ORDER {
        for row in rows.iter().filter(|r| r.rule == rule) {
            match ctx.apply(row) {
                Ok((vertices, provenance)) => ctx.insert(row, vertices, provenance),
                Err(reason) => absent.push(AbsentPoint {
                    id: row.fp,
                    rule,
                    reason,
                }),
            }
        }
        // Pupils of eyeless meshes come from the lid contour, so they wait for the lids.
        if rule == Rule::LowerLidMargin {
            let pending: Vec<AbsentPoint> = absent
                .iter()
                .filter(|a| a.rule == Rule::Pupil)
                .cloned()
                .collect();
            for a in pending {
                let row = rows.iter().find(|r| r.fp == a.id).expect("row");
                match ctx.lid_contour_pupil(row.fp) {
                    Ok((v, how)) => {
                        ctx.notes.push(format!("{}: {}", row.fp, a.reason));
                        absent.retain(|x| x.id != a.id);
                        ctx.insert(
                            row,
                            v,
                            Provenance::Derived {
                                rule: Rule::Pupil,
                                how,
                            },
                        );
                    }
                    Err(e) => {
                        if let Some(x) = absent.iter_mut().find(|x| x.id == a.id) {
                            x.reason = format!("{}; {e}", x.reason);
                        }
                    }
                }
            }
        }
    }
    absent.sort_by_key(|a| a.id);
    Ok(LandmarkFeaturePoints {
        scheme,
        points: ctx.placed.into_values().collect(),
        absent,
        notes: ctx.notes,
    })
}

impl Ctx<'_> {
    fn insert(&mut self, row: &PresetRow, vertices: Vec<u32>, provenance: Provenance) {
        let sum: Vec3 = vertices
            .iter()
            .map(|&v| self.mesh.positions[v as usize])
            .sum();
        let position = sum / vertices.len() as f32;
        self.placed.insert(
            row.fp,
            PlacedPoint {
                id: row.fp,
                vertices,
                position,
                provenance,
                reasoning: row.reasoning.clone(),
            },
        );
    }

    fn apply(&mut self, row: &PresetRow) -> Result<(Vec<u32>, Provenance), String> {
        if row.rule == Rule::Landmark {
            let i = row.landmarks[0];
            return Ok((
                vec![self.landmarks[i]],
                Provenance::Landmark {
                    landmark: i,
                    name: self.scheme.landmark_name(i),
                },
            ));
        }
        let side = row.fp.info().side;
        let (vertices, how) = match row.rule {
            Rule::Landmark => unreachable!("handled above"),
            Rule::ArcMidpoint => self.arc_midpoint(&row.landmarks),
            Rule::Pupil => self.eyeball_pupil(side),
            Rule::UpperLidMargin => self.lid_margin(side, true),
            Rule::LowerLidMargin => self.lid_margin(side, false),
            Rule::ChinBoss => self.chin_boss(),
            Rule::Cheek => self.cheek(side),
            Rule::Cheekbone => self.cheekbone(side),
            Rule::NostrilBorder => self.nostril_border(side),
            Rule::NoseBump => self.nose_bump(),
            Rule::TopOfSkull => self.top_of_skull(),
            Rule::BackOfSkull => self.back_of_skull(),
        }?;
        if row.rule == Rule::Pupil {
            self.eyeball_pupils.push(row.fp);
        }
        Ok((
            vertices,
            Provenance::Derived {
                rule: row.rule,
                how,
            },
        ))
    }

    /// Frame coordinates of a placed point (the mean of its vertices).
    fn local(&self, id: FeaturePointId) -> Result<Vec3, String> {
        let p = self
            .placed
            .get(&id)
            .ok_or_else(|| format!("needs feature point {id}, which is not placed"))?;
        Ok(p.vertices
            .iter()
            .map(|&v| self.skin.local[v as usize])
            .sum::<Vec3>()
            / p.vertices.len() as f32)
    }

    fn eye_centre(&self, side: Side) -> Result<Vec3, String> {
        let e = eye(side);
        Ok((self.local(e.inner)? + self.local(e.outer)?) * 0.5)
    }

    /// Eye-centre separation and eyes-to-nose-bottom height.
    fn scale(&self) -> Result<(f32, f32), String> {
        let (l, r) = (self.eye_centre(Side::Left)?, self.eye_centre(Side::Right)?);
        let es = l.x - r.x;
        let ens = (l.y + r.y) * 0.5 - self.local(FeaturePointId::FP_9_15)?.y;
        if es <= 0.0 || ens <= 0.0 {
            return Err(format!(
                "the eyes and nose bottom give no face proportions (eye separation {es}, eyes to nose {ens})"
            ));
        }
        Ok((es, ens))
    }

    fn snap(&self, p: Vec3) -> Result<u32, String> {
        self.skin
            .nearest_skin_vertex(p)
            .ok_or_else(|| "the skin has no vertices".to_string())
    }

    /// The front skin point at (x, y), snapped to the nearest skin vertex.
    fn front_vertex(&self, x: f32, y: f32, what: &str) -> RuleResult {
        let hit = self
            .skin
            .front(x, y)
            .ok_or_else(|| format!("no skin in front at x = {x:.3}, y = {y:.3} (face frame)"))?;
        let v = self.snap(hit.point)?;
        Ok((
            vec![v],
            format!("{what}: front skin at ({x:.3}, {y:.3}) in the face frame, vertex {v}"),
        ))
    }

    fn arc_midpoint(&self, landmarks: &[usize]) -> RuleResult {
        let pts: Vec<Vec3> = landmarks
            .iter()
            .map(|&i| self.skin.local[self.landmarks[i] as usize])
            .collect();
        let total: f32 = pts.windows(2).map(|w| w[0].distance(w[1])).sum();
        let mut left = total * 0.5;
        let mut at = pts[0];
        for w in pts.windows(2) {
            let d = w[0].distance(w[1]);
            if d >= left && d > 0.0 {
                at = w[0].lerp(w[1], left / d);
                break;
            }
            left -= d;
            at = w[1];
        }
        let v = self.snap(at)?;
        let names: Vec<String> = landmarks
            .iter()
            .map(|&i| self.scheme.landmark_name(i))
            .collect();
        Ok((
            vec![v],
            format!(
                "halfway along {} (length {total:.3}), nearest skin vertex {v}",
                names.join(" → ")
            ),
        ))
    }

    /// The front of a sphere-shaped part (eyeball) behind the eye opening.
    fn eyeball_pupil(&self, side: Side) -> RuleResult {
        let e = eye(side);
        let (inner, outer) = (self.local(e.inner)?, self.local(e.outer)?);
        let c0 = (inner + outer) * 0.5;
        let w = (outer.x - inner.x).abs();
        let mut spheres = Vec::new();
        for (c, members) in self.members.iter().enumerate() {
            if self.skin.skin_component[c] || members.len() < 20 {
                continue;
            }
            let pts: Vec<Vec3> = members
                .iter()
                .map(|&v| self.skin.local[v as usize])
                .collect();
            let Some((centre, r, rms)) = fit_sphere(&pts) else {
                continue;
            };
            let near = (centre.x - c0.x).abs() < 0.5 * w && (centre.y - c0.y).abs() < 0.5 * w;
            // A ball, not a thin cap over the eye (tear film, occlusion shells): it reaches
            // at least 1.2 radii deep.
            let (lo, hi) = pts
                .iter()
                .fold((f32::MAX, f32::MIN), |(a, b), p| (a.min(p.z), b.max(p.z)));
            let ball = hi - lo >= 1.2 * r;
            if near && ball && (0.25 * w..1.2 * w).contains(&r) && rms < 0.08 * r && centre.z < c0.z
            {
                spheres.push((c, centre, r, members.len()));
            }
        }
        if spheres.is_empty() {
            return Err(format!(
                "no eyeball (a sphere-shaped part of radius 0.25-1.2 eye widths behind the {} eye opening)",
                e.name
            ));
        }
        let apex = spheres
            .iter()
            .flat_map(|&(c, _, _, _)| self.members[c].iter().copied())
            .max_by(|&a, &b| {
                self.skin.local[a as usize]
                    .z
                    .total_cmp(&self.skin.local[b as usize].z)
            })
            .expect("non-empty component");
        let &(_, centre, r, _) = spheres.iter().max_by_key(|s| s.3).expect("non-empty");
        Ok((
            vec![apex],
            format!(
                "front-most vertex {apex} of the {} eyeball ({} ball-shaped part{}, largest radius {r:.3}, centre ({:.3}, {:.3}, {:.3}) in the face frame)",
                e.name,
                spheres.len(),
                if spheres.len() == 1 { "" } else { "s" },
                centre.x,
                centre.y,
                centre.z
            ),
        ))
    }

    /// The pupil of an eye without an eyeball: the mean of its lid contour's four points.
    fn lid_contour_pupil(&self, pupil: FeaturePointId) -> RuleResult {
        let side = pupil.info().side;
        let e = eye(side);
        let mut vertices = Vec::new();
        for id in [e.outer, e.upper, e.inner, e.lower] {
            let p = self
                .placed
                .get(&id)
                .ok_or_else(|| format!("the lid contour centre needs {id}"))?;
            vertices.extend_from_slice(&p.vertices);
        }
        Ok((
            vertices,
            format!(
                "centre of the {} lid contour: mean of {}, {}, {}, {}",
                e.name, e.outer, e.upper, e.inner, e.lower
            ),
        ))
    }

    /// The visible lid margin: scanning the front view from the pupil up (or down), the
    /// place where the front-most skin jumps forward from the eye opening (empty, or the
    /// socket behind the eyeball) onto the lid. The opening's own boundary, tucked behind
    /// the lid, is not visible from the front and so is never picked.
    fn lid_margin(&self, side: Side, upper: bool) -> RuleResult {
        let e = eye(side);
        let (inner, outer) = (self.local(e.inner)?, self.local(e.outer)?);
        let w = (outer.x - inner.x).abs();
        let (start, from) = if self.eyeball_pupils.contains(&e.pupil) {
            (self.local(e.pupil)?, "the pupil")
        } else {
            ((inner + outer) * 0.5, "the eye corners' midpoint")
        };
        let steps = 400usize;
        let dir = if upper { 1.0 } else { -1.0 };
        let step = 0.6 * w / steps as f32;
        let samples: Vec<(f32, Option<f32>)> = (0..=steps)
            .map(|i| {
                let y = start.y + dir * step * i as f32;
                (y, self.skin.front(start.x, y).map(|h| h.point.z))
            })
            .collect();
        let mut best: Option<(usize, f32)> = None;
        for i in 1..samples.len() {
            let Some(z) = samples[i].1 else { continue };
            let jump = match samples[i - 1].1 {
                None => f32::INFINITY,
                Some(p) => z - p,
            };
            if best.is_none_or(|(_, b)| jump > b) {
                best = Some((i, jump));
            }
            if jump == f32::INFINITY {
                break;
            }
        }
        let Some((i, jump)) = best.filter(|&(_, j)| j > 0.05 * w) else {
            return Err(format!(
                "no eye opening found {} {from} of the {} eye (the front skin does not jump forward onto a lid)",
                if upper { "above" } else { "below" },
                e.name
            ));
        };
        let (y, z) = (samples[i].0, samples[i].1.expect("sampled hit"));
        let v = self.snap(Vec3::new(start.x, y, z))?;
        let jump_text = if jump.is_finite() {
            format!("the front skin jumps forward {jump:.3}")
        } else {
            "the front skin starts".to_string()
        };
        Ok((
            vec![v],
            format!(
                "visible {} lid margin {} {from} of the {} eye: at y = {y:.3} (face frame) {jump_text}; vertex {v}",
                if upper { "upper" } else { "lower" },
                if upper { "above" } else { "below" },
                e.name
            ),
        ))
    }

    fn chin_boss(&self) -> RuleResult {
        let (lip, chin) = (
            self.local(FeaturePointId::FP_8_2)?,
            self.local(FeaturePointId::FP_2_1)?,
        );
        let x = (lip.x + chin.x) * 0.5;
        let mut best: Option<(f32, f32)> = None;
        for i in 0..=100 {
            let y = chin.y + (lip.y - chin.y) * 0.6 * i as f32 / 100.0;
            if let Some(h) = self.skin.front(x, y) {
                if best.is_none_or(|(_, z)| h.point.z > z) {
                    best = Some((y, h.point.z));
                }
            }
        }
        let (y, z) = best.ok_or("no skin in front between the chin and the lower lip")?;
        let v = self.snap(Vec3::new(x, y, z))?;
        Ok((
            vec![v],
            format!(
                "most protruding midline skin in the lower 60 % from 2.1 to 8.2, at y = {y:.3} (face frame); vertex {v}"
            ),
        ))
    }

    fn cheek(&self, side: Side) -> RuleResult {
        let (es, _) = self.scale()?;
        let corner = self.local(if side == Side::Left {
            FeaturePointId::FP_8_3
        } else {
            FeaturePointId::FP_8_4
        })?;
        let y = (self.local(FeaturePointId::FP_9_15)?.y + corner.y) * 0.5;
        self.front_vertex(
            sign(side) * 0.55 * es,
            y,
            "0.55 eye separations from the midline, halfway between the nose bottom and the mouth corner",
        )
    }

    fn cheekbone(&self, side: Side) -> RuleResult {
        let (es, ens) = self.scale()?;
        let y = self.eye_centre(side)?.y - 0.36 * ens;
        self.front_vertex(
            sign(side) * 0.66 * es,
            y,
            "0.66 eye separations from the midline, 0.36 eye-to-nose heights below the eye",
        )
    }

    fn nostril_border(&self, side: Side) -> RuleResult {
        let (es, ens) = self.scale()?;
        let y = self.local(FeaturePointId::FP_9_15)?.y + 0.07 * ens;
        let s = sign(side);
        let n = 200usize;
        let (from, to) = (0.05 * es, 0.45 * es);
        let h = (to - from) / n as f32;
        let z: Vec<Option<f32>> = (0..=n)
            .map(|i| {
                self.skin
                    .front(s * (from + h * i as f32), y)
                    .map(|p| p.point.z)
            })
            .collect();
        // Steepest sideways drop of the front surface over a short window.
        let k = 2usize;
        let mut best: Option<(usize, f32)> = None;
        for i in k..=n - k {
            if let (Some(a), Some(b)) = (z[i - k], z[i + k]) {
                let drop = (a - b) / (2 * k) as f32 / h;
                if best.is_none_or(|(_, d)| drop > d) {
                    best = Some((i, drop));
                }
            }
        }
        let (i, drop) = best.ok_or("no skin in front beside the nose")?;
        let x = s * (from + h * i as f32);
        let v = self.snap(Vec3::new(x, y, z[i].expect("sampled")))?;
        Ok((
            vec![v],
            format!(
                "outer edge of the nose wing: steepest sideways drop of the front skin (slope {drop:.2}) at x = {x:.3}, y = {y:.3} (face frame, 0.07 eye-to-nose heights above 9.15); vertex {v}"
            ),
        ))
    }

    fn nose_bump(&self) -> RuleResult {
        let (_, ens) = self.scale()?;
        let eyes = (self.eye_centre(Side::Left)? + self.eye_centre(Side::Right)?) * 0.5;
        let tip = self.local(FeaturePointId::FP_9_3)?;
        self.front_vertex(
            tip.x,
            eyes.y - 0.45 * ens,
            "nose ridge 0.45 of the way from the eyes to the nose bottom",
        )
    }

    /// The skull rules run only on a mesh that has the back of the head: midline skin at
    /// least 1.5 eye separations behind the eyes.
    fn skull(&self) -> Result<f32, String> {
        let (es, _) = self.scale()?;
        let x = self.local(FeaturePointId::FP_9_3)?.x;
        let deepest = self
            .skin
            .skin_vertices()
            .iter()
            .map(|&v| self.skin.local[v as usize])
            .filter(|p| (p.x - x).abs() < 0.05 * es)
            .map(|p| p.z)
            .fold(f32::MAX, f32::min);
        if deepest > -1.5 * es {
            return Err(format!(
                "the mesh does not include the skull (no midline skin 1.5 eye separations behind the eyes; the deepest is {:.3} behind)",
                -deepest
            ));
        }
        Ok(es)
    }

    fn top_of_skull(&self) -> RuleResult {
        let es = self.skull()?;
        let x = self.local(FeaturePointId::FP_9_3)?.x;
        let v = self
            .skin
            .skin_vertices()
            .iter()
            .copied()
            .filter(|&v| (self.skin.local[v as usize].x - x).abs() < 0.05 * es)
            .max_by(|&a, &b| {
                self.skin.local[a as usize]
                    .y
                    .total_cmp(&self.skin.local[b as usize].y)
            })
            .ok_or("no skin vertex near the midline")?;
        Ok((vec![v], format!("highest midline skin vertex {v}")))
    }

    fn back_of_skull(&self) -> RuleResult {
        let es = self.skull()?;
        let x = self.local(FeaturePointId::FP_9_3)?.x;
        let eyes = (self.eye_centre(Side::Left)? + self.eye_centre(Side::Right)?) * 0.5;
        let (lo, hi) = self
            .skin
            .skin_vertices()
            .iter()
            .map(|&v| self.skin.local[v as usize].z)
            .fold((f32::MAX, f32::MIN), |(a, b), z| (a.min(z), b.max(z)));
        let middle = (lo + hi) * 0.5;
        let v = self
            .skin
            .skin_vertices()
            .iter()
            .copied()
            .filter(|&v| {
                let p = self.skin.local[v as usize];
                (p.x - x).abs() < 0.05 * es && p.z < middle
            })
            .min_by(|&a, &b| {
                let d = |v: u32| (self.skin.local[v as usize].y - eyes.y).abs();
                d(a).total_cmp(&d(b))
            })
            .ok_or("no midline skin vertex at the back of the head")?;
        Ok((
            vec![v],
            format!("midline skin vertex {v} at the back of the head, nearest to eye height"),
        ))
    }
}
