//! The FAP player: a face and a FAP stream in, one deformed face per frame out.
//!
//! [`Player`] walks a stream frame by frame with the standard's hold rule
//! ([`crate::fap::FapTimeline`]): a FAP a frame does not transmit keeps its last value. Each
//! frame becomes a list of [`Activation`]s — every low-level FAP 3..=68 at its value, the viseme
//! pair (`select1` at `blend`, `select2` at `63 − blend`) and the expression pair — which the
//! face's [`FatEvaluator`] turns into vertex displacements and transform changes.
//!
//! A [`PlayerFrame`] holds the result: mesh positions in each mesh's local frame (neutral +
//! displacement), each transform's animated local matrix and the world (face-frame) matrices.
//! [`Player::next_frame`] refills one frame's buffers in place, so playing allocates nothing
//! after the first frame.
//!
//! ## Transforms
//! A `FaceDefTransform` changes a field of a VRML `Transform` relative to its neutral value:
//! the rotation delta is composed *before* the neutral rotation in the parent's frame
//! (`R = ΔR · R₀`, so the delta axis is read in the parent's axes, like the `rotation` field
//! itself), translation and scale deltas are added. The animated local matrix is the VRML
//! matrix `T · C · R · SR · S · SR⁻¹ · C⁻¹` of those fields, so rotations turn about the
//! transform's `center` (eyeball centres, FP 7.1 for the head in the synthetic faces).
//!
//! ## Timing
//! Output frame `n` is at `n / fps`. Without `--fps` the stream's own frame rate is used and
//! frames `0..=last frame number` are played (skipped frame numbers hold). With another rate
//! the stream is first resampled with [`crate::fap::resample`], which interpolates the
//! low-level values and the viseme blend / expression intensities.
//!
//! ## Missing tables
//! A FAP, viseme or expression with a non-zero value that the face has no table for cannot
//! move anything; [`Player::missing_tables`] lists each such key once with the number of
//! played frames that used it.

use std::ops::Range;

mod error;
pub use error::PlayerError;

use serde::Serialize;

use crate::error::Result;
use crate::face::{FaceModel, FacePose};
use crate::fap::{resample, FapStream, FapTimeline};
use crate::fat::eval::{frame_activations, Activation, FatEvaluator, FatOutput, TransformDelta};
use crate::fat::{Fat, TableKey};

/// How to play a stream.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PlayOptions {
    /// Output frame rate; `None` plays at the stream's own rate.
    pub fps: Option<f64>,
    /// Which output frames to play (clamped to the stream's end); `None` plays all.
    pub frames: Option<Range<usize>>,
}

/// A key used by the stream that the face has no table for.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct MissingTable {
    /// The FAP, viseme or expression.
    pub key: TableKey,
    /// Number of played frames in which it had a non-zero value.
    pub frames: usize,
}

/// One played frame. Create it with [`PlayerFrame::default`] (buffers are sized on first use)
/// or [`Player::new_frame`], then let [`Player::next_frame`] refill it.
#[derive(Clone, Debug, Default)]
pub struct PlayerFrame {
    /// Output frame number.
    pub index: usize,
    /// Time in seconds (`index / fps`).
    pub time: f64,
    /// The posed face: local positions, animated transform matrices, world frames.
    pub pose: FacePose,
    /// Per transform: the change from neutral the FAT produced.
    pub transform_deltas: Vec<TransformDelta>,
    /// The activations the frame was evaluated with (keys without a table included).
    pub activations: Vec<Activation>,
}

impl PlayerFrame {
    /// Face-frame positions of every vertex of the pose, per mesh (see
    /// [`FacePose::world_positions_into`] to reuse buffers).
    pub fn world_positions(&self) -> Vec<Vec<glam::Vec3>> {
        self.pose.all_world_positions()
    }

    /// What a glTF animation needs from this frame (no vertex data).
    pub fn animation_frame(&self) -> AnimationFrame {
        AnimationFrame {
            index: self.index,
            time: self.time,
            activations: self.activations.clone(),
            transform_deltas: self.transform_deltas.clone(),
        }
    }
}

/// The per-frame data a glTF animation is made of: activations (for morph weights) and
/// transform changes (for node channels), without vertex positions.
#[derive(Clone, Debug, PartialEq)]
pub struct AnimationFrame {
    /// Output frame number.
    pub index: usize,
    /// Time in seconds.
    pub time: f64,
    /// Activations of the frame.
    pub activations: Vec<Activation>,
    /// Per transform: the change from neutral.
    pub transform_deltas: Vec<TransformDelta>,
}

/// Plays a FAP stream on a face; see the module docs.
#[derive(Debug)]
pub struct Player<'a> {
    face: &'a FaceModel,
    evaluator: FatEvaluator,
    timeline: FapTimeline,
    fps: f64,
    range: Range<usize>,
    next: usize,
    /// Counted on first request: the count walks every frame, and a player whose span is
    /// refused (too long to output) must cost nothing to make.
    missing: std::sync::OnceLock<Vec<MissingTable>>,
    output: FatOutput,
}

impl<'a> Player<'a> {
    /// Prepares `stream` for playing on `face`.
    ///
    /// Errors: the face's FAT refers to unknown meshes/transforms, the stream's frame rate
    /// (or `opts.fps`) is not finite and positive, resampling would be too long, or the
    /// requested frame range is empty or starts after the last frame.
    ///
    /// ```
    /// use fbakit::error::Error;
    /// use fbakit::player::{PlayOptions, Player, PlayerError};
    /// let face = fbakit::face::read("alma")?;
    /// let (stream, _) = fbakit::fap::read_stream_file(
    ///     "samples/speech.fap",
    ///     &fbakit::fap::ReadOptions::lenient(),
    /// )?;
    /// let mut player = Player::new(&face, &stream, &PlayOptions::default())?;
    /// let mut frame = player.new_frame();
    /// while player.next_frame(&mut frame) {}
    /// // A frame range past the end is a typed error callers can match.
    /// let opts = PlayOptions { frames: Some(1_000_000..1_000_001), ..PlayOptions::default() };
    /// let err = Player::new(&face, &stream, &opts).err().unwrap();
    /// assert!(matches!(err, Error::Player(PlayerError::EmptyFrameRange { .. })));
    /// # Ok::<(), Error>(())
    /// ```
    pub fn new(face: &'a FaceModel, stream: &FapStream, opts: &PlayOptions) -> Result<Player<'a>> {
        face.check_structure()?;
        let evaluator = face.evaluator()?;
        if !(stream.frame_rate.is_finite()
            && stream.frame_rate > 0.0
            && stream.frame_rate <= crate::fap::MAX_FRAME_RATE)
        {
            return Err(PlayerError::StreamFrameRate {
                rate: stream.frame_rate,
                max: crate::fap::MAX_FRAME_RATE,
            }
            .into());
        }
        let (timeline, fps) = match opts.fps {
            Some(f) if f != stream.frame_rate => (FapTimeline::new(&resample(stream, f)?), f),
            _ => (FapTimeline::new(stream), stream.frame_rate),
        };
        let total = match timeline.last_number() {
            Some(n) => usize::try_from(n)
                .ok()
                .and_then(|n| n.checked_add(1))
                .filter(|&n| n as u64 <= crate::fap::MAX_RESAMPLED_FRAMES)
                .ok_or(PlayerError::FrameNumberTooLarge {
                    frame: n,
                    limit: crate::fap::MAX_RESAMPLED_FRAMES,
                })?,
            None => 0,
        };
        let range = match opts.frames.clone() {
            None => 0..total,
            Some(r) => {
                if r.start >= r.end || r.start >= total {
                    return Err(PlayerError::EmptyFrameRange {
                        start: r.start,
                        end: r.end,
                        total,
                    }
                    .into());
                }
                r.start..r.end.min(total)
            }
        };
        let output = evaluator.output();
        Ok(Player {
            face,
            evaluator,
            timeline,
            fps,
            next: range.start,
            range,
            missing: std::sync::OnceLock::new(),
            output,
        })
    }

    /// Output frame rate.
    pub fn fps(&self) -> f64 {
        self.fps
    }

    /// The output frames that are played.
    pub fn frame_range(&self) -> Range<usize> {
        self.range.clone()
    }

    /// Number of frames played in all.
    pub fn frame_count(&self) -> usize {
        self.range.len()
    }

    /// Duration in seconds covered by the played frames (`frames / fps`).
    pub fn duration(&self) -> f64 {
        self.range.len() as f64 / self.fps
    }

    /// Keys used by the played frames that the face has no table for, each once, in
    /// [`TableKey`] order.
    pub fn missing_tables(&self) -> Vec<(TableKey, usize)> {
        self.missing_table_records()
            .iter()
            .map(|m| (m.key, m.frames))
            .collect()
    }

    /// Same as [`Player::missing_tables`], as serialisable records.
    pub fn missing_table_records(&self) -> &[MissingTable] {
        self.missing
            .get_or_init(|| missing_tables(&self.evaluator, &self.timeline, self.range.clone()))
    }

    /// A frame with buffers sized for this face.
    pub fn new_frame(&self) -> PlayerFrame {
        let mut f = PlayerFrame::default();
        self.size_frame(&mut f);
        f
    }

    fn size_frame(&self, f: &mut PlayerFrame) {
        let face = self.face;
        let nt = face.transforms.len();
        f.transform_deltas.resize(nt, TransformDelta::IDENTITY);
        // `reserve` counts from the current length, which is the full size after a frame.
        let pose = &mut f.pose;
        pose.positions.resize_with(face.meshes.len(), Vec::new);
        for (p, m) in pose.positions.iter_mut().zip(&face.meshes) {
            reserve_total(p, m.mesh.positions.len());
        }
        reserve_total(&mut pose.transform_locals, nt);
        reserve_total(&mut pose.world.transforms, nt);
        reserve_total(&mut pose.world.meshes, face.meshes.len());
        reserve_total(&mut f.activations, ACTIVATIONS_PER_FRAME);
    }

    /// Evaluates the next frame into `frame` and returns true, or returns false after the
    /// last one. Reuses `frame`'s buffers: no allocation after they were sized once.
    pub fn next_frame(&mut self, frame: &mut PlayerFrame) -> bool {
        if self.next >= self.range.end {
            return false;
        }
        let n = self.next;
        self.next += 1;
        self.frame_at(n, frame);
        true
    }

    /// Evaluates output frame `index` (any frame, also outside the played range) into
    /// `frame`.
    pub fn frame_at(&mut self, index: usize, frame: &mut PlayerFrame) {
        self.size_frame(frame);
        let state = self.timeline.at_frame(index as u64);
        frame.index = index;
        frame.time = index as f64 / self.fps;
        frame_activations(state, &mut frame.activations);
        self.evaluator
            .evaluate(&frame.activations, &mut self.output);
        frame
            .transform_deltas
            .copy_from_slice(&self.output.transforms);
        self.face.pose_into(&self.output, &mut frame.pose);
    }

    /// Output frame `index` as a new frame (allocates; loops use [`Player::frame_at`] or
    /// [`Player::next_frame`] with one reused frame). `frame.world_positions()` gives every
    /// vertex of the pose in the face frame.
    ///
    /// ```
    /// use fbakit::prelude::*;
    /// let face = face::read("alma")?;
    /// let stream = fbakit::fap::read("samples/speech.fap")?;
    /// let mut player = Player::new(&face, &stream, &PlayOptions::default())?;
    /// let frame = player.frame(10);
    /// let world = frame.world_positions(); // per mesh, per vertex
    /// assert_eq!(world.len(), face.meshes.len());
    /// # Ok::<(), fbakit::error::Error>(())
    /// ```
    pub fn frame(&mut self, index: usize) -> PlayerFrame {
        let mut frame = self.new_frame();
        self.frame_at(index, &mut frame);
        frame
    }

    /// Restarts at the first frame of the range.
    pub fn rewind(&mut self) {
        self.next = self.range.start;
    }

    /// The per-frame data of every played frame for a glTF animation, computed without
    /// evaluating vertex motion (only transform entries), so it is cheap even for big faces.
    pub fn animation(&self) -> Result<Vec<AnimationFrame>> {
        // The clip is built whole in memory: refuse absurd spans before allocating them.
        if self.range.len() > crate::export::budget::MAX_PLAYED_FRAMES {
            return Err(PlayerError::TooManyFrames {
                start: self.range.start,
                end: self.range.end,
                count: self.range.len(),
                limit: crate::export::budget::MAX_PLAYED_FRAMES,
            }
            .into());
        }
        let face = self.face;
        let transform_fat = Fat {
            tables: face
                .fat
                .tables
                .iter()
                .map(|t| crate::fat::FaceDefTable {
                    key: t.key,
                    meshes: Vec::new(),
                    transforms: t.transforms.clone(),
                })
                .collect(),
        };
        let mut eval = FatEvaluator::new(&transform_fat, &[], &face.transform_names())?;
        let mut out = eval.output();
        let mut frames = Vec::with_capacity(self.range.len());
        for index in self.range.clone() {
            let mut activations = Vec::with_capacity(ACTIVATIONS_PER_FRAME);
            frame_activations(self.timeline.at_frame(index as u64), &mut activations);
            eval.evaluate(&activations, &mut out);
            frames.push(AnimationFrame {
                index,
                time: index as f64 / self.fps,
                activations,
                transform_deltas: out.transforms.clone(),
            });
        }
        Ok(frames)
    }
}

fn reserve_total<T>(v: &mut Vec<T>, total: usize) {
    if v.capacity() < total {
        v.reserve(total - v.len());
    }
}

/// 66 low-level FAPs, two viseme and two expression activations.
const ACTIVATIONS_PER_FRAME: usize = 66 + 4;

fn missing_tables(
    evaluator: &FatEvaluator,
    timeline: &FapTimeline,
    range: Range<usize>,
) -> Vec<MissingTable> {
    let mut counts = vec![0usize; TableKey::SLOTS];
    let mut keys: Vec<Option<TableKey>> = vec![None; TableKey::SLOTS];
    let mut activations = Vec::with_capacity(ACTIVATIONS_PER_FRAME);
    for n in range {
        frame_activations(timeline.at_frame(n as u64), &mut activations);
        // A key counts once per frame even when both halves of a pair select it.
        let mut seen = [false; TableKey::SLOTS];
        for a in &activations {
            let Some(slot) = a.key.slot() else { continue };
            if a.value != 0.0 && !seen[slot] && !evaluator.has_table(a.key) {
                seen[slot] = true;
                counts[slot] += 1;
                keys[slot] = Some(a.key);
            }
        }
    }
    let mut out: Vec<MissingTable> = keys
        .into_iter()
        .zip(counts)
        .filter_map(|(k, frames)| k.map(|key| MissingTable { key, frames }))
        .collect();
    out.sort_by_key(|m| m.key);
    out
}

#[cfg(test)]
mod tests;
