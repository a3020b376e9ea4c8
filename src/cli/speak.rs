//! `fbakit speak TEXT -o out.fap [--wav out.wav] [--voice en]`: text to a FAP stream of
//! visemes (and the speech audio) with espeak-ng.

use std::path::PathBuf;

use clap::{Args, ValueEnum};
use fbakit::error::{Error, Result};
use fbakit::fap::write_stream_file;
use fbakit::speech::{say, MouthFaps, SpeechOptions};
use serde::Serialize;

use super::{parse_fps, print_json, EXIT_OK};

/// What the stream moves the mouth with (`--mouth`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum MouthArg {
    /// FAP 1 visemes only: for faces with viseme tables (alma, bruno, cloned faces).
    Visemes,
    /// Jaw and lip FAPs (3-7, 16, 17) only: for faces without viseme tables (CANDIDE-3).
    Faps,
    /// Both (on faces with viseme tables the motions add up).
    Both,
}

impl From<MouthArg> for MouthFaps {
    fn from(m: MouthArg) -> MouthFaps {
        match m {
            MouthArg::Visemes => MouthFaps::Visemes,
            MouthArg::Faps => MouthFaps::LowLevel,
            MouthArg::Both => MouthFaps::Both,
        }
    }
}

/// Arguments of `speak`.
#[derive(Debug, Args)]
pub struct SpeakArgs {
    /// The text to say.
    pub text: String,
    /// FAP stream to write (`.fap`, or `.json`).
    #[arg(short, long, value_name = "OUT")]
    pub output: PathBuf,
    /// Also write the speech audio (WAV, mono 16-bit).
    #[arg(long, value_name = "FILE")]
    pub wav: Option<PathBuf>,
    /// espeak-ng voice (`espeak-ng --voices` lists them), e.g. en, en-us, de, fr.
    #[arg(long, default_value = "en")]
    pub voice: String,
    /// Frames per second of the stream.
    #[arg(long, value_name = "N", default_value_t = 25.0, allow_negative_numbers = true, value_parser = parse_fps)]
    pub fps: f64,
    /// What moves the mouth: FAP 1 visemes, low-level jaw and lip FAPs, or both.
    #[arg(long, value_enum, default_value = "visemes")]
    pub mouth: MouthArg,
    /// Print the report (phonemes, visemes, files) as JSON.
    #[arg(long)]
    pub json: bool,
}

#[derive(Debug, Serialize)]
struct SpeakReport {
    text: String,
    voice: String,
    output: String,
    wav: Option<String>,
    audio_seconds: f64,
    sample_rate: u32,
    frames: usize,
    fps: f64,
    stream_seconds: f64,
    mouth: MouthFaps,
    phonemes: Vec<fbakit::speech::TimedPhoneme>,
    visemes: Vec<fbakit::speech::VisemeKey>,
    unmapped_phonemes: Vec<String>,
}

/// Runs `speak`.
pub fn run(a: SpeakArgs) -> Result<u8> {
    if a.wav.as_ref() == Some(&a.output) {
        return Err(Error::Invalid(
            "-o and --wav name the same file; give them different names".into(),
        ));
    }
    let opts = SpeechOptions {
        fps: a.fps,
        mouth: a.mouth.into(),
        ..SpeechOptions::default()
    };
    let (utterance, animation) = say(&a.text, &a.voice, &opts)?;
    if let Some(wav) = &a.wav {
        fbakit::speech::wav::write_wav(wav, &utterance)?;
    }
    write_stream_file(&a.output, &animation.stream)?;
    let frames = animation.stream.frames.len();
    let report = SpeakReport {
        text: a.text.clone(),
        voice: a.voice.clone(),
        output: a.output.display().to_string(),
        wav: a.wav.as_ref().map(|p| p.display().to_string()),
        audio_seconds: utterance.duration(),
        sample_rate: utterance.sample_rate,
        frames,
        fps: a.fps,
        stream_seconds: frames as f64 / a.fps,
        mouth: opts.mouth,
        phonemes: utterance.phonemes.clone(),
        visemes: animation.keys.clone(),
        unmapped_phonemes: animation.unmapped.clone(),
    };
    if a.json {
        print_json(&report)?;
        return Ok(EXIT_OK);
    }
    if !report.unmapped_phonemes.is_empty() {
        eprintln!(
            "warning: no viseme for phoneme(s) {} (the mouth blends across them)",
            report.unmapped_phonemes.join(" ")
        );
    }
    let phonemes: Vec<&str> = report.phonemes.iter().map(|p| p.symbol.as_str()).collect();
    let visemes: Vec<&str> = report.visemes.iter().map(|k| k.viseme.label()).collect();
    println!(
        "wrote {}: {} frames at {} fps ({:.3} s)",
        report.output, report.frames, report.fps, report.stream_seconds
    );
    if let Some(w) = &report.wav {
        println!(
            "wrote {w}: {:.3} s of speech at {} Hz (espeak-ng voice `{}`)",
            report.audio_seconds, report.sample_rate, report.voice
        );
    }
    println!("phonemes: {}", phonemes.join(" "));
    println!("visemes:  {}", visemes.join(" "));
    Ok(EXIT_OK)
}
