//! `fbakit fap from-arkit` and `fbakit fap to-arkit`: face-capture weight curves (Live Link
//! Face CSV, the bare 52-column CSV, MediaPipe CSV and JSON lines; `fbakit::rig::capture`) to a
//! FAP stream and back (Live Link Face's layout with head and eye rotations), through a rig and
//! the FAT built from it, or through any face's own FAT (`fbakit::rig::arkit_weights`).

use std::path::{Path, PathBuf};

use clap::Args;
use fbakit::error::Result;
use fbakit::face::FaceModel;
use fbakit::fap::{write_stream_file, FapTimeline, ReadOptions};
use fbakit::format::{refuse_overwriting_input, OutputFormat};
use fbakit::rig::arkit_weights::{arkit_rig_of_face, ArkitBridge, FromArkitReport, ToArkitReport};
use fbakit::rig::capture::{read_capture_file, stream_rotations, write_live_link_csv, ROTATIONS};
use fbakit::rig::fat_build::{face_from_rig, RigFatReport};
use fbakit::rig::weights_csv::timecode_seconds;
use fbakit::rig::{read_rig, Rig, RigError};
use serde::Serialize;

use super::{print_json, EXIT_OK};

/// The face (a rig with its feature points, or any face with a FAT) both directions share.
#[derive(Debug, Args)]
pub struct RigArgs {
    /// The face. With --fp: a blendshape rig (.glb, .gltf, a folder of OBJs: neutral + one OBJ
    /// per shape, or a neutral .obj), whose FAT is built from its shapes. Without --fp: any
    /// face with a FAT (a face file such as a `clone` output, a glTF fbakit wrote, or a bundled
    /// name: alma, bruno, ict); the bridge then solves on that FAT, its ARKit shapes made
    /// from the bundled amplitude table.
    #[arg(long, value_name = "FACE")]
    pub face: PathBuf,
    /// Feature points of the rig's neutral (.xml, .fdp, .csv), e.g. from `fbakit fp
    /// from-landmarks`; the FAT is calibrated on them and the fit compares their motion.
    #[arg(long, value_name = "FILE")]
    pub fp: Option<PathBuf>,
    /// Mapping table of a rig (with --fp): `arkit` (built in) or a CSV file
    /// (fap,positive,negative,reasoning).
    #[arg(long, value_name = "arkit|FILE", default_value = "arkit")]
    pub map: String,
}

impl RigArgs {
    fn inputs(&self) -> Vec<&Path> {
        let mut v = vec![self.face.as_path()];
        v.extend(self.fp.as_deref());
        v
    }
}

/// Arguments of `fap from-arkit`.
#[derive(Debug, Args)]
pub struct FromArkitArgs {
    /// Capture file, detected by content: a weight CSV (a `Timecode`, `time`, `seconds` or
    /// `timestamp_ms` column, optionally `BlendShapeCount`, one column per blend shape and the
    /// Live Link Face head/eye rotations in radians: the Live Link Face layout, the bare
    /// 52-column form, MediaPipe's category names) or MediaPipe JSON lines
    /// ({"timestamp_ms": 33, "blendshapes": {"jawOpen": 0.12, ...}}).
    pub weights: PathBuf,
    #[command(flatten)]
    pub rig: RigArgs,
    /// Frame rate of the stream (default: detected from the times); also the timecode rate
    /// when the capture never crosses a second.
    #[arg(long, value_name = "N", value_parser = super::parse_fps)]
    pub fps: Option<f64>,
    /// Output FAP stream (.fap or .json).
    #[arg(short, long, value_name = "OUT")]
    pub output: PathBuf,
    /// Print the report as JSON.
    #[arg(long)]
    pub json: bool,
}

/// Arguments of `fap to-arkit`.
#[derive(Debug, Args)]
pub struct ToArkitArgs {
    /// FAP stream (.fap or .json).
    pub stream: PathBuf,
    #[command(flatten)]
    pub rig: RigArgs,
    /// Output CSV in Live Link Face's layout: `Timecode,BlendShapeCount`, the 52 ARKit shapes
    /// (EyeBlinkLeft, ...), then HeadYaw, HeadPitch, HeadRoll, LeftEyeYaw, LeftEyePitch,
    /// LeftEyeRoll, RightEyeYaw, RightEyePitch, RightEyeRoll in radians (from FAPs 48-50 and
    /// 23-26; eye roll 0). Timecodes `HH:MM:SS:FF.mmm` at the stream's rate from `--start`
    /// (00:00:00:00 by default); reading one shorter than a second back with `from-arkit`
    /// needs `--fps` (the timecode rate shows only once the seconds roll over).
    #[arg(short, long, value_name = "OUT")]
    pub output: PathBuf,
    /// Timecode of the first frame, `HH:MM:SS:FF` (optionally `.fff`) at the stream's rate:
    /// the time of day a capture started, as `fap from-arkit` reports it, so the CSV lines up
    /// with the video and audio recorded beside it.
    #[arg(long, value_name = "TIMECODE")]
    pub start: Option<String>,
    /// Print the report as JSON.
    #[arg(long)]
    pub json: bool,
}

/// The rig, its face with a FAT and, for a rig with feature points, the calibration report;
/// without feature points the face is read with its own FAT and the rig made from it.
fn load(a: &RigArgs) -> Result<(Rig, FaceModel, Option<RigFatReport>)> {
    let Some(fp_path) = &a.fp else {
        if a.map != "arkit" {
            return Err(fbakit::error::Error::Usage(
                "--map is the mapping table of a rig: it needs --fp FP".into(),
            ));
        }
        let face = super::inputs::read_face(&a.face, None)?;
        if face.fat.tables.is_empty() {
            return Err(RigError::FaceWithoutFat {
                file: a.face.clone(),
            }
            .into());
        }
        let rig = arkit_rig_of_face(&face)?;
        return Ok((rig, face, None));
    };
    // Small inputs first, so their errors come before the rig's seconds of reading.
    let fp = fbakit::fdp::read_feature_points(fp_path)?.points;
    let rig = read_rig(&a.face)?;
    let map = super::face_from_rig::load_map(&a.map, &rig)?;
    let (face, report) = face_from_rig(&rig, Some(fp), &map)?;
    super::print_warnings(&rig.warnings);
    Ok((rig, face, Some(report)))
}

fn bridge<'a>(
    rig: &'a Rig,
    face: &'a FaceModel,
    calibration: &Option<RigFatReport>,
) -> Result<ArkitBridge<'a>> {
    match calibration {
        Some(report) => ArkitBridge::new(rig, face, report),
        None => ArkitBridge::for_fat_face(rig, face),
    }
}

fn stream_name(path: &Path) -> String {
    path.file_stem()
        .map_or_else(|| "arkit".into(), |s| s.to_string_lossy().into_owned())
}

#[derive(Serialize)]
struct FromOutput<'a> {
    input: String,
    output: String,
    #[serde(flatten)]
    report: &'a FromArkitReport,
    warnings: &'a [fbakit::error::Diagnostic],
}

/// Runs `fap from-arkit`.
pub fn from_arkit(a: FromArkitArgs) -> Result<u8> {
    OutputFormat::resolve(
        &a.output,
        &[OutputFormat::Fap, OutputFormat::Json],
        "`fap from-arkit` output",
    )?;
    let mut inputs = a.rig.inputs();
    inputs.push(&a.weights);
    refuse_overwriting_input(&a.output, &inputs)?;
    let csv = read_capture_file(&a.weights, a.fps)?;
    super::print_warnings(&csv.warnings);
    let (rig, face, calibration) = load(&a.rig)?;
    let bridge = bridge(&rig, &face, &calibration)?;
    let (stream, report) = bridge.weights_to_faps(&csv, &stream_name(&a.weights))?;
    write_stream_file(&a.output, &stream)?;
    if a.json {
        print_json(&FromOutput {
            input: a.weights.display().to_string(),
            output: a.output.display().to_string(),
            report: &report,
            warnings: &csv.warnings,
        })?;
        return Ok(EXIT_OK);
    }
    let used = report
        .columns
        .iter()
        .filter(|c| c.ignored.is_empty())
        .count();
    println!(
        "wrote {}: {} frames at {} fps ({}), {} FAPs from {used} weight columns",
        a.output.display(),
        report.frames,
        report.fps,
        if report.fps_detected {
            "detected"
        } else {
            "--fps"
        },
        report.faps.len()
    );
    if let Some(t) = report
        .start_timecode
        .as_deref()
        .filter(|t| !t.starts_with("00:00:00:00.000"))
    {
        println!("first frame at timecode {t} (`fap to-arkit --start {t}` writes it back)");
    }
    let ignored: Vec<String> = report
        .columns
        .iter()
        .filter(|c| !c.ignored.is_empty())
        .map(|c| format!("{} ({})", c.column, c.ignored))
        .collect();
    if !ignored.is_empty() {
        println!(
            "ignored columns ({}): {}",
            ignored.len(),
            ignored.join(", ")
        );
    }
    println!(
        "fit residual: {:.2} % of the rig's motion at {} feature points",
        report.relative_residual * 100.0,
        report.feature_points
    );
    Ok(EXIT_OK)
}

#[derive(Serialize)]
struct ToOutput<'a> {
    input: String,
    output: String,
    #[serde(flatten)]
    report: &'a ToArkitReport,
    /// Rotation columns that are not 0 throughout.
    rotations: &'a [String],
}

/// Runs `fap to-arkit`.
pub fn to_arkit(a: ToArkitArgs) -> Result<u8> {
    OutputFormat::resolve(&a.output, &[OutputFormat::Csv], "`fap to-arkit` output")?;
    let mut inputs = a.rig.inputs();
    inputs.push(&a.stream);
    refuse_overwriting_input(&a.output, &inputs)?;
    let (stream, warnings) = fbakit::fap::read_stream_file(&a.stream, &ReadOptions::lenient())?;
    super::print_warnings(&warnings);
    let start = match &a.start {
        None => 0.0,
        Some(t) => {
            let fps = stream.frame_rate;
            timecode_seconds(t, fps).ok_or_else(|| {
                fbakit::error::Error::Usage(format!(
                    "--start `{t}`: expected a timecode HH:MM:SS:FF (optionally .fff) with its frame below the stream's {fps} fps"
                ))
            })?
        }
    };
    let (rig, face, calibration) = load(&a.rig)?;
    let mut bridge = bridge(&rig, &face, &calibration)?;
    let (frames, report) = bridge.faps_to_weights(&stream)?;
    let rotations = stream_rotations(&FapTimeline::new(&stream), frames.len() as u64);
    let text = write_live_link_csv(report.fps, start, &frames, &rotations);
    fbakit::io::write_atomic(&a.output, text.as_bytes())?;
    // The rotation columns that move (the others are written as 0).
    let moving: Vec<String> = ROTATIONS
        .iter()
        .enumerate()
        .filter(|(i, _)| rotations.iter().any(|r| r[*i] != 0.0))
        .map(|(_, r)| r.column.to_string())
        .collect();
    if a.json {
        print_json(&ToOutput {
            input: a.stream.display().to_string(),
            output: a.output.display().to_string(),
            report: &report,
            rotations: &moving,
        })?;
        return Ok(EXIT_OK);
    }
    println!(
        "wrote {}: {} frames at {} fps, {} ARKit shapes solved, {} absent from the face (written as 0)",
        a.output.display(),
        report.frames,
        report.fps,
        report.shapes.len(),
        report.absent.len()
    );
    if !report.absent.is_empty() {
        println!("absent: {}", report.absent.join(", "));
    }
    if !moving.is_empty() {
        println!("rotations (radians): {}", moving.join(", "));
    }
    if !report.unplayable.is_empty() {
        println!(
            "no table on this face (ignored): {}",
            report.unplayable.join(", ")
        );
    }
    println!(
        "fit residual: {:.2} % of the FAT's motion at {} feature points",
        report.relative_residual * 100.0,
        report.feature_points
    );
    Ok(EXIT_OK)
}
