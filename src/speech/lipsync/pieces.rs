//! Where a long recording is cut for forced alignment, and which of the transcript's words
//! each piece gets.
//!
//! The recogniser's grammar search costs about the grammar's length at every frame, so
//! aligning a file whole takes time growing with the square of its length (23 s for
//! 290 s of speech). Cut into pieces of at most [`PIECE_SECONDS`], an hour costs about
//! 90 short searches instead.
//!
//! A cut goes in the middle of a pause the recording has ([`mod@super::activity`]). The words
//! before it are found through the warp: espeak-ng's rendition of the transcript reports
//! where each word starts, in its own time and in the text, and the warp carries those
//! times into the recording's. Where the rendition also pauses (a sentence or clause end)
//! and the warp puts that pause on the recording's, the words are divided at the
//! rendition's pause, which does not depend on the warp placing each word well; elsewhere
//! at the first word the warp puts after the cut. Such matched pauses are preferred, then
//! longer ones.
//!
//! Measured on `examples/lipsync_eval.rs` with `LIPSYNC_EVAL_LONG=130` (each voice saying
//! the 24 sentences in turn with pauses of 0.3 to 1.2 s): Festival's three voices 100 %
//! closures shown, 96.4 % agreement, 1.0 % false closures (the warp alone on kal, 128 s:
//! 98.3 / 83.4 / 4.3 %); espeak-ng's three 95.1–97.6 / 87.6–90.8 / 2.4–3.4 %, one piece of
//! en-us+f3 at 200 wpm not fitting. A 300 s recording took 7.1 s of CPU, 43× real time
//! (60 s: 4.0 s), and at most 23 MB (60 s: 20 MB).

use std::ops::Range;

/// Longest piece aligned at once, seconds (its search takes about 0.5 s).
pub const PIECE_SECONDS: f64 = 40.0;
/// A cut is looked for this many seconds or more after the last.
pub const MIN_PIECE_SECONDS: f64 = 15.0;
/// How far, seconds, the warp may put a rendition's pause from the recording's and the two
/// still count as one.
const PAUSE_SLACK: f64 = 0.15;
/// The longest pause length that still counts for more when choosing a cut, seconds.
const LONG_PAUSE: f64 = 1.0;
/// What a pause the rendition shares counts for, as seconds of pause.
const SHARED_PAUSE_BONUS: f64 = 0.5;

/// A stretch of the recording and the transcript said in it.
#[derive(Clone, Debug, PartialEq)]
pub struct Piece {
    /// Start in the recording, seconds.
    pub start: f64,
    /// End, seconds.
    pub end: f64,
    /// The bytes of the transcript said in it.
    pub text: Range<usize>,
}

/// A word of the transcript placed in the recording by the warp.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlacedWord {
    /// Where the warp puts its start in the recording, seconds.
    pub start: f64,
    /// Byte offset of the word in the transcript.
    pub text_start: usize,
}

/// A pause in the rendition, in the recording's time (through the warp).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RenditionPause {
    /// Start in the recording, seconds.
    pub start: f64,
    /// End, seconds.
    pub end: f64,
    /// Byte offset in the transcript of the first word after the pause (its length when
    /// none follows).
    pub next_word: usize,
}

/// What the cutting reads.
#[derive(Clone, Copy, Debug)]
pub struct Timeline<'a> {
    /// Length of the recording, seconds.
    pub duration: f64,
    /// Length of the transcript, bytes.
    pub text_len: usize,
    /// The recording's pauses, (start, end) seconds, in order.
    pub silences: &'a [(f64, f64)],
    /// The rendition's pauses, in order.
    pub rendition_pauses: &'a [RenditionPause],
    /// The rendition's words, in order.
    pub words: &'a [PlacedWord],
    /// The recording's level every 10 ms, dB (for a cut where it has no pause).
    pub energy_db: &'a [f32],
}

/// The recording cut into pieces of at most `max` seconds (the last may be up to `max`
/// too), each with its words. A recording no longer than `max` is one piece with the whole
/// transcript.
pub fn plan(t: &Timeline, min: f64, max: f64) -> Vec<Piece> {
    let mut out = Vec::new();
    let (mut start, mut text_start) = (0.0f64, 0usize);
    while t.duration - start > max {
        let (cut, split) = best_cut(t, start + min, start + max);
        let split = split.clamp(text_start, t.text_len);
        out.push(Piece {
            start,
            end: cut,
            text: text_start..split,
        });
        start = cut;
        text_start = split;
    }
    out.push(Piece {
        start,
        end: t.duration,
        text: text_start..t.text_len,
    });
    out
}

/// The cut between `from` and `to` seconds and the byte offset dividing the words there.
fn best_cut(t: &Timeline, from: f64, to: f64) -> (f64, usize) {
    let mut best: Option<(f64, f64, usize)> = None;
    for &(s0, s1) in t.silences {
        let mid = 0.5 * (s0 + s1);
        if mid <= from || mid > to {
            continue;
        }
        let shared = t
            .rendition_pauses
            .iter()
            .filter(|p| p.start < s1 + PAUSE_SLACK && p.end > s0 - PAUSE_SLACK)
            .max_by(|a, b| overlap(a, s0, s1).total_cmp(&overlap(b, s0, s1)));
        let score = (s1 - s0).min(LONG_PAUSE)
            + if shared.is_some() {
                SHARED_PAUSE_BONUS
            } else {
                0.0
            };
        let split = shared.map_or_else(|| word_after(t, mid), |p| p.next_word);
        if best.is_none_or(|(b, _, _)| score >= b) {
            best = Some((score, mid, split));
        }
    }
    if let Some((_, cut, split)) = best {
        return (cut, split);
    }
    // No pause at all: the quietest 10 ms (the words then divide where the warp says).
    let frame = |s: f64| ((s / 0.01).round().max(0.0) as usize).min(t.energy_db.len());
    let cut = t.energy_db[frame(from)..frame(to)]
        .iter()
        .enumerate()
        .min_by(|a, b| a.1.total_cmp(b.1))
        .map_or(to, |(k, _)| (frame(from) + k) as f64 * 0.01);
    (cut, word_after(t, cut))
}

/// Seconds `p` shares with the recording's pause `s0..s1`.
fn overlap(p: &RenditionPause, s0: f64, s1: f64) -> f64 {
    p.end.min(s1) - p.start.max(s0)
}

/// Byte offset of the first word the warp puts at or after `time`.
fn word_after(t: &Timeline, time: f64) -> usize {
    t.words
        .iter()
        .find(|w| w.start >= time)
        .map_or(t.text_len, |w| w.text_start)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn word(start: f64, text_start: usize) -> PlacedWord {
        PlacedWord { start, text_start }
    }

    fn timeline<'a>(
        duration: f64,
        silences: &'a [(f64, f64)],
        rendition_pauses: &'a [RenditionPause],
        words: &'a [PlacedWord],
        energy_db: &'a [f32],
    ) -> Timeline<'a> {
        Timeline {
            duration,
            text_len: 1000,
            silences,
            rendition_pauses,
            words,
            energy_db,
        }
    }

    #[test]
    fn a_short_recording_is_one_piece_with_every_word() {
        let t = timeline(30.0, &[(10.0, 11.0)], &[], &[], &[]);
        assert_eq!(
            plan(&t, 15.0, 40.0),
            vec![Piece {
                start: 0.0,
                end: 30.0,
                text: 0..1000
            }]
        );
    }

    #[test]
    fn cuts_fall_in_the_longest_pauses_within_reach() {
        // A 100 s recording with words every 2 s (byte 10 per second).
        let words: Vec<PlacedWord> = (0..50)
            .map(|k| word(2.0 * k as f64 + 0.3, 20 * k))
            .collect();
        let silences = [
            (5.0, 6.0), // too early for a cut
            (20.0, 20.3),
            (30.0, 30.8), // the longest in 15..40 s
            (39.0, 39.2),
            (55.0, 55.2),
            (64.0, 65.0), // the longest in 45.4..70.4 s
        ];
        let t = timeline(100.0, &silences, &[], &words, &[]);
        let p = plan(&t, 15.0, 40.0);
        let cuts: Vec<f64> = p.iter().map(|p| p.end).collect();
        assert_eq!(cuts, [30.4, 64.5, 100.0]);
        // The words divide at the first the warp places after each cut.
        assert_eq!(p[0].text, 0..320);
        assert_eq!(p[1].text, 320..660);
        assert_eq!(p[2].text, 660..1000);
        for w in p.windows(2) {
            assert_eq!(w[0].end, w[1].start);
            assert!(w[0].end - w[0].start <= 40.0);
        }
    }

    #[test]
    fn a_pause_the_rendition_shares_wins_and_divides_the_words() {
        let words = [word(24.0, 100), word(26.0, 120), word(33.0, 200)];
        // The warp puts the rendition's pause on the recording's short pause at 26 s, and
        // puts the next word (byte 120) a little early, inside the pause.
        let pauses = [RenditionPause {
            start: 25.7,
            end: 26.1,
            next_word: 120,
        }];
        let silences = [(25.8, 26.3), (31.0, 31.6)];
        let t = timeline(60.0, &silences, &pauses, &words, &[]);
        let p = plan(&t, 15.0, 40.0);
        assert_eq!(p[0].end, 26.05);
        assert_eq!(p[0].text, 0..120);
        assert_eq!(p[1].text, 120..1000);
    }

    #[test]
    fn without_pauses_the_cut_is_the_quietest_moment() {
        let mut energy = vec![-20.0f32; 6000];
        energy[3300] = -50.0;
        energy[500] = -60.0; // before the window
        let words = [word(32.0, 300), word(33.5, 320)];
        let t = timeline(60.0, &[], &[], &words, &energy);
        let p = plan(&t, 15.0, 40.0);
        assert!((p[0].end - 33.0).abs() < 1e-9, "{p:?}");
        assert_eq!(p[0].text, 0..320);
    }

    #[test]
    fn word_divisions_never_run_backwards() {
        // A rendition pause whose next word the warp misplaced before the last cut.
        let pauses = [
            RenditionPause {
                start: 20.0,
                end: 21.0,
                next_word: 500,
            },
            RenditionPause {
                start: 45.0,
                end: 46.0,
                next_word: 400,
            },
        ];
        let silences = [(20.0, 21.0), (45.0, 46.0)];
        let t = timeline(70.0, &silences, &pauses, &[], &[]);
        let p = plan(&t, 15.0, 40.0);
        assert_eq!(p.len(), 3);
        assert_eq!(p[1].text, 500..500);
        assert_eq!(p[2].text, 500..1000);
    }
}
