//! Phones without a transcript from recognised *words* (English): PocketSphinx's word
//! search (`pocketsphinx_continuous` with the `pocketsphinx-en-us` language model and
//! pronouncing dictionary) gives words with times and posterior confidences, and each
//! word's dictionary phones share its time by their typical lengths ([`phones_of_words`]).
//!
//! A wrong word that sounds like the right one has nearly the right phones, and the mouth
//! shows phones, not words: that was the hope. Measured on `examples/lipsync_eval.rs`
//! (`LIPSYNC_EVAL_RECOGNISE`; closures / agreement / false closures, %, with
//! [`super::closures`] on top in every case):
//!
//! | phones from | espeak-ng voices | Festival voices |
//! |---|---|---|
//! | the phone loop (the default then; since, 8 kHz audio gets its top band mirrored first: 58.7 / 68.9 / 3.2 and 56.6 / 65.2 / 1.5, the word path not re-measured) | 57.7 / 66.5 / 2.9 | 44.4 / 59.9 / 1.3 |
//! | words, shared by typical lengths ([`WordPhones::Shared`]) | 47.4 / 57.7 / 4.0 | 45.9 / 57.5 / 3.6 |
//! | words, force-aligned ([`WordPhones::Aligned`]; measured as one piece per file, before `-remove_silence no`) | 48.0 / 59.2 / 2.4 | 45.4 / 59.2 / 2.0 |
//! | words, the phone loop under words surer than 0.6 ([`WordPhones::Mixed`]) | 55.6 / 60.4 / 3.5 | 51.0 / 57.1 / 3.8 |
//!
//! Per Festival condition (phone loop → words force-aligned): kal at 20 dB SNR 69.4 / 70.4
//! / 1.4 → 59.2 / 70.4 / 2.9; slt at 15 dB 26.5 / 59.2 / 0.2 → 20.4 / 61.9 / 0.4; ked at 8 kHz
//! 18.4 / 42.2 / 1.2 → 34.7 / 28.6 / 3.1; slt as MP3 63.3 / 67.7 / 2.3 → 67.3 / 76.3 / 1.5.
//! Words help where the speech is clean enough for the word search (slt's MP3 at 20 dB: the
//! sentences come out nearly word for word) and hurt in noise (at 15 dB the words are wrong
//! and the wrong words' phones are no nearer than the phone loop's) and at 8 kHz. No way
//! reaches issue 22's targets (80 / 70 / ≤ 3) and none is better on the Festival voices
//! overall, so the phone loop stays the default and the command line does not offer words.
//!
//! Speed: the word search took 3.7–6.1 s of CPU for 23.4 s of Festival speech (one file,
//! one core, load-dependent; 0.3 s of each run is loading the dictionary and language
//! model), the phone loop 1.1 s; on the evaluation's short sentences about 4× the phone
//! loop's time. Faster settings measured on the same file: `-fwdflat no -bestpath no` 7×
//! real time, adding `-maxhmmpf 3000 -topn 2` 10×, narrower beams (`-beam 1e-40 -wbeam
//! 1e-30 -pbeam 1e-40`) 12×, each with more wrong words ("an app of bombay", "the lazy
//! donde"), and without `-bestpath` the words have no confidence to mix by; `-ds 2` and
//! `-pl_window 5` were no faster. A dictionary cut to the language model's 72 547 words
//! halves the loading (0.32 → 0.17 s) but not the search.

use std::collections::{HashMap, HashSet};
use std::path::Path;
use std::process::Command;

use super::pieces::{Piece, MIN_PIECE_SECONDS, PIECE_SECONDS};
use super::recognition::{
    arpabet_to_espeak, in_pieces, model, model_dir, run_phone_loop, run_timed, PROGRAM,
};
use super::AlignedPhone;
use crate::error::{Error, Result};

/// The pronouncing dictionary's file in the model directory.
const DICTIONARY: &str = "cmudict-en-us.dict";
/// The word language model's file in the model directory.
const LANGUAGE_MODEL: &str = "en-us.lm.bin";

/// The silence phone.
const SILENCE: &str = "SIL";

/// How recognised words become timed phones.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum WordPhones {
    /// Each word's dictionary phones share its time by their typical lengths.
    Shared,
    /// The recognised words are force-aligned to the recording as a transcript, in pieces
    /// cut at the pauses the word search heard ([`word_pieces`],
    /// [`super::forced::align_pieces`]); a piece that does not fit keeps the shared phones.
    Aligned,
    /// Shared, but words less sure than [`MIXED_BELOW`] take the phone loop's phones.
    Mixed,
}

/// The word confidence (posterior) below which [`WordPhones::Mixed`] takes the phone
/// loop's phones.
pub const MIXED_BELOW: f64 = 0.6;

/// The ARPAbet phones of the recording at `path` from recognised words, with their times,
/// placed as `placing` says; the share of the file read goes to `progress`.
pub fn recognise_words_file(
    path: &Path,
    placing: WordPhones,
    progress: &mut dyn FnMut(f64),
) -> Result<Vec<AlignedPhone>> {
    let (hmm, phone_lm) = model()?;
    let dir = model_dir();
    let (lm, dict_path) = (dir.join(LANGUAGE_MODEL), dir.join(DICTIONARY));
    if !lm.is_file() || !dict_path.is_file() {
        return Err(super::recognition::missing(&format!(
            "no language model or dictionary in {}",
            dir.display()
        )));
    }
    let mut dict: Option<String> = None;
    let mut run = |wav: &Path| -> Result<Vec<AlignedPhone>> {
        let mut cmd = Command::new(PROGRAM);
        cmd.arg("-lm").arg(&lm).arg("-dict").arg(&dict_path);
        let words = run_timed(cmd, wav, &hmm)?;
        if dict.is_none() {
            dict = Some(std::fs::read_to_string(&dict_path).map_err(|e| Error::io(&dict_path, e))?);
        }
        let prons = pronunciations(&words, dict.as_deref().unwrap_or(""));
        let phones = phones_of_words(&words, &prons);
        let unsure = words
            .iter()
            .any(|w| !filler(&w.symbol) && w.confidence < MIXED_BELOW);
        if placing == WordPhones::Mixed && unsure {
            let heard = run_phone_loop(wav, &hmm, &phone_lm)?;
            return Ok(mixed(&words, phones, &heard, MIXED_BELOW));
        }
        if placing == WordPhones::Aligned {
            return aligned(wav, &words, phones);
        }
        Ok(phones)
    };
    in_pieces(path, progress, &mut run)
}

/// The recognised `words` of one recognition piece (the file `wav`) taken as its transcript
/// and force-aligned there ([`super::forced::align_pieces`]), in pieces cut at the pauses
/// the word search heard ([`word_pieces`]); a piece that does not fit keeps the `shared`
/// phones.
fn aligned(
    wav: &Path,
    words: &[AlignedPhone],
    shared: Vec<AlignedPhone>,
) -> Result<Vec<AlignedPhone>> {
    let (text, pieces) = word_pieces(words);
    if pieces.is_empty() {
        return Ok(shared);
    }
    let pronounced = super::forced::pronounced_words(&text)?;
    let fallback: Vec<AlignedPhone> = shared
        .into_iter()
        .map(|p| AlignedPhone {
            symbol: arpabet_to_espeak(&p.symbol).to_string(),
            ..p
        })
        .collect();
    let placed = super::forced::align_pieces(wav, &pronounced, &pieces, &fallback)?;
    // Back from espeak-ng's mnemonics, which every ARPAbet phone maps to one of.
    Ok(placed
        .phones
        .into_iter()
        .map(|p| AlignedPhone {
            symbol: super::forced::espeak_to_arpabet(&p.symbol)
                .first()
                .copied()
                .unwrap_or(SILENCE)
                .to_string(),
            ..p
        })
        .collect())
}

/// The spoken words as a transcript (variants' heads, spaces between) and its pieces for
/// forced alignment: a piece ends in the middle of the first filler (a heard pause) after
/// [`MIN_PIECE_SECONDS`], or at the first word gap after [`PIECE_SECONDS`]; the last piece
/// runs to the end of the last word.
pub fn word_pieces(words: &[AlignedPhone]) -> (String, Vec<Piece>) {
    let mut text = String::new();
    let mut pieces: Vec<Piece> = Vec::new();
    let (mut start, mut from) = (0.0, 0usize);
    for w in words {
        let long = w.start - start;
        let cut = if filler(&w.symbol) {
            (long >= MIN_PIECE_SECONDS).then_some(0.5 * (w.start + w.end))
        } else {
            (long >= PIECE_SECONDS).then_some(w.start)
        };
        if let Some(at) = cut.filter(|_| text.len() > from) {
            pieces.push(Piece {
                start,
                end: at,
                text: from..text.len(),
            });
            (start, from) = (at, text.len());
        }
        if !filler(&w.symbol) {
            let head = w
                .symbol
                .split_once('(')
                .map_or(w.symbol.as_str(), |(h, _)| h);
            text.push_str(head);
            text.push(' ');
        }
    }
    if text.len() > from {
        pieces.push(Piece {
            start,
            end: words.last().map_or(start, |w| w.end).max(start),
            text: from..text.len(),
        });
    }
    (text, pieces)
}

/// Whether a recognised word is a filler (silence, breath, noise) rather than speech.
fn filler(word: &str) -> bool {
    word.starts_with('<') || word.starts_with('[') || word.starts_with('+')
}

/// The phones of each recognised word (`word` or `word(2)`, as the dictionary heads them)
/// in `dict` (CMU dictionary lines), stress marks removed.
pub fn pronunciations(words: &[AlignedPhone], dict: &str) -> HashMap<String, Vec<String>> {
    let wanted: HashSet<&str> = words.iter().map(|w| w.symbol.as_str()).collect();
    let mut out = HashMap::new();
    for line in dict.lines() {
        let mut f = line.split_whitespace();
        let Some(head) = f.next() else { continue };
        if wanted.contains(head) {
            let phones: Vec<String> = f
                .map(|p| p.trim_end_matches(['0', '1', '2']).to_string())
                .collect();
            out.insert(head.to_string(), phones);
        }
    }
    out
}

/// A phone's typical length relative to others (milliseconds in read American English,
/// roughly): a word's time is shared out by these.
fn typical_length(phone: &str) -> f64 {
    match phone {
        "AW" | "AY" | "OY" => 150.0,
        "AE" | "EY" | "OW" => 130.0,
        "AA" | "AO" => 120.0,
        "ER" | "UW" | "SH" => 110.0,
        "S" => 105.0,
        "IY" | "CH" => 100.0,
        "EH" | "F" | "TH" => 90.0,
        "JH" | "Z" | "ZH" | "UH" | "P" => 80.0,
        "K" | "T" | "IH" | "AH" => 70.0,
        "B" | "G" | "M" | "NG" => 65.0,
        "HH" | "L" | "R" | "W" | "N" => 60.0,
        "D" | "V" | "Y" => 55.0,
        "DH" => 40.0,
        _ => 70.0,
    }
}

/// Recognised words to phones: each word's dictionary phones share its span in proportion
/// to their typical lengths, with the word's confidence; fillers and words missing from
/// `prons` become silence.
pub fn phones_of_words(
    words: &[AlignedPhone],
    prons: &HashMap<String, Vec<String>>,
) -> Vec<AlignedPhone> {
    let mut out: Vec<AlignedPhone> = Vec::new();
    for w in words {
        let phones = prons
            .get(&w.symbol)
            .filter(|p| !filler(&w.symbol) && !p.is_empty());
        let Some(phones) = phones else {
            out.push(AlignedPhone {
                symbol: SILENCE.into(),
                ..w.clone()
            });
            continue;
        };
        let total: f64 = phones.iter().map(|p| typical_length(p)).sum();
        let mut t = w.start;
        for p in phones {
            let end = t + (w.end - w.start) * typical_length(p) / total;
            out.push(AlignedPhone {
                symbol: p.clone(),
                start: t,
                end,
                confidence: w.confidence,
            });
            t = end;
        }
    }
    out
}

/// The word phones with every span of a word less sure than `threshold` replaced by the
/// phone loop's phones `heard` there (cut to the word's span).
pub fn mixed(
    words: &[AlignedPhone],
    phones: Vec<AlignedPhone>,
    heard: &[AlignedPhone],
    threshold: f64,
) -> Vec<AlignedPhone> {
    let unsure: Vec<(f64, f64)> = words
        .iter()
        .filter(|w| !filler(&w.symbol) && w.confidence < threshold)
        .map(|w| (w.start, w.end))
        .collect();
    let inside = |p: &AlignedPhone| {
        let mid = 0.5 * (p.start + p.end);
        unsure.iter().any(|&(a, b)| mid >= a && mid < b)
    };
    let mut out: Vec<AlignedPhone> = phones.into_iter().filter(|p| !inside(p)).collect();
    for &(a, b) in &unsure {
        out.extend(
            heard
                .iter()
                .filter(|p| p.end > a && p.start < b)
                .map(|p| AlignedPhone {
                    start: p.start.max(a),
                    end: p.end.min(b),
                    ..p.clone()
                })
                .filter(|p| p.end > p.start),
        );
    }
    out.sort_by(|x, y| x.start.total_cmp(&y.start));
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn heard(symbol: &str, start: f64, end: f64, confidence: f64) -> AlignedPhone {
        AlignedPhone {
            symbol: symbol.into(),
            start,
            end,
            confidence,
        }
    }

    #[test]
    fn variants_are_looked_up_by_their_own_head() {
        let dict = "the DH AH0\nthe(2) DH IY0\nmap M AE1 P\n";
        let words = [heard("the(2)", 0.0, 0.1, 1.0), heard("map", 0.1, 0.4, 1.0)];
        let p = pronunciations(&words, dict);
        assert_eq!(p["the(2)"], ["DH", "IY"]);
        assert_eq!(p["map"], ["M", "AE", "P"]);
        assert!(!p.contains_key("the"));
    }

    #[test]
    fn a_word_shares_its_span_by_typical_lengths_and_fillers_are_silence() {
        let prons = HashMap::from([("map".to_string(), vec!["M".into(), "AE".into(), "P".into()])]);
        let words = [
            heard("<sil>", 0.0, 0.2, 0.9),
            heard("map", 0.2, 0.475, 0.8),
            heard("zzz", 0.475, 0.5, 0.3),
        ];
        let p = phones_of_words(&words, &prons);
        let s: Vec<&str> = p.iter().map(|p| p.symbol.as_str()).collect();
        assert_eq!(s, ["SIL", "M", "AE", "P", "SIL"]);
        // 65 + 130 + 80 ms of typical length over 275 ms: one to one.
        assert!((p[1].end - 0.265).abs() < 1e-9 && (p[2].end - 0.395).abs() < 1e-9);
        assert!((p[3].end - 0.475).abs() < 1e-9 && (p[3].confidence - 0.8).abs() < 1e-9);
    }

    #[test]
    fn heard_pauses_cut_the_words_into_pieces_with_their_text() {
        let mut words = Vec::new();
        let mut t = 0.0;
        for k in 0..45 {
            let w = if k % 10 == 9 { "<sil>" } else { "the(2)" };
            words.push(heard(w, t, t + 1.0, 0.9));
            t += 1.0;
        }
        let (text, pieces) = word_pieces(&words);
        assert_eq!(text.matches("the ").count(), 41);
        // Pauses at 9–10 s (too early), 19–20 s (cut at 19.5), 29–30 s (too soon after it),
        // 39–40 s (cut at 39.5); the last piece runs to the end of the last word.
        let spans: Vec<(f64, f64)> = pieces.iter().map(|p| (p.start, p.end)).collect();
        assert_eq!(spans, [(0.0, 19.5), (19.5, 39.5), (39.5, 45.0)]);
        assert_eq!(pieces[0].text, 0..18 * 4);
        assert_eq!(pieces[1].text, 18 * 4..36 * 4);
        assert_eq!(pieces[2].text, 36 * 4..text.len());
    }

    #[test]
    fn aligned_phones_come_back_to_arpabet() {
        use super::super::forced::espeak_to_arpabet;
        use super::super::recognition::arpabet_to_espeak;
        for ph in [
            "AA", "AE", "AH", "AO", "AW", "AY", "B", "CH", "D", "DH", "EH", "ER", "EY", "F", "G",
            "HH", "IH", "IY", "JH", "K", "L", "M", "N", "NG", "OW", "OY", "P", "R", "S", "SH", "T",
            "TH", "UH", "UW", "V", "W", "Y", "Z", "ZH",
        ] {
            assert_eq!(espeak_to_arpabet(arpabet_to_espeak(ph)), [ph], "{ph}");
        }
    }

    #[test]
    fn unsure_words_take_the_phone_loops_phones() {
        let words = [heard("up", 0.0, 0.2, 0.1), heard("of", 0.2, 0.4, 0.9)];
        let phones = vec![
            heard("AH", 0.0, 0.1, 0.1),
            heard("P", 0.1, 0.2, 0.1),
            heard("AH", 0.2, 0.3, 0.9),
            heard("V", 0.3, 0.4, 0.9),
        ];
        let loop_phones = [heard("AE", 0.0, 0.12, 1.0), heard("M", 0.12, 0.25, 1.0)];
        let m = mixed(&words, phones, &loop_phones, 0.5);
        let s: Vec<&str> = m.iter().map(|p| p.symbol.as_str()).collect();
        assert_eq!(s, ["AE", "M", "AH", "V"]);
        assert!((m[1].end - 0.2).abs() < 1e-9);
    }
}
