//! Phones without a transcript (English): PocketSphinx's phone recogniser, run as the
//! `pocketsphinx_continuous` program of Debian's `pocketsphinx` package with the
//! `pocketsphinx-en-us` acoustic model and phone language model.
//!
//! It runs with context-independent phones (`-allphone_ci yes`, about 13× faster than the
//! context-dependent search and faster than real time) and prints one line per phone with
//! its start and end in seconds from the start of the file (`-time yes`); utterances its
//! own silence detector splits keep file times. Phones are ARPAbet (`AA`, `B`, `SIL`);
//! [`arpabet_to_espeak`] gives the espeak-ng mnemonic the viseme table knows.
//!
//! English only: `pocketsphinx-en-us` is the one model Debian packages. Its phones rarely
//! include m, b or p, so [`super::closures`] adds the closures the sound shows.
//!
//! Settings weighed on `examples/lipsync_eval.rs` (espeak-ng voices): a language weight of
//! 1 rather than 2 put more frames in the right mouth class on every condition (all: 63.9 →
//! 66.3 %, closures 50.5 → 53.1 %, false closures 2.5 → 2.9 %), so it is used; a weight of
//! 4, a phone insertion penalty of 0.3, wider beams, `-topn 2` or no noise removal moved
//! the phones' own figures by a few points at most, none better on every condition.
//!
//! On Festival's voices built from real speakers (`examples/lipsync_eval.rs`), clean, the
//! phones include most m, b and p; with the evaluation's noise they mostly turn into f, v or
//! th ([`super::closures::fricative_closures`] takes the f's and v's).
//!
//! Word recognition ([`Recognise::Words`], [`super::words`]) hears Festival's clean voices
//! word for word ("my mother bought a map of bombay"), but in the evaluation's noise the
//! words go wrong; its phones, shared over the words' times, force-aligned, or mixed with
//! the phone loop's where the words are unsure, were no better overall than the phone
//! loop's on Festival's voices and worse on espeak-ng's, at about a quarter of the speed
//! (figures in [`super::words`]). The phone loop stays the default.
//!
//! Retuned on the Festival voices too (`LIPSYNC_EVAL_NOSCRIPT_ONLY=1 cargo run --release
//! --example lipsync_eval`; closures / agreement / false closures, %, espeak-ng voices |
//! Festival's degraded conditions | Festival clean at 16 kHz, a condition added for this):
//!
//! | setting | espeak-ng | Festival | Festival clean |
//! |---|---|---|---|
//! | as before (`-lw 1.0`, context-independent phones) | 57.7 / 66.4 / 3.2 | 44.4 / 59.9 / 1.3 | 86.4 / 80.1 / 3.8 |
//! | `-lw 0.5` | 58.7 / 66.5 / 3.3 | 49.0 / 60.2 / 1.4 | 86.4 / 80.4 / 3.9 |
//! | `-lw 2` | 57.1 / 64.4 / 2.8 | 43.4 / 60.2 / 1.1 | 87.8 / 80.8 / 3.8 |
//! | `-pip 0.5` or `-pip 2` | unchanged | unchanged | unchanged |
//! | `-remove_noise no` | 52.6 / 66.3 / 2.5 | 41.8 / 57.4 / 1.0 | 87.8 / 80.7 / 3.9 |
//! | triphones (`-allphone_ci no`) pruned: `-maxhmmpf 3000 -topn 2 -beam 1e-10 -pbeam 1e-10 -ds 2` | 56.1 / 63.9 / 4.4 | 46.9 / 60.7 / 2.3 | 88.4 / 80.4 / 3.3 |
//! | `-lw 0.5` and the mirrored band (next row) together | 59.2 / 68.7 / 3.3 | 59.2 / 65.0 / 1.4 | 86.4 / 80.4 / 3.9 |
//! | the empty top band of sub-16 kHz audio mirrored ([`super::enhance`]) | 58.7 / 68.9 / 3.2 | 56.6 / 65.2 / 1.5 | 86.4 / 80.1 / 3.8 |
//! | and the closure edges set again after merging keys ([`super::coarticulation`]) | 58.2 / 68.8 / 2.0 | 56.1 / 65.3 / 1.0 | 86.4 / 80.1 / 2.5 |
//!
//! (The phone insertion penalty does not act on the phone loop.) The pruned triphone search
//! ran at 2× real time in CPU (the loop here ~10× on these 3–5 s sentences under load) and
//! put 9.8 % false closures on espeak-ng's 8 kHz voice: not kept. A language weight of 0.5
//! gains 4.6 points of closures on Festival's voices but loses 4 on espeak-ng's 20 dB voice
//! and takes espeak-ng's false closures further from 3 %; with the mirrored band it adds 2.6
//! points of closures on Festival's voices but loses a little agreement on both sets and
//! adds false closures on espeak-ng's (3.2 → 3.3 %): not kept. The mirrored band is the
//! default for recordings sampled below 16 kHz: Festival ked at 8 kHz goes from 18.4 / 42.2 /
//! 1.2 to 67.3 / 63.6 / 2.1, espeak-ng's 8 kHz voice from 53.1 / 54.7 / 3.8 to 57.1 / 63.2
//! / 3.8; nothing else changes. The espeak-ng false closures measure 3.2 % with the unchanged
//! default here, in every run (2.9 % in earlier notes). The clean Festival voices, the
//! nearest to the held-out clean read speech, passed 80 / 70 on closures and agreement but not
//! ≤ 3 % false closures (slt 4.0, ked 4.5 %); with the closure edges set again after merging
//! keys they pass all three (86.4 / 80.1 / 2.5 %), and espeak-ng's voices measure 2.0 %.
//! Noise reduction before the recogniser: see [`super::enhance`].
//!
//! Speed, CPU time of `fbakit lipsync REC.wav -o out.fap` and the recogniser on one core
//! (`taskset -c 0`, `/usr/bin/time`, a loaded machine), Festival kal: 4.8 s at 16 kHz 0.31 s
//! (15×), 154 s 6.8–7.0 s (22×); at 44.1 kHz stereo 0.49 s (9.7×) and 12.1 s (12.7×) before
//! the resampler's kernel was tabulated ([`crate::speech::audio`]; its sine and cosine per tap
//! were ~39 % of the CPU), 0.34 s (14×) and 7.4–7.8 s (20×) since. The recogniser's start-up
//! (model load) is ~0.1 s of it, ~0.045 s per second of audio the rest, so files shorter than
//! about 2 s miss 10× on that alone. It already runs once per piece of up to
//! [`SEGMENT_SECONDS`], not per sentence. Max RSS 37–38 MB (the recogniser's).
//!
//! The phone lattice (for phone posteriors) is not available: `pocketsphinx_batch
//! -outlatdir` gives none for the phone-loop search (`-allphone`).

use std::path::{Path, PathBuf};
use std::process::Command;

use super::enhance::{enhance, Enhance};
use super::AlignedPhone;
use crate::error::{Error, Result};
use crate::speech::audio::{open_audio, ANALYSIS_RATE};
use crate::speech::SpeechError;

/// The program run.
pub const PROGRAM: &str = "pocketsphinx_continuous";
/// Where Debian's `pocketsphinx-en-us` puts the model.
pub const MODEL_DIR: &str = "/usr/share/pocketsphinx/model/en-us";

/// The model directory: `FBAKIT_POCKETSPHINX_MODEL`, else [`MODEL_DIR`].
pub(super) fn model_dir() -> PathBuf {
    std::env::var_os("FBAKIT_POCKETSPHINX_MODEL")
        .map_or_else(|| PathBuf::from(MODEL_DIR), PathBuf::from)
}

/// The acoustic model and phone language model, or why they are missing.
pub(super) fn model() -> Result<(PathBuf, PathBuf)> {
    let dir = model_dir();
    let hmm = dir.join("en-us");
    let lm = dir.join("en-us-phone.lm.bin");
    if hmm.join("mdef").is_file() && lm.is_file() {
        Ok((hmm, lm))
    } else {
        Err(missing(&format!("no model in {}", dir.display())))
    }
}

pub(super) fn missing(detail: &str) -> Error {
    SpeechError::EngineMissing {
        engine: "PocketSphinx".into(),
        why: format!("lip sync without a transcript recognises phones with it ({detail})"),
        package: "pocketsphinx pocketsphinx-en-us".into(),
    }
    .into()
}

/// Whether the recogniser and its English model are installed.
pub fn recognition_available() -> bool {
    check_recogniser().is_ok()
}

/// The recogniser and its English model, or an error naming the packages to install.
pub fn check_recogniser() -> Result<()> {
    model()?;
    Command::new(PROGRAM)
        .arg("-help")
        .output()
        .map(|_| ())
        .map_err(|e| missing(&format!("cannot run {PROGRAM}: {e}")))
}

/// Longest stretch of audio given to the recogniser at once, seconds: its memory grows with
/// the length of what it reads (about 250 MB for 40 minutes), so a long recording is
/// recognised in pieces.
pub const SEGMENT_SECONDS: f64 = 300.0;
/// A piece ends at the quietest 10 ms within this many seconds before its limit, so that a
/// cut falls in a pause rather than inside a phone.
const CUT_SEARCH_SECONDS: f64 = 20.0;

/// The ARPAbet phones of the recording at `path` with their times, recognised as `how`
/// says; the share of the file read goes to `progress`.
pub fn recognise_file_with(
    path: &Path,
    how: Recognise,
    progress: &mut dyn FnMut(f64),
) -> Result<Vec<AlignedPhone>> {
    match how {
        Recognise::Phones => recognise_file(path, progress),
        Recognise::Words(placing) => super::words::recognise_words_file(path, placing, progress),
    }
}

/// How speech is recognised without a transcript.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Recognise {
    /// Phones from the phone loop.
    #[default]
    Phones,
    /// Words from the English dictionary and language model, their phones placed so
    /// ([`super::words`]).
    Words(super::words::WordPhones),
}

/// The ARPAbet phones of the recording at `path` with their times, from the phone loop;
/// the share of the file read goes to `progress`.
pub fn recognise_file(path: &Path, progress: &mut dyn FnMut(f64)) -> Result<Vec<AlignedPhone>> {
    let (hmm, lm) = model()?;
    in_pieces(path, progress, &mut |wav| run_phone_loop(wav, &hmm, &lm))
}

/// `run` on the recording at `path`, written as 16 kHz WAV files of at most
/// [`SEGMENT_SECONDS`] one at a time; what it finds in each, in file times.
pub(super) fn in_pieces(
    path: &Path,
    progress: &mut dyn FnMut(f64),
    run: &mut dyn FnMut(&Path) -> Result<Vec<AlignedPhone>>,
) -> Result<Vec<AlignedPhone>> {
    // The recogniser reads 16 kHz mono 16-bit: pieces of the recording are written so, one
    // at a time, and recognised in turn.
    let scratch = tempfile::tempdir().map_err(|e| Error::io(std::env::temp_dir(), e))?;
    let wav = scratch.path().join("piece.wav");
    let rate = ANALYSIS_RATE as usize;
    let limit = (SEGMENT_SECONDS * rate as f64) as usize;
    let mut reader = open_audio(path)?;
    let how = enhancement(reader.info().sample_rate);
    let total = (reader.info().seconds * f64::from(reader.info().sample_rate)).max(1.0);
    let mut pending: Vec<i16> = Vec::new();
    let mut offset = 0usize;
    let mut phones: Vec<AlignedPhone> = Vec::new();
    let mut recognise = |samples: &[i16], offset: usize, phones: &mut Vec<AlignedPhone>| {
        if how.is_identity() {
            write_piece(&wav, samples)?;
        } else {
            write_piece(&wav, &enhance(samples, &how, rate as f64))?;
        }
        let start = offset as f64 / rate as f64;
        for mut p in run(&wav)? {
            p.start += start;
            p.end += start;
            let floor = phones.last().map_or(0.0, |q: &AlignedPhone| q.end);
            p.start = p.start.max(floor);
            p.end = p.end.max(p.start);
            phones.push(p);
        }
        Ok::<(), Error>(())
    };
    while let Some(chunk) = reader.next_chunk()? {
        pending.extend(
            chunk
                .iter()
                .map(|s| (s.clamp(-1.0, 1.0) * 32_767.0).round() as i16),
        );
        progress((reader.frames_read() as f64 / total).min(1.0));
        if pending.len() >= limit {
            let cut = quietest_cut(&pending, limit, (CUT_SEARCH_SECONDS * rate as f64) as usize);
            recognise(&pending[..cut], offset, &mut phones)?;
            pending.drain(..cut);
            offset += cut;
        }
    }
    if !pending.is_empty() || phones.is_empty() {
        recognise(&pending, offset, &mut phones)?;
    }
    Ok(phones)
}

/// Where the band of a band-limited recording is taken to end, as a share of its Nyquist
/// frequency (the resampler's filter has already fallen off above it).
const MIRROR_EDGE: f64 = 0.95;
/// Level of the mirrored band relative to its source (see [`super::enhance`]).
const MIRROR_GAIN: f32 = 0.5;

/// How a recording first sampled at `source_rate` Hz is enhanced before recognition: below
/// the model's 16 kHz its empty top band is filled; the rest is left as it is.
pub(super) fn enhancement(source_rate: u32) -> Enhance {
    if source_rate < ANALYSIS_RATE {
        Enhance {
            mirror_above: Some(MIRROR_EDGE * 0.5 * f64::from(source_rate)),
            mirror_gain: MIRROR_GAIN,
            ..Enhance::default()
        }
    } else {
        Enhance::default()
    }
}

/// Where to end a piece of `samples` at most `limit` long: the start of the quietest 10 ms
/// in the `search` samples before `limit`.
fn quietest_cut(samples: &[i16], limit: usize, search: usize) -> usize {
    const FRAME: usize = 160;
    let end = limit.min(samples.len());
    let from = end.saturating_sub(search);
    let mut best = (u64::MAX, end);
    let mut k = from;
    while k + FRAME <= end {
        let e: u64 = samples[k..k + FRAME]
            .iter()
            .map(|&s| (i64::from(s) * i64::from(s)) as u64)
            .sum();
        if e < best.0 {
            best = (e, k);
        }
        k += FRAME;
    }
    best.1.max(1)
}

pub(super) fn write_piece(path: &Path, samples: &[i16]) -> Result<()> {
    let spec = hound::WavSpec {
        channels: 1,
        sample_rate: ANALYSIS_RATE,
        bits_per_sample: 16,
        sample_format: hound::SampleFormat::Int,
    };
    let encode = |e: hound::Error| -> Error { crate::error::EncodeError::new("WAV", e).into() };
    let mut w = hound::WavWriter::create(path, spec).map_err(encode)?;
    for &s in samples {
        w.write_sample(s).map_err(encode)?;
    }
    w.finalize().map_err(encode)
}

/// Runs the phone loop on the 16 kHz WAV file `wav`.
pub(super) fn run_phone_loop(wav: &Path, hmm: &Path, lm: &Path) -> Result<Vec<AlignedPhone>> {
    let mut cmd = Command::new(PROGRAM);
    cmd.arg("-allphone")
        .arg(lm)
        .args(["-allphone_ci", "yes", "-backtrace", "yes"])
        .args(["-beam", "1e-20", "-pbeam", "1e-20", "-lw", "1.0"]);
    run_timed(cmd, wav, hmm)
}

/// Runs the recogniser `cmd` (its search set up) on the 16 kHz WAV file `wav` with the
/// acoustic model `hmm`: what it heard, one `SYMBOL START END CONFIDENCE` line each.
pub(super) fn run_timed(mut cmd: Command, wav: &Path, hmm: &Path) -> Result<Vec<AlignedPhone>> {
    let out = cmd
        .arg("-infile")
        .arg(wav)
        .arg("-hmm")
        .arg(hmm)
        .args(["-time", "yes", "-logfn", "/dev/null"])
        .output()
        .map_err(|e| missing(&e.to_string()))?;
    if !out.status.success() {
        return Err(SpeechError::RecognitionFailed {
            detail: String::from_utf8_lossy(&out.stderr)
                .lines()
                .last()
                .unwrap_or("")
                .to_string(),
        }
        .into());
    }
    Ok(parse_phones(&String::from_utf8_lossy(&out.stdout)))
}

/// The phone lines (`SYMBOL START END CONFIDENCE`) of the recogniser's output; the
/// hypothesis lines between them have no times and are skipped.
pub fn parse_phones(text: &str) -> Vec<AlignedPhone> {
    let mut phones: Vec<AlignedPhone> = Vec::new();
    for line in text.lines() {
        let f: Vec<&str> = line.split_whitespace().collect();
        let [symbol, start, end, conf] = f.as_slice() else {
            continue;
        };
        let (Ok(start), Ok(end), Ok(conf)) = (
            start.parse::<f64>(),
            end.parse::<f64>(),
            conf.parse::<f64>(),
        ) else {
            continue;
        };
        if !(start.is_finite() && end.is_finite() && end >= start) {
            continue;
        }
        let floor = phones.last().map_or(0.0, |p| p.end);
        // Phones end 10 ms before the next starts: close the gap so intervals touch.
        if let Some(last) = phones.last_mut() {
            if start > last.end && start - last.end <= 0.011 {
                last.end = start;
            }
        }
        phones.push(AlignedPhone {
            symbol: (*symbol).to_string(),
            start: start.max(floor),
            end: (end + 0.01).max(start.max(floor)),
            confidence: conf.clamp(0.0, 1.0),
        });
    }
    phones
}

/// The espeak-ng mnemonic of an ARPAbet phone (`_` for silence and noises).
pub fn arpabet_to_espeak(phone: &str) -> &'static str {
    match phone.trim_end_matches(['0', '1', '2']) {
        "AA" => "A:",
        "AE" => "a",
        "AH" => "V",
        "AO" => "O:",
        "AW" => "aU",
        "AY" => "aI",
        "B" => "b",
        "CH" => "tS",
        "D" => "d",
        "DH" => "D",
        "EH" => "E",
        "ER" => "3:",
        "EY" => "eI",
        "F" => "f",
        "G" => "g",
        "HH" => "h",
        "IH" => "I",
        "IY" => "i:",
        "JH" => "dZ",
        "K" => "k",
        "L" => "l",
        "M" => "m",
        "N" => "n",
        "NG" => "N",
        "OW" => "oU",
        "OY" => "OI",
        "P" => "p",
        "R" => "r",
        "S" => "s",
        "SH" => "S",
        "T" => "t",
        "TH" => "T",
        "UH" => "U",
        "UW" => "u:",
        "V" => "v",
        "W" => "w",
        "Y" => "j",
        "Z" => "z",
        "ZH" => "Z",
        _ => "_",
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn phone_lines_are_read_and_hypotheses_skipped() {
        let out = "SIL AA B SIL\nSIL 0.000 0.160 1.000000\nAA 0.170 0.260 0.9\nB 0.270 0.330 1.000000\nnoise\nSIL 3.330 x 1\n";
        let p = parse_phones(out);
        let s: Vec<&str> = p.iter().map(|p| p.symbol.as_str()).collect();
        assert_eq!(s, ["SIL", "AA", "B"]);
        assert!((p[0].end - 0.17).abs() < 1e-9 && (p[1].start - 0.17).abs() < 1e-9);
        assert!((p[1].confidence - 0.9).abs() < 1e-9);
    }

    #[test]
    fn pieces_end_in_the_quietest_stretch_before_the_limit() {
        let mut x = vec![1000i16; 10_000];
        for s in &mut x[6_920..7_400] {
            *s = 0;
        }
        // Frames of 160 from 5 000: the first silent one starts at 6 920.
        assert_eq!(quietest_cut(&x, 9_000, 4_000), 6_920);
        // Nothing to search: the limit itself.
        assert_eq!(quietest_cut(&x, 9_000, 0), 9_000);
    }

    #[test]
    fn only_band_limited_recordings_are_enhanced() {
        let phone = enhancement(8_000);
        let edge = phone.mirror_above.unwrap_or(0.0);
        assert!((3_700.0..4_000.0).contains(&edge), "{phone:?}");
        for rate in [16_000, 44_100, 48_000] {
            assert!(enhancement(rate).is_identity(), "{rate}");
        }
    }

    #[test]
    fn every_arpabet_phone_has_a_viseme() {
        let table = crate::speech::phonemes::PhonemeVisemeTable::standard();
        for ph in [
            "AA", "AE", "AH", "AO", "AW", "AY", "B", "CH", "D", "DH", "EH", "ER", "EY", "F", "G",
            "HH", "IH", "IY", "JH", "K", "L", "M", "N", "NG", "OW", "OY", "P", "R", "S", "SH", "T",
            "TH", "UH", "UW", "V", "W", "Y", "Z", "ZH", "SIL", "+NSN+",
        ] {
            assert!(table.lookup(arpabet_to_espeak(ph)).is_some(), "{ph}");
        }
        assert_eq!(arpabet_to_espeak("M"), "m");
    }
}
