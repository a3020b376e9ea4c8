//! Where the recording has speech: an energy detector with a threshold set from the
//! recording's own level distribution (its quiet floor and its loud peaks), so it works
//! for quiet and loud, clean and noisy recordings alike.

use super::features::{frame_time, FeatureFrame, HOP_SECONDS};

/// Frames a silence must last to count as one (shorter dips are stop closures and gaps
/// between words).
const MIN_SILENCE_FRAMES: usize = 15;
/// Least dB between the quiet floor and the peaks for there to be speech at all.
const MIN_DYNAMIC_RANGE_DB: f32 = 12.0;
/// Peaks below this level (dB full scale) are silence.
const MIN_PEAK_DB: f32 = -65.0;

/// Speech and silence in a recording.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Activity {
    /// The quiet floor (10th percentile of frame energy), dB.
    pub floor_db: f32,
    /// The peaks (97th percentile), dB.
    pub peak_db: f32,
    /// Frames at or above this are speech.
    pub threshold_db: f32,
    /// Seconds of speech.
    pub speech_seconds: f64,
    /// The silences at least `MIN_SILENCE_FRAMES` long, (start, end) in seconds.
    pub silences: Vec<(f64, f64)>,
    /// Seconds from the first to the last speech frame.
    pub speech_span: (f64, f64),
}

impl Activity {
    /// Why there is no speech, when there is none.
    pub fn no_speech(&self) -> Option<String> {
        if self.peak_db < MIN_PEAK_DB {
            return Some(format!(
                "no speech: the recording is silent (peaks at {:.0} dBFS)",
                self.peak_db
            ));
        }
        if self.peak_db - self.floor_db < MIN_DYNAMIC_RANGE_DB {
            return Some(format!(
                "no speech found: the level varies by only {:.1} dB (steady noise or a tone?)",
                self.peak_db - self.floor_db
            ));
        }
        if self.speech_seconds < 0.1 {
            return Some(format!(
                "no speech found: {:.2} s above the noise floor",
                self.speech_seconds
            ));
        }
        None
    }
}

fn percentile(sorted: &[f32], q: f64) -> f32 {
    if sorted.is_empty() {
        return -120.0;
    }
    sorted[((sorted.len() - 1) as f64 * q).round() as usize]
}

/// Finds speech and silence in `frames`.
pub fn activity(frames: &[FeatureFrame]) -> Activity {
    let mut sorted: Vec<f32> = frames.iter().map(|f| f.energy_db).collect();
    sorted.sort_by(f32::total_cmp);
    let floor_db = percentile(&sorted, 0.10);
    let peak_db = percentile(&sorted, 0.97);
    let threshold_db = floor_db + (0.3 * (peak_db - floor_db)).max(6.0);
    let speech: Vec<bool> = frames.iter().map(|f| f.energy_db >= threshold_db).collect();
    let count = speech.iter().filter(|s| **s).count();
    let mut silences = Vec::new();
    let mut run_start: Option<usize> = None;
    for (k, &s) in speech.iter().chain(std::iter::once(&true)).enumerate() {
        match (s, run_start) {
            (false, None) => run_start = Some(k),
            (true, Some(a)) => {
                if k - a >= MIN_SILENCE_FRAMES {
                    let start = if a == 0 {
                        0.0
                    } else {
                        frame_time(a) - 0.5 * HOP_SECONDS
                    };
                    silences.push((start, frame_time(k - 1) + 0.5 * HOP_SECONDS));
                }
                run_start = None;
            }
            _ => {}
        }
    }
    let first = speech.iter().position(|s| *s).unwrap_or(0);
    let last = speech.iter().rposition(|s| *s).unwrap_or(0);
    Activity {
        floor_db,
        peak_db,
        threshold_db,
        speech_seconds: count as f64 * HOP_SECONDS,
        silences,
        speech_span: (frame_time(first), frame_time(last)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frames(levels: &[(f32, usize)]) -> Vec<FeatureFrame> {
        levels
            .iter()
            .flat_map(|&(db, n)| {
                std::iter::repeat_n(
                    FeatureFrame {
                        mfcc: [0.0; 13],
                        energy_db: db,
                        high_db: db,
                    },
                    n,
                )
            })
            .collect()
    }

    #[test]
    fn speech_between_silences() {
        let a = activity(&frames(&[
            (-70.0, 50),
            (-20.0, 100),
            (-70.0, 5),
            (-20.0, 100),
            (-70.0, 40),
        ]));
        assert!(a.no_speech().is_none());
        assert_eq!(a.silences.len(), 2, "{:?}", a.silences);
        assert!(a.silences[0].0 == 0.0 && (a.silences[0].1 - 0.5).abs() < 0.011);
        assert!((a.speech_seconds - 2.0).abs() < 0.01);
    }

    #[test]
    fn silence_and_steady_noise_have_no_speech() {
        assert!(activity(&frames(&[(-120.0, 300)])).no_speech().is_some());
        assert!(activity(&frames(&[(-30.0, 150), (-27.0, 150)]))
            .no_speech()
            .is_some());
        assert!(activity(&[]).no_speech().is_some());
    }
}
