//! Two FAP streams compared: frame rate, transmitted frames and masks, and the held value
//! of every FAP (the hold rule applied) at every frame either stream transmits.

use std::collections::BTreeMap;
use std::fmt;

use serde::Serialize;

use crate::fap::{DenseFrame, FapStream, FapTimeline};
use crate::spec::FapId;

use super::{Side, SnapshotError};

/// Default tolerance in FAP units: a change of one unit (the smallest an integer stream
/// makes) is a difference.
pub const DEFAULT_FAP_TOLERANCE: f64 = 0.5;

/// What [`fap_diff`] compares with.
#[derive(Clone, Debug, PartialEq)]
pub struct FapDiffOptions {
    /// Held values that differ by no more than this (in FAP units: FAPU or, for FAPs 1 and
    /// 2, blend / intensity steps) are equal.
    pub tolerance: f64,
}

impl Default for FapDiffOptions {
    fn default() -> Self {
        FapDiffOptions {
            tolerance: DEFAULT_FAP_TOLERANCE,
        }
    }
}

/// One FAP compared over the stream.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FapValueDiff {
    /// FAP number (1 viseme, 2 expression, 3..=68 low level).
    pub fap: u8,
    /// Its name (`open_jaw`, `viseme`, `expression`).
    pub name: String,
    /// Within tolerance at every compared frame.
    pub equal: bool,
    /// Largest difference of the held values (for FAPs 1 and 2: of blend / intensities,
    /// or 63 when the selected visemes / expressions differ).
    pub max_difference: f64,
    /// Compared frames where it differs beyond tolerance.
    pub differing_frames: usize,
    /// Frame number (of A's rate) where the largest difference is.
    pub worst_frame: Option<u64>,
    /// Frames that transmit it in A.
    pub transmitted_a: usize,
    /// Frames that transmit it in B.
    pub transmitted_b: usize,
}

/// The typed report of [`fap_diff`]; `Display` renders the text report.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FapDiff {
    /// Same frame rate, same transmitted frames and masks, every held value within tolerance.
    pub equal: bool,
    /// Stream A's name.
    pub a: String,
    /// Stream B's name.
    pub b: String,
    /// The tolerance in FAP units.
    pub tolerance: f64,
    /// A's frame rate.
    pub frame_rate_a: f64,
    /// B's frame rate.
    pub frame_rate_b: f64,
    /// Transmitted frames in A.
    pub frames_a: usize,
    /// Transmitted frames in B.
    pub frames_b: usize,
    /// Frame numbers transmitted only in A (same rate only; otherwise every frame differs).
    pub frames_only_in_a: usize,
    /// Frame numbers transmitted only in B.
    pub frames_only_in_b: usize,
    /// Frames transmitted in both whose masks differ.
    pub mask_differences: usize,
    /// First frame number (of A) where anything differs.
    pub first_difference: Option<u64>,
    /// Frames (the union of both streams' transmitted frames) compared.
    pub compared_frames: usize,
    /// Every FAP either stream transmits, differing first (worst first), then by number.
    pub faps: Vec<FapValueDiff>,
}

impl FapDiff {
    /// True when the streams are equal within tolerance.
    pub fn is_equal(&self) -> bool {
        self.equal
    }
}

impl fmt::Display for FapDiff {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&super::report::fap_diff_text(self))
    }
}

#[derive(Default)]
struct Acc {
    max: f64,
    differing: usize,
    worst: Option<u64>,
}

/// Compares two FAP streams (see [`FapDiff`]). The tolerance must be positive and finite.
pub fn fap_diff(
    a: &FapStream,
    b: &FapStream,
    options: &FapDiffOptions,
) -> Result<FapDiff, SnapshotError> {
    let tol = options.tolerance;
    if !(tol.is_finite() && tol > 0.0) {
        return Err(SnapshotError::BadTolerance {
            given: tol.to_string(),
        });
    }
    let (ta, tb) = (FapTimeline::new(a), FapTimeline::new(b));
    let same_rate = a.frame_rate == b.frame_rate;

    // Transmission: frame numbers and masks (meaningful at one rate).
    let frames_a: BTreeMap<u64, _> = a.frames.iter().map(|f| (f.number, f.mask())).collect();
    let frames_b: BTreeMap<u64, _> = b.frames.iter().map(|f| (f.number, f.mask())).collect();
    let (mut only_a, mut only_b, mut masks) = (0, 0, 0);
    let mut first: Option<u64> = None;
    let note = |n: u64, first: &mut Option<u64>| {
        *first = Some(first.map_or(n, |f: u64| f.min(n)));
    };
    if same_rate {
        for (n, m) in &frames_a {
            match frames_b.get(n) {
                None => {
                    only_a += 1;
                    note(*n, &mut first);
                }
                Some(mb) if mb != m => {
                    masks += 1;
                    note(*n, &mut first);
                }
                Some(_) => {}
            }
        }
        for n in frames_b.keys() {
            if !frames_a.contains_key(n) {
                only_b += 1;
                note(*n, &mut first);
            }
        }
    }

    // Values: at every transmitted frame of either stream, as times.
    let (ra, rb) = (a.frame_rate, b.frame_rate);
    let at = |t: &FapTimeline, rate: f64, time: f64| -> u64 {
        let n = (time * rate + 1e-9).floor();
        if n.is_finite() && n >= 0.0 {
            n as u64
        } else {
            0
        }
        .min(t.last_number().unwrap_or(0))
    };
    let mut times: Vec<f64> = frames_a.keys().map(|n| *n as f64 / ra).collect();
    times.extend(frames_b.keys().map(|n| *n as f64 / rb));
    times.retain(|t| t.is_finite());
    times.sort_by(f64::total_cmp);
    times.dedup();
    let mut acc: BTreeMap<u8, Acc> = BTreeMap::new();
    for &time in &times {
        let frame_a = at(&ta, ra, time);
        let sa = ta.at_frame(frame_a);
        let sb = tb.at_frame(at(&tb, rb, time));
        for (fap, d) in state_differences(sa, sb) {
            let e = acc.entry(fap).or_default();
            if d > tol {
                e.differing += 1;
                note(frame_a, &mut first);
            }
            if d > e.max {
                e.max = d;
                e.worst = Some(frame_a);
            }
        }
    }
    let transmitted =
        |s: &FapStream, fap: FapId| s.frames.iter().filter(|f| f.mask().contains(fap)).count();
    let mut faps: Vec<FapValueDiff> = FapId::all()
        .filter(|id| {
            a.frames
                .iter()
                .chain(&b.frames)
                .any(|f| f.mask().contains(*id))
        })
        .map(|id| {
            let e = acc.remove(&id.number()).unwrap_or_default();
            FapValueDiff {
                fap: id.number(),
                name: id.name().to_string(),
                equal: e.differing == 0,
                max_difference: e.max,
                differing_frames: e.differing,
                worst_frame: e.worst,
                transmitted_a: transmitted(a, id),
                transmitted_b: transmitted(b, id),
            }
        })
        .collect();
    faps.sort_by(|x, y| {
        x.equal.cmp(&y.equal).then_with(|| {
            if x.equal {
                x.fap.cmp(&y.fap)
            } else {
                y.max_difference
                    .total_cmp(&x.max_difference)
                    .then(x.fap.cmp(&y.fap))
            }
        })
    });
    let equal =
        same_rate && only_a == 0 && only_b == 0 && masks == 0 && faps.iter().all(|f| f.equal);
    Ok(FapDiff {
        equal,
        a: a.name.clone(),
        b: b.name.clone(),
        tolerance: tol,
        frame_rate_a: ra,
        frame_rate_b: rb,
        frames_a: a.frames.len(),
        frames_b: b.frames.len(),
        frames_only_in_a: only_a,
        frames_only_in_b: only_b,
        mask_differences: masks,
        first_difference: if same_rate {
            first
        } else {
            Some(first.unwrap_or(0))
        },
        compared_frames: times.len(),
        faps,
    })
}

/// Per FAP number, how far two held states are apart. Visemes and expressions: the blend /
/// intensity difference when the selects agree, the full scale (63) when they do not.
fn state_differences(a: &DenseFrame, b: &DenseFrame) -> Vec<(u8, f64)> {
    let mut out = Vec::with_capacity(68);
    let (va, vb) = (&a.viseme, &b.viseme);
    let d = if (va.select1, va.select2) == (vb.select1, vb.select2) {
        (f64::from(va.blend) - f64::from(vb.blend)).abs()
    } else if (va.select1, va.select2) == (vb.select2, vb.select1) {
        // The same two visemes named the other way round: blend counts from the other end.
        (f64::from(va.blend) - (63.0 - f64::from(vb.blend))).abs()
    } else {
        63.0
    };
    out.push((FapId::VISEME.number(), d));
    let (ea, eb) = (&a.expression, &b.expression);
    let d = if (ea.select1, ea.select2) == (eb.select1, eb.select2) {
        (f64::from(ea.intensity1) - f64::from(eb.intensity1))
            .abs()
            .max((f64::from(ea.intensity2) - f64::from(eb.intensity2)).abs())
    } else {
        63.0
    };
    out.push((FapId::EXPRESSION.number(), d));
    for id in FapId::low_level() {
        let (x, y) = (a.value(id), b.value(id));
        let d = if x.is_nan() || y.is_nan() {
            if x.is_nan() && y.is_nan() {
                0.0
            } else {
                f64::INFINITY
            }
        } else {
            (x - y).abs()
        };
        out.push((id.number(), d));
    }
    out
}

/// Which stream has a FAP the other never transmits (for the report).
pub fn transmitted_only(f: &FapValueDiff) -> Option<Side> {
    match (f.transmitted_a > 0, f.transmitted_b > 0) {
        (true, false) => Some(Side::A),
        (false, true) => Some(Side::B),
        _ => None,
    }
}
