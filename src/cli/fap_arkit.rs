//! `fbakit fap from-arkit` and `fbakit fap to-arkit`: ARKit blend-shape weight curves (the CSV
//! iPhone capture apps write) to a FAP stream and back, through a rig and the FAT built from
//! it (`fbakit::rig::arkit_weights`).

use std::path::{Path, PathBuf};

use clap::Args;
use fbakit::error::Result;
use fbakit::face::FaceModel;
use fbakit::fap::{read_stream_file, write_stream_file, ReadOptions};
use fbakit::format::{refuse_overwriting_input, OutputFormat};
use fbakit::rig::arkit_names::{capture_name, ARKIT_SHAPES};
use fbakit::rig::arkit_weights::{ArkitBridge, FromArkitReport, ToArkitReport};
use fbakit::rig::fat_build::{face_from_rig, RigFatReport};
use fbakit::rig::weights_csv::{read_weights_csv, write_weights_csv};
use fbakit::rig::{read_rig, Rig};
use serde::Serialize;

use super::{print_json, EXIT_OK};

/// The rig, mapping and feature points both directions share.
#[derive(Debug, Args)]
pub struct RigArgs {
    /// The rig: .glb, .gltf, a folder of OBJs (neutral + one OBJ per shape) or a neutral .obj.
    #[arg(long, value_name = "RIG")]
    pub face: PathBuf,
    /// Feature points of the rig's neutral (.xml, .fdp, .csv), e.g. from `fbakit fp
    /// from-landmarks`; the FAT is calibrated on them and the fit compares their motion.
    #[arg(long, value_name = "FILE")]
    pub fp: PathBuf,
    /// Mapping table: `arkit` (built in) or a CSV file (fap,positive,negative,reasoning).
    #[arg(long, value_name = "arkit|FILE", default_value = "arkit")]
    pub map: String,
}

/// Arguments of `fap from-arkit`.
#[derive(Debug, Args)]
pub struct FromArkitArgs {
    /// Weight CSV: a `Timecode` (or `time` / `seconds`) column, optionally `BlendShapeCount`,
    /// then one column per blend shape (Live Link Face layout).
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
    /// Output weight CSV: `Timecode`, then the 52 ARKit shapes (EyeBlinkLeft, ...). Its
    /// timecodes start at 00:00:00:00; reading one shorter than a second back with
    /// `from-arkit` needs `--fps` (the timecode rate shows only once the seconds roll over).
    #[arg(short, long, value_name = "OUT")]
    pub output: PathBuf,
    /// Print the report as JSON.
    #[arg(long)]
    pub json: bool,
}

/// The rig, its face with a FAT and the calibration report.
fn load(a: &RigArgs) -> Result<(Rig, FaceModel, RigFatReport)> {
    // Small inputs first, so their errors come before the rig's seconds of reading.
    let fp = fbakit::fdp::read_feature_points(&a.fp)?.points;
    let rig = read_rig(&a.face)?;
    let map = super::face_from_rig::load_map(&a.map, &rig)?;
    let (face, report) = face_from_rig(&rig, Some(fp), &map)?;
    super::print_warnings(&rig.warnings);
    Ok((rig, face, report))
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
    refuse_overwriting_input(&a.output, &[&a.weights, &a.rig.face, &a.rig.fp])?;
    let csv = read_weights_csv(&a.weights, a.fps)?;
    super::print_warnings(&csv.warnings);
    let (rig, face, calibration) = load(&a.rig)?;
    let bridge = ArkitBridge::new(&rig, &face, &calibration)?;
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
}

/// Runs `fap to-arkit`.
pub fn to_arkit(a: ToArkitArgs) -> Result<u8> {
    OutputFormat::resolve(&a.output, &[OutputFormat::Csv], "`fap to-arkit` output")?;
    refuse_overwriting_input(&a.output, &[&a.stream, &a.rig.face, &a.rig.fp])?;
    let (stream, warnings) = read_stream_file(&a.stream, &ReadOptions::lenient())?;
    super::print_warnings(&warnings);
    let (rig, face, calibration) = load(&a.rig)?;
    let mut bridge = ArkitBridge::new(&rig, &face, &calibration)?;
    let (frames, report) = bridge.faps_to_weights(&stream)?;
    let names: Vec<String> = ARKIT_SHAPES.iter().map(|n| capture_name(n)).collect();
    let text = write_weights_csv(&names, report.fps, &frames);
    fbakit::io::write_atomic(&a.output, text.as_bytes())?;
    if a.json {
        print_json(&ToOutput {
            input: a.stream.display().to_string(),
            output: a.output.display().to_string(),
            report: &report,
        })?;
        return Ok(EXIT_OK);
    }
    println!(
        "wrote {}: {} frames at {} fps, {} ARKit shapes solved, {} absent from the rig (written as 0)",
        a.output.display(),
        report.frames,
        report.fps,
        report.shapes.len(),
        report.absent.len()
    );
    if !report.absent.is_empty() {
        println!("absent: {}", report.absent.join(", "));
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
