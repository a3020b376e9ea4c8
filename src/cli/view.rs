//! `fbakit view FACE [STREAM] -o face.html`: one self-contained HTML page that shows the face,
//! plays the stream looping and poses the face with FAP sliders.

use std::path::{Path, PathBuf};

use clap::Args;
use fbakit::error::{Error, Result, ResultExt};
use fbakit::export::viewer::{ViewerAnimation, ViewerPage};
use fbakit::format::{refuse_overwriting_input, OutputFormat};
use fbakit::player::{PlayOptions, Player};
use serde::Serialize;

use super::play::parse_range;
use super::{print_json, EXIT_OK};

/// Arguments of `view`.
#[derive(Debug, Args)]
pub struct ViewArgs {
    /// Face: a VRML face file (.wrl, .wrl.gz), an OBJ with --fp, or `alma` / `bruno`.
    pub face: PathBuf,
    /// FAP stream to play (`.fap` or `.json`); without it the page shows the neutral face.
    pub stream: Option<PathBuf>,
    /// Feature points for the face (replacing its own; needed for an OBJ face).
    #[arg(long, value_name = "FILE")]
    pub fp: Option<PathBuf>,
    /// Output page (`.html`).
    #[arg(short, long, value_name = "OUT")]
    pub output: PathBuf,
    /// Frame rate of the embedded animation (the stream is resampled); default: the stream's.
    #[arg(long, value_name = "N", allow_negative_numbers = true, value_parser = super::parse_fps)]
    pub fps: Option<f64>,
    /// Stream frames to play, `a..b` (end exclusive; `a..` and `..b` too).
    #[arg(long, value_name = "a..b", value_parser = parse_range)]
    pub frames: Option<std::ops::Range<usize>>,
    /// Read the stream strictly.
    #[arg(long)]
    pub strict: bool,
    /// Print the report as JSON.
    #[arg(long)]
    pub json: bool,
}

#[derive(Debug, Serialize)]
struct ViewReport {
    face: String,
    stream: Option<String>,
    output: String,
    bytes: usize,
    glb_bytes: usize,
    frames: usize,
    fps: Option<f64>,
    duration_seconds: f64,
    missing_tables: Vec<String>,
    warnings: Vec<fbakit::error::Diagnostic>,
}

/// Refuses an output that is not an `.html` / `.htm` file (so a typo never overwrites a face).
/// Runs `view`.
pub fn run(a: ViewArgs) -> Result<u8> {
    OutputFormat::resolve(&a.output, &[OutputFormat::Html], "the viewer page")?;
    let mut inputs: Vec<&Path> = vec![&a.face];
    inputs.extend(a.stream.as_deref());
    inputs.extend(a.fp.as_deref());
    refuse_overwriting_input(&a.output, &inputs)?;
    if a.stream.is_none() && (a.fps.is_some() || a.frames.is_some()) {
        return Err(Error::Usage(
            "--fps and --frames need a STREAM to play".into(),
        ));
    }
    let face = super::inputs::read_face(&a.face, a.fp.as_deref())?;
    let mut warnings = Vec::new();
    let mut missing = Vec::new();
    let played = match &a.stream {
        Some(path) => {
            let (stream, diags) = super::inputs::read_stream(path, a.strict)?;
            warnings.extend(diags);
            let player = Player::new(
                &face,
                &stream,
                &PlayOptions {
                    fps: a.fps,
                    frames: a.frames.clone(),
                },
            )
            .with_context(|| format!("playing {} on {}", path.display(), a.face.display()))?;
            if player.frame_count() > fbakit::export::viewer::MAX_FRAMES {
                return Err(Error::Usage(format!(
                    "{}: {} frames, more than the {} the viewer embeds; play fewer with \
                     --frames a..b or a lower --fps",
                    a.output.display(),
                    player.frame_count(),
                    fbakit::export::viewer::MAX_FRAMES
                )));
            }
            super::play::with_play_hint(fbakit::export::budget::check_clip(
                &a.output,
                &player.frame_range(),
                &face,
            ))?;
            missing = player
                .missing_tables()
                .into_iter()
                .map(|(k, n)| format!("{k} in {n} frames"))
                .collect();
            let name = path.file_name().map_or_else(
                || path.display().to_string(),
                |n| n.to_string_lossy().into(),
            );
            Some((player.animation()?, player.fps(), name))
        }
        None => None,
    };
    let anim = played.as_ref().map(|(frames, fps, name)| ViewerAnimation {
        frames,
        fps: *fps,
        name,
    });
    let page = ViewerPage::new(&face, anim.as_ref())?;
    page.write(&a.output)?;
    warnings.extend(page.warnings);
    let report = ViewReport {
        face: face.name.clone(),
        stream: a.stream.as_ref().map(|p| p.display().to_string()),
        output: a.output.display().to_string(),
        bytes: page.html.len(),
        glb_bytes: page.glb_bytes,
        frames: anim.as_ref().map_or(0, |a| a.frames.len()),
        fps: anim.as_ref().map(|a| a.fps),
        duration_seconds: anim.as_ref().map_or(0.0, |a| a.duration()),
        missing_tables: missing,
        warnings,
    };
    if a.json {
        print_json(&report)?;
    } else {
        println!(
            "wrote {}: viewer page, {:.1} MB (glb {:.1} MB)",
            report.output,
            report.bytes as f64 / 1e6,
            report.glb_bytes as f64 / 1e6
        );
        match (&report.stream, report.fps) {
            (Some(s), Some(fps)) => println!(
                "plays {} frames of `{s}` on `{}` at {fps} fps ({:.3} s), looping",
                report.frames, report.face, report.duration_seconds
            ),
            _ => println!("shows `{}` at neutral (no stream)", report.face),
        }
        if !report.missing_tables.is_empty() {
            println!("missing tables (used by the stream, no table in the face):");
            for m in &report.missing_tables {
                println!("  {m}");
            }
        }
        super::print_warnings(&report.warnings);
    }
    Ok(EXIT_OK)
}
