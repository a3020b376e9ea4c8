//! How well a viseme stream shows a recording's phones, scored as issue 22 defines it: the
//! stream is read as its dominant viseme per frame (select1 when blend ≥ 32, else
//! select2) in five mouth classes, against phones with known times.
//!
//! - closures shown: the share of m/b/p phones with a PP frame within ±40 ms of the phone;
//! - agreement: the share of speech frames whose class appears in the stream within ±1
//!   frame;
//! - false closures: the share of speech frames showing PP where the phone is an open or
//!   rounded vowel.
//!
//! Beside them, not an issue target: closures on other consonants, the share of frames of
//! consonants that are not m/b/p (f, t, s, n, l, …) showing PP, which the false closures
//! do not count but a viewer sees.

use serde::Serialize;

use super::coarticulation::{dominant, is_closure, MouthClass};
use crate::fap::VisemeParams;
use crate::speech::espeak::TimedPhoneme;
use crate::speech::phonemes::{PhonemeVisemeTable, VisemeTarget};

/// Tolerance around a closure, seconds.
const CLOSURE_TOLERANCE: f64 = 0.040;

/// The three figures and what they count.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct LipsyncScore {
    /// m/b/p phones.
    pub closures: usize,
    /// Of them, shown.
    pub closures_shown: usize,
    /// Speech frames scored.
    pub speech_frames: usize,
    /// Of them, in the right class (±1 frame).
    pub agreeing_frames: usize,
    /// Of them, PP on an open or rounded vowel.
    pub false_closures: usize,
    /// Speech frames of consonants other than m/b/p.
    pub consonant_frames: usize,
    /// Of them, PP.
    pub consonant_closures: usize,
}

impl LipsyncScore {
    /// Share of closures shown (1 when there are none).
    pub fn closure_rate(&self) -> f64 {
        ratio(self.closures_shown, self.closures, 1.0)
    }
    /// Share of speech frames in the right class.
    pub fn agreement(&self) -> f64 {
        ratio(self.agreeing_frames, self.speech_frames, 1.0)
    }
    /// Share of speech frames with a false closure.
    pub fn false_closure_rate(&self) -> f64 {
        ratio(self.false_closures, self.speech_frames, 0.0)
    }
    /// Share of frames of other consonants showing PP.
    pub fn consonant_closure_rate(&self) -> f64 {
        ratio(self.consonant_closures, self.consonant_frames, 0.0)
    }
    /// Adds another case's counts.
    pub fn add(&mut self, o: &LipsyncScore) {
        self.consonant_frames += o.consonant_frames;
        self.consonant_closures += o.consonant_closures;
        self.closures += o.closures;
        self.closures_shown += o.closures_shown;
        self.speech_frames += o.speech_frames;
        self.agreeing_frames += o.agreeing_frames;
        self.false_closures += o.false_closures;
    }
}

fn ratio(a: usize, b: usize, empty: f64) -> f64 {
    if b == 0 {
        empty
    } else {
        a as f64 / b as f64
    }
}

/// The class a phone shows at `share` (0..1) of its length; `None` for pauses and sounds
/// without a shape of their own.
fn truth_class(p: &TimedPhoneme, share: f64) -> Option<MouthClass> {
    let v = match PhonemeVisemeTable::standard().lookup(&p.symbol)? {
        VisemeTarget::Single(v) => v,
        VisemeTarget::Glide(a, b) => {
            if share < 0.5 {
                a
            } else {
                b
            }
        }
        VisemeTarget::Next => return None,
    };
    match MouthClass::of(v) {
        MouthClass::Silence => None,
        c => Some(c),
    }
}

/// Scores `frames` (FAP 1 of each frame at `fps`, from time 0) against `truth`.
pub fn score(truth: &[TimedPhoneme], frames: &[VisemeParams], fps: f64) -> LipsyncScore {
    let shown: Vec<MouthClass> = frames.iter().map(|f| MouthClass::of(dominant(f))).collect();
    let mut s = LipsyncScore::default();
    for p in truth.iter().filter(|p| is_closure(&p.symbol)) {
        s.closures += 1;
        let first = ((p.start - CLOSURE_TOLERANCE) * fps).ceil().max(0.0) as usize;
        let last = ((p.end + CLOSURE_TOLERANCE) * fps).floor().max(0.0) as usize;
        if (first..=last.min(shown.len().saturating_sub(1)))
            .any(|n| shown.get(n) == Some(&MouthClass::Closed))
        {
            s.closures_shown += 1;
        }
    }
    for (n, &here) in shown.iter().enumerate() {
        let t = n as f64 / fps;
        let Some(p) = truth.iter().find(|p| p.start <= t && t < p.end) else {
            continue;
        };
        let share = if p.end > p.start {
            (t - p.start) / (p.end - p.start)
        } else {
            0.0
        };
        let Some(want) = truth_class(p, share) else {
            continue;
        };
        s.speech_frames += 1;
        let near = n.saturating_sub(1)..=(n + 1).min(shown.len() - 1);
        if near.into_iter().any(|k| shown[k] == want) {
            s.agreeing_frames += 1;
        }
        if here == MouthClass::Closed && matches!(want, MouthClass::Open | MouthClass::Rounded) {
            s.false_closures += 1;
        }
        if matches!(want, MouthClass::Labiodental | MouthClass::Other) {
            s.consonant_frames += 1;
            if here == MouthClass::Closed {
                s.consonant_closures += 1;
            }
        }
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spec::Viseme;

    fn p(symbol: &str, start: f64, end: f64) -> TimedPhoneme {
        TimedPhoneme {
            symbol: symbol.into(),
            start,
            end,
        }
    }

    fn held(n: u8) -> VisemeParams {
        let v = Viseme::new(n).unwrap();
        VisemeParams {
            select1: v,
            select2: v,
            blend: 63,
            def: false,
        }
    }

    #[test]
    fn a_perfect_and_a_wrong_stream() {
        // "ma" at 25 fps: m for 0.0-0.12 s, a for 0.12-0.4 s.
        let truth = vec![p("m", 0.0, 0.12), p("a", 0.12, 0.4)];
        let good: Vec<VisemeParams> = (0..10)
            .map(|n| if n < 3 { held(1) } else { held(10) })
            .collect();
        let s = score(&truth, &good, 25.0);
        assert_eq!(
            (
                s.closures,
                s.closures_shown,
                s.speech_frames,
                s.agreeing_frames,
                s.false_closures
            ),
            (1, 1, 10, 10, 0)
        );
        let bad: Vec<VisemeParams> = (0..10).map(|_| held(1)).collect();
        let s = score(&truth, &bad, 25.0);
        assert_eq!(s.closure_rate(), 1.0);
        assert!((s.agreement() - 0.3).abs() < 1e-9, "{s:?}");
        assert!((s.false_closure_rate() - 0.7).abs() < 1e-9);
        let none: Vec<VisemeParams> = (0..10).map(|_| held(10)).collect();
        assert_eq!(score(&truth, &none, 25.0).closure_rate(), 0.0);
    }

    #[test]
    fn closures_on_other_consonants_are_counted_apart() {
        // "ta": t for 0.0-0.12 s (3 frames), a after; PP shown on the first two t frames.
        let truth = vec![p("t", 0.0, 0.12), p("a", 0.12, 0.4)];
        let frames: Vec<VisemeParams> = (0..10)
            .map(|n| if n < 2 { held(1) } else { held(10) })
            .collect();
        let s = score(&truth, &frames, 25.0);
        assert_eq!((s.consonant_frames, s.consonant_closures), (3, 2));
        assert_eq!(s.false_closures, 0);
        assert!((s.consonant_closure_rate() - 2.0 / 3.0).abs() < 1e-9);
    }
}

/// How to degrade a rendition into a test recording.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Degradation {
    /// Sample rate of the recording written.
    pub sample_rate: u32,
    /// Channels (the same signal in each).
    pub channels: u16,
    /// White noise this many dB below the speech's RMS level (`None`: no noise).
    pub snr_db: Option<f64>,
    /// Seconds of silence added before the speech.
    pub lead_in: f64,
    /// Seed of the noise.
    pub seed: u64,
}

impl Default for Degradation {
    fn default() -> Self {
        Degradation {
            sample_rate: 44_100,
            channels: 2,
            snr_db: Some(20.0),
            lead_in: 0.3,
            seed: 1,
        }
    }
}

/// `u`'s audio resampled, padded, with noise added, as 16-bit WAV bytes; and its phones
/// moved by the lead-in (the truth for scoring).
pub fn degrade(
    u: &crate::speech::espeak::Utterance,
    d: &Degradation,
) -> crate::error::Result<(Vec<u8>, Vec<TimedPhoneme>)> {
    use crate::speech::audio::Resampler;
    let mut rs = Resampler::new(u.sample_rate, d.sample_rate);
    let mut x: Vec<f32> = vec![0.0; (d.lead_in * f64::from(d.sample_rate)) as usize];
    let input: Vec<f32> = u.samples.iter().map(|&s| f32::from(s) / 32_768.0).collect();
    rs.push(&input, &mut x);
    rs.finish(&mut x);
    x.extend(std::iter::repeat_n(
        0.0,
        (0.3 * f64::from(d.sample_rate)) as usize,
    ));
    if let Some(snr) = d.snr_db {
        let speech: Vec<f64> = input.iter().map(|s| f64::from(*s).powi(2)).collect();
        let rms = (speech.iter().sum::<f64>() / speech.len().max(1) as f64).sqrt();
        let sigma = rms / 10f64.powf(snr / 20.0);
        let mut state = d.seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
        let mut uniform = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        for s in &mut x {
            // Box–Muller: a Gaussian sample from two uniform ones.
            let (a, b) = (uniform().max(1e-12), uniform());
            let g = (-2.0 * a.ln()).sqrt() * (2.0 * std::f64::consts::PI * b).cos();
            *s += (sigma * g) as f32;
        }
    }
    let spec = hound::WavSpec {
        channels: d.channels.max(1),
        sample_rate: d.sample_rate,
        bits_per_sample: 16,
        sample_format: hound::SampleFormat::Int,
    };
    let mut cursor = std::io::Cursor::new(Vec::new());
    let encode = |e: hound::Error| -> crate::error::Error {
        crate::error::EncodeError::new("WAV", e).into()
    };
    let mut w = hound::WavWriter::new(&mut cursor, spec).map_err(encode)?;
    for s in &x {
        let v = (s.clamp(-1.0, 1.0) * 32_767.0).round() as i16;
        for _ in 0..spec.channels {
            w.write_sample(v).map_err(encode)?;
        }
    }
    w.finalize().map_err(encode)?;
    let truth = u
        .phonemes
        .iter()
        .map(|p| TimedPhoneme {
            start: p.start + d.lead_in,
            end: p.end + d.lead_in,
            ..p.clone()
        })
        .collect();
    Ok((cursor.into_inner(), truth))
}
