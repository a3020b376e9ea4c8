//! Phones without a transcript from recognised *words* (English): PocketSphinx's word
//! search (`pocketsphinx_continuous` with the `pocketsphinx-en-us` language model and
//! pronouncing dictionary) gives words with times and posterior confidences, and each
//! word's dictionary phones share its time by their typical lengths ([`phones_of_words`]).
//!
//! A wrong word that sounds like the right one has nearly the right phones, and the mouth
//! shows phones, not words. Where the search is unsure of a word, the phone loop's phones
//! ([`super::recognition`]) stand in for it ([`mixed`]).

use std::collections::{HashMap, HashSet};
use std::path::Path;
use std::process::Command;

use super::recognition::{in_pieces, model, model_dir, run_timed, PROGRAM};
use super::AlignedPhone;
use crate::error::{Error, Result};

/// The pronouncing dictionary's file in the model directory.
const DICTIONARY: &str = "cmudict-en-us.dict";
/// The word language model's file in the model directory.
const LANGUAGE_MODEL: &str = "en-us.lm.bin";

/// The silence phone.
const SILENCE: &str = "SIL";

/// The ARPAbet phones of the recording at `path` from recognised words, with their times;
/// the share of the file read goes to `progress`.
pub fn recognise_words_file(
    path: &Path,
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
    let settings = std::env::var("FBAKIT_WORDS_ARGS").unwrap_or_default();
    let mode = std::env::var("FBAKIT_WORDS_MODE").unwrap_or_default();
    let threshold: Option<f64> = mode.strip_prefix("mix:").and_then(|t| t.parse().ok());
    let mut dict: Option<String> = None;
    let mut said: Vec<String> = Vec::new();
    let mut run = |wav: &Path| -> Result<Vec<AlignedPhone>> {
        let mut cmd = Command::new(PROGRAM);
        cmd.arg("-lm").arg(&lm).arg("-dict").arg(&dict_path);
        cmd.args(settings.split_whitespace());
        let words = run_timed(cmd, wav, &hmm)?;
        said.extend(
            words
                .iter()
                .filter(|w| !filler(&w.symbol))
                .map(|w| w.symbol.split_once('(').map_or(w.symbol.as_str(), |(h, _)| h).to_string()),
        );
        if dict.is_none() {
            dict = Some(std::fs::read_to_string(&dict_path).map_err(|e| Error::io(&dict_path, e))?);
        }
        let prons = pronunciations(&words, dict.as_deref().unwrap_or(""));
        let phones = phones_of_words(&words, &prons);
        match threshold {
            Some(t) if words.iter().any(|w| !filler(&w.symbol) && w.confidence < t) => {
                let mut cmd = Command::new(PROGRAM);
                cmd.arg("-allphone")
                    .arg(&phone_lm)
                    .args(["-allphone_ci", "yes", "-backtrace", "yes"])
                    .args(["-beam", "1e-20", "-pbeam", "1e-20", "-lw", "1.0"]);
                let heard = run_timed(cmd, wav, &hmm)?;
                Ok(mixed(&words, phones, &heard, t))
            }
            _ => Ok(phones),
        }
    };
    let phones = in_pieces(path, progress, &mut run)?;
    if mode == "forced" && !said.is_empty() {
        if let Some(placed) = super::forced::align_file(path, &said.join(" "))? {
            return Ok(placed
                .into_iter()
                .map(|p| AlignedPhone {
                    symbol: super::forced::espeak_to_arpabet(&p.symbol)
                        .first()
                        .copied()
                        .unwrap_or(SILENCE)
                        .to_string(),
                    ..p
                })
                .collect());
        }
    }
    Ok(phones)
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
        let phones = prons.get(&w.symbol).filter(|p| !filler(&w.symbol) && !p.is_empty());
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
