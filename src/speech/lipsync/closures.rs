//! Lip closures found in the sound itself, for lip sync without a transcript.
//!
//! PocketSphinx's context-independent phones rarely say m, b or p (on the evaluation's
//! voices it mostly hears them as l, h, f or a vowel), so closures would go missing. A
//! bilabial closure has an acoustic signature of its own: between two louder, vocalic
//! stretches the sound drops (the mouth is shut) and what remains is dark — a nasal murmur
//! or the voice bar of a b, radiated through the nose and cheeks with little energy above
//! 1 kHz. Alveolar and velar stops and fricatives drop less at high frequencies (their
//! bursts and hiss), vowels do not drop. So a dip in the high-frequency energy whose bottom
//! is dark is taken as a closure, unless the recogniser heard something there that
//! explains it with the lips open: a consonant with its own place (n, t, k, s, …) or lip
//! rounding (w, oo, r).
//!
//! Measured on `examples/lipsync_eval.rs` (espeak-ng voices, the recogniser's language
//! weight at 2): the closures shown rise from 26 % to 50 %, mostly m's (b and p on these
//! voices often have a silent or noise-filled gap, which says nothing of the place); PP on
//! other consonants' frames goes from 3.4 % to about 9 % (n, d, l are dark too) and false
//! closures on vowels from 1.0 % to 2.5 %.
//!
//! Tried after that and not kept (measured on the same evaluation, language weight 1, where
//! this module gives closures 53.1 %, agreement 66.3 %, false closures 2.9 %). Of the 196
//! m/b/p there, 176 lie in a dip at least 10 dB deep, but 87 of those dips (51 of the 60
//! p's, 32 of the 68 b's, 4 of the 68 m's) are bright at the bottom: a silent gap filled by
//! the recording's noise, which says nothing of the place.
//! - Place from the formant transitions and the burst, read from the cepstral envelope:
//!   for the 182 bright deep dips, the change of four band levels (below 0.8, 0.8–1.8, 1.8–3,
//!   above 3 kHz, relative to their mean) into the gap and out of it and the levels of the first
//!   frame after it (the burst) each told labial from other dips no better than chance (area
//!   under the ROC curve 0.40–0.57; the best, less energy above 3 kHz in the burst, 0.60); a
//!   logistic model over all of them with what the recogniser heard, fitted leaving out one
//!   voice (or one sentence) at a time, found 30 of 79 labial dips with 33 false (by
//!   sentence 21 with 33 false), against 18 with 7 false from the heard phones alone.
//! - Every bright deep dip with no placed consonant heard in it (a length of at least 40–70
//!   ms or not): closures 63–65 %, but false closures 4.0–4.6 % and PP on other consonants
//!   17 %.
//! - A bright deep dip where the recogniser heard f or v (the labial place with the wrong
//!   manner; 15 of the 18 such dips are m/b/p) and no placed consonant: closures 53.1 →
//!   58.2 % (per condition 61 → 73, 39 → 45, 55 → 55, 57 → 59 %), agreement 66.3 → 66.1 %,
//!   false closures 2.9 → 3.2 % (up on three conditions): past the 3 %, so not
//!   kept; with m, b or p heard too, 58.7 % and 3.4 %. Asking for more depth (15 dB) or
//!   length (50 ms) did not change the balance.
//! - Not counting a dark dip where the recogniser heard w anywhere in it: one condition
//!   changed, closures −2, false closures −0.3 points.
//!
//! Kept since ([`fricative_closures`]): in noise the recogniser hears most b's and p's as f
//! or v (on the evaluation's Festival voices, which are built from real speakers'
//! recordings, 53 of the 80 f's it heard inside speech and 25 of the 42 v's lay on an
//! m/b/p; on espeak-ng's, 19 of 24 and 12 of 20), and many of those have no dip in the
//! high-frequency energy at all (the noise floods it). So an f or v heard on a gap in the
//! total energy at least 24 dB deep gets a closure at its quietest frame. On
//! `examples/lipsync_eval.rs`, espeak-ng conditions: closures 53.1 → 57.7 %, agreement 66.3
//! → 66.5 %, false closures 2.9 → 2.9 %; Festival conditions: 29.1 → 44.4 %, 57.2 → 59.9 %,
//! 1.1 → 1.3 %; no condition shows fewer closures, false closures rose by 0.4 points at most
//! (PP on other consonants 8.8 → 10.0 % and 7.4 → 12.1 %: the other stops' gaps sound
//! alike). With a closure at every f or v heard outside pauses (its middle): espeak-ng 59.2 %,
//! 65.7 %, 3.5 % false; Festival 55.6 %, 61.6 %, 2.2 %. Asking for a gap 20 or 22 dB deep
//! rather than 24: espeak-ng false closures 3.3 and 3.1 % (past the 3 %), Festival
//! closures 52.0 and 49.5 %. A gap reaching the recording's noise floor (within 3–15 dB of
//! it) rather than a depth kept as many other consonants as closures. Taking a th heard so
//! too (the recogniser also hears noisy b's and p's as th): espeak-ng 61.2 %, 66.3 %, 3.1 %
//! false; Festival 49.5 %, 60.7 %, 1.5 %: past 3 % again, so not kept.
//!
//! Where the false closures without a transcript come from (PP on an open or rounded
//! vowel's frame; `LIPSYNC_EVAL_TRACE=1` on `examples/lipsync_eval.rs` puts each on the
//! nearest closure phone, held when the frame lies between that closure's PP keys, spread
//! when only the blend to the next shape leaves PP there). Frames, with those within ±40 ms
//! of a real m/b/p in brackets:
//!
//! | | heard m/b/p held | heard spread | dip held | dip spread | f/v held | f/v spread | total |
//! |---|---|---|---|---|---|---|---|
//! | espeak-ng, before | 30 (19) | 14 (9) | 7 (6) | 13 (11) | 1 (1) | 0 | 65 of 2017 |
//! | Festival degraded, before | 16 (10) | 7 (4) | 0 | 4 (3) | 0 | 2 (2) | 29 of 1926 |
//! | Festival clean, before | 29 (26) | 21 (15) | 1 (1) | 2 (1) | 1 (0) | 1 (0) | 55 of 1451 |
//! | espeak-ng, edges set after merging | 30 (19) | 3 (3) | 7 (6) | 0 | 1 (1) | 0 | 41 |
//! | Festival degraded, so | 16 (10) | 3 (3) | 0 | 0 | 0 | 0 | 19 |
//! | Festival clean, so | 29 (26) | 5 (5) | 1 (1) | 0 | 1 (0) | 0 | 36 |
//!
//! Clean Festival per voice: kal 14 → 10, slt 19 → 13, ked 22 → 13. The spread ones were the
//! blend left by a merged-away key ([`super::coarticulation`]). What is left is an m, b or p
//! heard a frame off a real closure (26 of 36 on clean Festival) or heard where there is none
//! (espeak-ng: 11 of its 30; 15 of the 30 from a heard phone longer than 60 ms); the dips and
//! the heard f's and v's put few.
//!
//! Tried on top of that and not kept: each heard closure (and each added one) moved onto the
//! video frames where the sound is quietest within it (±20 ms, frames within 6 dB of the
//! quietest held): espeak-ng 59.7 / 69.2 / 2.6 %, Festival degraded 58.2 / 64.7 / 3.4 %,
//! clean 86.4 / 79.6 / 5.2 % — the quietest frame is often the pause or the stop's silent
//! gap beside the closure, not the closure; with a heard closure also dropped where its
//! quietest frame lies less than 3 dB below the louder frames around it: clean Festival
//! closures 86.4 → 71.4 % (2.9 % false), Festival degraded 58.2 → 47.4 %.

use super::features::{frame_at, frame_time, FeatureFrame};
use super::AlignedPhone;

/// How far the high-frequency energy must fall below the lower of the peaks on either
/// side, dB.
const MIN_DEPTH_DB: f32 = 10.0;
/// How far on each side those peaks are looked for, frames (10 ms).
const REACH: usize = 15;
/// The bottom of the dip is dark when its high-frequency energy is at least this far below
/// its total energy, dB (vowels sit near 0, t/d/k/g near −2, m and b near −9 to −11).
const DARK_DB: f32 = -8.0;
/// Half the length of the closure phone added, seconds: one frame shows it.
const HALF_CLOSURE: f64 = 0.01;

/// Consonants with a place of their own: heard anywhere in a dip, they explain it.
const PLACED: [&str; 14] = [
    "N", "NG", "T", "D", "K", "G", "S", "Z", "SH", "ZH", "CH", "JH", "TH", "DH",
];
/// Rounded or dark open-lip sounds: heard at the bottom of a dip, they explain its darkness.
const ROUNDED: [&str; 7] = ["W", "UW", "OW", "AO", "UH", "R", "ER"];
/// The recogniser's own closures.
const CLOSURES: [&str; 3] = ["M", "B", "P"];

/// A dip in the high-frequency energy: a stretch where the mouth narrows or shuts.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Dip {
    /// First frame below the half-depth level.
    pub first: usize,
    /// Last frame below it.
    pub last: usize,
    /// The deepest frame.
    pub bottom: usize,
    /// How far the bottom lies below the lower of the peaks around it, dB.
    pub depth: f32,
}

/// How far `level[k]` lies below the lower of the peaks on either side of it (within
/// `REACH` frames).
fn gap_depth(level: &[f32], k: usize) -> f32 {
    let peak = |r: &[f32]| r.iter().copied().fold(f32::MIN, f32::max);
    let left = peak(&level[k.saturating_sub(REACH)..k]);
    let right = peak(&level[k + 1..(k + 1 + REACH).min(level.len())]);
    left.min(right) - level[k]
}

/// Whether the recogniser heard a phone of `set` overlapping `from..to` (seconds).
fn heard(phones: &[AlignedPhone], set: &[&str], from: f64, to: f64) -> bool {
    phones
        .iter()
        .any(|p| p.end > from && p.start < to && set.contains(&p.symbol.as_str()))
}

/// The dips at least `min_depth` dB deep in `frames`' high-frequency energy.
pub fn dips(frames: &[FeatureFrame], min_depth: f32) -> Vec<Dip> {
    let n = frames.len();
    if n < 3 {
        return Vec::new();
    }
    // The high-frequency energy, smoothed over three frames.
    let high: Vec<f32> = (0..n)
        .map(|i| {
            let (a, b) = (i.saturating_sub(1), (i + 1).min(n - 1));
            (frames[a].high_db + frames[i].high_db + frames[b].high_db) / 3.0
        })
        .collect();
    let mut dips: Vec<Dip> = Vec::new();
    for i in 1..n - 1 {
        if !(high[i] <= high[i - 1] && high[i] < high[i + 1]) {
            continue;
        }
        let depth = gap_depth(&high, i);
        if depth < min_depth {
            continue;
        }
        let level = high[i] + 0.5 * depth;
        let (mut a, mut b) = (i, i);
        while a > 0 && high[a - 1] < level {
            a -= 1;
        }
        while b + 1 < n && high[b + 1] < level {
            b += 1;
        }
        let dip = Dip {
            first: a,
            last: b,
            bottom: i,
            depth,
        };
        // Two minima of one dip: the deeper one stands for it.
        if let Some(last) = dips.last_mut() {
            if a <= last.last {
                if depth > last.depth {
                    *last = dip;
                }
                continue;
            }
        }
        dips.push(dip);
    }
    dips
}

/// The times (seconds) of the closures the sound shows, given the recogniser's `phones`
/// (ARPAbet).
pub fn acoustic_closures(frames: &[FeatureFrame], phones: &[AlignedPhone]) -> Vec<f64> {
    let mut out = Vec::new();
    for d in dips(frames, MIN_DEPTH_DB) {
        let i = d.bottom;
        let dark = frames[i].high_db - frames[i].energy_db <= DARK_DB;
        if !dark {
            continue;
        }
        let (start, end, bottom) = (frame_time(d.first), frame_time(d.last), frame_time(i));
        // A closure the recogniser heard in the dip is shown at its bottom too (the
        // recogniser's times are rough); otherwise the dip is a closure when nothing heard
        // there explains it with open lips.
        if heard(phones, &CLOSURES, start, end)
            || !(heard(phones, &PLACED, start, end)
                || heard(phones, &ROUNDED, bottom, bottom + 1e-6))
        {
            out.push(bottom);
        }
    }
    out
}

/// Phones the recogniser hears where a lip closure often is: with noise in the recording,
/// the silent gap and burst of a b or p sound to it like a labiodental fricative.
const FRICATIVE_LABIALS: [&str; 2] = ["F", "V"];
/// How far the quietest frame of such a phone must lie below the louder stretches on either
/// side (the lower of the two peaks within `REACH` frames), total energy, dB: a gap at
/// least this deep is a stop's, not a fricative's (an f or v keeps its hiss).
const FRICATIVE_GAP_DB: f32 = 24.0;
/// A closure already this near (seconds) makes another one redundant.
const SAME_CLOSURE: f64 = 0.04;

/// The times (seconds) of closures the recogniser heard as f or v (ARPAbet `phones`): the
/// quietest frame of each such phone whose gap is deep enough, unless it lies in one of
/// `silences` (noise in a pause is heard as f too) or a closure is already near it (one in
/// `known`, or an m, b or p heard).
pub fn fricative_closures(
    frames: &[FeatureFrame],
    phones: &[AlignedPhone],
    silences: &[(f64, f64)],
    known: &[f64],
) -> Vec<f64> {
    let n = frames.len();
    let mut out = Vec::new();
    if n == 0 {
        return out;
    }
    let energy: Vec<f32> = frames.iter().map(|f| f.energy_db).collect();
    for p in phones
        .iter()
        .filter(|p| FRICATIVE_LABIALS.contains(&p.symbol.as_str()))
    {
        let first = frame_at(p.start, n);
        let last = frame_at(p.end, n).max(first);
        let Some(k) = (first..=last).min_by(|&i, &j| energy[i].total_cmp(&energy[j])) else {
            continue;
        };
        let t = frame_time(k);
        if gap_depth(&energy, k) < FRICATIVE_GAP_DB
            || silences.iter().any(|&(a, b)| a <= t && t < b)
            || known.iter().any(|&c| (c - t).abs() < SAME_CLOSURE)
            || heard(phones, &CLOSURES, t - SAME_CLOSURE, t + SAME_CLOSURE)
        {
            continue;
        }
        out.push(t);
    }
    out
}

/// `phones` with a short `B` at each of `times` (the phones there are cut around it).
pub fn with_closures(phones: Vec<AlignedPhone>, times: &[f64]) -> Vec<AlignedPhone> {
    let mut phones = phones;
    for &t in times {
        let (a, b) = ((t - HALF_CLOSURE).max(0.0), t + HALF_CLOSURE);
        let mut out = Vec::with_capacity(phones.len() + 2);
        for p in phones.drain(..) {
            if p.end <= a || p.start >= b {
                out.push(p);
                continue;
            }
            if p.start < a {
                out.push(AlignedPhone {
                    end: a,
                    ..p.clone()
                });
            }
            if p.end > b {
                out.push(AlignedPhone { start: b, ..p });
            }
        }
        let k = out.iter().position(|p| p.start >= b).unwrap_or(out.len());
        out.insert(
            k,
            AlignedPhone {
                symbol: "B".into(),
                start: a,
                end: b,
                confidence: 0.5,
            },
        );
        phones = out;
    }
    phones
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frame(energy_db: f32, high_db: f32) -> FeatureFrame {
        FeatureFrame {
            mfcc: [0.0; 13],
            energy_db,
            high_db,
        }
    }

    fn phone(symbol: &str, start: f64, end: f64) -> AlignedPhone {
        AlignedPhone {
            symbol: symbol.into(),
            start,
            end,
            confidence: 1.0,
        }
    }

    /// A vowel, a 60 ms dip whose bottom has `bottom` (total, high) dB, a vowel.
    fn vcv(bottom: (f32, f32)) -> Vec<FeatureFrame> {
        let mut f = vec![frame(-20.0, -22.0); 20];
        f.extend([frame(-30.0, -34.0), frame(-34.0, -40.0)]);
        f.extend([frame(bottom.0, bottom.1); 2]);
        f.extend([frame(-34.0, -40.0), frame(-30.0, -34.0)]);
        f.extend(vec![frame(-20.0, -22.0); 20]);
        f
    }

    #[test]
    fn a_dark_dip_between_vowels_is_a_closure() {
        let f = vcv((-38.0, -50.0));
        let t = acoustic_closures(&f, &[phone("AA", 0.0, 0.23), phone("L", 0.23, 0.29)]);
        assert_eq!(t.len(), 1, "{t:?}");
        assert!((0.22..0.26).contains(&t[0]), "{t:?}");
        let p = with_closures(vec![phone("AA", 0.0, 0.23), phone("L", 0.23, 0.5)], &t);
        let s: Vec<&str> = p.iter().map(|p| p.symbol.as_str()).collect();
        assert!(s.contains(&"B"), "{s:?}");
        for w in p.windows(2) {
            assert!(w[0].end <= w[1].start + 1e-9, "{p:?}");
        }
    }

    #[test]
    fn a_dip_spans_the_frames_below_half_its_depth() {
        let f = vcv((-38.0, -50.0));
        let d = dips(&f, MIN_DEPTH_DB);
        assert_eq!(d.len(), 1, "{d:?}");
        // Smoothed high energy: -22 on the vowels, about -48 at the bottom (frames 22, 23).
        assert!(d[0].bottom == 22 || d[0].bottom == 23, "{d:?}");
        assert!(d[0].depth > 20.0 && d[0].depth < 30.0, "{d:?}");
        assert!(d[0].first >= 20 && d[0].first <= 22 && d[0].last >= 23 && d[0].last <= 25);
        // Asking for more depth than there is finds nothing.
        assert!(dips(&f, 40.0).is_empty());
    }

    #[test]
    fn a_bright_dip_or_one_the_recogniser_explains_is_not() {
        // A hiss at the bottom (a t burst, an s).
        assert!(acoustic_closures(&vcv((-38.0, -36.0)), &[]).is_empty());
        // Dark, but the recogniser heard an n there, or a w at its bottom.
        for heard in ["N", "W"] {
            let p = [phone("AA", 0.0, 0.2), phone(heard, 0.2, 0.3)];
            assert!(
                acoustic_closures(&vcv((-38.0, -50.0)), &p).is_empty(),
                "{heard}"
            );
        }
        // A heard m in a bright dip is not moved (the dip is not dark).
        let p = [phone("AA", 0.0, 0.2), phone("M", 0.2, 0.3)];
        assert!(acoustic_closures(&vcv((-38.0, -36.0)), &p).is_empty());
        // No dip at all.
        assert!(acoustic_closures(&vec![frame(-20.0, -40.0); 50], &[]).is_empty());
        assert!(acoustic_closures(&[], &[]).is_empty());
    }

    /// Vowels around a 60 ms gap whose quietest frames have `bottom` dB total energy.
    fn gap(bottom: f32) -> Vec<FeatureFrame> {
        let mut f = vec![frame(-20.0, -22.0); 20];
        f.extend([
            frame(-30.0, -30.0),
            frame(bottom, bottom),
            frame(bottom, bottom),
        ]);
        f.extend([frame(-35.0, -35.0), frame(-30.0, -30.0)]);
        f.extend(vec![frame(-20.0, -22.0); 20]);
        f
    }

    #[test]
    fn an_f_heard_on_a_deep_gap_is_a_closure_at_its_quietest_frame() {
        let heard = [
            phone("AA", 0.0, 0.19),
            phone("F", 0.19, 0.26),
            phone("AA", 0.26, 0.5),
        ];
        let t = fricative_closures(&gap(-60.0), &heard, &[], &[]);
        assert_eq!(t.len(), 1, "{t:?}");
        assert!((t[0] - frame_time(21)).abs() < 1e-9, "{t:?}");
        // A v too; an n is not labial.
        let mut v = heard.clone();
        v[1].symbol = "V".into();
        assert_eq!(fricative_closures(&gap(-60.0), &v, &[], &[]).len(), 1);
        v[1].symbol = "N".into();
        assert!(fricative_closures(&gap(-60.0), &v, &[], &[]).is_empty());
    }

    #[test]
    fn a_shallow_gap_a_pause_or_a_closure_already_there_adds_none() {
        let heard = [
            phone("AA", 0.0, 0.19),
            phone("F", 0.19, 0.26),
            phone("AA", 0.26, 0.5),
        ];
        // 15 dB below the vowels: an f's own hiss, not a stop's gap.
        assert!(fricative_closures(&gap(-35.0), &heard, &[], &[]).is_empty());
        // Inside a pause.
        assert!(fricative_closures(&gap(-60.0), &heard, &[(0.15, 0.4)], &[]).is_empty());
        // A closure found in the sound 30 ms away, or an m heard beside it.
        let at = frame_time(21);
        assert!(fricative_closures(&gap(-60.0), &heard, &[], &[at + 0.03]).is_empty());
        let mut m = heard.to_vec();
        m.insert(2, phone("M", 0.26, 0.28));
        m[3].start = 0.28;
        assert!(fricative_closures(&gap(-60.0), &m, &[], &[]).is_empty());
        assert!(fricative_closures(&[], &heard, &[], &[]).is_empty());
    }
}
