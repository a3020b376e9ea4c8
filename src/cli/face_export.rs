//! `fbakit face export FACE -o OUT.glb|.gltf`: a face with its FAT as morph targets
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
    /// Face: any face file or rig, or a bundled face (`alma`, `bruno`, `ict`).
    pub face: PathBuf,
    /// Output `.glb` or `.gltf` file.
    #[arg(short, long, value_name = "OUT")]
    pub output: PathBuf,
    /// Length unit of the face's coordinates (default: guessed from its size); glTF output
    /// is scaled from it to metres.
    #[arg(long, value_name = "mm|cm|m")]
    pub units: Option<fbakit::face::units::LengthUnit>,
    /// Morph target names: `fat` (one target per FAT table interval, named after its key) or
    /// `arkit` (the 52 ARKit shapes, each the face posed with its FAP recipe from
    /// specs/arkit-fap-amplitudes.csv; shapes without a recipe get no target).
    #[arg(long, value_name = "fat|arkit", default_value = "fat")]
    pub names: NamesArg,
    /// Print the report as JSON.
    #[arg(long)]
    pub json: bool,
}

/// Morph target naming of `face export`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum NamesArg {
    /// The FAT's keys (`open_jaw`, `viseme_7`, ...).
    Fat,
    /// ARKit's 52 blend shapes (`jawOpen`, `eyeBlinkLeft`, ...).
    Arkit,
}

#[derive(Serialize)]
struct Report {
    face: String,
    output: String,
    meshes: usize,
    morph_targets: usize,
    warnings: Vec<fbakit::error::Diagnostic>,
    #[serde(skip_serializing_if = "Option::is_none")]
    arkit: Option<fbakit::rig::arkit_export::ArkitExportReport>,
}

/// Runs `face export`.
pub fn run_face_export(a: FaceExportArgs) -> Result<u8> {
    let format = OutputFormat::resolve(
        &a.output,
        &[OutputFormat::Glb, OutputFormat::Gltf],
        "`face export` output",
    )?;
    fbakit::format::refuse_overwriting_input(&a.output, &[&a.face])?;
    let face = fbakit::face::read(&a.face)?;
    if a.names == NamesArg::Arkit {
        return export_arkit(&a, &face);
    }
    let mut warnings = Vec::new();
    if let Some(export) =
        fbakit::export::gltf_patch::patch_if_fits(&face, None, &Default::default(), &mut warnings)?
    {
        return export_patch(&a, &face, export);
    }
    let mut export = export_face_with_units(&face, None, a.units)?;
    warnings.append(&mut export.warnings);
    export.warnings = warnings;
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
        arkit: None,
    };
    if a.json {
        print_json(&report)?;
    } else {
        println!(
            "wrote {}: {} meshes, {} morph targets",
            report.output, report.meshes, report.morph_targets
        );
        super::print_warnings(&report.warnings);
    }
    Ok(EXIT_OK)
}

/// `face export` of a face read from glTF: its own document, patched with the FAT.
fn export_patch(
    a: &FaceExportArgs,
    face: &fbakit::face::FaceModel,
    export: fbakit::export::gltf_patch::GltfPatchExport,
) -> Result<u8> {
    export.document.write(&a.output)?;
    let report = Report {
        face: face.name.clone(),
        output: a.output.display().to_string(),
        meshes: export.document.json["meshes"]
            .as_array()
            .map_or(0, Vec::len),
        morph_targets: export.morph_targets,
        warnings: export.warnings,
        arkit: None,
    };
    if a.json {
        print_json(&report)?;
    } else {
        println!(
            "wrote {}: {} meshes, {} morph targets added",
            report.output, report.meshes, report.morph_targets
        );
        super::print_warnings(&report.warnings);
    }
    Ok(EXIT_OK)
}

/// `face export --names arkit`: the face as ARKit-named blend shapes, in metres.
fn export_arkit(a: &FaceExportArgs, face: &fbakit::face::FaceModel) -> Result<u8> {
    let (arkit, warnings) = fbakit::rig::arkit_export::write_arkit_gltf(face, &a.output, a.units)?;
    if !a.json {
        super::print_warnings(&warnings);
    }
    let report = Report {
        face: face.name.clone(),
        output: a.output.display().to_string(),
        meshes: face.meshes.len(),
        morph_targets: arkit.targets.len(),
        warnings,
        arkit: Some(arkit),
    };
    if a.json {
        print_json(&report)?;
        return Ok(EXIT_OK);
    }
    print_arkit_report(&report.output, report.meshes, report.arkit.as_ref());
    Ok(EXIT_OK)
}

/// The text report of an ARKit-named export (shared with `clone --names arkit`).
pub fn print_arkit_report(
    output: &str,
    meshes: usize,
    arkit: Option<&fbakit::rig::arkit_export::ArkitExportReport>,
) {
    let Some(arkit) = arkit else { return };
    println!(
        "wrote {output}: {meshes} meshes, {} ARKit morph targets",
        arkit.targets.len()
    );
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
    if !arkit.missing_tables.is_empty() {
        println!(
            "recipe parts without a table on this face: {}",
            arkit.missing_tables.join(", ")
        );
    }
}
