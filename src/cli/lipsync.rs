//! `fbakit lipsync RECORDING --text "…" -o out.fap|.json|.mp4|.gif|.html|.glb|.csv`: a voice
//! recording and its transcript to a talking face (`fbakit::speech::lipsync`).

use std::io::IsTerminal;
use std::path::{Path, PathBuf};

use clap::Args;
use fbakit::error::{Error, Result};
use fbakit::fap::write_stream_file;
use fbakit::format::OutputFormat;
use fbakit::speech::lipsync::coarticulation::dominant;
use fbakit::speech::lipsync::recognition::{check_recogniser, recognise_file};
use fbakit::speech::lipsync::{
    analyse_file, lipsync_recognised, lipsync_transcript_at, AlignedPhone, LipsyncOptions,
};
use fbakit::speech::{MouthFaps, SpeechOptions};
use serde::Serialize;

use super::speak::MouthArg;
use super::{parse_fps, print_json, EXIT_OK};

/// Longest transcript file read, bytes.
const MAX_TRANSCRIPT_BYTES: u64 = 1 << 20;

/// Arguments of `lipsync`.
#[derive(Debug, Args)]
pub struct LipsyncArgs {
    /// The voice recording: WAV (8/16/24/32-bit integer or 32-bit float), MP3, FLAC, Ogg
    /// Vorbis or M4A/MP4 (AAC), told apart by content; any rate from 4 kHz, stereo mixed down.
    pub recording: PathBuf,
    /// What the recording says (its transcript). Without --text or --text-file, English
    /// phones are recognised with PocketSphinx (Debian: pocketsphinx pocketsphinx-en-us).
    #[arg(long, value_name = "TEXT", conflicts_with = "text_file")]
    pub text: Option<String>,
    /// A UTF-8 text file holding what the recording says.
    #[arg(long, value_name = "FILE")]
    pub text_file: Option<PathBuf>,
    /// Language of the transcript, as an espeak-ng voice (`espeak-ng --voices`): en, en-us,
    /// de, fr, es, …
    #[arg(long, value_name = "LANG", default_value = "en")]
    pub lang: String,
    /// What to write: a FAP stream (`.fap`, `.json`), a video of the face speaking (`.mp4`
    /// with the recording as its soundtrack, `.gif`), a viewer page (`.html`), an animated
    /// glTF (`.glb`) or ARKit weights (`.csv`, needs an ARKit rig as --face and its --fp).
    #[arg(short, long, value_name = "OUT")]
    pub output: PathBuf,
    /// The face that speaks: a face file or rig, or a bundled face.
    #[arg(long, value_name = "FACE", default_value = "ict")]
    pub face: PathBuf,
    /// Feature points of the face (an OBJ or an ARKit rig for .csv needs them).
    #[arg(long, value_name = "FILE")]
    pub fp: Option<PathBuf>,
    /// Video frame size in pixels, `WxH`.
    #[arg(long, value_name = "WxH", default_value = "512x512", value_parser = super::play::parse_size)]
    pub size: (u32, u32),
    /// Frames per second of the stream.
    #[arg(long, value_name = "N", default_value_t = 25.0, value_parser = parse_fps)]
    pub fps: f64,
    /// What moves the mouth: FAP 1 visemes, low-level jaw and lip FAPs, or both.
    #[arg(long, value_enum, default_value = "visemes")]
    pub mouth: MouthArg,
    /// Print the report (phones with times and confidences, per-frame visemes) as JSON.
    /// A phone's confidence (0..1) says how well its sound fits the phone: from the speech
    /// recogniser's acoustic score when it placed the phone (one half at −4 nats a frame
    /// below the best-matching sound), else from how close the sound is to the transcript
    /// spoken by espeak-ng there. The report's `confidence` is the transcript's overall fit.
    #[arg(long)]
    pub json: bool,
}

#[derive(Debug, Serialize)]
struct FrameViseme {
    frame: u64,
    time: f64,
    select1: u8,
    select2: u8,
    blend: u8,
    /// The viseme shown most (select1 when blend ≥ 32).
    viseme: &'static str,
}

#[derive(Debug, Serialize)]
struct LipsyncReport {
    recording: String,
    format: Option<String>,
    sample_rate: Option<u32>,
    channels: Option<u16>,
    audio_seconds: f64,
    speech_seconds: f64,
    lang: String,
    /// `transcript` (forced alignment) or `recognition` (PocketSphinx phones, ARPAbet).
    method: &'static str,
    output: String,
    confidence: f64,
    frames: usize,
    fps: f64,
    mouth: MouthFaps,
    warnings: Vec<String>,
    unmapped_phonemes: Vec<String>,
    phones: Vec<AlignedPhone>,
    visemes: Vec<FrameViseme>,
    #[serde(skip_serializing_if = "Option::is_none")]
    talking_head: Option<serde_json::Value>,
}

fn progress_bar(len: u64, what: &str) -> indicatif::ProgressBar {
    if std::io::stderr().is_terminal() {
        super::play::progress(len, what)
    } else {
        indicatif::ProgressBar::hidden()
    }
}

fn transcript(a: &LipsyncArgs) -> Result<Option<String>> {
    match (&a.text, &a.text_file) {
        (Some(t), _) => Ok(Some(t.clone())),
        (None, Some(path)) => {
            let bytes = fbakit::io::read_bounded(path, MAX_TRANSCRIPT_BYTES)?;
            String::from_utf8(bytes).map(Some).map_err(|_| {
                Error::io(
                    path,
                    std::io::Error::new(
                        std::io::ErrorKind::InvalidData,
                        "the transcript is not UTF-8 text",
                    ),
                )
            })
        }
        (None, None) if a.lang == "en" || a.lang.starts_with("en-") => Ok(None),
        (None, None) => Err(Error::Usage(format!(
            "without a transcript only English is recognised; give the {} transcript with \
             --text \"…\" or --text-file FILE",
            a.lang
        ))),
    }
}

/// Runs `lipsync`.
pub fn run(a: LipsyncArgs) -> Result<u8> {
    let kind = OutputFormat::resolve(
        &a.output,
        &[
            OutputFormat::Fap,
            OutputFormat::Json,
            OutputFormat::Mp4,
            OutputFormat::Gif,
            OutputFormat::Html,
            OutputFormat::Glb,
            OutputFormat::Csv,
        ],
        "`lipsync` output",
    )?;
    let head = !matches!(kind, OutputFormat::Fap | OutputFormat::Json);
    let mut inputs: Vec<&Path> = vec![&a.recording];
    inputs.extend(a.text_file.as_deref());
    if head {
        inputs.push(&a.face);
        inputs.extend(a.fp.as_deref());
    }
    fbakit::format::refuse_overwriting_input(&a.output, &inputs)?;
    if kind == OutputFormat::Csv && a.fp.is_none() {
        return Err(Error::Usage(
            ".csv (ARKit weights) needs an ARKit rig as --face and its feature points as --fp"
                .into(),
        ));
    }
    let text = transcript(&a)?;
    // Read the face before the audio work, so a bad face fails fast.
    let face = if head && kind != OutputFormat::Csv {
        Some(super::inputs::read_face(&a.face, a.fp.as_deref())?)
    } else {
        None
    };
    if text.is_none() {
        // A missing recogniser is said before anything is read.
        check_recogniser()?;
    }
    let bar = progress_bar(1000, "reading");
    let rec = analyse_file(&a.recording, &mut |f| bar.set_position((f * 1000.0) as u64));
    bar.finish_and_clear();
    let rec = rec?;
    let sync = match &text {
        Some(text) => {
            let opts = LipsyncOptions {
                lang: a.lang.clone(),
                ..LipsyncOptions::default()
            };
            lipsync_transcript_at(&rec, text, &opts, a.fps)?
        }
        None => {
            let bar = progress_bar(1000, "recognising");
            let phones =
                recognise_file(&a.recording, &mut |f| bar.set_position((f * 1000.0) as u64));
            bar.finish_and_clear();
            lipsync_recognised(&rec, phones?, a.fps)?
        }
    };
    let speech = SpeechOptions {
        fps: a.fps,
        mouth: a.mouth.into(),
        name: "fbakit-lipsync".into(),
    };
    let stream = sync.stream(&speech)?;
    let mut talking_head = None;
    match (&face, kind) {
        (_, OutputFormat::Fap | OutputFormat::Json) => write_stream_file(&a.output, &stream)?,
        (_, OutputFormat::Csv) => talking_head = Some(write_arkit_csv(&a, &stream)?),
        (Some(face), OutputFormat::Html) => {
            talking_head = Some(super::speak::write_page(face, &stream, &a.output)?);
        }
        (Some(face), OutputFormat::Glb) => {
            talking_head = Some(write_glb(face, &stream, &a.output)?)
        }
        (Some(face), _) => {
            let job = super::render::VideoJob {
                output: &a.output,
                format: fbakit::export::video::VideoFormat::from_path(&a.output)?,
                size: a.size,
                fps: None,
                audio: (kind == OutputFormat::Mp4).then_some(a.recording.as_path()),
            };
            let video = super::render::write_video(
                face,
                &stream,
                &a.recording.display().to_string(),
                &job,
                Vec::new(),
            )?;
            talking_head = Some(serde_json::to_value(&video).unwrap_or_default());
        }
        (None, _) => unreachable!("faces are read for every head output"),
    }
    let visemes: Vec<FrameViseme> = stream
        .frames
        .iter()
        .filter_map(|f| {
            let v = f.viseme()?;
            Some(FrameViseme {
                frame: f.number,
                time: f.number as f64 / a.fps,
                select1: v.select1.number(),
                select2: v.select2.number(),
                blend: v.blend,
                viseme: dominant(&v).label(),
            })
        })
        .collect();
    let info = rec.info.as_ref();
    let report = LipsyncReport {
        recording: a.recording.display().to_string(),
        format: info.map(|i| i.format.clone()),
        sample_rate: info.map(|i| i.sample_rate),
        channels: info.map(|i| i.channels),
        audio_seconds: rec.seconds,
        speech_seconds: rec.activity.speech_seconds,
        lang: a.lang.clone(),
        method: if text.is_some() {
            "transcript"
        } else {
            "recognition"
        },
        output: a.output.display().to_string(),
        confidence: sync.confidence,
        frames: stream.frames.len(),
        fps: a.fps,
        mouth: speech.mouth,
        warnings: sync.warnings.clone(),
        unmapped_phonemes: sync.unmapped.clone(),
        phones: sync.phones.clone(),
        visemes,
        talking_head,
    };
    super::print_warnings(&report.warnings);
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
    let what = match kind {
        OutputFormat::Fap | OutputFormat::Json => "FAP stream".to_string(),
        OutputFormat::Mp4 => format!(
            "`{}` speaking, with the recording as its soundtrack",
            a.face.display()
        ),
        OutputFormat::Html => format!("viewer page of `{}` speaking (silent)", a.face.display()),
        OutputFormat::Csv => "ARKit weights".to_string(),
        _ => format!("`{}` speaking", a.face.display()),
    };
    println!(
        "wrote {}: {what}, {} frames at {} fps ({:.3} s)",
        report.output,
        report.frames,
        report.fps,
        report.frames as f64 / report.fps
    );
    println!(
        "aligned {} phones to {:.2} s of speech in {:.2} s of audio (confidence {:.2})",
        report.phones.len(),
        report.speech_seconds,
        report.audio_seconds,
        report.confidence
    );
    // A long recording has thousands of keys: the line is for a glance, --json has them all.
    let labels: Vec<&str> = sync
        .keys
        .iter()
        .take(60)
        .map(|k| k.viseme.label())
        .collect();
    let more = sync.keys.len().saturating_sub(labels.len());
    let tail = if more > 0 {
        format!(" … ({more} more)")
    } else {
        String::new()
    };
    println!("visemes: {}{tail}", labels.join(" "));
    Ok(EXIT_OK)
}

/// The face playing `stream` as an animated glTF binary.
fn write_glb(
    face: &fbakit::face::FaceModel,
    stream: &fbakit::fap::FapStream,
    path: &Path,
) -> Result<serde_json::Value> {
    use fbakit::player::{PlayOptions, Player};
    let player = Player::new(face, stream, &PlayOptions::default())?;
    super::play::with_play_hint(fbakit::export::budget::check_clip(
        path,
        &player.frame_range(),
        face,
    ))?;
    let anim = player.animation()?;
    let export = fbakit::export::gltf::export_face_with_units(face, Some(&anim), None)?;
    super::print_warnings(&export.warnings);
    export.document.write_glb(path)?;
    Ok(serde_json::json!({
        "output": path.display().to_string(),
        "face": face.name,
        "frames": anim.len(),
    }))
}

/// ARKit weights of `stream` through the rig in --face, as `fap to-arkit` writes them.
fn write_arkit_csv(a: &LipsyncArgs, stream: &fbakit::fap::FapStream) -> Result<serde_json::Value> {
    use fbakit::rig::arkit_names::{capture_name, ARKIT_SHAPES};
    use fbakit::rig::arkit_weights::ArkitBridge;
    use fbakit::rig::fat_build::face_from_rig;
    use fbakit::rig::weights_csv::write_weights_csv;
    let Some(fp) = &a.fp else {
        return Err(Error::Usage(".csv needs --fp".into()));
    };
    let points = fbakit::fdp::read_feature_points(fp)?.points;
    let rig = fbakit::rig::read_rig(&a.face)?;
    let map = super::face_from_rig::load_map("arkit", &rig)?;
    let (face, calibration) = face_from_rig(&rig, Some(points), &map)?;
    super::print_warnings(&rig.warnings);
    let mut bridge = ArkitBridge::new(&rig, &face, &calibration)?;
    let (frames, report) = bridge.faps_to_weights(stream)?;
    let names: Vec<String> = ARKIT_SHAPES.iter().map(|n| capture_name(n)).collect();
    let text = write_weights_csv(&names, report.fps, &frames);
    fbakit::io::write_atomic(&a.output, text.as_bytes())?;
    Ok(serde_json::to_value(&report).unwrap_or_default())
}
