//! `fbakit face export FACE -o OUT.glb|.gltf [--gltf]`: a face with its FAT as morph targets
//! (no animation).

use std::path::PathBuf;

use clap::Args;
use fbakit::error::Result;
use fbakit::export::gltf::export_face_with_units;
use fbakit::format::OutputFormat;
use serde::Serialize;

use super::{print_json, EXIT_OK};

/// Arguments of `face export`.
#[derive(Debug, Args)]
pub struct FaceExportArgs {
    /// Face: a VRML face file, or `alma` / `bruno` for the built-in faces.
    pub face: PathBuf,
    /// Output `.glb` or `.gltf` file.
    #[arg(short, long, value_name = "OUT")]
    pub output: PathBuf,
    /// Export as glTF 2.0 (the export format; binary or text by OUT's extension).
    #[arg(long)]
    pub gltf: bool,
    /// Length unit of the face's coordinates (default: guessed from its size); glTF output
    /// is scaled from it to metres.
    #[arg(long, value_name = "mm|cm|m")]
    pub units: Option<fbakit::face::units::LengthUnit>,
    /// Print the report as JSON.
    #[arg(long)]
    pub json: bool,
}

#[derive(Serialize)]
struct Report {
    face: String,
    output: String,
    meshes: usize,
    morph_targets: usize,
    warnings: Vec<String>,
}

/// Runs `face export`.
pub fn run_face_export(a: FaceExportArgs) -> Result<u8> {
    let format = OutputFormat::resolve(
        &a.output,
        &[OutputFormat::Glb, OutputFormat::Gltf],
        "`face export` output",
    )?;
    let face = fbakit::face::read(&a.face)?;
    let export = export_face_with_units(&face, None, a.units)?;
    if format == OutputFormat::Glb {
        export.document.write_glb(&a.output)?;
    } else {
        export.document.write_gltf(&a.output)?;
    }
    let root = &export.document.root;
    let report = Report {
        face: face.name.clone(),
        output: a.output.display().to_string(),
        meshes: root.meshes.len(),
        morph_targets: root
            .meshes
            .iter()
            .flat_map(|m| m.primitives.first())
            .map(|p| p.targets.len())
            .sum(),
        warnings: export.warnings,
    };
    if a.json {
        print_json(&report)?;
    } else {
        println!(
            "wrote {}: {} meshes, {} morph targets",
            report.output, report.meshes, report.morph_targets
        );
        for w in &report.warnings {
            println!("warning: {w}");
        }
    }
    Ok(EXIT_OK)
}
