//! `fbakit fap info|validate|convert|from-arkit|to-arkit`: FAP stream commands.

use std::path::PathBuf;

use clap::{Args, Subcommand};
use fbakit::error::Result;
use fbakit::fap::{
    read_stream_file, summarize, validate_fap_file, write_stream_file, FapSummary, ReadOptions,
};

use super::{print_json, EXIT_FAILURE, EXIT_OK};

/// FAP stream subcommands.
#[derive(Debug, Subcommand)]
pub enum FapCommand {
    /// Summarise a FAP stream: header, timing, FAPs used with ranges, masks, visemes,
    /// expressions and reader warnings.
    #[command(after_help = "Examples:\n  fbakit fap info samples/speech.fap\n  \
                            fbakit fap info joy.fap --json --strict")]
    Info(InfoArgs),
    /// Check a `.fap` file strictly and list every problem as file:line:column.
    /// Exit code 0 when valid, 1 when problems were found, 2 when unreadable.
    #[command(after_help = "Example:\n  fbakit fap validate samples/lowlevel.fap")]
    Validate(ValidateArgs),
    /// Convert between `.fap` and `.json` (chosen by extension); writes atomically.
    #[command(after_help = "Examples:\n  fbakit fap convert joy.fap joy.json\n  \
                            fbakit fap convert joy.json joy-canonical.fap --strict")]
    Convert(ConvertArgs),
    /// Face-capture weights → a FAP stream: a Live Link Face CSV (or the bare 52-column CSV,
    /// MediaPipe CSV or JSON lines; detected by content), through a rig and the FAT built from
    /// it (--fp), or through any face's own FAT: each frame poses the feature points with the
    /// weights and solves a bounded least-squares fit for the FAP values (positive and negative
    /// parts each 0..2× the calibrated range, small Tikhonov term). Head and eye rotations
    /// (radians) become FAPs 48-50 and 23-26 in angle units (1e-5 rad); eye roll has no FAP.
    /// Weights outside 0..1 are clamped with one warning.
    #[command(
        name = "from-arkit",
        after_help = "Examples:\n  fbakit fp from-landmarks ict/generic_neutral_mesh.obj --ibug68 ict/vertex_indices.json -o ict-fp.csv\n  \
                      fbakit fap from-arkit capture.csv --face ict/ --fp ict-fp.csv -o capture.fap\n  \
                      fbakit fap from-arkit mediapipe.jsonl --face bruno -o capture.fap"
    )]
    FromArkit(super::fap_arkit::FromArkitArgs),
    /// A FAP stream → ARKit weights in Live Link Face's CSV layout (Timecode,
    /// BlendShapeCount, the 52 shapes, the 9 head/eye rotations in radians from FAPs 48-50
    /// and 23-26) at the stream's frame rate: the stream is played on the face's FAT (built
    /// from a rig with --fp, or the face's own) and each frame's feature-point motion is
    /// fitted by the ARKit shapes, 0 ≤ w ≤ 1 (bounded least squares, small Tikhonov term).
    /// Shapes the face lacks are written as 0.
    #[command(
        name = "to-arkit",
        after_help = "Examples:\n  fbakit fap to-arkit samples/speech.fap --face ict/ --fp ict-fp.csv -o speech-arkit.csv\n  \
                      fbakit clone alma head.obj --fp-target head-fp.csv -o head.wrl\n  \
                      fbakit fap to-arkit samples/speech.fap --face head.wrl -o speech-arkit.csv\n  \
                      fbakit fap to-arkit take.fap --face head.wrl --start 14:03:22:15 -o take.csv"
    )]
    ToArkit(super::fap_arkit::ToArkitArgs),
    /// Compare two FAP streams: frame rate, transmitted frames and masks, and every FAP's
    /// held value at every frame either stream transmits, within a tolerance in FAP units.
    /// Exit codes: 0 equal, 1 different, 2 unreadable input or bad --tolerance.
    #[command(after_help = "Examples:\n  fbakit fap diff expected.fap out.fap\n  \
                            fbakit fap diff a.fap b.json --tolerance 2 --json")]
    Diff(super::snapshot::FapDiffArgs),
}

/// Arguments of `fap info`.
#[derive(Debug, Args)]
pub struct InfoArgs {
    /// Input `.fap` (or `.json`) file.
    pub file: PathBuf,
    /// Print JSON instead of text.
    #[arg(long)]
    pub json: bool,
    /// Read strictly (deviations are errors instead of warnings).
    #[arg(long)]
    pub strict: bool,
}

/// Arguments of `fap validate`.
#[derive(Debug, Args)]
pub struct ValidateArgs {
    /// Input `.fap` file.
    pub file: PathBuf,
    /// Print the findings as JSON.
    #[arg(long)]
    pub json: bool,
}

/// Arguments of `fap convert`.
#[derive(Debug, Args)]
pub struct ConvertArgs {
    /// Input file (`.fap` or `.json`).
    pub input: PathBuf,
    /// Output file (`.fap` or `.json`).
    pub output: PathBuf,
    /// Read the input strictly.
    #[arg(long)]
    pub strict: bool,
    /// Print the report as JSON.
    #[arg(long)]
    pub json: bool,
}

/// Runs one FAP subcommand and returns its exit code.
pub fn run(cmd: FapCommand) -> Result<u8> {
    match cmd {
        FapCommand::Info(a) => info(a),
        FapCommand::Validate(a) => validate(a),
        FapCommand::Convert(a) => convert(a),
        FapCommand::FromArkit(a) => super::fap_arkit::from_arkit(a),
        FapCommand::ToArkit(a) => super::fap_arkit::to_arkit(a),
        FapCommand::Diff(a) => super::snapshot::fap_diff_cmd(a),
    }
}

fn options(strict: bool) -> ReadOptions {
    if strict {
        ReadOptions::strict()
    } else {
        ReadOptions::lenient()
    }
}

fn info(a: InfoArgs) -> Result<u8> {
    let (stream, warnings) = read_stream_file(&a.file, &options(a.strict))?;
    let s = summarize(&stream, warnings);
    if a.json {
        print_json(&s)?;
    } else {
        super::print_text(&info_text(&s));
    }
    Ok(EXIT_OK)
}

/// The text form of `fap info`.
pub fn info_text(s: &FapSummary) -> String {
    use std::fmt::Write as _;
    let mut o = String::new();
    let _ = writeln!(o, "version:    {}", s.version);
    let _ = writeln!(o, "name:       {}", s.name);
    let _ = writeln!(o, "frame rate: {} fps", s.frame_rate);
    let _ = writeln!(o, "frames:     {}", s.frames);
    let _ = writeln!(o, "duration:   {:.3} s", s.duration_seconds);
    match s.frame_numbers {
        Some((a, b)) => {
            let gaps = if s.skipped_frame_numbers {
                " (with gaps)"
            } else {
                ""
            };
            let _ = writeln!(o, "numbers:    {a}..={b}{gaps}");
        }
        None => {
            let _ = writeln!(o, "numbers:    none");
        }
    }
    let _ = writeln!(o, "masks:      {} distinct", s.distinct_masks);
    let visemes: Vec<String> = s.visemes.iter().map(|v| v.to_string()).collect();
    let _ = writeln!(o, "visemes:    {}", none_if_empty(&visemes.join(" ")));
    let _ = writeln!(
        o,
        "expressions: {}",
        none_if_empty(&s.expressions.join(" "))
    );
    let _ = writeln!(o, "FAPs used:  {}", s.faps.len());
    for f in &s.faps {
        match (f.min, f.max) {
            (Some(lo), Some(hi)) => {
                let _ = writeln!(
                    o,
                    "  {:>2} {:<22} {:>6} frames  min {lo:>8}  max {hi:>8}",
                    f.number, f.name, f.frames
                );
            }
            _ => {
                let _ = writeln!(o, "  {:>2} {:<22} {:>6} frames", f.number, f.name, f.frames);
            }
        }
    }
    let _ = writeln!(o, "warnings:   {}", s.warnings.len());
    for w in &s.warnings {
        let _ = writeln!(o, "  {w}");
    }
    o
}

fn none_if_empty(s: &str) -> &str {
    if s.is_empty() {
        "none"
    } else {
        s
    }
}

fn validate(a: ValidateArgs) -> Result<u8> {
    let findings = validate_fap_file(&a.file)?;
    if a.json {
        print_json(&serde_json::json!({
            "file": a.file,
            "valid": findings.is_empty(),
            "problems": findings,
        }))?;
    } else if findings.is_empty() {
        outln!("{}: valid", a.file.display());
    } else {
        for f in &findings {
            outln!("{f}");
        }
        outln!("{}: {} problem(s)", a.file.display(), findings.len());
    }
    Ok(if findings.is_empty() {
        EXIT_OK
    } else {
        EXIT_FAILURE
    })
}

fn convert(a: ConvertArgs) -> Result<u8> {
    fbakit::format::OutputFormat::resolve(
        &a.output,
        &[
            fbakit::format::OutputFormat::Fap,
            fbakit::format::OutputFormat::Json,
        ],
        "`fap convert` output",
    )?;
    fbakit::format::refuse_overwriting_input(&a.output, &[&a.input])?;
    let (stream, warnings) = read_stream_file(&a.input, &options(a.strict))?;
    write_stream_file(&a.output, &stream)?;
    if a.json {
        print_json(&serde_json::json!({
            "input": a.input.display().to_string(),
            "output": a.output.display().to_string(),
            "frames": stream.frames.len(),
            "warnings": warnings,
        }))?;
    } else {
        super::print_warnings(&warnings);
    }
    Ok(EXIT_OK)
}
