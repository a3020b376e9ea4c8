//! Lip sync from a recording: a voice file and its transcript in, timed phones and a FAP
//! stream of visemes out.
//!
//! The transcript is spoken by espeak-ng (which knows the phonemes of 100+ languages and
//! reports when each starts), both that rendition and the recording are described by MFCCs
//! ([`features`]), and dynamic time warping ([`alignment`]) finds how the rendition's time
//! maps onto the recording's; each phone boundary is carried through that map. Silences
//! found in the recording ([`mod@activity`]) relax the mouth, and [`coarticulation`] makes the
//! viseme keys. (Moving m/b/p closures onto the recording's energy dips was tried and
//! measured: it showed fewer closures on the evaluation set, so it is not done.)
//!
//! **English** (`--lang en`, `en-*`) recordings read from a file then have their phones
//! placed by PocketSphinx's forced alignment ([`forced`]: the transcript's dictionary
//! phones, the recording searched for exactly that sequence) when Debian's `pocketsphinx`
//! and `pocketsphinx-en-us` are installed, a piece of at most
//! [`pieces::PIECE_SECONDS`] at a time cut at pauses ([`pieces`]), so recordings of any
//! length; each phone gets a confidence from the recogniser's acoustic score, and the warp
//! still gives the overall confidence, its warning and the refusal. Every other language,
//! a missing PocketSphinx, or a piece of the transcript the recogniser cannot fit (a warning
//! names its time span) keep the warp's times. On `examples/lipsync_eval.rs` forced alignment took
//! Festival's voices built from real speakers (the honest stand-in for people) from 93.4 %
//! closures shown, 78.7 % agreement and 4.9 % false closures to 100 / 96.3 / 1.3 %, every
//! Festival condition better; on espeak-ng's own voices, whose rendition is the recording's
//! twin so the warp is nearly exact, it went from 100 / 95.5 / 1.6 to 98.0 / 89.9 / 3.0 %
//! (pocketsphinx's boundaries are acoustic, espeak-ng's reported phone starts are not
//! always); it is kept because people are not espeak-ng. Speed on one core: 50× → 23× real
//! time on a 24 s recording, 76× → 16× on 97 s (the warp still runs, for the confidence).
//!
//! Without a transcript (English only), PocketSphinx recognises the phones
//! ([`recognition`]; audio sampled below 16 kHz has its empty top band filled first,
//! [`enhance`]) and [`closures`] adds the lip closures the sound shows that the phones
//! miss ([`lipsync_recognised`]). Recognising words instead ([`words`]) was measured and is
//! no better on the evaluation, and slower.
//!
//! The recording is read a chunk at a time ([`analyse_chunks`]): only its features (about
//! 60 bytes per 10 ms) are kept, and the warp's memory grows linearly with the length. The
//! transcript's rendition is spoken a few sentences at a time and kept as features too
//! ([`rendition`]), so an hour-long recording stays in bounded memory.
//!
//! ```no_run
//! use fbakit::speech::lipsync::{analyse_file, lipsync_transcript, LipsyncOptions};
//! let rec = analyse_file("voice.wav".as_ref(), &mut |_| {}).unwrap();
//! let sync = lipsync_transcript(&rec, "Hello world", &LipsyncOptions::default()).unwrap();
//! let stream = sync.stream(&Default::default()).unwrap();
//! fbakit::fap::write_fap_file("voice.fap".as_ref(), &stream).unwrap();
//! ```

pub mod activity;
pub mod alignment;
pub mod closures;
pub mod coarticulation;
pub mod enhance;
pub mod evaluation;
pub mod features;
pub mod forced;
pub mod pieces;
pub mod recognition;
pub mod rendition;
pub mod words;

use std::path::{Path, PathBuf};

use serde::Serialize;

use self::activity::{activity, Activity};
use self::alignment::{unrelated_distance, warp, DEFAULT_RADIUS};
use self::coarticulation::lipsync_keys;
use self::features::{frame_at, frame_time, normalise, FeatureExtractor, FeatureFrame};
use self::pieces::{plan, PlacedWord, RenditionPause, Timeline, MIN_PIECE_SECONDS, PIECE_SECONDS};
pub use self::rendition::{render_features, render_transcript, Rendition};
use super::animation::{frame_count, key_frame, MouthFaps, SpeechOptions, VisemeKey};
use super::audio::{open_audio, AudioInfo, ANALYSIS_RATE};
use super::espeak::TimedPhoneme;
use super::SpeechError;
use crate::error::Result;
use crate::fap::{FapFrame, FapStream};

/// How to lip-sync.
#[derive(Clone, Debug, PartialEq)]
pub struct LipsyncOptions {
    /// espeak-ng voice whose phonemes the transcript gets (its language), e.g. `en`, `de`.
    pub lang: String,
    /// Half-width of the warp's search corridor, in frames of each level.
    pub radius: usize,
    /// Extra cost of a warp step that holds one side still, as a share of the distance
    /// between unrelated frames: keeps the warp from stalling on noise.
    pub step_penalty: f64,
    /// For English read from a file, place the phones with PocketSphinx's forced alignment
    /// when it is installed, rather than through the warp alone.
    pub forced: bool,
}

impl Default for LipsyncOptions {
    fn default() -> Self {
        LipsyncOptions {
            lang: "en".into(),
            radius: DEFAULT_RADIUS,
            step_penalty: 0.3,
            forced: true,
        }
    }
}

/// A recording described for alignment.
#[derive(Clone, Debug)]
pub struct RecordingAnalysis {
    /// The file (or the name given to a stream).
    pub source: PathBuf,
    /// What the file is, when read from one.
    pub info: Option<AudioInfo>,
    /// Features every 10 ms.
    pub frames: Vec<FeatureFrame>,
    /// Length in seconds.
    pub seconds: f64,
    /// Share of samples at full scale (clipping).
    pub clipped: f64,
    /// Speech and silence.
    pub activity: Activity,
}

/// Describes a recording given as chunks of mono samples at
/// [`super::audio::ANALYSIS_RATE`]; `source` names it in errors.
pub fn analyse_chunks<I>(chunks: I, source: &Path) -> Result<RecordingAnalysis>
where
    I: IntoIterator<Item = Result<Vec<f32>>>,
{
    let mut fx = FeatureExtractor::new();
    let mut samples = 0u64;
    let mut clipped = 0u64;
    for chunk in chunks {
        let chunk = chunk?;
        samples += chunk.len() as u64;
        clipped += chunk.iter().filter(|s| s.abs() >= 0.999).count() as u64;
        fx.push(&chunk);
    }
    let frames = fx.finish();
    let seconds = samples as f64 / f64::from(ANALYSIS_RATE);
    if frames.is_empty() {
        return Err(SpeechError::NoSpeech {
            path: source.to_path_buf(),
            detail: "the recording has no samples".into(),
        }
        .into());
    }
    let activity = activity(&frames);
    Ok(RecordingAnalysis {
        source: source.to_path_buf(),
        info: None,
        frames,
        seconds,
        clipped: clipped as f64 / samples.max(1) as f64,
        activity,
    })
}

/// Reads and describes the recording at `path`; `progress` hears the share read (0..=1).
pub fn analyse_file(path: &Path, progress: &mut dyn FnMut(f64)) -> Result<RecordingAnalysis> {
    let mut reader = open_audio(path)?;
    let info = reader.info().clone();
    let total = (info.seconds * f64::from(info.sample_rate)).max(1.0);
    let chunks = std::iter::from_fn(|| {
        let next = reader.next_chunk().transpose();
        progress((reader.frames_read() as f64 / total).min(1.0));
        next
    });
    let mut analysis = analyse_chunks(chunks, path)?;
    analysis.info = Some(info);
    Ok(analysis)
}

/// A phone placed in the recording.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct AlignedPhone {
    /// espeak-ng's mnemonic (`_` and `_:` are pauses).
    pub symbol: String,
    /// Start, seconds.
    pub start: f64,
    /// End, seconds.
    pub end: f64,
    /// How sure the placement is, 0 (not at all) to 1. Placed by forced alignment: from
    /// the recogniser's acoustic score for the phone per frame, against the best-matching
    /// sound of its model at each frame ([`forced::acoustic_confidence`]: one half at
    /// −4 nats a frame). Placed by the warp: how close the recording's sound is to the
    /// rendition's here, against unrelated frames. Recognised without a transcript: the
    /// recogniser's own phone confidence.
    pub confidence: f64,
}

/// The result: phones in the recording and the viseme keys that animate them.
#[derive(Clone, Debug, PartialEq)]
pub struct Lipsync {
    /// The phones, in time order.
    pub phones: Vec<AlignedPhone>,
    /// The viseme keys the stream blends between.
    pub keys: Vec<VisemeKey>,
    /// Length of the recording, seconds.
    pub duration: f64,
    /// Overall fit of the transcript to the recording, 0..=1.
    pub confidence: f64,
    /// Phonemes without a viseme (the mouth blends across them).
    pub unmapped: Vec<String>,
    /// Warnings for the user (a poor fit, clipping).
    pub warnings: Vec<String>,
    /// Frame rate the keys were made for.
    pub fps: f64,
}

/// Below this overall confidence the transcript is refused: it does not match at all.
pub const REFUSE_CONFIDENCE: f64 = 0.08;
/// Below this overall confidence a warning says the fit is poor.
pub const WARN_CONFIDENCE: f64 = 0.5;
/// The path's mean distance as a share of unrelated frames' at which confidence is 0 …
const RATIO_NONE: f64 = 0.95;
/// … and at which it is 1 (a rendition matched against itself under noise scores ~0.45).
const RATIO_FULL: f64 = 0.5;

fn confidence_of(ratio: f64) -> f64 {
    ((RATIO_NONE - ratio) / (RATIO_NONE - RATIO_FULL)).clamp(0.0, 1.0)
}

/// Pause added before and after the rendition, seconds: room for the recording's own
/// lead-in and tail to match silence rather than stretch the first and last phones.
const RENDITION_PAD: f64 = 0.3;

/// Aligns `text` with the analysed recording and makes its viseme keys at `fps`.
pub fn lipsync_transcript(
    rec: &RecordingAnalysis,
    text: &str,
    opts: &LipsyncOptions,
) -> Result<Lipsync> {
    lipsync_transcript_at(rec, text, opts, super::animation::SPEECH_FPS)
}

/// [`lipsync_transcript`] with keys made for `fps` frames per second.
pub fn lipsync_transcript_at(
    rec: &RecordingAnalysis,
    text: &str,
    opts: &LipsyncOptions,
    fps: f64,
) -> Result<Lipsync> {
    frame_count(rec.seconds, fps)?;
    if let Some(why) = rec.activity.no_speech() {
        return Err(SpeechError::NoSpeech {
            path: rec.source.clone(),
            detail: why,
        }
        .into());
    }
    let mut rendition = render_features(text, &opts.lang, RENDITION_PAD)?;
    let synth = std::mem::take(&mut rendition.frames);
    let cannot = |detail: String| -> crate::error::Error {
        SpeechError::CannotAlign {
            path: rec.source.clone(),
            detail,
        }
        .into()
    };
    let synth_activity = activity(&synth);
    let (spoken, heard) = (synth_activity.speech_seconds, rec.activity.speech_seconds);
    if spoken > 0.0 && !(0.25..=4.0).contains(&(heard / spoken)) {
        return Err(cannot(format!(
            "the transcript takes {spoken:.1} s to say but the recording has {heard:.1} s of speech"
        )));
    }
    let a = normalise(&synth);
    drop(synth);
    let b = normalise(&rec.frames);
    let unrelated = unrelated_distance(&a, &b);
    let penalty = (opts.step_penalty * unrelated) as f32;
    let path =
        warp(&a, &b, opts.radius, penalty).ok_or_else(|| cannot("nothing to align".into()))?;
    let ratio = if unrelated > 0.0 {
        path.mean_distance / unrelated
    } else {
        1.0
    };
    let confidence = confidence_of(ratio);
    if confidence < REFUSE_CONFIDENCE {
        return Err(cannot(format!(
            "the recording does not sound like the transcript (confidence {confidence:.2})"
        )));
    }
    // Each rendition frame's matched recording frames (first, last) and local distance.
    let mut rows: Vec<(u32, u32, f32, u32)> = vec![(u32::MAX, 0, 0.0, 0); a.len()];
    for &(i, j) in &path.pairs {
        let r = &mut rows[i as usize];
        r.0 = r.0.min(j);
        r.1 = r.1.max(j);
        r.2 += alignment::distance(&a[i as usize], &b[j as usize]);
        r.3 += 1;
    }
    let map_time = |t: f64| -> f64 {
        let i = frame_at(t, a.len());
        let (first, last, _, _) = rows[i];
        let mid = 0.5 * (frame_time(first as usize) + frame_time(last as usize));
        (mid + (t - frame_time(i)).clamp(-0.005, 0.005)).clamp(0.0, rec.seconds)
    };
    let mut phones: Vec<AlignedPhone> = Vec::with_capacity(rendition.phonemes.len());
    let mut floor = 0.0f64;
    for p in &rendition.phonemes {
        let start = map_time(p.start).max(floor);
        let end = map_time(p.end).max(start);
        floor = start;
        let (i0, i1) = (
            frame_at(p.start, a.len()),
            frame_at(p.end, a.len()).max(frame_at(p.start, a.len())),
        );
        let (sum, n) = rows[i0..=i1]
            .iter()
            .fold((0f64, 0u32), |(s, n), r| (s + f64::from(r.2), n + r.3));
        let local = if n > 0 {
            sum / f64::from(n)
        } else {
            path.mean_distance
        };
        phones.push(AlignedPhone {
            symbol: p.symbol.clone(),
            start,
            end,
            confidence: confidence_of(local / unrelated.max(1e-9)),
        });
    }
    // Keep intervals contiguous: each phone ends where the next starts.
    for k in 0..phones.len().saturating_sub(1) {
        phones[k].end = phones[k + 1].start.max(phones[k].start);
    }
    let mut notes = Vec::new();
    if opts.forced && forced::is_english(&opts.lang) && rec.info.is_some() && forced::available() {
        let words: Vec<PlacedWord> = rendition
            .words
            .iter()
            .map(|w| PlacedWord {
                start: map_time(w.start),
                text_start: w.text_start,
            })
            .collect();
        let pauses = rendition_pauses(&rendition, text.len(), &map_time);
        let energy: Vec<f32> = rec.frames.iter().map(|f| f.energy_db).collect();
        let timeline = Timeline {
            duration: rec.seconds,
            text_len: text.len(),
            silences: &rec.activity.silences,
            rendition_pauses: &pauses,
            words: &words,
            energy_db: &energy,
        };
        let pieces = plan(&timeline, MIN_PIECE_SECONDS, PIECE_SECONDS);
        drop(energy);
        let pronounced = forced::pronounced_words(text)?;
        let aligned = forced::align_pieces(&rec.source, &pronounced, &pieces, &phones)?;
        if aligned.aligned_pieces > 0 {
            phones = aligned.phones;
        }
        if pieces.len() == 1 && !aligned.failed.is_empty() {
            notes.push(
                "PocketSphinx could not fit the transcript's phones to the recording; \
                 their times come from the warp alone"
                    .to_string(),
            );
        } else {
            notes.extend(aligned.failed.iter().map(|(a, b)| {
                format!(
                    "PocketSphinx could not fit the transcript's phones from {a:.1} to {b:.1} s; \
                     their times there come from the warp alone"
                )
            }));
        }
    }
    let mut sync = finish(rec, phones, confidence, fps, |s| s.to_string(), false);
    sync.warnings.extend(notes);
    Ok(sync)
}

/// The rendition's pauses between words, carried into the recording by `map_time`, each
/// with the byte offset of the word after it (`text_len` when none follows).
fn rendition_pauses(
    rendition: &Rendition,
    text_len: usize,
    map_time: &dyn Fn(f64) -> f64,
) -> Vec<RenditionPause> {
    let n = rendition.phonemes.len();
    rendition
        .phonemes
        .iter()
        .enumerate()
        .filter(|(k, p)| *k > 0 && k + 1 < n && p.symbol.starts_with('_'))
        .map(|(_, p)| {
            let mid = 0.5 * (p.start + p.end);
            RenditionPause {
                start: map_time(p.start),
                end: map_time(p.end),
                next_word: rendition
                    .words
                    .get(rendition.words.partition_point(|w| w.start < mid))
                    .map_or(text_len, |w| w.text_start),
            }
        })
        .collect()
}

/// Phones recognised in the recording (ARPAbet, [`recognition`]) to a lip sync at `fps`;
/// lip closures the recogniser missed are found in the sound, or in an f or v it heard on a
/// deep gap ([`closures`]), and added as short `B` phones.
pub fn lipsync_recognised(
    rec: &RecordingAnalysis,
    phones: Vec<AlignedPhone>,
    fps: f64,
) -> Result<Lipsync> {
    frame_count(rec.seconds, fps)?;
    if let Some(why) = rec.activity.no_speech() {
        return Err(SpeechError::NoSpeech {
            path: rec.source.clone(),
            detail: why,
        }
        .into());
    }
    let spoken: Vec<&AlignedPhone> = phones
        .iter()
        .filter(|p| recognition::arpabet_to_espeak(&p.symbol) != "_")
        .collect();
    if spoken.is_empty() {
        return Err(SpeechError::NoSpeech {
            path: rec.source.clone(),
            detail: "no speech sounds recognised".into(),
        }
        .into());
    }
    let confidence = spoken.iter().map(|p| p.confidence).sum::<f64>() / spoken.len() as f64;
    let mut found = closures::acoustic_closures(&rec.frames, &phones);
    let heard = closures::fricative_closures(&rec.frames, &phones, &rec.activity.silences, &found);
    found.extend(heard);
    found.sort_by(f64::total_cmp);
    let phones = closures::with_closures(phones, &found);
    Ok(finish(
        rec,
        phones,
        confidence,
        fps,
        |s| recognition::arpabet_to_espeak(s).to_string(),
        true,
    ))
}

/// Warnings and the viseme keys; `espeak` names each phone's
/// symbol as the viseme table knows it.
fn finish(
    rec: &RecordingAnalysis,
    phones: Vec<AlignedPhone>,
    confidence: f64,
    fps: f64,
    espeak: impl Fn(&str) -> String,
    recognised: bool,
) -> Lipsync {
    let mut warnings = Vec::new();
    if confidence < WARN_CONFIDENCE {
        warnings.push(if recognised {
            format!("the phones were recognised with low confidence ({confidence:.2}): a transcript (--text) helps")
        } else {
            format!(
                "the transcript fits the recording poorly (confidence {confidence:.2}): check that it is what is said"
            )
        });
    }
    if rec.clipped > 0.001 {
        warnings.push(format!(
            "{:.1} % of the recording's samples are clipped (at full scale)",
            100.0 * rec.clipped
        ));
    }
    let timed: Vec<TimedPhoneme> = phones
        .iter()
        .map(|p| TimedPhoneme {
            symbol: espeak(&p.symbol),
            start: p.start,
            end: p.end,
        })
        .collect();
    let (keys, unmapped) = lipsync_keys(&timed, rec.seconds, &rec.activity.silences, fps);
    Lipsync {
        phones,
        keys,
        duration: rec.seconds,
        confidence,
        unmapped,
        warnings,
        fps,
    }
}

impl Lipsync {
    /// Frames of the stream at the rate the keys were made for, one by one.
    pub fn frames(&self, mouth: MouthFaps) -> Result<impl Iterator<Item = FapFrame> + '_> {
        let count = frame_count(self.duration, self.fps)?;
        Ok((0..count).map(move |n| key_frame(&self.keys, n, self.fps, mouth)))
    }

    /// The whole FAP stream (`opts.fps` must be the rate the keys were made for; its name
    /// and mouth mode are used).
    pub fn stream(&self, opts: &SpeechOptions) -> Result<FapStream> {
        let mut stream = FapStream::new(opts.name.clone(), self.fps);
        stream.frames.extend(self.frames(opts.mouth)?);
        Ok(stream)
    }
}
