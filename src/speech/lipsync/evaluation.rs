//! How well a viseme stream shows a recording's phones, scored as issue 22 defines it: the
//! stream is read as its dominant viseme per frame (select1 when blend ≥ 32, else
//! select2) in five mouth classes, against phones with known times.
//!
//! - closures shown: the share of m/b/p phones with a PP frame within ±40 ms of the phone;
//! - agreement: the share of speech frames whose class appears in the stream within ±1
//!   frame;
//! - false closures: the share of speech frames showing PP where the phone is an open or
//!   rounded vowel.

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
    /// Adds another case's counts.
    pub fn add(&mut self, o: &LipsyncScore) {
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
        if (first..=last.min(shown.len().saturating_sub(1))).any(|n| shown.get(n) == Some(&MouthClass::Closed)) {
            s.closures_shown += 1;
        }
    }
    for (n, &here) in shown.iter().enumerate() {
        let t = n as f64 / fps;
        let Some(p) = truth.iter().find(|p| p.start <= t && t < p.end) else {
            continue;
        };
        let share = if p.end > p.start { (t - p.start) / (p.end - p.start) } else { 0.0 };
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
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spec::Viseme;

    fn p(symbol: &str, start: f64, end: f64) -> TimedPhoneme {
        TimedPhoneme { symbol: symbol.into(), start, end }
    }

    fn held(n: u8) -> VisemeParams {
        let v = Viseme::new(n).unwrap();
        VisemeParams { select1: v, select2: v, blend: 63, def: false }
    }

    #[test]
    fn a_perfect_and_a_wrong_stream() {
        // "ma" at 25 fps: m for 0.0-0.12 s, a for 0.12-0.4 s.
        let truth = vec![p("m", 0.0, 0.12), p("a", 0.12, 0.4)];
        let good: Vec<VisemeParams> = (0..10).map(|n| if n < 3 { held(1) } else { held(10) }).collect();
        let s = score(&truth, &good, 25.0);
        assert_eq!((s.closures, s.closures_shown, s.speech_frames, s.agreeing_frames, s.false_closures), (1, 1, 10, 10, 0));
        let bad: Vec<VisemeParams> = (0..10).map(|_| held(1)).collect();
        let s = score(&truth, &bad, 25.0);
        assert_eq!(s.closure_rate(), 1.0);
        assert!((s.agreement() - 0.3).abs() < 1e-9, "{s:?}");
        assert!((s.false_closure_rate() - 0.7).abs() < 1e-9);
        let none: Vec<VisemeParams> = (0..10).map(|_| held(10)).collect();
        assert_eq!(score(&truth, &none, 25.0).closure_rate(), 0.0);
    }
}
