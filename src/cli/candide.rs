//! `fbakit candide WFM --fp CSV [--shape ...] -o FACE` and `fbakit sample NAME -o FACE`.

use std::path::PathBuf;

use fbakit::candide::{parse_shape_spec, read_wfm_file};
use fbakit::error::Result;
use fbakit::face::candide::candide_face_with_notes;
use fbakit::face::write as write_face;

use serde::Serialize;

use super::{print_json, EXIT_OK};

/// Arguments of `candide`.
#[derive(Debug, clap::Args)]
pub struct CandideArgs {
    /// CANDIDE-3 model (.wfm).
    pub wfm: PathBuf,
    /// Feature-point table binding MPEG-4 points to CANDIDE vertices (.csv).
    #[arg(long, value_name = "CSV")]
    pub fp: PathBuf,
    /// Shape units to apply, `name=value,...` (names may contain commas: `Eyes, width=0.2`).
    #[arg(long, value_name = "SPEC", allow_hyphen_values = true)]
    pub shape: Option<String>,
    /// Output face (.wrl, .wrl.gz, .obj).
    #[arg(short, long, value_name = "FILE")]
    pub output: PathBuf,
    /// Print the report as JSON.
    #[arg(long)]
    pub json: bool,
}

/// Writes a CANDIDE face.
pub fn run(a: CandideArgs) -> Result<u8> {
    let model = read_wfm_file(&a.wfm)?;
    let fp = fbakit::fdp::read_feature_points(&a.fp)?.points;
    let shape = match &a.shape {
        Some(s) => parse_shape_spec(s)?,
        None => Vec::new(),
    };
    let c = candide_face_with_notes(&model, &fp, &shape)?;
    write_face(&a.output, &c.face)?;
    let report = Written::of(&a.output, &c.face, c.notes.clone());
    if a.json {
        print_json(&report)?;
    } else {
        for n in &c.notes {
            eprintln!("note: {n}");
        }
        eprintln!("{report}");
    }
    Ok(EXIT_OK)
}

/// Arguments of `sample`.
#[derive(Debug, clap::Args)]
pub struct SampleArgs {
    /// Which procedural face.
    #[arg(value_parser = ["alma", "bruno"])]
    pub name: String,
    /// Output face (.wrl, .wrl.gz, .obj).
    #[arg(short, long, value_name = "FILE")]
    pub output: PathBuf,
    /// Print the report as JSON.
    #[arg(long)]
    pub json: bool,
}

/// Writes a bundled procedural face.
pub fn sample(a: SampleArgs) -> Result<u8> {
    let synth = match a.name.as_str() {
        "alma" => fbakit::synth::alma(),
        _ => fbakit::synth::bruno(),
    };
    let face = synth.to_face_model();
    write_face(&a.output, &face)?;
    let report = Written::of(&a.output, &face, Vec::new());
    if a.json {
        print_json(&report)?;
    } else {
        eprintln!("{report}");
    }
    Ok(EXIT_OK)
}

/// What `candide` and `sample` wrote.
#[derive(Serialize)]
struct Written {
    output: String,
    meshes: usize,
    vertices: usize,
    tables: usize,
    notes: Vec<String>,
}

impl Written {
    fn of(path: &std::path::Path, face: &fbakit::face::FaceModel, notes: Vec<String>) -> Self {
        Written {
            output: path.display().to_string(),
            meshes: face.meshes.len(),
            vertices: face.vertex_count(),
            tables: face.fat.tables.len(),
            notes,
        }
    }
}

impl std::fmt::Display for Written {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "wrote {} ({} vertices, {} FAT tables)",
            self.output, self.vertices, self.tables
        )
    }
}
