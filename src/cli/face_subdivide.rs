//! `fbakit face subdivide`: a face made denser, its FAT carried exactly.

use std::path::PathBuf;

use fbakit::error::Result;
use fbakit::export::write_face;
use fbakit::face::subdivide::subdivide_face;
use fbakit::format::{refuse_overwriting_input, OutputFormat};
use fbakit::mesh::subdivide::Scheme;

use super::{print_json, print_warnings, EXIT_OK};

/// Subdivision scheme on the command line.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum SchemeArg {
    /// Loop subdivision: a smooth surface.
    #[default]
    Loop,
    /// Midpoint subdivision: the same surface, more triangles.
    Midpoint,
}

/// Arguments of `face subdivide`.
#[derive(Debug, clap::Args)]
pub struct SubdivideArgs {
    /// Input face (any face format or a bundled name).
    pub input: PathBuf,
    /// Output face file; the format follows its extension.
    #[arg(short, long, value_name = "OUT")]
    pub output: PathBuf,
    /// Rounds of subdivision (each makes about 4× the triangles).
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u8).range(0..=6))]
    pub rounds: u8,
    /// Subdivision scheme.
    #[arg(long, value_enum, default_value_t)]
    pub scheme: SchemeArg,
    /// Feature-point file for the input (an OBJ face needs one).
    #[arg(long, value_name = "FILE")]
    pub fp: Option<PathBuf>,
    /// Print the report as JSON.
    #[arg(long)]
    pub json: bool,
}

/// Runs `face subdivide`.
pub fn run(a: SubdivideArgs) -> Result<u8> {
    OutputFormat::resolve(&a.output, OutputFormat::FACES, "`face subdivide` output")?;
    refuse_overwriting_input(&a.output, &[&a.input])?;
    let face = super::inputs::read_face(&a.input, a.fp.as_deref())?;
    let scheme = match a.scheme {
        SchemeArg::Loop => Scheme::Loop,
        SchemeArg::Midpoint => Scheme::Midpoint,
    };
    let sub = subdivide_face(&face, scheme, a.rounds as usize)?;
    let warnings = write_face(&a.output, &sub)?;
    if a.json {
        print_json(&serde_json::json!({
            "output": a.output.display().to_string(),
            "scheme": scheme,
            "rounds": a.rounds,
            "vertices_before": face.vertex_count(),
            "vertices": sub.vertex_count(),
            "tables": sub.fat.tables.len(),
            "warnings": warnings,
        }))?;
        return Ok(EXIT_OK);
    }
    print_warnings(&warnings);
    eprintln!(
        "wrote {} ({} → {} vertices, {} FAT tables)",
        a.output.display(),
        face.vertex_count(),
        sub.vertex_count(),
        sub.fat.tables.len()
    );
    Ok(EXIT_OK)
}
