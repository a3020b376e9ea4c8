//! `fbakit speak TEXT -o out.fap|out.mp4|out.gif|out.html [--wav out.wav] [--voice en]
//! [--face FACE]`: text to a FAP stream of visemes (and the speech audio) with espeak-ng, or
//! straight to a talking head: a video with the speech as its soundtrack, or a viewer page.

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
    /// What to write: a FAP stream (`.fap`, `.json`), or the talking head itself: a video
    /// (`.mp4` with the speech as its soundtrack, `.gif`, a folder of PNG frames) or a viewer
    /// page (`.html`, silent: browsers do not start sound on load).
    #[arg(short, long, value_name = "OUT")]
    pub output: PathBuf,
    /// The face that speaks in a video or page: a face file or rig, or a bundled face.
    #[arg(long, value_name = "FACE", default_value = "ict")]
    pub face: PathBuf,
    /// Feature points of the face (an OBJ needs them; with them a rig's shapes become its
    /// FAT).
    #[arg(long, value_name = "FILE")]
    pub fp: Option<PathBuf>,
    /// Video frame size in pixels, `WxH`.
    #[arg(long, value_name = "WxH", default_value = "512x512", value_parser = super::play::parse_size)]
    pub size: (u32, u32),
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
    /// The video or page written, when OUT is one.
    #[serde(skip_serializing_if = "Option::is_none")]
    talking_head: Option<serde_json::Value>,
}

/// Runs `speak`.
pub fn run(a: SpeakArgs) -> Result<u8> {
    if a.wav.as_ref() == Some(&a.output) {
        return Err(Error::Usage(
            "-o and --wav name the same file; give them different names".into(),
        ));
    }
    use fbakit::format::OutputFormat;
    let kind = OutputFormat::resolve(
        &a.output,
        &[
            OutputFormat::Fap,
            OutputFormat::Json,
            OutputFormat::Mp4,
            OutputFormat::Gif,
            OutputFormat::Html,
            OutputFormat::Directory,
        ],
        "`speak` output",
    )?;
    let head = !matches!(kind, OutputFormat::Fap | OutputFormat::Json);
    let mut inputs: Vec<&std::path::Path> = Vec::new();
    if head {
        inputs.push(&a.face);
        inputs.extend(a.fp.as_deref());
    }
    fbakit::format::refuse_overwriting_input(&a.output, &inputs)?;
    if let Some(wav) = &a.wav {
        fbakit::format::refuse_overwriting_input(wav, &inputs)?;
    }
    // Read the face before synthesising, so a bad face fails fast.
    let face = if head {
        Some(super::inputs::read_face(&a.face, a.fp.as_deref())?)
    } else {
        None
    };
    let opts = SpeechOptions {
        fps: a.fps,
        mouth: a.mouth.into(),
        ..SpeechOptions::default()
    };
    let (utterance, animation) = say(&a.text, &a.voice, &opts)?;
    if let Some(wav) = &a.wav {
        fbakit::speech::wav::write_wav(wav, &utterance)?;
    }
    let mut talking_head = None;
    match (&face, kind) {
        (None, _) => write_stream_file(&a.output, &animation.stream)?,
        (Some(face), OutputFormat::Html) => {
            talking_head = Some(write_page(face, &animation.stream, &a.output)?);
        }
        (Some(face), _) => {
            // The soundtrack goes through a temporary WAV that ffmpeg reads.
            let scratch = tempfile::tempdir().map_err(|e| Error::io(std::env::temp_dir(), e))?;
            let audio = if kind == OutputFormat::Mp4 {
                let path = scratch.path().join("speech.wav");
                fbakit::speech::wav::write_wav(&path, &utterance)?;
                Some(path)
            } else {
                None
            };
            let job = super::render::VideoJob {
                output: &a.output,
                format: fbakit::export::video::VideoFormat::from_path(&a.output)?,
                size: a.size,
                fps: None,
                audio: audio.as_deref(),
            };
            let video = super::render::write_video(
                face,
                &animation.stream,
                &format!("\"{}\"", a.text),
                &job,
                Vec::new(),
            )?;
            talking_head = Some(serde_json::to_value(&video).unwrap_or_default());
        }
    }
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
        talking_head,
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
    match (&face, kind) {
        (None, _) => println!(
            "wrote {}: {} frames at {} fps ({:.3} s)",
            report.output, report.frames, report.fps, report.stream_seconds
        ),
        (Some(face), OutputFormat::Html) => println!(
            "wrote {}: viewer page of `{}` saying it, {} frames at {} fps ({:.3} s), silent \
             (write .mp4 for sound)",
            report.output, face.name, report.frames, report.fps, report.stream_seconds
        ),
        (Some(face), _) => println!(
            "wrote {}: `{}` saying it, {} frames at {} fps ({:.3} s){}",
            report.output,
            face.name,
            report.frames,
            report.fps,
            report.stream_seconds,
            if kind == OutputFormat::Mp4 {
                ", with the speech as its soundtrack"
            } else {
                ""
            }
        ),
    }
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

/// The viewer page of `face` playing `stream`; its report as JSON.
pub(super) fn write_page(
    face: &fbakit::face::FaceModel,
    stream: &fbakit::fap::FapStream,
    path: &std::path::Path,
) -> Result<serde_json::Value> {
    use fbakit::export::viewer::{ViewerAnimation, ViewerPage};
    use fbakit::player::{PlayOptions, Player};
    let player = Player::new(face, stream, &PlayOptions::default())?;
    let frames = player.animation()?;
    let anim = ViewerAnimation {
        frames: &frames,
        fps: player.fps(),
        name: "speech",
    };
    let page = ViewerPage::new(face, Some(&anim))?;
    page.write(path)?;
    super::print_warnings(&page.warnings);
    Ok(serde_json::json!({
        "output": path.display().to_string(),
        "face": face.name,
        "bytes": page.html.len(),
        "frames": frames.len(),
        "duration_seconds": anim.duration(),
    }))
}
