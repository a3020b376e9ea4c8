//! `fbakit play FACE STREAM -o OUT`: plays a FAP stream on a face into an animated glTF, an
//! OBJ sequence, a PNG contact sheet / turntable or one PNG per frame.

use std::io::IsTerminal;
use std::ops::Range;
use std::path::{Path, PathBuf};

use clap::{Args, ValueEnum};
use fbakit::error::{Error, Result, ResultExt};
use fbakit::export::gltf::export_face_with_units;
use fbakit::export::obj_sequence::ObjSequence;
use fbakit::export::picture::{contact_sheet_for_player, turntable_sheet, FaceView};
use fbakit::export::{budget, ExportError};
use fbakit::format::OutputFormat;
use fbakit::player::{PlayOptions, Player};
use fbakit::render::RenderOptions;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use serde::Serialize;

use super::{print_json, EXIT_OK};

/// Output formats of `play`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum PlayFormat {
    /// Binary glTF (one file).
    Glb,
    /// Text glTF with the buffer embedded (one file).
    Gltf,
    /// One OBJ per frame in a directory, plus `frames.json`.
    Obj,
    /// PNG: OUT.png is a contact sheet (or turntable); a directory gets one PNG per frame.
    Png,
}

/// Arguments of `play`.
#[derive(Debug, Args)]
pub struct PlayArgs {
    /// Face: a face file or rig, or a bundled face (`alma`, `bruno`, `ict`).
    pub face: PathBuf,
    /// Feature points of the face (an OBJ needs them; with them a rig's shapes become its
    /// FAT).
    #[arg(long, value_name = "FILE")]
    pub fp: Option<PathBuf>,
    /// FAP stream (`.fap` or `.json`).
    pub stream: PathBuf,
    /// Output: `.glb` / `.gltf` file (`.vrm` for a VRM avatar), `.png` contact sheet, or a
    /// directory for an OBJ or PNG sequence.
    #[arg(short, long, value_name = "OUT")]
    pub output: PathBuf,
    /// Output frame rate (the stream is resampled, values interpolated); default: the
    /// stream's.
    #[arg(long, value_name = "N", allow_negative_numbers = true, value_parser = super::parse_fps)]
    pub fps: Option<f64>,
    /// Output frames to play, `a..b` (end exclusive; `a..` and `..b` too).
    #[arg(long, value_name = "a..b", value_parser = parse_range)]
    pub frames: Option<Range<usize>>,
    /// Output format (default: from OUT's extension; a directory or no extension means obj).
    #[arg(long)]
    pub format: Option<PlayFormat>,
    /// PNG contact sheet: number of frames, spread over the played range.
    #[arg(long, value_name = "N", default_value_t = 8, value_parser = clap::value_parser!(u32).range(1..=256))]
    pub sheet_frames: u32,
    /// PNG: image (or sheet cell) size in pixels, `WxH`.
    #[arg(long, value_name = "WxH", default_value = "512x512", value_parser = parse_size)]
    pub size: (u32, u32),
    /// PNG sheet: instead of frames, K views of the first played frame turning around the head.
    #[arg(long, value_name = "K", value_parser = clap::value_parser!(u32).range(1..=72))]
    pub turntable: Option<u32>,
    /// Read the stream strictly.
    #[arg(long)]
    pub strict: bool,
    #[command(flatten)]
    pub nodes: NodeArgs,
    /// Print the report as JSON.
    #[arg(long)]
    pub json: bool,
    /// Length unit of the face's coordinates (default: guessed from its size); glTF output
    /// is scaled from it to metres.
    #[arg(long, value_name = "mm|cm|m")]
    pub units: Option<fbakit::face::units::LengthUnit>,
}

/// Largest image side `--size` accepts.
const MAX_SIZE: u32 = 4096;

/// Parses `WxH` (each 16..=4096).
pub fn parse_size(s: &str) -> std::result::Result<(u32, u32), String> {
    let (w, h) = s
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("`{s}` is not a size like 512x512"))?;
    let side = |t: &str| -> std::result::Result<u32, String> {
        match t.trim().parse::<u32>() {
            Ok(v) if (16..=MAX_SIZE).contains(&v) => Ok(v),
            _ => Err(format!(
                "`{t}` is not a side between 16 and {MAX_SIZE} pixels"
            )),
        }
    };
    Ok((side(w)?, side(h)?))
}

/// Parses `a..b`, `a..` or `..b`.
pub fn parse_range(s: &str) -> std::result::Result<Range<usize>, String> {
    let (a, b) = s
        .split_once("..")
        .ok_or_else(|| format!("`{s}` is not a range like 10..50"))?;
    let num = |t: &str, default: usize| -> std::result::Result<usize, String> {
        if t.is_empty() {
            Ok(default)
        } else {
            t.trim()
                .parse()
                .map_err(|_| format!("`{t}` is not a frame number"))
        }
    };
    let r = num(a, 0)?..num(b, usize::MAX)?;
    if r.start >= r.end {
        return Err(format!("range `{s}` is empty"));
    }
    Ok(r)
}

#[derive(Debug, Serialize)]
struct MissingRecord {
    key: String,
    frames: usize,
}

#[derive(Debug, Serialize)]
struct PlayReport {
    face: String,
    stream: String,
    output: String,
    format: PlayFormat,
    frames: usize,
    first_frame: usize,
    fps: f64,
    duration_seconds: f64,
    files_written: usize,
    missing_tables: Vec<MissingRecord>,
    warnings: Vec<fbakit::error::Diagnostic>,
}

/// Picks the output format from `--format` or OUT (through the one output rule,
/// [`OutputFormat::resolve`]; a path without extension is a new folder of OBJ frames).
pub fn output_format(out: &Path, format: Option<PlayFormat>) -> Result<PlayFormat> {
    if let Some(f) = format {
        return Ok(f);
    }
    if out.extension().is_none() {
        return Ok(PlayFormat::Obj);
    }
    let accepted = [
        OutputFormat::Glb,
        OutputFormat::Gltf,
        OutputFormat::Png,
        OutputFormat::Directory,
    ];
    Ok(
        match OutputFormat::resolve(out, &accepted, "`play` output (or give --format)")? {
            OutputFormat::Glb => PlayFormat::Glb,
            OutputFormat::Gltf => PlayFormat::Gltf,
            OutputFormat::Png => PlayFormat::Png,
            _ => PlayFormat::Obj,
        },
    )
}

/// A progress bar on stderr, hidden when stderr is not a terminal.
pub fn progress(len: u64, what: &str) -> ProgressBar {
    let target = if std::io::stderr().is_terminal() {
        ProgressDrawTarget::stderr()
    } else {
        ProgressDrawTarget::hidden()
    };
    let bar = ProgressBar::with_draw_target(Some(len), target);
    if let Ok(style) = ProgressStyle::with_template("{msg} [{bar:40}] {pos}/{len} frames") {
        bar.set_style(style.progress_chars("=> "));
    }
    bar.set_message(what.to_string());
    bar
}

/// Runs `play`.
pub fn run(a: PlayArgs) -> Result<u8> {
    let format = output_format(&a.output, a.format)?;
    let mut inputs: Vec<&Path> = vec![&a.face, &a.stream];
    inputs.extend(a.fp.as_deref());
    fbakit::format::refuse_overwriting_input(&a.output, &inputs)?;
    let face = super::inputs::read_face(&a.face, a.fp.as_deref())?;
    let (stream, mut warnings) = super::inputs::read_stream(&a.stream, a.strict)?;
    let mut player = Player::new(
        &face,
        &stream,
        &PlayOptions {
            fps: a.fps,
            frames: a.frames.clone(),
        },
    )
    .with_context(|| format!("playing {} on {}", a.stream.display(), a.face.display()))?;
    let span = player.frame_range();
    match format {
        PlayFormat::Glb | PlayFormat::Gltf => {
            with_play_hint(budget::check_clip(&a.output, &span, &face))?
        }
        PlayFormat::Obj => check_budget(&a.output, &span, budget::obj_bytes_per_frame(&face))?,
        // A sheet renders a fixed number of frames whatever the span.
        PlayFormat::Png if is_png_file(&a.output) => check_budget(&a.output, &span, 0)?,
        PlayFormat::Png => check_budget(
            &a.output,
            &span,
            budget::image_bytes_per_frame(a.size.0, a.size.1),
        )?,
    }
    let bar = progress(player.frame_count() as u64, "playing");
    let files_written = match format {
        PlayFormat::Glb | PlayFormat::Gltf => {
            let anim = player.animation()?;
            bar.set_position(anim.len() as u64);
            // A glTF face plays into its own document, which keeps its units.
            if let Some(export) = fbakit::export::gltf_patch::patch_if_fits(
                &face,
                Some(&anim),
                &a.nodes.rotation_nodes(),
                &mut warnings,
            )? {
                warnings.extend(export.warnings);
                export.document.write(&a.output)?;
            } else {
                let export = export_face_with_units(&face, Some(&anim), a.units)?;
                warnings.extend(export.warnings);
                match format {
                    PlayFormat::Glb => export.document.write_glb(&a.output)?,
                    _ => export.document.write_gltf(&a.output)?,
                }
            }
            1
        }
        PlayFormat::Obj => {
            let mut seq = ObjSequence::new(&face, &a.output, player.fps())?;
            let mut frame = player.new_frame();
            let mut n = 0;
            while player.next_frame(&mut frame) {
                seq.write_frame(&frame)?;
                n += 1;
                bar.inc(1);
            }
            seq.finish()?;
            n + 1
        }
        PlayFormat::Png => {
            let n = write_pngs(&a, &face, &mut player, &bar)?;
            bar.set_position(player.frame_count() as u64);
            n
        }
    };
    bar.finish_and_clear();
    let report = PlayReport {
        face: face.name.clone(),
        stream: a.stream.display().to_string(),
        output: a.output.display().to_string(),
        format,
        frames: player.frame_count(),
        first_frame: player.frame_range().start,
        fps: player.fps(),
        duration_seconds: player.duration(),
        files_written,
        missing_tables: player
            .missing_tables()
            .into_iter()
            .map(|(k, frames)| MissingRecord {
                key: k.to_string(),
                frames,
            })
            .collect(),
        warnings,
    };
    if a.json {
        print_json(&report)?;
    } else {
        super::print_text(&report_text(&report));
        super::print_warnings(&report.warnings);
    }
    Ok(EXIT_OK)
}

/// Refuses an output estimated too large ([`budget::check`]), saying how to play less.
pub fn check_budget(output: &Path, frames: &Range<usize>, bytes_per_frame: u64) -> Result<()> {
    with_play_hint(budget::check(output, frames, bytes_per_frame))
}

/// A budget refusal with the options that play less.
pub fn with_play_hint(checked: Result<()>) -> Result<()> {
    checked.map_err(|mut e| {
        if let Error::Export(ExportError::OverBudget { advice, .. }) = &mut e {
            *advice = "; play fewer with --frames a..b or a lower --fps".into();
        }
        e
    })
}

/// Whether OUT names a single PNG file (a sheet) rather than a directory of frames.
fn is_png_file(out: &Path) -> bool {
    out.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("png"))
}

/// PNG output: a contact sheet or turntable when OUT ends in `.png`, else one PNG per
/// frame in the directory OUT. Returns the number of files written.
fn write_pngs(
    a: &PlayArgs,
    face: &fbakit::face::FaceModel,
    player: &mut Player,
    bar: &ProgressBar,
) -> Result<usize> {
    if is_png_file(&a.output) {
        let image = match a.turntable {
            Some(k) => turntable_sheet(face, player, k as usize, a.size)?,
            None => contact_sheet_for_player(face, player, a.sheet_frames as usize, a.size)?,
        };
        image.write_png(&a.output)?;
        return Ok(1);
    }
    // Frames go into a temporary sibling renamed at the end: a failure leaves nothing.
    let dir = fbakit::io::open_frame_dir(&a.output, |n| {
        fbakit::io::is_numbered_file(n, "frame_", ".png")
    })?;
    let view = FaceView::new(face)?;
    let camera = view.front_camera();
    let opts = RenderOptions::sized(a.size.0, a.size.1);
    let mut frame = player.new_frame();
    let mut positions = Vec::new();
    let mut n = 0;
    while player.next_frame(&mut frame) {
        frame.pose.world_positions_into(&mut positions);
        let image = view.render(&positions, &camera, &opts);
        let file = format!("frame_{:05}.png", frame.index);
        image
            .write_png(&dir.temp_path().join(&file))
            .map_err(|e| match e {
                Error::Output { source, .. } => Error::output(dir.path().join(&file), source),
                other => other,
            })?;
        n += 1;
        bar.inc(1);
    }
    dir.commit()?;
    Ok(n)
}

fn report_text(r: &PlayReport) -> String {
    use std::fmt::Write as _;
    let mut o = String::new();
    let what = match r.format {
        PlayFormat::Obj => format!("{} files (OBJ frames + frames.json)", r.files_written),
        PlayFormat::Png if r.files_written == 1 => "PNG sheet".to_string(),
        PlayFormat::Png => format!("{} PNG frames", r.files_written),
        _ => "animated glTF".to_string(),
    };
    let _ = writeln!(o, "wrote {}: {what}", r.output);
    let _ = writeln!(
        o,
        "played {} frames from {} of `{}` on `{}` at {} fps ({:.3} s)",
        r.frames, r.first_frame, r.stream, r.face, r.fps, r.duration_seconds
    );
    if r.missing_tables.is_empty() {
        let _ = writeln!(o, "missing tables: none");
    } else {
        let _ = writeln!(
            o,
            "missing tables (used by the stream, no table in the face):"
        );
        for m in &r.missing_tables {
            let _ = writeln!(o, "  {} in {} frames", m.key, m.frames);
        }
    }
    o
}

/// The user's glTF nodes that turn for head, eye and jaw FAPs (`play`, `clone`).
#[derive(Debug, Clone, Default, clap::Args)]
pub struct NodeArgs {
    /// glTF face: the node head pitch, yaw and roll (FAPs 48-50) turn (default: found by the
    /// usual names such as `Head`, or the VRM humanoid head bone, when it carries the nose
    /// tip 9.3). A cloned face's head transform is shown and recorded on it.
    #[arg(long, value_name = "NODE")]
    pub head_node: Option<String>,
    /// glTF face: the left and right eye nodes eyeball yaw and pitch (FAPs 23-26) turn, as
    /// `LEFT,RIGHT` (default: `LeftEye`/`RightEye`, `eye.L`/`eye.R` or the VRM eye bones).
    /// An eye node that holds its eyeball's mesh alone, or an eye joint its eyeball is
    /// skinned to (95 % of its weight or more, none of the skin's), shows the cloned eye's
    /// motion.
    #[arg(long, value_name = "LEFT,RIGHT", value_parser = parse_node_pair)]
    pub eye_nodes: Option<(String, String)>,
    /// glTF face: the jaw node open_jaw turns and thrust_jaw / shift_jaw move (FAPs 3, 14,
    /// 15), instead of their morph targets (default: a node named `Jaw`/`jaw` or the VRM
    /// humanoid jaw bone, when it carries the chin 2.1: skinned to it at least half, or under
    /// it). Needs the face's feature points (FAP units and the chin, 2.1).
    #[arg(long, value_name = "NODE")]
    pub jaw_node: Option<String>,
}

impl NodeArgs {
    /// The rotation nodes the options name.
    pub fn rotation_nodes(&self) -> fbakit::export::gltf_rotations::RotationNodes {
        fbakit::export::gltf_rotations::RotationNodes {
            head: self.head_node.clone(),
            eyes: self.eye_nodes.clone(),
            jaw: self.jaw_node.clone(),
        }
    }
}

/// `--eye-nodes LEFT,RIGHT`.
fn parse_node_pair(s: &str) -> std::result::Result<(String, String), String> {
    match s.split_once(',') {
        Some((l, r)) if !l.trim().is_empty() && !r.trim().is_empty() => {
            Ok((l.trim().to_string(), r.trim().to_string()))
        }
        _ => Err(format!("`{s}`: expected LEFT,RIGHT node names")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranges() {
        assert_eq!(parse_range("3..10"), Ok(3..10));
        assert_eq!(parse_range("3.."), Ok(3..usize::MAX));
        assert_eq!(parse_range("..10"), Ok(0..10));
        assert!(parse_range("10..3").is_err());
        assert!(parse_range("5").is_err());
        assert!(parse_range("a..b").is_err());
    }

    #[test]
    fn sizes() {
        assert_eq!(parse_size("512x256"), Ok((512, 256)));
        assert_eq!(parse_size("64X64"), Ok((64, 64)));
        assert!(parse_size("0x10").is_err());
        assert!(parse_size("512").is_err());
        assert!(parse_size("99999x10").is_err());
        assert!(parse_size("ax10").is_err());
    }

    #[test]
    fn formats() {
        let f = |p: &str| output_format(Path::new(p), None);
        assert_eq!(f("x.glb").unwrap(), PlayFormat::Glb);
        assert_eq!(f("x.GLTF").unwrap(), PlayFormat::Gltf);
        assert_eq!(f("frames").unwrap(), PlayFormat::Obj);
        assert_eq!(f("x.png").unwrap(), PlayFormat::Png);
        assert!(f("x.txt").is_err());
        assert_eq!(
            output_format(Path::new("x.txt"), Some(PlayFormat::Obj)).unwrap(),
            PlayFormat::Obj
        );
    }
}
