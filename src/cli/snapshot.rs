//! `fbakit face diff`, `fbakit face snapshot` and `fbakit fap diff`: comparing FATs and FAP
//! streams, and printing a face's stable snapshot text.

use std::path::{Path, PathBuf};

use fbakit::error::Result;
use fbakit::face::FaceModel;
use fbakit::snapshot::{
    face_snapshot, fap_diff, try_diff, DiffOptions, FapDiffOptions, SnapshotOptions, Tolerance,
    VertexMatch,
};

use super::{print_json, print_text, print_warnings, EXIT_FAILURE, EXIT_OK};

/// `--match` on the command line.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum MatchArg {
    /// Vertex to vertex (the faces must have the same vertex layout).
    #[default]
    Index,
    /// Each vertex of A against the nearest neutral vertex of B.
    Nearest,
}

fn parse_tolerance(s: &str) -> std::result::Result<Tolerance, String> {
    s.parse::<Tolerance>().map_err(|_| {
        format!("`{s}` is not a positive finite number (absolute, e.g. 0.001, or relative to the face size, e.g. 1e-4x)")
    })
}

fn parse_fap_tolerance(s: &str) -> std::result::Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(v) if v.is_finite() && v > 0.0 => Ok(v),
        _ => Err(format!(
            "`{s}` is not a positive finite number of FAP units"
        )),
    }
}

/// Arguments of `face diff`.
#[derive(Debug, clap::Args)]
pub struct FaceDiffArgs {
    /// Face A (any face format, a rig with --fp-a, or a bundled name).
    pub a: PathBuf,
    /// Face B.
    pub b: PathBuf,
    /// Differences up to this are equal: a distance in the face's units (0.001) or a
    /// fraction of face A's size, its neutral's bounding-box diagonal (1e-4x).
    #[arg(long, value_name = "TOL", default_value = "1e-4x", value_parser = parse_tolerance, allow_negative_numbers = true)]
    pub tolerance: Tolerance,
    /// How vertices are paired: `index` (same layout) or `nearest` (nearest neutral vertex).
    #[arg(long = "match", value_enum, default_value_t)]
    pub vertex_match: MatchArg,
    /// Feature points for A (an OBJ needs them; a rig's shapes become a FAT with them).
    #[arg(long, value_name = "FILE")]
    pub fp_a: Option<PathBuf>,
    /// Feature points for B.
    #[arg(long, value_name = "FILE")]
    pub fp_b: Option<PathBuf>,
    /// Print the report as JSON.
    #[arg(long)]
    pub json: bool,
}

/// Arguments of `face snapshot`.
#[derive(Debug, clap::Args)]
pub struct FaceSnapshotArgs {
    /// The face (any face format, a rig with --fp, or a bundled name).
    pub face: PathBuf,
    /// Numbers are printed on the grid of this tolerance: a distance (0.001) or a fraction of
    /// the face size (1e-4x).
    #[arg(long, value_name = "TOL", default_value = "1e-4x", value_parser = parse_tolerance, allow_negative_numbers = true)]
    pub tolerance: Tolerance,
    /// Feature-point file for the face.
    #[arg(long, value_name = "FILE")]
    pub fp: Option<PathBuf>,
    /// Print JSON instead of YAML.
    #[arg(long)]
    pub json: bool,
}

/// Arguments of `fap diff`.
#[derive(Debug, clap::Args)]
pub struct FapDiffArgs {
    /// Stream A (`.fap` or `.json`).
    pub a: PathBuf,
    /// Stream B.
    pub b: PathBuf,
    /// Held values that differ by no more than this many FAP units are equal.
    #[arg(long, value_name = "UNITS", default_value_t = fbakit::snapshot::DEFAULT_FAP_TOLERANCE, value_parser = parse_fap_tolerance, allow_negative_numbers = true)]
    pub tolerance: f64,
    /// Read strictly (deviations are errors instead of warnings).
    #[arg(long)]
    pub strict: bool,
    /// Print the report as JSON.
    #[arg(long)]
    pub json: bool,
}

/// A face read for comparing, named by its path so reports and errors name the file.
fn read_named(path: &Path, fp: Option<&Path>) -> Result<FaceModel> {
    let mut face = super::inputs::read_face(path, fp)?;
    face.name = path.display().to_string();
    Ok(face)
}

/// Runs `face diff`: exit 0 equal, 1 different, 2 bad input.
pub fn face_diff(a: FaceDiffArgs) -> Result<u8> {
    let fa = read_named(&a.a, a.fp_a.as_deref())?;
    let fb = read_named(&a.b, a.fp_b.as_deref())?;
    let options = DiffOptions {
        tolerance: a.tolerance,
        vertex_match: match a.vertex_match {
            MatchArg::Index => VertexMatch::Index,
            MatchArg::Nearest => VertexMatch::Nearest,
        },
    };
    let report = try_diff(&fa, &fb, &options)?;
    if a.json {
        print_json(&report)?;
    } else {
        print_text(&report.to_string());
    }
    Ok(if report.is_equal() {
        EXIT_OK
    } else {
        EXIT_FAILURE
    })
}

/// Runs `face snapshot`.
pub fn face_snapshot_cmd(a: FaceSnapshotArgs) -> Result<u8> {
    let face = read_named(&a.face, a.fp.as_deref())?;
    let snap = face_snapshot(
        &face,
        &SnapshotOptions {
            tolerance: a.tolerance,
        },
    )?;
    if a.json {
        print_json(&snap)?;
    } else {
        print_text(&snap.to_yaml());
    }
    Ok(EXIT_OK)
}

/// Runs `fap diff`: exit 0 equal, 1 different, 2 bad input.
pub fn fap_diff_cmd(a: FapDiffArgs) -> Result<u8> {
    let (sa, wa) = super::inputs::read_stream(&a.a, a.strict)?;
    let (sb, wb) = super::inputs::read_stream(&a.b, a.strict)?;
    print_warnings(&wa);
    print_warnings(&wb);
    let mut report = fap_diff(
        &sa,
        &sb,
        &FapDiffOptions {
            tolerance: a.tolerance,
        },
    )?;
    report.a = a.a.display().to_string();
    report.b = a.b.display().to_string();
    if a.json {
        print_json(&report)?;
    } else {
        print_text(&report.to_string());
    }
    Ok(if report.is_equal() {
        EXIT_OK
    } else {
        EXIT_FAILURE
    })
}
