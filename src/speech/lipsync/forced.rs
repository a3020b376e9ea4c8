//! English forced alignment: the transcript's phones placed in the recording by
//! PocketSphinx (`pocketsphinx_batch` of Debian's `pocketsphinx`, the acoustic model and
//! `cmudict-en-us.dict` of `pocketsphinx-en-us`), searching only the phone sequences the
//! transcript allows. Nothing is downloaded.
//!
//! Each word's pronunciations come from the CMU dictionary (all its variants, `a` and
//! `a(2)`); a word it lacks gets espeak-ng's `en-us` phonemes mapped to ARPAbet
//! ([`espeak_to_arpabet`]). The words become a JSGF grammar whose tokens are single phones,
//! with a dictionary in which each token is pronounced as itself, and an optional pause
//! between words ([`grammar`]): the recogniser's segmentation (`-hypseg`) then gives every
//! phone its start and end ([`parse_hypseg`]). The result is checked against the grammar
//! ([`follows`]); when the recogniser could not reach its end (the transcript does not fit)
//! the warp's times are kept. Pauses shorter than the mouth relaxes for are given to a
//! neighbour ([`absorb_short_pauses`]).
//!
//! The recording is aligned in pieces of at most [`super::pieces::PIECE_SECONDS`] cut at
//! pauses, each with the words said in it ([`align_pieces`]; a shorter recording is one
//! piece): the grammar search's time grows with the square of its length. Only one piece's
//! samples are held at once, written to a temporary WAV file for the recogniser. A piece
//! that does not fit keeps the warp's times for its span alone.
//!
//! Each phone's confidence comes from its acoustic score ([`acoustic_confidence`]).
//!
//! Tried and measured on `examples/lipsync_eval.rs`:
//! - `pocketsphinx_continuous` cuts the file at pauses (its voice activity detector, even
//!   with `-vad_threshold 0`) and each piece must match the whole grammar, so on many
//!   espeak-ng recordings nothing fitted; its fillers (`-fsgusefiller yes`) may also come
//!   between any two phones and took the quiet hold of a p, b or m for a pause (mouth
//!   open). That first version: espeak-ng 81.6 % closures, 81.8 % agreement, 1.5 % false
//!   closures; Festival 93.9 / 89.6 / 2.1 %. The batch program (the file as one utterance)
//!   with pauses only between words: espeak-ng 99.0 / 89.9 / 2.9 %, Festival 100 / 95.8 /
//!   1.4 %.
//! - With the default beams no path survived on most espeak-ng recordings (nor at 1e-80);
//!   1e-200 always found one, at about twice the search time. Trying the defaults first
//!   and the wide beams only on failure gave the same figures on Festival's voices and
//!   98.0 rather than 98.5 % closures on espeak-ng's, at 13× rather than 9× real time on
//!   the evaluation (short sentences, where starting the program is most of the cost).
//! - By default the recogniser drops the frames its voice activity detector finds quiet
//!   before searching, and the times it reports then leave out the pauses before them: on
//!   recordings of several sentences every sentence after a pause was placed early (31 s of
//!   Festival's kal: 39 % closures shown, 37 % agreement). Keeping them (`-remove_silence
//!   no`): 100 / 97.9 % on a minute of it; the short evaluation moved by 0.1–0.3 points.
//! - Joining pauses under 0.25 s to a neighbour: Festival agreement 95.8 → 96.3 %, false
//!   closures 1.4 → 1.3 %; espeak-ng agreement 89.9 → 90.1 %, closures 99.0 → 98.5 %.

use std::collections::{HashMap, HashSet};
use std::path::Path;
use std::process::Command;
use std::sync::OnceLock;

use super::coarticulation::MIN_RELAXED_SILENCE;
use super::pieces::Piece;
use super::recognition::{arpabet_to_espeak, model_dir, write_piece};
use super::AlignedPhone;
use crate::error::{Error, Result};
use crate::speech::audio::{open_audio, ANALYSIS_RATE};
use crate::speech::espeak::speak;
use crate::speech::SpeechError;

/// The program run: `pocketsphinx_batch`, of the same package as the recogniser.
pub const BATCH_PROGRAM: &str = "pocketsphinx_batch";

/// Whether the recogniser, its English acoustic model and dictionary are installed (asked
/// once per process).
pub fn available() -> bool {
    static ANSWER: OnceLock<bool> = OnceLock::new();
    *ANSWER.get_or_init(|| {
        let dir = model_dir();
        dir.join("en-us").join("mdef").is_file()
            && dir.join(DICTIONARY).is_file()
            && Command::new(BATCH_PROGRAM).arg("-help").output().is_ok()
    })
}

/// The pronouncing dictionary's file in the model directory.
const DICTIONARY: &str = "cmudict-en-us.dict";

/// Whether `lang` (an espeak-ng voice) is English, the one language with a model.
pub fn is_english(lang: &str) -> bool {
    lang == "en" || lang.starts_with("en-")
}

/// The words of `text` as the dictionary spells them: lower case, apostrophes kept
/// inside words, everything else a separator.
pub fn words(text: &str) -> Vec<String> {
    word_spans(text).into_iter().map(|(_, w)| w).collect()
}

/// [`words`] with the byte offset in `text` where each starts.
pub fn word_spans(text: &str) -> Vec<(usize, String)> {
    let mut out = Vec::new();
    let mut start: Option<usize> = None;
    let word_char = |c: char| c.is_alphanumeric() || c == '\'';
    for (i, c) in text
        .char_indices()
        .chain(std::iter::once((text.len(), ' ')))
    {
        match (word_char(c), start) {
            (true, None) => start = Some(i),
            (false, Some(a)) => {
                start = None;
                let raw = &text[a..i];
                let trimmed = raw.trim_start_matches('\'');
                let at = a + (raw.len() - trimmed.len());
                let w = trimmed.trim_end_matches('\'').to_lowercase();
                if !w.is_empty() {
                    out.push((at, w));
                }
            }
            _ => {}
        }
    }
    out
}

/// The pronunciations in `dict` (CMU dictionary lines `word PH PH`, `word(2) PH PH`) of
/// the `wanted` words.
pub fn lookup(dict: &str, wanted: &HashSet<&str>) -> HashMap<String, Vec<Vec<String>>> {
    let mut out: HashMap<String, Vec<Vec<String>>> = HashMap::new();
    for line in dict.lines() {
        let mut f = line.split_whitespace();
        let Some(head) = f.next() else { continue };
        let word = head.split_once('(').map_or(head, |(w, _)| w);
        if !wanted.contains(word) {
            continue;
        }
        let phones: Vec<String> = f
            .map(|p| p.trim_end_matches(['0', '1', '2']))
            .map(str::to_string)
            .collect();
        if !phones.is_empty() {
            out.entry(word.to_string()).or_default().push(phones);
        }
    }
    out
}

/// ARPAbet for one espeak-ng English phoneme mnemonic (stress marks already removed); none
/// for pauses and for what has no English counterpart.
pub fn espeak_to_arpabet(symbol: &str) -> &'static [&'static str] {
    match symbol {
        "a" | "aa" | "a#" => &["AE"],
        "A:" | "A" | "0" | "A." => &["AA"],
        "A@" | "A:r" => &["AA", "R"],
        "O:" | "O" => &["AO"],
        "O@" | "o@" | "O:r" => &["AO", "R"],
        "V" | "@" | "@2" | "@5" | "@#" => &["AH"],
        "3:" | "3" | "@r" => &["ER"],
        "E" | "E2" => &["EH"],
        "e@" => &["EH", "R"],
        "eI" => &["EY"],
        "I" | "I2" | "I#" | "y" => &["IH"],
        "i" | "i:" => &["IY"],
        "i@" | "i@3" | "I@" => &["IH", "R"],
        "U" => &["UH"],
        "u:" | "u" => &["UW"],
        "U@" => &["UH", "R"],
        "aI" => &["AY"],
        "aI@" | "aI3" => &["AY", "ER"],
        "aU" => &["AW"],
        "aU@" => &["AW", "ER"],
        "oU" | "o" | "@U" | "O2" => &["OW"],
        "OI" => &["OY"],
        "@L" => &["AH", "L"],
        "p" => &["P"],
        "b" => &["B"],
        "t" | "t#" | "?" => &["T"],
        "d" | "d#" => &["D"],
        "k" | "x" => &["K"],
        "g" => &["G"],
        "f" => &["F"],
        "v" => &["V"],
        "T" => &["TH"],
        "D" => &["DH"],
        "s" => &["S"],
        "z" => &["Z"],
        "S" => &["SH"],
        "Z" => &["ZH"],
        "h" => &["HH"],
        "m" => &["M"],
        "n" | "n-" => &["N"],
        "N" => &["NG"],
        "l" | "l/" => &["L"],
        "r" | "r-" => &["R"],
        "w" | "W" => &["W"],
        "j" => &["Y"],
        "tS" => &["CH"],
        "dZ" => &["JH"],
        _ => &[],
    }
}

/// ARPAbet for a word the dictionary lacks, from espeak-ng's `en-us` phonemes.
fn spoken_arpabet(word: &str) -> Result<Vec<String>> {
    let said = speak(word, "en-us")?;
    Ok(said
        .phonemes
        .iter()
        .flat_map(|p| espeak_to_arpabet(p.symbol.trim_matches(['\'', ',', '%', '='])))
        .map(|s| s.to_string())
        .collect())
}

/// The silence token of the grammar (pronounced with the model's silence phone).
const SILENCE: &str = "SIL";

/// The JSGF grammar of the word sequence (alternative pronunciations in parentheses, an
/// optional pause before, between and after the words) and the dictionary that pronounces
/// each phone token as itself.
///
/// Pauses go only between words: the recogniser's own fillers (`-fsgusefiller`, off) would
/// also take the silent hold of a p or b inside a word, and a pause there opens the mouth.
pub fn grammar(prons: &[Vec<Vec<String>>]) -> (String, String) {
    let mut jsgf = String::from("#JSGF V1.0;\ngrammar forced;\npublic <s> = [ SIL ]");
    for alts in prons {
        let alts: Vec<String> = alts.iter().map(|a| a.join(" ")).collect();
        if alts.len() == 1 {
            jsgf.push(' ');
            jsgf.push_str(&alts[0]);
        } else {
            jsgf.push_str(" ( ");
            jsgf.push_str(&alts.join(" | "));
            jsgf.push_str(" )");
        }
        jsgf.push_str(" [ SIL ]");
    }
    jsgf.push_str(" ;\n");
    let mut phones: Vec<&str> = vec![SILENCE];
    for alts in prons {
        phones.extend(alts.iter().flatten().map(String::as_str));
    }
    phones.sort_unstable();
    phones.dedup();
    let dict: String = phones.iter().map(|p| format!("{p} {p}\n")).collect();
    (jsgf, dict)
}

/// Seconds per recogniser frame.
const FRAME_SECONDS: f64 = 0.01;

/// Nats per unit of the recogniser's scores: they are logarithms to base 1.0001 shifted
/// down 10 bits, so one unit is 1024 · ln 1.0001.
const NATS_PER_SCORE: f64 = 0.102_394_88;

/// The phones of a `-hypseg` line (`UTT S s T t A a L l` then `FRAME ASCR LSCR WORD` per
/// segment and the last frame): each runs from its first frame to the next segment's;
/// `(NULL)` grammar transitions are not phones. Each phone's confidence comes from its
/// acoustic score ([`acoustic_confidence`]). Empty when nothing was recognised.
pub fn parse_hypseg(line: &str) -> Vec<AlignedPhone> {
    let f: Vec<&str> = line.split_whitespace().collect();
    let Some(body) = f.get(9..) else {
        return Vec::new();
    };
    let mut starts: Vec<(u32, i64, &str)> = body
        .chunks_exact(4)
        .filter_map(|c| Some((c[0].parse::<u32>().ok()?, c[1].parse::<i64>().ok()?, c[3])))
        .collect();
    let Some(last) = body
        .get(body.len() / 4 * 4)
        .and_then(|t| t.parse::<u32>().ok())
    else {
        return Vec::new();
    };
    starts.push((last + 1, 0, ""));
    let mut out: Vec<AlignedPhone> = Vec::new();
    for (k, &(start, score, w)) in starts.iter().enumerate() {
        if w.is_empty() || w.starts_with('(') {
            continue;
        }
        let end = starts[k + 1..]
            .iter()
            .find(|(_, _, n)| !n.starts_with('('))
            .map_or(start, |(t, _, _)| *t)
            .max(start);
        let frames = f64::from((end - start).max(1));
        out.push(AlignedPhone {
            symbol: w.to_string(),
            start: f64::from(start) * FRAME_SECONDS,
            end: f64::from(end) * FRAME_SECONDS,
            confidence: acoustic_confidence(score as f64 * NATS_PER_SCORE / frames),
        });
    }
    out
}

/// The log-likelihood per frame, nats, at which a phone's confidence is one half …
const HALF_CONFIDENCE_NATS: f64 = -4.0;
/// … and the spread of the logistic curve around it.
const CONFIDENCE_SPREAD_NATS: f64 = 0.8;

/// A phone's confidence, 0..1, from its acoustic score per frame, in nats. PocketSphinx
/// scores each frame against the best-matching sound of the whole model at that frame, so
/// 0 is a phone that sounds exactly like the best-matching sound, and the more negative,
/// the more something else fits the sound better.
///
/// The curve was set on Festival's kal, ked and slt voices (clean, 16 kHz, the evaluation's
/// eight sentences): the transcript's phones scored −1.9 nats a frame at the median and
/// −3.8 at the 10th percentile (confidence 0.93 and 0.56); with one word of each sentence
/// swapped for another of like length, that word's phones scored −6.5 at the median
/// (0.04), a quarter of them above −4.3, −4.6 and −2.5 on the three voices, and the other
/// words' phones as before. Noise lowers it for every phone: under 20 dB of white noise
/// (kal, 300 s, the right transcript) the median was 0.52 and the 10th percentile 0.10.
pub fn acoustic_confidence(nats_per_frame: f64) -> f64 {
    1.0 / (1.0 + (-(nats_per_frame - HALF_CONFIDENCE_NATS) / CONFIDENCE_SPREAD_NATS).exp())
}

/// Whether the spoken `phones` (fillers left out) are one of the sequences `prons` allows.
pub fn follows(prons: &[Vec<Vec<String>>], phones: &[&str]) -> bool {
    // Positions reached: the word and, within one of its pronunciations, the phone.
    let mut at: HashSet<(usize, usize, usize)> = HashSet::new();
    let mut starts: HashSet<usize> = HashSet::from([0]);
    for p in phones {
        let mut next_at = HashSet::new();
        let mut next_starts = HashSet::new();
        let mut step = |w: usize, a: usize, k: usize| {
            if k == prons[w][a].len() {
                next_starts.insert(w + 1);
            } else {
                next_at.insert((w, a, k));
            }
        };
        for &w in &starts {
            for (a, alt) in prons.get(w).into_iter().flatten().enumerate() {
                if alt.first().is_some_and(|q| q == p) {
                    step(w, a, 1);
                }
            }
        }
        for &(w, a, k) in &at {
            if prons[w][a][k] == *p {
                step(w, a, k + 1);
            }
        }
        at = next_at;
        starts = next_starts;
    }
    starts.contains(&prons.len())
}

/// Interior pauses shorter than `min` seconds joined to a neighbour: to the next phone when
/// it is a stop or affricate (the silence is its closure, which for p, b and m must show
/// as closed lips), else to the previous one. The recogniser takes the quiet hold of a
/// stop or of an m between words for a pause, and a short pause shown as one opens the
/// mouth where the lips are shut.
pub fn absorb_short_pauses(phones: Vec<AlignedPhone>, min: f64) -> Vec<AlignedPhone> {
    let stop = |s: &str| matches!(s, "P" | "B" | "M" | "T" | "D" | "K" | "G" | "CH" | "JH");
    let n = phones.len();
    let mut out: Vec<AlignedPhone> = Vec::with_capacity(n);
    let mut carry: Option<f64> = None;
    for (k, p) in phones.iter().enumerate() {
        let interior = k > 0 && k + 1 < n;
        if p.symbol == SILENCE && interior && p.end - p.start < min {
            if stop(&phones[k + 1].symbol) {
                carry = Some(p.start);
            } else if let Some(prev) = out.last_mut() {
                prev.end = p.end;
            }
            continue;
        }
        let mut p = p.clone();
        if let Some(start) = carry.take() {
            p.start = start;
        }
        out.push(p);
    }
    out
}

/// The transcript's words that have a sound: each one's byte offset in the transcript and
/// its pronunciations.
pub type PronouncedWords = Vec<(usize, Vec<Vec<String>>)>;

/// The pronounced words of `text`, from the installed dictionary or espeak-ng.
pub fn pronounced_words(text: &str) -> Result<PronouncedWords> {
    let dir = model_dir();
    let dict_path = dir.join(DICTIONARY);
    let dict = std::fs::read_to_string(&dict_path).map_err(|e| Error::io(&dict_path, e))?;
    let spans = word_spans(text);
    let words: Vec<String> = spans.iter().map(|(_, w)| w.clone()).collect();
    let wanted: HashSet<&str> = words.iter().map(String::as_str).collect();
    let mut found = lookup(&dict, &wanted);
    drop(dict);
    let mut out = Vec::with_capacity(spans.len());
    for (at, w) in spans {
        if !found.contains_key(&w) {
            let p = spoken_arpabet(&w)?;
            found.insert(w.clone(), if p.is_empty() { vec![] } else { vec![p] });
        }
        // A word with no sound (a stray symbol) is left out rather than made unmatchable.
        if !found[&w].is_empty() {
            out.push((at, found[&w].clone()));
        }
    }
    Ok(out)
}

/// The transcript's phones in the recording at `path`, aligned a piece at a time
/// ([`super::pieces`]); symbols are espeak-ng mnemonics, `_` for pauses. A piece the
/// recogniser cannot fit keeps the `fallback` phones (the warp's) within its span, and a
/// warning names it; a piece without words keeps them silently.
pub fn align_pieces(
    path: &Path,
    words: &PronouncedWords,
    pieces: &[Piece],
    fallback: &[AlignedPhone],
) -> Result<Aligned> {
    let scratch = tempfile::tempdir().map_err(|e| Error::io(std::env::temp_dir(), e))?;
    let wav = scratch.path().join("piece.wav");
    let rate = f64::from(ANALYSIS_RATE);
    let mut reader = open_audio(path)?;
    // Samples of the recording from `offset` on, read but not yet aligned: one piece's.
    let mut pending: Vec<i16> = Vec::new();
    let mut offset = 0usize;
    let mut done = false;
    let mut out = Aligned::default();
    for (k, piece) in pieces.iter().enumerate() {
        let first = ((piece.start * rate).round() as usize).max(offset);
        let last = if k + 1 == pieces.len() {
            usize::MAX
        } else {
            (piece.end * rate).round() as usize
        };
        while !done && offset + pending.len() < last {
            match reader.next_chunk()? {
                Some(chunk) => pending.extend(
                    chunk
                        .iter()
                        .map(|s| (s.clamp(-1.0, 1.0) * 32_767.0).round() as i16),
                ),
                None => done = true,
            }
        }
        let end = last.min(offset + pending.len()).max(first);
        pending.drain(..(first - offset).min(pending.len()));
        let samples: Vec<i16> = pending.drain(..end - first).collect();
        offset = end;
        let prons: Vec<Vec<Vec<String>>> = words
            .iter()
            .filter(|(at, _)| piece.text.contains(at))
            .map(|(_, p)| p.clone())
            .collect();
        let warp = || within(fallback, piece.start, piece.end);
        if prons.is_empty() || samples.is_empty() {
            out.push(warp());
            continue;
        }
        write_piece(&wav, &samples)?;
        drop(samples);
        match align_piece(&wav, &prons)? {
            Some(phones) => {
                let start = first as f64 / rate;
                out.push(
                    placed(phones)
                        .into_iter()
                        .map(|p| AlignedPhone {
                            start: (p.start + start).min(piece.end),
                            end: (p.end + start).min(piece.end),
                            ..p
                        })
                        .collect(),
                );
                out.aligned_pieces += 1;
            }
            None => {
                out.failed.push((piece.start, piece.end));
                out.push(warp());
            }
        }
    }
    Ok(out)
}

/// Phones placed piece by piece.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Aligned {
    /// All the phones, in order, each ending where the next starts.
    pub phones: Vec<AlignedPhone>,
    /// Pieces the recogniser placed.
    pub aligned_pieces: usize,
    /// Spans (start, end seconds) the recogniser could not fit, which keep the warp's times.
    pub failed: Vec<(f64, f64)>,
}

impl Aligned {
    /// Appends a piece's phones: a pause continuing one is joined to it, and the last
    /// phone before ends where these start.
    fn push(&mut self, phones: Vec<AlignedPhone>) {
        for p in phones {
            match self.phones.last_mut() {
                Some(q) if q.symbol == "_" && p.symbol == "_" => {
                    q.end = p.end.max(q.end);
                    q.confidence = q.confidence.min(p.confidence);
                }
                Some(q) => {
                    q.end = p.start.max(q.start);
                    let start = p.start.max(q.end);
                    self.phones.push(AlignedPhone { start, ..p });
                }
                None => self.phones.push(p),
            }
        }
    }
}

/// The part of `phones` between `start` and `end` seconds: those whose middle falls in it,
/// clipped to it.
fn within(phones: &[AlignedPhone], start: f64, end: f64) -> Vec<AlignedPhone> {
    phones
        .iter()
        .filter(|p| (start..end).contains(&(0.5 * (p.start + p.end))))
        .map(|p| AlignedPhone {
            start: p.start.max(start),
            end: p.end.min(end),
            ..p.clone()
        })
        .collect()
}

/// The phones (ARPAbet, times from the start of `wav`) of the grammar `prons` found in the
/// 16 kHz WAV file `wav`, or `None` when the recogniser could not fit them.
fn align_piece(wav: &Path, prons: &[Vec<Vec<String>>]) -> Result<Option<Vec<AlignedPhone>>> {
    let dir = model_dir();
    let (jsgf, phone_dict) = grammar(prons);
    let scratch = wav.parent().unwrap_or(Path::new("."));
    let stem = wav
        .file_stem()
        .and_then(|s| s.to_str())
        .unwrap_or("piece")
        .to_string();
    let write = |name: &str, text: &str| -> Result<std::path::PathBuf> {
        let p = scratch.join(name);
        std::fs::write(&p, text).map_err(|e| Error::io(&p, e))?;
        Ok(p)
    };
    let jsgf_path = write("forced.jsgf", &jsgf)?;
    let dict_path = write("forced.dict", &phone_dict)?;
    let ctl = write("forced.ctl", &format!("{stem}\n"))?;
    let hypseg = scratch.join("forced.seg");
    // The batch program decodes the whole file as one utterance (the continuous one cuts
    // it at pauses, and each piece would have to match the whole grammar). The recogniser's
    // own beams come first; when no path through the grammar survives them (so on most of
    // espeak-ng's voices) very wide ones are tried, about 2× slower.
    for beam in [None, Some("1e-200")] {
        let _ = std::fs::remove_file(&hypseg);
        let mut cmd = Command::new(BATCH_PROGRAM);
        cmd.arg("-ctl")
            .arg(&ctl)
            .arg("-cepdir")
            .arg(scratch)
            .args(["-cepext", ".wav", "-adcin", "yes", "-adchdr", "44"])
            .arg("-hmm")
            .arg(dir.join("en-us"))
            .arg("-jsgf")
            .arg(&jsgf_path)
            .arg("-dict")
            .arg(&dict_path)
            .arg("-hypseg")
            .arg(&hypseg)
            .args(["-fsgusefiller", "no", "-logfn", "/dev/null"])
            // Its voice activity detector otherwise drops quiet frames before the search,
            // and the times it reports then leave out every pause before them.
            .args(["-remove_silence", "no"]);
        if let Some(b) = beam {
            cmd.args(["-beam", b, "-pbeam", b, "-wbeam", b]);
        }
        let out = cmd.output().map_err(|e| SpeechError::RecognitionFailed {
            detail: format!("cannot run {BATCH_PROGRAM}: {e}"),
        })?;
        if !out.status.success() {
            continue;
        }
        let seg = std::fs::read_to_string(&hypseg).unwrap_or_default();
        let phones = parse_hypseg(seg.lines().next().unwrap_or(""));
        let spoken: Vec<&str> = phones
            .iter()
            .map(|p| p.symbol.as_str())
            .filter(|s| *s != SILENCE)
            .collect();
        if follows(prons, &spoken) {
            return Ok(Some(phones));
        }
    }
    Ok(None)
}

/// The recogniser's phones as the lip sync takes them.
fn placed(phones: Vec<AlignedPhone>) -> Vec<AlignedPhone> {
    absorb_short_pauses(phones, MIN_RELAXED_SILENCE)
        .into_iter()
        .map(|p| AlignedPhone {
            symbol: arpabet_to_espeak(&p.symbol).to_string(),
            ..p
        })
        .collect()
}
#[cfg(test)]
mod tests {
    use super::*;

    fn s(v: &[&str]) -> Vec<String> {
        v.iter().map(|x| x.to_string()).collect()
    }

    #[test]
    fn words_are_lower_case_with_inner_apostrophes() {
        assert_eq!(
            words("Mary's 'famous' pie, 42 times--OK?"),
            s(&["mary's", "famous", "pie", "42", "times", "ok"])
        );
    }

    #[test]
    fn word_spans_give_each_word_its_byte_offset() {
        assert_eq!(
            word_spans("Née 'quoted' it's"),
            [
                (0, "née".to_string()),
                (6, "quoted".into()),
                (14, "it's".into())
            ]
        );
        assert!(word_spans(" -- ").is_empty());
    }

    fn ph(s: &str, a: f64, b: f64, c: f64) -> AlignedPhone {
        AlignedPhone {
            symbol: s.into(),
            start: a,
            end: b,
            confidence: c,
        }
    }

    #[test]
    fn pieces_join_into_one_contiguous_sequence() {
        let mut all = Aligned::default();
        all.push(vec![
            ph("_", 0.0, 0.5, 0.9),
            ph("m", 0.5, 0.7, 0.8),
            ph("_", 0.7, 1.0, 0.9),
        ]);
        // The next piece starts with a pause (joined) and a phone a little late.
        all.push(vec![ph("_", 1.0, 1.2, 0.7), ph("aI", 1.25, 1.5, 0.6)]);
        let got: Vec<(&str, f64, f64, f64)> = all
            .phones
            .iter()
            .map(|p| (p.symbol.as_str(), p.start, p.end, p.confidence))
            .collect();
        assert_eq!(
            got,
            [
                ("_", 0.0, 0.5, 0.9),
                ("m", 0.5, 0.7, 0.8),
                ("_", 0.7, 1.25, 0.7),
                ("aI", 1.25, 1.5, 0.6)
            ]
        );
    }

    #[test]
    fn the_warp_fills_a_span_with_the_phones_centred_in_it() {
        let warp = [
            ph("_", 0.0, 1.0, 1.0),
            ph("m", 1.0, 1.4, 0.5),
            ph("u:", 1.4, 2.0, 0.5),
        ];
        let got = within(&warp, 0.9, 1.6);
        let s: Vec<(&str, f64, f64)> = got
            .iter()
            .map(|p| (p.symbol.as_str(), p.start, p.end))
            .collect();
        assert_eq!(s, [("m", 1.0, 1.4)]);
        let got = within(&warp, 0.9, 1.8);
        assert_eq!(got.len(), 2);
        assert_eq!((got[1].start, got[1].end), (1.4, 1.8));
    }

    #[test]
    fn dictionary_variants_are_gathered_without_stress() {
        let dict = "a AH\na(2) EY\nab AE1 B\nabbey AE B IY\n";
        let wanted = HashSet::from(["a", "ab"]);
        let d = lookup(dict, &wanted);
        assert_eq!(d["a"], vec![s(&["AH"]), s(&["EY"])]);
        assert_eq!(d["ab"], vec![s(&["AE", "B"])]);
        assert!(!d.contains_key("abbey"));
    }

    #[test]
    fn grammar_has_alternatives_and_a_self_pronouncing_dictionary() {
        let prons = vec![vec![s(&["M", "AY"])], vec![s(&["AH"]), s(&["EY"])]];
        let (jsgf, dict) = grammar(&prons);
        assert!(
            jsgf.contains("public <s> = [ SIL ] M AY [ SIL ] ( AH | EY ) [ SIL ] ;"),
            "{jsgf}"
        );
        assert_eq!(dict, "AH AH\nAY AY\nEY EY\nM M\nSIL SIL\n");
    }

    #[test]
    fn hypseg_segments_become_phones_without_null_transitions() {
        let line = "rec S 0 T -3439 A -3439 L 0 0 -123 0 SIL 21 -144 0 M 27 -319 0 AY \
                    42 0 0 (NULL) 43 -137 0 B 52 -96 0 SIL 60";
        let p = parse_hypseg(line);
        let s: Vec<&str> = p.iter().map(|p| p.symbol.as_str()).collect();
        assert_eq!(s, ["SIL", "M", "AY", "B", "SIL"]);
        let t: Vec<(f64, f64)> = p.iter().map(|p| (p.start, p.end)).collect();
        let want = [
            (0.0, 0.21),
            (0.21, 0.27),
            (0.27, 0.43),
            (0.43, 0.52),
            (0.52, 0.61),
        ];
        for (got, want) in t.iter().zip(want) {
            assert!(
                (got.0 - want.0).abs() < 1e-9 && (got.1 - want.1).abs() < 1e-9,
                "{t:?}"
            );
        }
        // Confidence falls with the score per frame: B -15, AY -20, M -24.
        let c: Vec<f64> = p.iter().map(|p| p.confidence).collect();
        assert!(c[3] > c[2] && c[2] > c[1], "{c:?}");
        assert!(c.iter().all(|c| (0.0..=1.0).contains(c)));
        // Nothing recognised (the grammar's end was not reached).
        assert!(parse_hypseg("rec S 0 T 0 A 0 L 0 0").is_empty());
        assert!(parse_hypseg("").is_empty());
    }

    #[test]
    fn phone_sequences_are_checked_against_the_grammar() {
        let prons = vec![vec![s(&["AH", "V"]), s(&["AH"])], vec![s(&["V", "AY"])]];
        assert!(follows(&prons, &["AH", "V", "V", "AY"]));
        assert!(follows(&prons, &["AH", "V", "AY"]));
        assert!(!follows(&prons, &["AH", "V"]));
        assert!(!follows(&prons, &["AH", "V", "AY", "AY"]));
        assert!(!follows(&prons, &[]));
    }

    #[test]
    fn short_pauses_join_the_stop_after_or_the_sound_before() {
        let ph = |s: &str, a: f64, b: f64| AlignedPhone {
            symbol: s.into(),
            start: a,
            end: b,
            confidence: 1.0,
        };
        let phones = vec![
            ph("SIL", 0.0, 0.2),
            ph("AY", 0.2, 0.4),
            ph("SIL", 0.4, 0.5),
            ph("M", 0.5, 0.6),
            ph("AH", 0.6, 0.7),
            ph("SIL", 0.7, 0.8),
            ph("S", 0.8, 0.9),
            ph("SIL", 0.9, 1.3),
            ph("Z", 1.3, 1.4),
            ph("SIL", 1.4, 1.45),
        ];
        let got: Vec<(String, f64, f64)> = absorb_short_pauses(phones, 0.25)
            .into_iter()
            .map(|p| (p.symbol, p.start, p.end))
            .collect();
        let want = [
            ("SIL", 0.0, 0.2),
            ("AY", 0.2, 0.4),
            ("M", 0.4, 0.6),
            ("AH", 0.6, 0.8),
            ("S", 0.8, 0.9),
            ("SIL", 0.9, 1.3),
            ("Z", 1.3, 1.4),
            ("SIL", 1.4, 1.45),
        ];
        assert_eq!(got.len(), want.len(), "{got:?}");
        for (g, w) in got.iter().zip(want) {
            assert!(
                g.0 == w.0 && (g.1 - w.1).abs() < 1e-9 && (g.2 - w.2).abs() < 1e-9,
                "{got:?}"
            );
        }
    }

    #[test]
    fn espeak_phonemes_map_to_arpabet() {
        assert_eq!(espeak_to_arpabet("tS"), ["CH"]);
        assert_eq!(espeak_to_arpabet("A@"), ["AA", "R"]);
        assert!(espeak_to_arpabet("_:").is_empty());
        // Every ARPAbet phone it gives has a viseme through the recogniser's table.
        for sym in [
            "a", "0", "@", "3:", "e@", "aI@", "oU", "@L", "t#", "n-", "l/", "j",
        ] {
            for p in espeak_to_arpabet(sym) {
                assert_ne!(arpabet_to_espeak(p), "_", "{sym} → {p}");
            }
        }
    }
}
