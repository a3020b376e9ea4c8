//! The ARKit blendshape bridge: ARKit weight curves ⇄ MPEG-4 FAP streams, through a rig and
//! the FAT built from it ([`super::fat_build::face_from_rig`]).
//!
//! Both directions compare **feature-point motion**: the rig's blend shapes and the FAT's FAPs
//! are two linear models of how the face's feature points (every point bound to a vertex; `P`
//! of them, `3P` coordinates) move, and each direction fits one model to the other's motion
//! by bounded least squares ([`super::bounded_ls`]).
//!
//! ## ARKit → FAP ([`ArkitBridge::weights_to_faps`])
//! A frame's weights `w` pose the rig linearly: the feature points move by
//! `b = Σ_s w_s Δ_s` (`Δ_s` the shape's offsets at the points). The FAT was calibrated per
//! FAP side: side `k` (a FAP and a sign) shows value `V_k` (FAPU) when its shapes are at
//! weight 1, and moves the points by `a_k` at that value. The unknowns are `t_k ≥ 0`, the
//! fraction of `V_k` each side shows (the FAP's positive and negative part are separate
//! unknowns, as the table's two intervals are):
//!
//! ```text
//! t* = argmin ‖Σ_k t_k a_k − b‖² + λ‖t‖²,   0 ≤ t_k ≤ 2,   FAP f = Σ_{k of f} t_k V_k
//! ```
//!
//! The upper bound 2 allows twice the calibrated range (the table extrapolates linearly, but
//! far beyond what it was measured on the fit would be guessing). `λ` is [`TIKHONOV`] times
//! the mean `‖a_k‖²`: small enough not to bias well-seen FAPs, large enough that a FAP no
//! point distinguishes (two sides moving the points identically) shares evenly and a FAP no
//! point sees stays 0. FAP values are rounded to whole FAPU.
//!
//! ## FAP → ARKit ([`ArkitBridge::faps_to_weights`])
//! Each frame of the stream (hold rule, [`crate::fap::FapTimeline`]) is posed on the FAT and
//! its feature-point displacement `d` fitted by the rig's ARKit shapes:
//! `w* = argmin ‖Σ_s w_s Δ_s − d‖² + λ‖w‖²`, `0 ≤ w_s ≤ 1`, over the 52 shapes the rig has
//! (an ARKit shape a rig splits in halves, ICT's `browInnerUp_L` + `_R`, is one unknown
//! playing both).
//!
//! A low-level FAP the bridge has a side for moves the points by that side's motion scaled
//! linearly, `(x / V_k) a_k`, not by the FAT played at `x`: the shapes are linear, and a FAT
//! whose side has several intervals (alma's `open_jaw` moves most of the jaw 0.32×, not 0.5×,
//! at half its calibrated value) would otherwise be read as other shapes (half an open jaw came
//! back as `jawOpen` 0.42 with `jawForward` 0.70 and `mouthFunnel` 1). So a FAP value maps to
//! the same weight both ways; visemes, expressions and FAPs without a side are played on the FAT.
//!
//! **Rotations.** Head and eye rotation columns ([`super::capture::ROTATIONS`]) are not
//! fitted: they set FAPs 48–50 and 23–26 directly (replacing what the fit gave the eyeball
//! FAPs). The other way, head rotation FAPs are left out of the posed frames (rigid motion
//! no blend shape shows); the caller writes them, and the eyeball FAPs, as angles
//! ([`super::capture::stream_rotations`]).
//!
//! **Any face with a FAT.** [`arkit_rig_of_face`] makes ARKit-named shapes from the face's
//! own FAT (the bundled amplitude table) and [`ArkitBridge::for_fat_face`] pairs them with
//! FAP sides from the same table, so both directions work without a rig.
//!
//! Feature points see a face sparsely, so shapes that move no feature point (or move them
//! like another shape) cannot be recovered; the reports give the fit's residual.

use glam::Vec3;
use serde::Serialize;

use super::arkit_names::{arkit_index, bind_rig, ARKIT_SHAPES};
use super::bounded_ls::NormalEquations;
use super::capture::{is_head_rotation_fap, is_rotation_fap, rotation_index, Rotation, ROTATIONS};
use super::fap_map::ShapeLookup;
use super::fat_build::RigFatReport;
use super::weights_csv::{WeightCsv, MAX_FRAME_NUMBER};
use super::Rig;
use crate::error::Result;
use crate::face::{FaceModel, FacePose};
use crate::fap::{FapFrame, FapStream, FapTimeline};
use crate::fat::eval::{frame_activations, Activation, FatEvaluator, FatOutput};
use crate::fat::TableKey;
use crate::spec::{FapId, FeaturePointId};

/// Tikhonov weight relative to the mean squared column norm (module docs).
pub const TIKHONOV: f64 = 1e-4;

/// Upper bound of a FAP side's fraction of its calibrated value (module docs).
pub const MAX_SIDE_FRACTION: f64 = 2.0;

/// One calibrated FAP side as an unknown of the ARKit → FAP fit.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SideUnknown {
    /// The FAP.
    pub fap: FapId,
    /// Value (FAPU, signed) the side shows at its shapes' weight 1.
    pub value: f64,
}

/// The two linear models of feature-point motion, ready to fit each other.
#[derive(Debug)]
pub struct ArkitBridge<'a> {
    rig: &'a Rig,
    face: &'a FaceModel,
    /// The feature points compared, each with its mesh and vertex.
    probes: Vec<(FeaturePointId, usize, u32)>,
    /// FAP sides, with their feature-point motion at the calibrated value.
    sides: Vec<SideUnknown>,
    side_eq: NormalEquations,
    side_columns: Vec<Vec<f64>>,
    /// Per ARKit shape (52), the rig shapes that play it.
    bindings: Vec<Vec<usize>>,
    /// The ARKit shapes the rig has (indices into [`ARKIT_SHAPES`]) and their equations.
    shape_unknowns: Vec<usize>,
    shape_eq: NormalEquations,
    shape_columns: Vec<Vec<f64>>,
    evaluator: FatEvaluator,
    output: FatOutput,
    pose: FacePose,
}

/// What became of one weight column.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ColumnUse {
    /// The header as written.
    pub column: String,
    /// The rig shapes it drives (empty: ignored, or a rotation).
    pub shapes: Vec<String>,
    /// The FAP a rotation column sets directly ([`super::capture::ROTATIONS`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub fap: Option<String>,
    /// Why it is ignored (empty when used).
    pub ignored: String,
}

/// What [`ArkitBridge::weights_to_faps`] did.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FromArkitReport {
    /// Frame rate of the stream.
    pub fps: f64,
    /// Whether it was detected from the times.
    pub fps_detected: bool,
    /// The first row's time as a timecode at the stream's rate, for a file with a `Timecode`
    /// column (Live Link Face writes the time of day): the stream's frame 0 stands for it,
    /// and `fap to-arkit --start` writes it back.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub start_timecode: Option<String>,
    /// Frames written (rows of the CSV, after replacements).
    pub frames: usize,
    /// Feature points compared.
    pub feature_points: usize,
    /// FAPs in the stream (those with a calibrated side).
    pub faps: Vec<String>,
    /// Each weight column and what it drove.
    pub columns: Vec<ColumnUse>,
    /// Root-mean-square of the fit residual over all frames, relative to the RMS of the
    /// rig's feature-point motion (0: the FAT reproduces the rig exactly at the points).
    pub relative_residual: f64,
}

/// What [`ArkitBridge::faps_to_weights`] did.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ToArkitReport {
    /// Frame rate of the weights (the stream's).
    pub fps: f64,
    /// Frames written (0 ..= the stream's last frame number).
    pub frames: usize,
    /// Feature points compared.
    pub feature_points: usize,
    /// ARKit shapes solved for (the rig has them).
    pub shapes: Vec<String>,
    /// ARKit shapes the rig lacks (written as 0).
    pub absent: Vec<String>,
    /// FAPs, visemes or expressions the stream uses that the face has no table for.
    pub unplayable: Vec<String>,
    /// As in [`FromArkitReport::relative_residual`], for the rig fitting the FAT's motion.
    pub relative_residual: f64,
}

impl<'a> ArkitBridge<'a> {
    /// The bridge between `rig` and `face`, the face [`super::fat_build::face_from_rig`] built
    /// from it (same meshes, in order) with its `report`.
    pub fn new(rig: &'a Rig, face: &'a FaceModel, report: &RigFatReport) -> Result<Self> {
        let sides = report
            .calibrated
            .iter()
            .filter_map(|c| Some((FapId::from_name(&c.fap)?, c.value)))
            .collect();
        Self::with_sides(rig, face, sides)
    }

    /// The bridge between a face with a FAT and the rig [`arkit_rig_of_face`] made of it: the
    /// FAP sides are those of the bundled amplitude table the face has tables for, each at
    /// the largest value an ARKit shape gives it (its positive and negative part apart).
    pub fn for_fat_face(rig: &'a Rig, face: &'a FaceModel) -> Result<Self> {
        let mut sides: Vec<(FapId, f64)> = Vec::new();
        for a in super::arkit_amplitudes::arkit_amplitudes() {
            if face.fat.table(TableKey::LowLevel(a.fap)).is_none() || a.value == 0.0 {
                continue;
            }
            match sides
                .iter_mut()
                .find(|(f, v)| *f == a.fap && (*v > 0.0) == (a.value > 0.0))
            {
                Some((_, v)) => {
                    if a.value.abs() > v.abs() {
                        *v = a.value;
                    }
                }
                None => sides.push((a.fap, a.value)),
            }
        }
        Self::with_sides(rig, face, sides)
    }

    /// The bridge with the given FAP sides (FAP, value at a side's full extent).
    fn with_sides(
        rig: &'a Rig,
        face: &'a FaceModel,
        calibrated: Vec<(FapId, f64)>,
    ) -> Result<Self> {
        if face.meshes.len() != rig.meshes.len()
            || face
                .meshes
                .iter()
                .zip(&rig.meshes)
                .any(|(f, r)| f.mesh.vertex_count() != r.mesh.vertex_count())
        {
            return Err(super::RigError::FaceNotOfRig {
                face: face.name.clone(),
                rig: rig.name.clone(),
            }
            .into());
        }
        let probes = probe_vertices(face);
        if probes.is_empty() {
            return Err(super::RigError::NoBoundFeaturePoints {
                face: face.name.clone(),
            }
            .into());
        }
        let mut evaluator = face.evaluator()?;
        let mut output = evaluator.output();
        let mut pose = FacePose::default();
        let neutral = probe_positions(face, &probes, &mut evaluator, &mut output, &mut pose, &[]);

        let mut sides = Vec::new();
        let mut side_columns = Vec::new();
        for (fap, value) in calibrated {
            if !(value.is_finite() && value != 0.0) {
                continue;
            }
            let act = [Activation {
                key: TableKey::LowLevel(fap),
                value,
            }];
            let moved =
                probe_positions(face, &probes, &mut evaluator, &mut output, &mut pose, &act);
            side_columns.push(diff(&moved, &neutral));
            sides.push(SideUnknown { fap, value });
        }
        let side_eq = NormalEquations::new(
            &side_columns,
            TIKHONOV * NormalEquations::mean_column_energy(&side_columns),
        );

        let bindings = bind_rig(rig);
        let mut shape_unknowns = Vec::new();
        let mut shape_columns = Vec::new();
        for (i, shapes) in bindings.iter().enumerate() {
            if shapes.is_empty() {
                continue;
            }
            shape_unknowns.push(i);
            shape_columns.push(shape_probe_delta(rig, &probes, shapes));
        }
        let shape_eq = NormalEquations::new(
            &shape_columns,
            TIKHONOV * NormalEquations::mean_column_energy(&shape_columns),
        );
        Ok(ArkitBridge {
            rig,
            face,
            probes,
            sides,
            side_eq,
            side_columns,
            bindings,
            shape_unknowns,
            shape_eq,
            shape_columns,
            evaluator,
            output,
            pose,
        })
    }

    /// The FAP sides the ARKit → FAP fit solves for.
    pub fn sides(&self) -> &[SideUnknown] {
        &self.sides
    }

    /// The feature points compared.
    pub fn feature_points(&self) -> Vec<FeaturePointId> {
        self.probes.iter().map(|p| p.0).collect()
    }

    /// What each weight column drives: an ARKit name plays its bound rig shapes, another
    /// name a rig shape of that name; a head or eye rotation sets its FAP (eye roll, which
    /// has none, and rotations that are 0 on every row are ignored); anything else is ignored.
    pub fn resolve_columns(&self, csv: &WeightCsv) -> Vec<(ColumnUse, Vec<usize>)> {
        let lookup = ShapeLookup::new(self.rig);
        csv.columns
            .iter()
            .enumerate()
            .map(|(k, c)| {
                if let Some(r) = rotation_index(&c.name).map(|i| ROTATIONS[i]) {
                    let moves = csv.rows.iter().any(|row| row.weights[k] != 0.0);
                    let (fap, ignored) = match r.fap_id() {
                        None => (None, "eye roll has no FAP"),
                        Some(_) if !moves => (None, "rotation 0 on every row"),
                        Some(f) => (Some(f.name().to_string()), ""),
                    };
                    return (
                        ColumnUse {
                            column: c.name.clone(),
                            shapes: Vec::new(),
                            fap,
                            ignored: ignored.into(),
                        },
                        Vec::new(),
                    );
                }
                let (shapes, ignored) = match arkit_index(&c.name) {
                    Some(i) if !self.bindings[i].is_empty() => (self.bindings[i].clone(), ""),
                    Some(_) => (Vec::new(), "ARKit shape the rig does not have"),
                    None => match lookup.find(&c.name) {
                        Some(s) => (vec![s], ""),
                        None => (Vec::new(), "not a blend shape of the rig"),
                    },
                };
                let names = shapes
                    .iter()
                    .map(|&s| self.rig.shapes[s].name.clone())
                    .collect();
                (
                    ColumnUse {
                        column: c.name.clone(),
                        shapes: names,
                        fap: None,
                        ignored: ignored.into(),
                    },
                    shapes,
                )
            })
            .collect()
    }

    /// The FAP values (per calibrated FAP, in [`FromArkitReport::faps`] order) that best show
    /// the rig posed with `weights` (`(rig shape, weight)` pairs), and the squared residual
    /// and squared target norm of the fit.
    pub fn fit_faps(&self, weights: &[(usize, f64)]) -> (Vec<(FapId, f64)>, f64, f64) {
        let mut b = vec![0.0; self.probes.len() * 3];
        for &(s, w) in weights {
            if w == 0.0 {
                continue;
            }
            for (k, &(_, m, v)) in self.probes.iter().enumerate() {
                let o = self.rig.shapes[s].offset(m, v).as_dvec3() * w;
                b[3 * k] += o.x;
                b[3 * k + 1] += o.y;
                b[3 * k + 2] += o.z;
            }
        }
        let n = self.sides.len();
        let t = self
            .side_eq
            .solve(&b, &vec![0.0; n], &vec![MAX_SIDE_FRACTION; n]);
        let (res, norm) = residual(&self.side_columns, &t, &b);
        let mut values: Vec<(FapId, f64)> = Vec::new();
        for (side, ti) in self.sides.iter().zip(&t) {
            match values.iter_mut().find(|(f, _)| *f == side.fap) {
                Some((_, v)) => *v += ti * side.value,
                None => values.push((side.fap, ti * side.value)),
            }
        }
        (values, res, norm)
    }

    /// ARKit weight curves → a FAP stream named `name` (module docs); head and eye rotation
    /// columns set their FAPs directly, replacing what the fit gave those FAPs.
    pub fn weights_to_faps(
        &self,
        csv: &WeightCsv,
        name: &str,
    ) -> Result<(FapStream, FromArkitReport)> {
        let columns = self.resolve_columns(csv);
        // (column index, rotation) of the rotation columns that set a FAP.
        let rotations: Vec<(usize, Rotation, FapId)> = columns
            .iter()
            .enumerate()
            .filter(|(_, (c, _))| c.fap.is_some())
            .filter_map(|(k, (c, _))| {
                let r = ROTATIONS[rotation_index(&c.column)?];
                Some((k, r, r.fap_id()?))
            })
            .collect();
        let mut stream = FapStream::new(name, csv.fps);
        let (mut res, mut norm) = (0.0, 0.0);
        let mut faps: Vec<FapId> = Vec::new();
        let mut weights: Vec<(usize, f64)> = Vec::new();
        for row in &csv.rows {
            weights.clear();
            for ((_, shapes), &w) in columns.iter().zip(&row.weights) {
                for &s in shapes {
                    weights.push((s, w as f64));
                }
            }
            let (values, r, n) = self.fit_faps(&weights);
            res += r;
            norm += n;
            let mut frame = FapFrame::new(row.frame);
            for (fap, v) in values {
                if rotations.iter().any(|r| r.2 == fap) {
                    continue;
                }
                if !faps.contains(&fap) {
                    faps.push(fap);
                }
                // Whole FAPU, and no `-0` in the file.
                frame.set(fap, v.round() + 0.0);
            }
            for &(k, r, fap) in &rotations {
                if !faps.contains(&fap) {
                    faps.push(fap);
                }
                frame.set(fap, r.to_fap(f64::from(row.weights[k])));
            }
            stream.frames.push(frame);
        }
        faps.sort();
        let report = FromArkitReport {
            fps: csv.fps,
            fps_detected: csv.fps_detected,
            start_timecode: (csv.time == super::weights_csv::TimeColumn::Timecode)
                .then(|| super::weights_csv::timecode_at(csv.start, csv.fps)),
            frames: stream.frames.len(),
            feature_points: self.probes.len(),
            faps: faps.iter().map(|f| f.name().to_string()).collect(),
            columns: columns.into_iter().map(|(c, _)| c).collect(),
            relative_residual: relative(res, norm),
        };
        Ok((stream, report))
    }

    /// The ARKit weights (52, [`ARKIT_SHAPES`] order; absent shapes 0) whose rig pose best
    /// shows the feature-point displacement `d` (`3P` values), with the squared residual and
    /// squared target norm.
    pub fn fit_weights(&self, d: &[f64]) -> (Vec<f32>, f64, f64) {
        let n = self.shape_unknowns.len();
        let w = self.shape_eq.solve(d, &vec![0.0; n], &vec![1.0; n]);
        let (res, norm) = residual(&self.shape_columns, &w, d);
        let mut out = vec![0.0f32; ARKIT_SHAPES.len()];
        for (&i, &wi) in self.shape_unknowns.iter().zip(&w) {
            out[i] = wi as f32;
        }
        (out, res, norm)
    }

    /// Plays `stream` on the face (hold rule, frames `0 ..=` its last frame number) and fits
    /// the ARKit weights of every frame (module docs).
    pub fn faps_to_weights(
        &mut self,
        stream: &FapStream,
    ) -> Result<(Vec<Vec<f32>>, ToArkitReport)> {
        if !(stream.frame_rate.is_finite() && stream.frame_rate > 0.0) {
            return Err(super::RigError::StreamFrameRate {
                stream: stream.name.clone(),
                rate: stream.frame_rate,
            }
            .into());
        }
        let timeline = FapTimeline::new(stream);
        let Some(last) = timeline.last_number() else {
            return Err(super::RigError::EmptyStream {
                stream: stream.name.clone(),
            }
            .into());
        };
        if last > MAX_FRAME_NUMBER {
            return Err(super::RigError::StreamTooLong {
                stream: stream.name.clone(),
                last,
                limit: MAX_FRAME_NUMBER,
            }
            .into());
        }
        let face = self.face;
        let neutral = probe_positions(
            face,
            &self.probes,
            &mut self.evaluator,
            &mut self.output,
            &mut self.pose,
            &[],
        );
        let mut frames = Vec::with_capacity(last as usize + 1);
        let mut acts = Vec::new();
        let mut unplayable: Vec<TableKey> = Vec::new();
        let (mut res, mut norm) = (0.0, 0.0);
        for n in 0..=last {
            frame_activations(timeline.at_frame(n), &mut acts);
            // Head rotation is rigid motion, carried by the rotation columns, never a shape.
            acts.retain(|a| !matches!(a.key, TableKey::LowLevel(f) if is_head_rotation_fap(f)));
            for a in &acts {
                // Eyeball rotations travel in the rotation columns whatever the FAT has.
                if a.value != 0.0
                    && a.key.slot().is_some()
                    && !matches!(a.key, TableKey::LowLevel(f) if is_rotation_fap(f))
                    && face.fat.table(a.key).is_none()
                    && !unplayable.contains(&a.key)
                {
                    unplayable.push(a.key);
                }
            }
            // Calibrated sides move linearly (module docs).
            let mut linear = vec![0.0; neutral.len()];
            let (sides, columns) = (&self.sides, &self.side_columns);
            acts.retain(|a| {
                let TableKey::LowLevel(f) = a.key else {
                    return true;
                };
                let side = sides.iter().position(|s| {
                    s.fap == f && a.value != 0.0 && (s.value > 0.0) == (a.value > 0.0)
                });
                let Some(k) = side else {
                    return true;
                };
                let t = a.value / sides[k].value;
                for (l, c) in linear.iter_mut().zip(&columns[k]) {
                    *l += t * c;
                }
                false
            });
            let moved = probe_positions(
                face,
                &self.probes,
                &mut self.evaluator,
                &mut self.output,
                &mut self.pose,
                &acts,
            );
            let mut d = diff(&moved, &neutral);
            for (di, l) in d.iter_mut().zip(&linear) {
                *di += l;
            }
            let (w, r, nn) = self.fit_weights(&d);
            res += r;
            norm += nn;
            frames.push(w);
        }
        unplayable.sort();
        let report = ToArkitReport {
            fps: stream.frame_rate,
            frames: frames.len(),
            feature_points: self.probes.len(),
            shapes: self
                .shape_unknowns
                .iter()
                .map(|&i| ARKIT_SHAPES[i].to_string())
                .collect(),
            absent: (0..ARKIT_SHAPES.len())
                .filter(|i| !self.shape_unknowns.contains(i))
                .map(|i| ARKIT_SHAPES[i].to_string())
                .collect(),
            unplayable: unplayable.iter().map(|k| k.name()).collect(),
            relative_residual: relative(res, norm),
        };
        Ok((frames, report))
    }
}

/// The feature points compared and their vertices: the bound vertex, or for a point known
/// by position only (a face file's feature points) the nearest vertex of the neutral face.
fn probe_vertices(face: &FaceModel) -> Vec<(FeaturePointId, usize, u32)> {
    let mut world: Option<Vec<Vec<Vec3>>> = None;
    face.feature_points
        .iter()
        .filter_map(|p| {
            if let Some((m, v)) = face.fp_vertex(p.id) {
                return Some((p.id, m, v));
            }
            let at = p.position?;
            let world = world.get_or_insert_with(|| face.neutral_world_positions());
            let mut best: Option<(f32, usize, u32)> = None;
            for (m, positions) in world.iter().enumerate() {
                for (v, q) in positions.iter().enumerate() {
                    let d = q.distance_squared(at);
                    if best.is_none_or(|b| d < b.0) {
                        best = Some((d, m, v as u32));
                    }
                }
            }
            best.map(|(_, m, v)| (p.id, m, v))
        })
        .collect()
}

/// A face with a FAT as a rig of ARKit-named shapes (the bundled amplitudes,
/// [`super::arkit_export::face_to_arkit_rig`]), so the bridge solves FAP → ARKit on the
/// face's own FAT: `ArkitBridge::new(&rig, face, &RigFatReport::default())`.
pub fn arkit_rig_of_face(face: &FaceModel) -> Result<Rig> {
    if face.fat.tables.is_empty() {
        return Err(super::RigError::NoFat {
            face: face.name.clone(),
        }
        .into());
    }
    let amplitudes = super::arkit_amplitudes::arkit_amplitudes();
    Ok(super::arkit_export::face_to_arkit_rig(face, &amplitudes)?.0)
}

/// World positions of the probes (flattened x, y, z) with `acts` evaluated on the FAT.
fn probe_positions(
    face: &FaceModel,
    probes: &[(FeaturePointId, usize, u32)],
    evaluator: &mut FatEvaluator,
    output: &mut FatOutput,
    pose: &mut FacePose,
    acts: &[Activation],
) -> Vec<f64> {
    evaluator.evaluate(acts, output);
    face.pose_into(output, pose);
    let mut out = Vec::with_capacity(probes.len() * 3);
    for &(_, m, v) in probes {
        let local = pose
            .positions
            .get(m)
            .and_then(|p| p.get(v as usize))
            .copied()
            .unwrap_or(Vec3::ZERO);
        let world = pose
            .world
            .meshes
            .get(m)
            .map_or(local, |w| w.transform_point3(local));
        out.extend([world.x as f64, world.y as f64, world.z as f64]);
    }
    out
}

/// The summed offsets of `shapes` at the probes (flattened).
fn shape_probe_delta(
    rig: &Rig,
    probes: &[(FeaturePointId, usize, u32)],
    shapes: &[usize],
) -> Vec<f64> {
    let mut out = vec![0.0; probes.len() * 3];
    for &s in shapes {
        for (k, &(_, m, v)) in probes.iter().enumerate() {
            let o = rig.shapes[s].offset(m, v).as_dvec3();
            out[3 * k] += o.x;
            out[3 * k + 1] += o.y;
            out[3 * k + 2] += o.z;
        }
    }
    out
}

fn diff(a: &[f64], b: &[f64]) -> Vec<f64> {
    a.iter().zip(b).map(|(x, y)| x - y).collect()
}

/// `‖Σ x_k c_k − b‖²` and `‖b‖²`.
fn residual(columns: &[Vec<f64>], x: &[f64], b: &[f64]) -> (f64, f64) {
    let mut r = b.iter().map(|v| -v).collect::<Vec<f64>>();
    for (c, xi) in columns.iter().zip(x) {
        for (ri, ci) in r.iter_mut().zip(c) {
            *ri += xi * ci;
        }
    }
    (r.iter().map(|v| v * v).sum(), b.iter().map(|v| v * v).sum())
}

fn relative(res: f64, norm: f64) -> f64 {
    if norm > 0.0 {
        (res / norm).sqrt()
    } else {
        0.0
    }
}
