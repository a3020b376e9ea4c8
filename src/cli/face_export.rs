//! `fbakit face export FACE -o OUT`: a face with its FAT as an asset, through
//! [`fbakit::export::write`] (no animation).

use std::path::PathBuf;

use clap::Args;
use fbakit::error::Result;
use fbakit::export::{ExportOptions, ExportReport, ShapeNames};
use serde::Serialize;

use super::{print_json, EXIT_OK};

/// Arguments of `face export`.
#[derive(Debug, Args)]
pub struct FaceExportArgs {
    /// Face: any face file or rig, or a bundled face (`alma`, `bruno`, `ict`).
    pub face: PathBuf,
    /// Output: `.glb`, `.gltf` (`.vrm` for a VRM avatar), `.obj` or a directory (`DIR/`: OBJ
    /// shape set), `.wrl`, `.wrl.gz`.
    #[arg(short, long, value_name = "OUT")]
    pub output: PathBuf,
    /// Length unit of the face's coordinates (default: guessed from its size); a new glTF
    /// document is scaled from it to metres. A face's own glTF is never rescaled.
    #[arg(long, value_name = "mm|cm|m")]
    pub units: Option<fbakit::face::units::LengthUnit>,
    /// Morph target names: `fat` (one target per FAT table interval, named after its key) or
    /// `arkit` (the 52 ARKit shapes, each the face posed with its FAP recipe from
    /// specs/arkit-fap-amplitudes.csv; shapes without a recipe get no target).
    #[arg(long, value_name = "fat|arkit", default_value = "fat")]
    pub names: NamesArg,
    /// Write a new glTF document even when the face was read from one.
    #[arg(long)]
    pub new_document: bool,
    /// Print the report as JSON.
    #[arg(long)]
    pub json: bool,
    #[command(flatten)]
    pub nodes: super::play::NodeArgs,
}

/// Morph target naming of `face export` and `clone`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum NamesArg {
    /// The FAT's keys (`open_jaw`, `viseme_7`, ...).
    Fat,
    /// ARKit's 52 blend shapes (`jawOpen`, `eyeBlinkLeft`, ...).
    Arkit,
}

impl From<NamesArg> for ShapeNames {
    fn from(n: NamesArg) -> ShapeNames {
        match n {
            NamesArg::Fat => ShapeNames::Fat,
            NamesArg::Arkit => ShapeNames::Arkit,
        }
    }
}

#[derive(Serialize)]
struct Report<'a> {
    face: &'a str,
    #[serde(flatten)]
    export: &'a ExportReport,
}

/// Runs `face export`.
pub fn run_face_export(a: FaceExportArgs) -> Result<u8> {
    // Check the output's kind before reading the face: a wrong extension is a usage error.
    fbakit::format::OutputFormat::resolve(
        &a.output,
        fbakit::export::EXPORTS,
        "`face export` output",
    )?;
    fbakit::format::refuse_overwriting_input(&a.output, &[&a.face])?;
    let face = super::inputs::read_face(&a.face, None)?;
    let opts = ExportOptions {
        names: a.names.into(),
        units: a.units,
        new_document: a.new_document,
        nodes: a.nodes.rotation_nodes(),
    };
    let report = fbakit::export::write(&a.output, &face, &opts)?;
    if a.json {
        print_json(&Report {
            face: &face.name,
            export: &report,
        })?;
        return Ok(EXIT_OK);
    }
    super::print_warnings(&report.warnings);
    println!("{report}");
    print_arkit_details(report.arkit.as_ref());
    Ok(EXIT_OK)
}

/// The shapes an ARKit-named export left out (shared with `clone --names arkit`).
pub fn print_arkit_details(arkit: Option<&fbakit::rig::arkit_export::ArkitExportReport>) {
    let Some(arkit) = arkit else { return };
    if !arkit.unmapped.is_empty() {
        println!(
            "no target ({}): {}",
            arkit.unmapped.len(),
            arkit
                .unmapped
                .iter()
                .map(|u| format!("{} ({})", u.shape, u.reason))
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
    if !arkit.missing_tables.is_empty() {
        println!(
            "recipe parts without a table on this face: {}",
            arkit.missing_tables.join(", ")
        );
    }
}
