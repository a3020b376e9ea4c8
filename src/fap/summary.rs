//! A summary of a stream for `fbakit fap info`: header, timing, FAPs used with their ranges,
//! distinct masks, visemes and expressions used.

use serde::Serialize;

use super::model::FapStream;
use crate::error::Diagnostic;
use crate::spec::FapId;

/// What a stream contains.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FapSummary {
    /// Header version.
    pub version: String,
    /// Header name.
    pub name: String,
    /// Frames per second.
    pub frame_rate: f64,
    /// Number of transmitted frames.
    pub frames: usize,
    /// Seconds from time 0 to the end of the last frame: (last frame number + 1) / fps.
    pub duration_seconds: f64,
    /// First and last frame numbers (`None` when empty).
    pub frame_numbers: Option<(u64, u64)>,
    /// Whether frame numbers skip values (frames not transmitted hold the previous values).
    pub skipped_frame_numbers: bool,
    /// Number of distinct masks.
    pub distinct_masks: usize,
    /// Every FAP transmitted at least once, in FAP order.
    pub faps: Vec<FapUsage>,
    /// Viseme numbers used in FAP 1 (select1 or select2), sorted.
    pub visemes: Vec<u8>,
    /// Expression names used in FAP 2 (select1 or select2), in standard order.
    pub expressions: Vec<&'static str>,
    /// Reader warnings.
    pub warnings: Vec<Diagnostic>,
}

/// One FAP's use in a stream.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FapUsage {
    /// FAP number.
    pub number: u8,
    /// Standard name.
    pub name: &'static str,
    /// Frames transmitting it.
    pub frames: usize,
    /// Smallest value (low-level FAPs only).
    pub min: Option<f64>,
    /// Largest value (low-level FAPs only).
    pub max: Option<f64>,
}

/// Summarises `stream`; `warnings` are the reader's diagnostics, passed through.
pub fn summarize(stream: &FapStream, warnings: Vec<Diagnostic>) -> FapSummary {
    let mut counts = [0usize; crate::spec::NUM_FAPS];
    let mut min = [f64::INFINITY; crate::spec::NUM_FAPS];
    let mut max = [f64::NEG_INFINITY; crate::spec::NUM_FAPS];
    let mut masks: Vec<u128> = Vec::new();
    let mut visemes = [false; 15];
    let mut expressions = [false; 7];
    for f in &stream.frames {
        masks.push(f.mask().bits());
        for id in f.mask().iter() {
            counts[id.index()] += 1;
        }
        for (id, v) in f.low_level() {
            min[id.index()] = min[id.index()].min(v);
            max[id.index()] = max[id.index()].max(v);
        }
        if let Some(v) = f.viseme() {
            visemes[v.select1.number() as usize] = true;
            visemes[v.select2.number() as usize] = true;
        }
        if let Some(e) = f.expression() {
            expressions[e.select1.number() as usize] = true;
            expressions[e.select2.number() as usize] = true;
        }
    }
    masks.sort_unstable();
    masks.dedup();
    let faps = FapId::all()
        .filter(|id| counts[id.index()] > 0)
        .map(|id| {
            let i = id.index();
            let low = !id.is_high_level();
            FapUsage {
                number: id.number(),
                name: id.name(),
                frames: counts[i],
                min: low.then_some(min[i]),
                max: low.then_some(max[i]),
            }
        })
        .collect();
    let first = stream.frames.first().map(|f| f.number);
    let last = stream.frames.last().map(|f| f.number);
    let frame_numbers = first.zip(last);
    let skipped = stream
        .frames
        .windows(2)
        .any(|w| w[1].number != w[0].number + 1)
        || first.is_some_and(|n| n != 0);
    FapSummary {
        version: stream.version.clone(),
        name: stream.name.clone(),
        frame_rate: stream.frame_rate,
        frames: stream.frames.len(),
        duration_seconds: last.map_or(0.0, |l| (l as f64 + 1.0) / stream.frame_rate),
        frame_numbers,
        skipped_frame_numbers: skipped,
        distinct_masks: masks.len(),
        faps,
        visemes: (0..15u8).filter(|&v| visemes[v as usize]).collect(),
        expressions: crate::spec::Expression::ALL
            .into_iter()
            .filter(|e| expressions[e.number() as usize])
            .map(|e| e.name())
            .collect(),
        warnings,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fap::{FapFrame, VisemeParams};

    #[test]
    fn summary_counts_ranges_and_masks() {
        let mut a = FapFrame::new(0);
        a.set(FapId::OPEN_JAW, 5.0);
        let mut b = FapFrame::new(2);
        b.set(FapId::OPEN_JAW, -1.0);
        b.set_viseme(Some(VisemeParams::NEUTRAL));
        let s = FapStream {
            frames: vec![a, b],
            ..FapStream::new("x", 25.0)
        };
        let sum = summarize(&s, vec![]);
        assert_eq!(sum.frames, 2);
        assert_eq!(sum.duration_seconds, 3.0 / 25.0);
        assert_eq!(sum.frame_numbers, Some((0, 2)));
        assert!(sum.skipped_frame_numbers);
        assert_eq!(sum.distinct_masks, 2);
        assert_eq!(sum.faps.len(), 2);
        assert_eq!(sum.faps[1].min, Some(-1.0));
        assert_eq!(sum.faps[1].max, Some(5.0));
        assert_eq!(sum.faps[0].min, None);
        assert_eq!(sum.visemes, [0]);
    }
}
