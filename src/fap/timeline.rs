//! What a player needs from a stream: the value of every FAP at any frame, resampling to
//! another frame rate, and the motion a FAP value causes on a face.
//!
//! **Hold rule** (MPEG-4 decoders keep the last decoded value of a FAP that a frame does not
//! transmit): the value of FAP k at frame number n is its value in the latest frame with
//! number <= n whose mask contains k; before k's first transmission it is 0 (neutral). The
//! high-level FAPs hold the same way: viseme and expression keep their last transmitted
//! parameters (all fields, including the `def`/`init_face` bits), and are
//! [`VisemeParams::NEUTRAL`] / [`ExpressionParams::NEUTRAL`] before the first transmission.

use glam::Vec3;

use super::model::{ExpressionParams, FapFrame, FapMask, FapStream, VisemeParams, NUM_LOW_LEVEL};
use super::FapError;
use crate::error::Result;
use crate::fdp::Fapu;
use crate::spec::{FapId, PositiveMotion};

/// The state of every FAP at one frame, after applying the hold rule.
#[derive(Clone, Debug, PartialEq)]
pub struct DenseFrame {
    /// Values of FAPs 3..=68; index `fap.number() - 3` (see [`DenseFrame::value`]).
    pub low_level: [f64; NUM_LOW_LEVEL],
    /// FAP 1 in force.
    pub viseme: VisemeParams,
    /// FAP 2 in force.
    pub expression: ExpressionParams,
    /// FAPs transmitted at least once up to this frame.
    pub seen: FapMask,
}

impl DenseFrame {
    /// The neutral face: every FAP at 0, no viseme, no expression.
    pub const NEUTRAL: DenseFrame = DenseFrame {
        low_level: [0.0; NUM_LOW_LEVEL],
        viseme: VisemeParams::NEUTRAL,
        expression: ExpressionParams::NEUTRAL,
        seen: FapMask::EMPTY,
    };

    /// Value of a low-level FAP (0 for FAPs 1 and 2, which carry structured values).
    pub fn value(&self, fap: FapId) -> f64 {
        if fap.is_high_level() {
            0.0
        } else {
            self.low_level[fap.index() - 2]
        }
    }

    /// Applies a transmitted frame: the FAPs it sends take its values, the others hold.
    pub fn apply(&mut self, f: &FapFrame) {
        for (id, v) in f.low_level() {
            self.low_level[id.index() - 2] = v;
        }
        if let Some(v) = f.viseme() {
            self.viseme = v;
        }
        if let Some(e) = f.expression() {
            self.expression = e;
        }
        self.seen = self.seen.union(f.mask());
    }
}

/// A stream with the hold rule applied once per transmitted frame, so any frame can be queried
/// without allocation (binary search over the transmitted frame numbers).
#[derive(Clone, Debug)]
pub struct FapTimeline {
    frame_rate: f64,
    numbers: Vec<u64>,
    states: Vec<DenseFrame>,
}

static NEUTRAL: DenseFrame = DenseFrame::NEUTRAL;

impl FapTimeline {
    /// Computes the held state at every transmitted frame. Frames must be in increasing
    /// number order (as every reader guarantees).
    pub fn new(stream: &FapStream) -> FapTimeline {
        let mut numbers = Vec::with_capacity(stream.frames.len());
        let mut states = Vec::with_capacity(stream.frames.len());
        let mut state = DenseFrame::NEUTRAL;
        for f in &stream.frames {
            state.apply(f);
            numbers.push(f.number);
            states.push(state.clone());
        }
        FapTimeline {
            frame_rate: stream.frame_rate,
            numbers,
            states,
        }
    }

    /// The stream's frame rate.
    pub fn frame_rate(&self) -> f64 {
        self.frame_rate
    }

    /// Number of the last transmitted frame (`None` for an empty stream).
    pub fn last_number(&self) -> Option<u64> {
        self.numbers.last().copied()
    }

    /// The state in force at frame number `n`.
    pub fn at_frame(&self, n: u64) -> &DenseFrame {
        match self.numbers.partition_point(|&m| m <= n) {
            0 => &NEUTRAL,
            i => &self.states[i - 1],
        }
    }

    /// The state in force at time `t` seconds (frame `floor(t * frame_rate)`; negative or
    /// non-finite times give the neutral state).
    pub fn at_time(&self, t: f64) -> &DenseFrame {
        let n = (t * self.frame_rate).floor();
        if n.is_finite() && n >= 0.0 {
            self.at_frame(n as u64)
        } else {
            &NEUTRAL
        }
    }

    /// Held value of `fap` at frame `n`.
    pub fn value(&self, n: u64, fap: FapId) -> f64 {
        self.at_frame(n).value(fap)
    }
}

/// Largest number of frames [`resample`] produces.
pub const MAX_RESAMPLED_FRAMES: u64 = 10_000_000;

/// The stream at another frame rate, one output frame per output frame number from 0 to the
/// time of the last input frame (output frame m is at time m / new_fps).
///
/// - Low-level FAPs: linear interpolation between the held values at the two input frame
///   numbers around the output time (so a FAP held over skipped frames stays flat). An
///   output frame transmits every FAP that has a weight in it and was transmitted before.
/// - Viseme / expression: the earlier held parameters; when both neighbours share the same
///   selects (and bits), the blend / intensities are interpolated and rounded, which turns a
///   blend ramp into a ramp at the new rate instead of a staircase.
///
/// Errors: `new_fps` not finite and positive, or more than [`MAX_RESAMPLED_FRAMES`] output
/// frames.
pub fn resample(stream: &FapStream, new_fps: f64) -> Result<FapStream> {
    if !(new_fps.is_finite() && new_fps > 0.0) {
        return Err(FapError::BadFrameRate { rate: new_fps }.into());
    }
    if !(stream.frame_rate.is_finite() && stream.frame_rate > 0.0) {
        return Err(FapError::BadStreamFrameRate {
            rate: stream.frame_rate,
        }
        .into());
    }
    let timeline = FapTimeline::new(stream);
    let mut out = FapStream {
        frame_rate: new_fps,
        frames: Vec::new(),
        ..stream.clone()
    };
    let Some(last) = timeline.last_number() else {
        return Ok(out);
    };
    let end_time = last as f64 / stream.frame_rate;
    // Small tolerance so 3 s at 25 fps -> 50 fps ends exactly on frame 150.
    let last_out = (end_time * new_fps + 1e-9).floor();
    if last_out.is_nan() || last_out >= MAX_RESAMPLED_FRAMES as f64 {
        return Err(FapError::TooManyFrames {
            limit: MAX_RESAMPLED_FRAMES,
        }
        .into());
    }
    let last_out = last_out as u64;
    out.frames.reserve(last_out as usize + 1);
    for m in 0..=last_out {
        let pos = m as f64 / new_fps * stream.frame_rate;
        let n0 = pos.floor() as u64;
        let w = (pos - n0 as f64).clamp(0.0, 1.0);
        let a = timeline.at_frame(n0);
        let b = timeline.at_frame(n0.saturating_add(1));
        let (seen, w) = if w > 1e-9 && n0 < last {
            (a.seen.union(b.seen), w)
        } else {
            (a.seen, 0.0)
        };
        let mut f = FapFrame::new(m);
        for id in seen.iter().filter(|id| !id.is_high_level()) {
            let (va, vb) = (a.value(id), b.value(id));
            f.set(id, va + (vb - va) * w);
        }
        if a.seen.contains(FapId::VISEME) {
            let mut v = a.viseme;
            let bv = b.viseme;
            if w > 0.0 && (bv.select1, bv.select2, bv.def) == (v.select1, v.select2, v.def) {
                v.blend = lerp_u8(v.blend, bv.blend, w);
            }
            f.set_viseme(Some(v));
        }
        if a.seen.contains(FapId::EXPRESSION) {
            let mut e = a.expression;
            let be = b.expression;
            let same = (be.select1, be.select2, be.init_face, be.def)
                == (e.select1, e.select2, e.init_face, e.def);
            if w > 0.0 && same {
                e.intensity1 = lerp_u8(e.intensity1, be.intensity1, w);
                e.intensity2 = lerp_u8(e.intensity2, be.intensity2, w);
            }
            f.set_expression(Some(e));
        }
        out.frames.push(f);
    }
    Ok(out)
}

fn lerp_u8(a: u8, b: u8, w: f64) -> u8 {
    (f64::from(a) + (f64::from(b) - f64::from(a)) * w)
        .round()
        .clamp(0.0, 255.0) as u8
}

/// What one FAP value does to its feature point(s) on a face with units `fapu`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FapMotion {
    /// Displacement of the feature point in model units (MPEG-4 axes): value × unit ×
    /// direction.
    Translation(Vec3),
    /// Right-handed rotation about `axis` (unit, MPEG-4 axes) by `angle` radians (value × AU);
    /// eyeball FAPs turn about the eye centre, head FAPs about FP 7.1.
    Rotation {
        /// Unit rotation axis.
        axis: Vec3,
        /// Angle in radians.
        angle: f64,
    },
    /// Pupil dilation (FAPs 29, 30): change of the pupil diameter in model units (value ×
    /// IRISD unit); positive grows the pupil.
    PupilDilation(f64),
    /// Tongue roll (FAP 47): angle in radians (value × AU) by which both tongue borders (FPs
    /// 6.3 and 6.4) rise, making the tongue concave upward.
    TongueRoll(f64),
    /// FAPs 1 and 2 have no direct motion (they select viseme / expression shapes).
    None,
}

/// The motion of `fap`'s feature point for `value` on a face with units `fapu`.
pub fn displacement(fap: FapId, value: f64, fapu: &Fapu) -> FapMotion {
    let info = fap.info();
    let Some(unit) = fapu.unit_of(fap) else {
        return FapMotion::None;
    };
    let amount = value * unit;
    if let Some(axis) = info.rotation_axis() {
        return FapMotion::Rotation {
            axis,
            angle: amount,
        };
    }
    if let Some(dir) = info.direction() {
        return FapMotion::Translation(dir * amount as f32);
    }
    match info.positive_motion {
        Some(PositiveMotion::Growing) => FapMotion::PupilDilation(amount),
        Some(PositiveMotion::ConcaveUpward) => FapMotion::TongueRoll(amount),
        _ => FapMotion::None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fdp::FapuDistances;
    use crate::spec::Viseme;

    fn id(n: u8) -> FapId {
        FapId::new(n).unwrap()
    }

    fn stream() -> FapStream {
        let mut a = FapFrame::new(0);
        a.set(FapId::OPEN_JAW, 100.0);
        a.set_viseme(Some(VisemeParams {
            select1: Viseme::new(3).unwrap(),
            select2: Viseme::new(10).unwrap(),
            blend: 0,
            def: false,
        }));
        let mut b = FapFrame::new(4);
        b.set(id(19), 50.0);
        let mut c = FapFrame::new(6);
        c.set(FapId::OPEN_JAW, 300.0);
        let mut v = a.viseme().unwrap();
        v.blend = 60;
        c.set_viseme(Some(v));
        FapStream {
            frames: vec![a, b, c],
            ..FapStream::new("t", 2.0)
        }
    }

    #[test]
    fn hold_rule() {
        let t = FapTimeline::new(&stream());
        assert_eq!(t.value(0, FapId::OPEN_JAW), 100.0);
        assert_eq!(t.value(5, FapId::OPEN_JAW), 100.0, "held over frames 1..5");
        assert_eq!(t.value(6, FapId::OPEN_JAW), 300.0);
        assert_eq!(t.value(3, id(19)), 0.0, "neutral before first transmission");
        assert_eq!(t.value(99, id(19)), 50.0);
        assert_eq!(t.at_frame(5).viseme.blend, 0);
        assert_eq!(t.at_frame(6).viseme.blend, 60);
        assert_eq!(t.at_time(2.9).value(FapId::OPEN_JAW), 100.0);
        assert_eq!(t.at_time(3.0).value(FapId::OPEN_JAW), 300.0);
        assert_eq!(t.at_time(-1.0), &DenseFrame::NEUTRAL);
        let empty = FapTimeline::new(&FapStream::new("e", 25.0));
        assert_eq!(empty.at_frame(0), &DenseFrame::NEUTRAL);
    }

    #[test]
    fn resample_interpolates_held_values() {
        let r = resample(&stream(), 4.0).unwrap();
        // Input ends at 6 / 2 = 3 s; output frames 0..=12 at 4 fps.
        assert_eq!(r.frames.len(), 13);
        assert_eq!(r.frame_rate, 4.0);
        let jaw: Vec<f64> = r
            .frames
            .iter()
            .map(|f| f.value(FapId::OPEN_JAW).unwrap())
            .collect();
        // Flat while held (frames 0..5), then a ramp from frame 5 to 6 (output 10..12).
        assert_eq!(jaw[..10], [100.0; 10]);
        assert_eq!(jaw[10], 100.0);
        assert_eq!(jaw[11], 200.0);
        assert_eq!(jaw[12], 300.0);
        // FAP 19 starts ramping from 0 between input frames 3 and 4 (output 7 is halfway).
        assert_eq!(r.frames[6].value(id(19)), None);
        assert_eq!(r.frames[7].value(id(19)), Some(25.0));
        // Viseme blend ramps because selects match.
        assert_eq!(r.frames[11].viseme().unwrap().blend, 30);
        assert!(resample(&stream(), 0.0).is_err());
        assert!(resample(&stream(), 1e12).is_err());
        // Round trip of the rate keeps transmitted values.
        let same = resample(&stream(), 2.0).unwrap();
        assert_eq!(same.frames[6].value(FapId::OPEN_JAW), Some(300.0));
    }

    #[test]
    fn displacement_kinds() {
        let fapu = Fapu::from_distances(FapuDistances {
            irisd0: 1024.0,
            es0: 2048.0,
            ens0: 1024.0,
            mns0: 1024.0,
            mw0: 1024.0,
        })
        .unwrap();
        // open_jaw: MNS, down.
        assert_eq!(
            displacement(FapId::OPEN_JAW, 10.0, &fapu),
            FapMotion::Translation(Vec3::new(0.0, -10.0, 0.0))
        );
        // head_yaw (49): about +y, 1e-5 rad per unit.
        match displacement(id(49), 15708.0, &fapu) {
            FapMotion::Rotation { axis, angle } => {
                assert_eq!(axis, Vec3::Y);
                assert!((angle - 0.15708).abs() < 1e-12);
            }
            m => panic!("{m:?}"),
        }
        assert_eq!(
            displacement(id(29), 2.0, &fapu),
            FapMotion::PupilDilation(2.0)
        );
        assert_eq!(
            displacement(id(47), 100.0, &fapu),
            FapMotion::TongueRoll(1e-3)
        );
        assert_eq!(displacement(FapId::VISEME, 1.0, &fapu), FapMotion::None);
    }
}
