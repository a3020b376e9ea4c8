//! espeak-ng's rendition of a transcript, kept only as what alignment needs: its timed
//! phonemes and its features every 10 ms.
//!
//! The transcript is spoken a piece at a time (pieces end at sentence or clause ends, at
//! most [`PIECE_BYTES`] long), and each piece's samples are resampled and featurised as
//! they come, then dropped: an hour of transcript keeps about 20 MB of features instead of
//! 160 MB of samples, and the samples held at once are one piece's (about a minute).

use super::features::{FeatureExtractor, FeatureFrame};
use crate::error::Result;
use crate::speech::audio::{Resampler, ANALYSIS_RATE};
use crate::speech::espeak::{
    espeak_available, speak_at, TimedPhoneme, TimedWord, Utterance, DEFAULT_RATE,
};
use crate::speech::SpeechError;

/// Longest piece of transcript spoken at once, bytes (about a minute of speech).
pub const PIECE_BYTES: usize = 1_000;

/// A transcript's rendition as features.
#[derive(Clone, Debug, PartialEq)]
pub struct Rendition {
    /// The phonemes, in time order, covering the rendition (pauses `_` at both ends).
    pub phonemes: Vec<TimedPhoneme>,
    /// Where each word starts, in time order (byte offsets into the whole transcript).
    pub words: Vec<TimedWord>,
    /// Features every 10 ms.
    pub frames: Vec<FeatureFrame>,
    /// Length in seconds.
    pub seconds: f64,
}

/// Byte offset of `piece`, a slice of `text`, within it.
fn offset_in(text: &str, piece: &str) -> usize {
    (piece.as_ptr() as usize).saturating_sub(text.as_ptr() as usize)
}

/// `words` of a piece starting `seconds` and `bytes` into the whole.
fn shifted(words: Vec<TimedWord>, seconds: f64, bytes: usize) -> impl Iterator<Item = TimedWord> {
    words.into_iter().map(move |w| TimedWord {
        start: w.start + seconds,
        text_start: w.text_start + bytes,
    })
}

fn engine_missing() -> crate::error::Error {
    SpeechError::EngineMissing {
        engine: "espeak-ng".into(),
        why: "lip sync with a transcript speaks it with libespeak-ng".into(),
        package: "espeak-ng".into(),
    }
    .into()
}

/// `text` cut into pieces of at most `limit` bytes, after sentence ends where it can, else
/// after clause ends or spaces.
pub fn pieces(text: &str, limit: usize) -> Vec<&str> {
    let mut out: Vec<&str> = Vec::new();
    let mut rest = text.trim();
    while rest.len() > limit {
        let window = &rest[..floor_char_boundary(rest, limit)];
        let cut = window
            .rfind(['.', '!', '?', '\n'])
            .or_else(|| window.rfind([';', ',', ':']))
            .or_else(|| window.rfind(' '))
            .map_or(window.len(), |i| i + 1);
        // A window with no break at all is cut at its end (on a character boundary).
        let cut = if cut == 0 { window.len().max(1) } else { cut };
        let cut = ceil_char_boundary(rest, cut);
        out.push(&rest[..cut]);
        rest = rest[cut..].trim_start();
    }
    if !rest.trim().is_empty() || out.is_empty() {
        out.push(rest);
    }
    out
}

fn floor_char_boundary(s: &str, mut i: usize) -> usize {
    while i > 0 && !s.is_char_boundary(i) {
        i -= 1;
    }
    i
}

fn ceil_char_boundary(s: &str, mut i: usize) -> usize {
    while i < s.len() && !s.is_char_boundary(i) {
        i += 1;
    }
    i
}

/// espeak-ng's rendition of `text` as one utterance, spoken in pieces (the whole audio is
/// kept: for short texts; [`render_features`] keeps only features).
pub fn render_transcript(text: &str, voice: &str) -> Result<Utterance> {
    if !espeak_available() {
        return Err(engine_missing());
    }
    let mut whole: Option<Utterance> = None;
    for piece in pieces(text, PIECE_BYTES) {
        let mut u = speak_at(piece, voice, DEFAULT_RATE)?;
        let bytes = offset_in(text, piece);
        match &mut whole {
            None => {
                u.words = shifted(u.words, 0.0, bytes).collect();
                whole = Some(u);
            }
            Some(w) => {
                let offset = w.duration();
                w.words.extend(shifted(u.words, offset, bytes));
                w.samples.extend_from_slice(&u.samples);
                w.phonemes
                    .extend(u.phonemes.into_iter().map(|p| TimedPhoneme {
                        start: p.start + offset,
                        end: p.end + offset,
                        ..p
                    }));
            }
        }
    }
    whole.ok_or_else(|| SpeechError::EmptyText.into())
}

/// Samples of espeak-ng's audio on their way to features.
///
/// espeak-ng's pauses are digital silence, which no recording has: a faint noise (about
/// −60 dBFS) makes them look like a quiet room, so the recording's pauses match them
/// rather than its quietest phones (nasals).
struct Featuriser {
    resampler: Option<Resampler>,
    extractor: FeatureExtractor,
    out: Vec<f32>,
    state: u64,
}

impl Featuriser {
    fn new() -> Featuriser {
        Featuriser {
            resampler: None,
            extractor: FeatureExtractor::new(),
            out: Vec::new(),
            state: 0x2545_F491_4F6C_DD1D,
        }
    }

    fn push(&mut self, rate: u32, samples: &[i16]) {
        let rs = self
            .resampler
            .get_or_insert_with(|| Resampler::new(rate, ANALYSIS_RATE));
        for chunk in samples.chunks(16_384) {
            let f: Vec<f32> = chunk
                .iter()
                .map(|&s| {
                    self.state ^= self.state << 13;
                    self.state ^= self.state >> 7;
                    self.state ^= self.state << 17;
                    let dither = ((self.state >> 40) as f32 / (1u64 << 24) as f32 - 0.5) * 0.003;
                    f32::from(s) / 32_768.0 + dither
                })
                .collect();
            self.out.clear();
            rs.push(&f, &mut self.out);
            self.extractor.push(&self.out);
        }
    }

    fn finish(mut self) -> Vec<FeatureFrame> {
        if let Some(rs) = &mut self.resampler {
            self.out.clear();
            rs.finish(&mut self.out);
            self.extractor.push(&self.out);
        }
        self.extractor.finish()
    }
}

/// espeak-ng's rendition of `text` with voice `voice`, with `pad` seconds of pause before
/// and after (room for a recording's own lead-in and tail), as features.
pub fn render_features(text: &str, voice: &str, pad: f64) -> Result<Rendition> {
    if !espeak_available() {
        return Err(engine_missing());
    }
    let mut fx = Featuriser::new();
    let mut phonemes: Vec<TimedPhoneme> = Vec::new();
    let mut words: Vec<TimedWord> = Vec::new();
    let mut rate = 0u32;
    let mut samples = 0u64;
    for piece in pieces(text, PIECE_BYTES) {
        let u = speak_at(piece, voice, DEFAULT_RATE)?;
        if rate == 0 {
            rate = u.sample_rate.max(1);
            let n = (pad * f64::from(rate)) as usize;
            fx.push(rate, &vec![0i16; n]);
            samples = n as u64;
            let first = u.phonemes.first().map_or(0.0, |p| p.start);
            phonemes.push(TimedPhoneme {
                symbol: "_".into(),
                start: 0.0,
                end: first + samples as f64 / f64::from(rate),
            });
        }
        let offset = samples as f64 / f64::from(rate);
        words.extend(shifted(u.words, offset, offset_in(text, piece)));
        phonemes.extend(u.phonemes.into_iter().map(|p| TimedPhoneme {
            start: p.start + offset,
            end: p.end + offset,
            ..p
        }));
        fx.push(rate, &u.samples);
        samples += u.samples.len() as u64;
    }
    if rate == 0 {
        return Err(SpeechError::EmptyText.into());
    }
    let n = (pad * f64::from(rate)) as usize;
    fx.push(rate, &vec![0i16; n]);
    samples += n as u64;
    let seconds = samples as f64 / f64::from(rate);
    if let Some(last) = phonemes.last_mut() {
        last.end = seconds;
    }
    Ok(Rendition {
        phonemes,
        words,
        frames: fx.finish(),
        seconds,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pieces_end_at_sentences_and_never_split_a_character() {
        let text = "One two. Three four five; six seven. Eight";
        let p = pieces(text, 20);
        assert_eq!(p, ["One two.", "Three four five;", "six seven. Eight"]);
        assert!(p.iter().all(|s| s.len() <= 20));
        let umlauts = "ää".repeat(30);
        let p = pieces(&umlauts, 7);
        assert_eq!(p.concat(), umlauts);
        assert!(p.iter().all(|s| !s.is_empty() && s.len() <= 8));
        assert_eq!(pieces("  ", 10), [""]);
    }
}
