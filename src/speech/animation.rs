//! Timed phonemes to a FAP stream: viseme keys, blended between neighbours, sampled at the
//! output frame rate.
//!
//! Each phoneme puts a key (its viseme) at the middle of its interval; a diphthong puts its
//! two visemes at one and three quarters; `h` takes the next phoneme's viseme; a pause is
//! viseme 0 (rest). The mouth starts and ends at rest. Between two keys the frame sends
//! FAP 1 with `viseme_select1` = the earlier key, `viseme_select2` = the later one and
//! `viseme_blend` = 63 × (1 − smoothstep(s)), s the frame's fraction of the way between the
//! keys: the standard's blend (select1 at blend/63, select2 at the rest) moves the mouth
//! from one shape to the next with eased starts and stops, and every phoneme reaches its
//! full shape at its key.
//!
//! The stream has `round(duration × fps)` frames, so it lasts as long as the audio to
//! within half a frame. With [`MouthFaps::LowLevel`] or [`MouthFaps::Both`] every frame also
//! sends the same blend of the visemes' light jaw and lip FAPs
//! ([`super::articulation`]).

use serde::Serialize;

use super::articulation::{articulation, ARTICULATION_FAPS};
use super::espeak::TimedPhoneme;
use super::phonemes::{PhonemeVisemeTable, VisemeTarget};
use super::SpeechError;
use crate::error::Result;
use crate::fap::{FapFrame, FapStream, VisemeParams};
use crate::spec::{FapId, Viseme};

/// Frame rate of speech streams unless asked otherwise.
pub const SPEECH_FPS: f64 = 25.0;

/// What the stream moves the mouth with.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum MouthFaps {
    /// FAP 1 only: faces with viseme tables.
    #[default]
    Visemes,
    /// Jaw and lip FAPs only (3–7, 16, 17): faces without viseme tables.
    LowLevel,
    /// Both (on a face with viseme tables the low-level motion adds to the visemes').
    Both,
}

/// How to build a speech stream.
#[derive(Clone, Debug, PartialEq)]
pub struct SpeechOptions {
    /// Frames per second.
    pub fps: f64,
    /// What the stream sends.
    pub mouth: MouthFaps,
    /// Name written in the stream header.
    pub name: String,
}

impl Default for SpeechOptions {
    fn default() -> Self {
        SpeechOptions {
            fps: SPEECH_FPS,
            mouth: MouthFaps::Visemes,
            name: "fbakit-speak".into(),
        }
    }
}

/// A viseme at a time: where the mouth has exactly that shape.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct VisemeKey {
    /// Seconds.
    pub time: f64,
    /// The shape.
    pub viseme: Viseme,
}

/// A speech stream and how it was made.
#[derive(Clone, Debug, PartialEq)]
pub struct SpeechAnimation {
    /// The FAP stream.
    pub stream: FapStream,
    /// The viseme keys it blends between, in time order.
    pub keys: Vec<VisemeKey>,
    /// Phonemes the table has no viseme for (each once), skipped: the mouth blends across.
    pub unmapped: Vec<String>,
}

/// The viseme keys of `phonemes` (see the module docs) for audio `duration` seconds long,
/// and the phonemes without a viseme.
pub fn viseme_keys(
    phonemes: &[TimedPhoneme],
    duration: f64,
    table: &PhonemeVisemeTable,
) -> (Vec<VisemeKey>, Vec<String>) {
    let rest = Viseme::new(0).unwrap_or_else(|| unreachable!("viseme 0 exists"));
    let targets: Vec<Option<VisemeTarget>> =
        phonemes.iter().map(|p| table.lookup(&p.symbol)).collect();
    let mut unmapped: Vec<String> = Vec::new();
    let mut keys = vec![VisemeKey {
        time: 0.0,
        viseme: rest,
    }];
    for (i, p) in phonemes.iter().enumerate() {
        let len = (p.end - p.start).max(0.0);
        let target = match targets[i] {
            Some(VisemeTarget::Next) => {
                // The first following phoneme with a shape of its own, else rest.
                let next = targets[i + 1..]
                    .iter()
                    .flatten()
                    .find(|t| **t != VisemeTarget::Next);
                match next {
                    Some(VisemeTarget::Single(v) | VisemeTarget::Glide(v, _)) => {
                        VisemeTarget::Single(*v)
                    }
                    _ => VisemeTarget::Single(rest),
                }
            }
            Some(t) => t,
            None => {
                if !unmapped.contains(&p.symbol) {
                    unmapped.push(p.symbol.clone());
                }
                continue;
            }
        };
        match target {
            VisemeTarget::Single(v) => keys.push(VisemeKey {
                time: p.start + 0.5 * len,
                viseme: v,
            }),
            VisemeTarget::Glide(a, b) => {
                keys.push(VisemeKey {
                    time: p.start + 0.25 * len,
                    viseme: a,
                });
                keys.push(VisemeKey {
                    time: p.start + 0.75 * len,
                    viseme: b,
                });
            }
            VisemeTarget::Next => {}
        }
    }
    keys.push(VisemeKey {
        time: duration.max(keys.last().map_or(0.0, |k| k.time)),
        viseme: rest,
    });
    // Phoneme intervals are ordered, so keys are; a stable sort guards odd inputs.
    keys.sort_by(|a, b| a.time.total_cmp(&b.time));
    (keys, unmapped)
}

/// `3s² − 2s³` on `[0, 1]`: eases in and out.
fn smoothstep(s: f64) -> f64 {
    let s = s.clamp(0.0, 1.0);
    s * s * (3.0 - 2.0 * s)
}

/// The two keys around time `t` and the weight of the later one.
fn bracket(keys: &[VisemeKey], t: f64) -> Option<(VisemeKey, VisemeKey, f64)> {
    let first = *keys.first()?;
    let i = keys.partition_point(|k| k.time <= t);
    if i == 0 {
        return Some((first, first, 0.0));
    }
    let a = keys[i - 1];
    let Some(&b) = keys.get(i) else {
        return Some((a, a, 0.0));
    };
    let span = b.time - a.time;
    let s = if span > 0.0 { (t - a.time) / span } else { 1.0 };
    Some((a, b, smoothstep(s)))
}

/// FAP 1 at time `t`: the surrounding keys blended (see the module docs).
pub fn viseme_at(keys: &[VisemeKey], t: f64) -> VisemeParams {
    match bracket(keys, t) {
        None => VisemeParams::NEUTRAL,
        Some((a, b, w)) => {
            let blend = if a.viseme == b.viseme {
                VisemeParams::MAX_BLEND
            } else {
                (f64::from(VisemeParams::MAX_BLEND) * (1.0 - w)).round() as u8
            };
            VisemeParams {
                select1: a.viseme,
                select2: b.viseme,
                blend,
                def: false,
            }
        }
    }
}

/// The FAP stream for `phonemes` over `duration` seconds of audio.
pub fn speech_animation(
    phonemes: &[TimedPhoneme],
    duration: f64,
    opts: &SpeechOptions,
) -> Result<SpeechAnimation> {
    let count = frame_count(duration, opts.fps)?;
    let (keys, unmapped) = viseme_keys(phonemes, duration, PhonemeVisemeTable::standard());
    let mut stream = FapStream::new(opts.name.clone(), opts.fps);
    stream.frames.reserve(count as usize);
    stream
        .frames
        .extend((0..count).map(|n| key_frame(&keys, n, opts.fps, opts.mouth)));
    Ok(SpeechAnimation {
        stream,
        keys,
        unmapped,
    })
}

/// Frames a stream of `duration` seconds has at `fps` (`round(duration × fps)`, at least
/// one); refuses a bad rate, a bad duration or too many frames.
pub fn frame_count(duration: f64, fps: f64) -> Result<u64> {
    if !(fps.is_finite() && fps > 0.0 && fps <= 1000.0) {
        return Err(SpeechError::BadFrameRate { fps }.into());
    }
    if !(duration.is_finite() && duration >= 0.0) {
        return Err(SpeechError::BadDuration { duration }.into());
    }
    let count = ((duration * fps).round() as u64).max(1);
    if count > crate::fap::MAX_RESAMPLED_FRAMES {
        return Err(SpeechError::TooManyFrames {
            count,
            limit: crate::fap::MAX_RESAMPLED_FRAMES,
        }
        .into());
    }
    Ok(count)
}

/// Frame `n` (at `fps`) of the stream blending `keys`, sending what `mouth` says.
pub fn key_frame(keys: &[VisemeKey], n: u64, fps: f64, mouth: MouthFaps) -> FapFrame {
    let t = n as f64 / fps;
    let mut frame = FapFrame::new(n);
    if mouth != MouthFaps::LowLevel {
        frame.set_viseme(Some(viseme_at(keys, t)));
    }
    if mouth != MouthFaps::Visemes {
        if let Some((a, b, w)) = bracket(keys, t) {
            let mut low = [0.0f64; ARTICULATION_FAPS.len()];
            for (k, ((_, va), (_, vb))) in articulation(a.viseme)
                .zip(articulation(b.viseme))
                .enumerate()
            {
                low[k] = va * (1.0 - w) + vb * w;
            }
            for (k, &n) in ARTICULATION_FAPS.iter().enumerate() {
                if let Some(id) = FapId::new(n) {
                    // Whole FAP units: the file stays short and the motion is the same.
                    frame.set(id, low[k].round());
                }
            }
        }
    }
    frame
}

#[cfg(test)]
mod tests {
    use super::*;

    fn p(symbol: &str, start: f64, end: f64) -> TimedPhoneme {
        TimedPhoneme {
            symbol: symbol.into(),
            start,
            end,
        }
    }

    fn v(n: u8) -> Viseme {
        Viseme::new(n).unwrap()
    }

    /// "Hello" as espeak-ng times it (milliseconds from the `en` voice).
    fn hello() -> Vec<TimedPhoneme> {
        vec![
            p("h", 0.011, 0.062),
            p("@", 0.062, 0.123),
            p("l", 0.123, 0.196),
            p("oU", 0.196, 0.307),
            p("_", 0.307, 0.4),
        ]
    }

    #[test]
    fn keys_follow_the_phonemes() {
        let (keys, unmapped) = viseme_keys(&hello(), 0.4, PhonemeVisemeTable::standard());
        assert!(unmapped.is_empty());
        let seq: Vec<u8> = keys.iter().map(|k| k.viseme.number()).collect();
        // rest, h → next (@ = 11), @, l, oU = 13 then 14, pause, rest.
        assert_eq!(seq, vec![0, 11, 11, 8, 13, 14, 0, 0]);
        assert!(keys.windows(2).all(|w| w[0].time <= w[1].time));
        assert!((keys[3].time - 0.1595).abs() < 1e-9);
    }

    #[test]
    fn blend_reaches_each_key_and_eases_between() {
        let keys = vec![
            VisemeKey {
                time: 0.0,
                viseme: v(1),
            },
            VisemeKey {
                time: 1.0,
                viseme: v(10),
            },
        ];
        let at0 = viseme_at(&keys, 0.0);
        assert_eq!((at0.select1, at0.select2, at0.blend), (v(1), v(10), 63));
        let mid = viseme_at(&keys, 0.5);
        assert_eq!(mid.blend, 32);
        // After the last key: that viseme alone.
        let end = viseme_at(&keys, 2.0);
        assert_eq!((end.select1, end.blend), (v(10), 63));
        // Eased: a tenth of the way the earlier shape still has > 90 %.
        assert!(viseme_at(&keys, 0.1).blend > 57);
        assert_eq!(viseme_at(&[], 0.3), VisemeParams::NEUTRAL);
    }

    #[test]
    fn stream_length_matches_the_audio() {
        let opts = SpeechOptions::default();
        for duration in [0.4, 0.41, 1.028, 2.0] {
            let a = speech_animation(&hello(), duration, &opts).unwrap();
            let len = a.stream.frames.len() as f64 / a.stream.frame_rate;
            assert!(
                (len - duration).abs() <= 0.5 / opts.fps + 1e-12,
                "{duration}"
            );
            assert!(a.stream.problems().is_empty());
        }
    }

    #[test]
    fn mouth_modes_choose_the_faps() {
        let mut opts = SpeechOptions {
            mouth: MouthFaps::LowLevel,
            ..SpeechOptions::default()
        };
        let low = speech_animation(&hello(), 0.4, &opts).unwrap();
        assert!(low.stream.frames.iter().all(|f| f.viseme().is_none()));
        let max_jaw = low
            .stream
            .frames
            .iter()
            .filter_map(|f| f.value(FapId::OPEN_JAW))
            .fold(0.0, f64::max);
        assert!(max_jaw > 100.0, "{max_jaw}");
        opts.mouth = MouthFaps::Both;
        let both = speech_animation(&hello(), 0.4, &opts).unwrap();
        assert!(both
            .stream
            .frames
            .iter()
            .all(|f| f.viseme().is_some() && f.value(FapId::OPEN_JAW).is_some()));
        let vis = speech_animation(&hello(), 0.4, &SpeechOptions::default()).unwrap();
        assert!(vis.stream.frames.iter().all(|f| f.values().is_empty()));
    }

    #[test]
    fn unknown_phonemes_are_reported_and_skipped() {
        let ph = vec![p("p", 0.0, 0.1), p("Qx", 0.1, 0.2), p("Qx", 0.2, 0.3)];
        let (keys, unmapped) = viseme_keys(&ph, 0.3, PhonemeVisemeTable::standard());
        assert_eq!(unmapped, vec!["Qx".to_string()]);
        assert_eq!(keys.len(), 3);
        assert!(speech_animation(&ph, f64::NAN, &SpeechOptions::default()).is_err());
    }
}
