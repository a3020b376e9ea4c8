//! `fbakit fp ...`: feature-point files from other descriptions of a face.

use std::path::{Path, PathBuf};

use fbakit::error::Result;
use fbakit::fdp::landmarks::{
    feature_points_from_landmarks, read_landmark_ids, AbsentPoint, LandmarkIds, LandmarkScheme,
    PlacedPoint,
};
use fbakit::fdp::{Fapu, FapuDistances, FdpError};
use serde::Serialize;

use super::{print_json, EXIT_OK};

#[derive(Debug, clap::Subcommand)]
pub enum FpCommand {
    /// Place MPEG-4 feature points on a mesh from its landmarks (iBUG-68 or MediaPipe-468),
    /// deriving the points the landmarks do not give from the mesh.
    #[command(
        long_about = "Place MPEG-4 feature points on a mesh from its landmarks. The preset \
                      table (specs/landmarks-ibug68.csv or specs/landmarks-mediapipe468.csv) \
                      maps landmarks to feature points; the points no landmark gives are \
                      derived from the mesh: eyelid centres on the visible lid margin, pupils \
                      at the front of the eyeball (or the lid contour's centre), chin boss, \
                      cheeks, cheek bones, nose wings, nose bump, top and back of the skull \
                      when the mesh has one. Every point is bound to a mesh vertex and printed \
                      with its provenance. OUT is .csv (fp,vertices,combine,description with \
                      the provenance), fbakit .xml or Xface .fdp (points on the mesh file's \
                      name, FAPU in its head). Exit codes: 0 ok, 2 bad input (ids out \
                      of range or repeated, wrong count, unreadable mesh, unknown output \
                      extension).",
        after_help = "Examples:\n  fbakit fp from-landmarks generic_neutral_mesh.obj --ibug68 vertex_indices.json -o ict-fp.csv\n  \
                      fbakit fp from-landmarks head.obj --ibug68 landmarks.csv -o head.xml --json\n  \
                      fbakit fp from-landmarks head.obj --ibug68 landmarks.json -o head.fdp\n  \
                      fbakit fp from-landmarks canonical_face_model.obj --mediapipe468 -o mp-fp.csv"
    )]
    FromLandmarks(FromLandmarksArgs),
}

#[derive(Debug, clap::Args)]
#[command(group(clap::ArgGroup::new("scheme").required(true).args(["ibug68", "mediapipe468"])))]
pub struct FromLandmarksArgs {
    /// The mesh (.obj, .glb/.gltf, or a .wrl / .wrl.gz face) the landmark ids index (with
    /// --mesh when the file has several meshes).
    pub mesh: PathBuf,
    /// The 68 iBUG landmark vertex ids: ICT-FaceKit's vertex_indices.json (key
    /// idx_to_landmark_verts), a JSON array, or a CSV / text list of vertex ids.
    #[arg(long, value_name = "IDS")]
    pub ibug68: Option<PathBuf>,
    /// MediaPipe-468 landmarks: the vertex ids like --ibug68, or none when the mesh's own
    /// vertex order is the landmark order (MediaPipe's canonical face).
    #[arg(long, value_name = "IDS", num_args = 0..=1)]
    pub mediapipe468: Option<Option<PathBuf>>,
    /// The mesh the landmark ids index, in a file of several meshes: its name as `fbakit face
    /// info` lists it, `Name/1` for primitive 1 of glTF mesh or node `Name`, `#3/1` by glTF
    /// mesh index. The output's bindings name it, so `clone --fp-target` reads them back on
    /// the same file.
    #[arg(long = "mesh", value_name = "NAME")]
    pub mesh_name: Option<String>,
    /// Output feature-point file: .csv or .xml.
    #[arg(short, long, value_name = "OUT")]
    pub output: PathBuf,
    /// Print the report as JSON on stdout.
    #[arg(long)]
    pub json: bool,
}

#[derive(Serialize)]
struct Report<'a> {
    mesh: String,
    scheme: LandmarkScheme,
    landmarks: String,
    output: String,
    points: &'a [PlacedPoint],
    absent: &'a [AbsentPoint],
    notes: &'a [String],
    fapu: Option<FapuDistances>,
    warnings: Vec<fbakit::error::Diagnostic>,
}

pub fn run(cmd: FpCommand) -> Result<u8> {
    match cmd {
        FpCommand::FromLandmarks(args) => from_landmarks(args),
    }
}

#[derive(Clone, Copy)]
enum OutFormat {
    Csv,
    Xml,
    Fdp,
}

fn out_format(path: &Path) -> Result<OutFormat> {
    use fbakit::format::OutputFormat;
    match OutputFormat::resolve(
        path,
        &[OutputFormat::Csv, OutputFormat::Xml, OutputFormat::Fdp],
        "`fp from-landmarks` output",
    )? {
        OutputFormat::Xml => Ok(OutFormat::Xml),
        OutputFormat::Fdp => Ok(OutFormat::Fdp),
        _ => Ok(OutFormat::Csv),
    }
}

fn from_landmarks(args: FromLandmarksArgs) -> Result<u8> {
    // Refuse a bad output before reading anything.
    let format = out_format(&args.output)?;
    let (scheme, ids_path) = match (&args.ibug68, &args.mediapipe468) {
        (Some(p), _) => (LandmarkScheme::Ibug68, Some(p.clone())),
        (None, Some(p)) => (LandmarkScheme::MediaPipe468, p.clone()),
        (None, None) => unreachable!("clap requires one scheme"),
    };
    let face = fbakit::face::read(&args.mesh)?;
    // The mesh the landmark ids index: the only one, or the one --mesh names (its name then
    // goes into the output, so `clone` binds the points to it on the same file).
    let (only, named) = match (&args.mesh_name, face.meshes.as_slice()) {
        (Some(spec), meshes) => {
            let Some(i) = face.resolve_mesh_spec(spec) else {
                return Err(FdpError::UnknownLandmarkMesh {
                    file: args.mesh.clone(),
                    mesh: spec.clone(),
                    meshes: meshes
                        .iter()
                        .map(|m| m.name.as_str())
                        .collect::<Vec<_>>()
                        .join(", "),
                }
                .into());
            };
            (&meshes[i], meshes.len() > 1)
        }
        (None, [only]) => (only, false),
        (None, meshes) => {
            return Err(FdpError::LandmarksNeedOneMesh {
                file: args.mesh.clone(),
                meshes: meshes.len(),
            }
            .into())
        }
    };
    let mesh = &only.mesh;
    let (ids, ids_name) = match &ids_path {
        Some(p) => (read_landmark_ids(p)?, p.display().to_string()),
        None => (
            LandmarkIds::identity(scheme.landmark_count()),
            format!("{} vertex order", args.mesh.display()),
        ),
    };
    if ids_path.is_none() && mesh.positions.len() < scheme.landmark_count() {
        return Err(FdpError::TooFewLandmarkVertices {
            file: args.mesh.clone(),
            vertices: mesh.positions.len(),
            needed: scheme.landmark_count(),
        }
        .into());
    }
    ids.check(scheme.landmark_count(), mesh.positions.len(), &ids_name)?;
    let found = feature_points_from_landmarks(mesh, scheme, &ids.ids)
        .map_err(|e| fbakit::face::FaceError::in_file(&args.mesh, e))?;
    let mut set = found.feature_point_set();
    let mut table = found.table();
    if named {
        for r in &mut table.rows {
            r.mesh = Some(only.name.clone());
        }
        let ids: Vec<_> = set.iter().map(|p| p.id).collect();
        for id in ids {
            if let Some(b) = set.get_mut(id).and_then(|p| p.binding.as_mut()) {
                b.mesh = Some(only.name.clone());
            }
        }
    }
    let mut warnings = Vec::new();
    let fapu = match Fapu::from_feature_points(&set) {
        Ok(f) => Some(f.distances),
        Err(e) => {
            warnings.push(fbakit::error::Diagnostic::warning(format!(
                "FAP units: {e}"
            )));
            None
        }
    };
    match format {
        OutFormat::Csv => fbakit::fdp::csv::write_csv_file(&args.output, &table)?,
        // Xface names the mesh a point is on; the mesh file's name is what `--fp` matches.
        OutFormat::Fdp => fbakit::fdp::xface::write_xface_file(
            &args.output,
            &fbakit::fdp::xface::XfaceFdp::from_points(
                &set,
                &args
                    .mesh
                    .file_name()
                    .map_or_else(|| "mesh".into(), |n| n.to_string_lossy()),
                fapu,
            ),
        )?,
        OutFormat::Xml => fbakit::fdp::xml::write_xml_file(
            &args.output,
            &fbakit::fdp::xml::FeaturePointDocument {
                units: None,
                fapu: None,
                points: set,
            },
        )?,
    }
    let report = Report {
        mesh: args.mesh.display().to_string(),
        scheme,
        landmarks: ids_name,
        output: args.output.display().to_string(),
        points: &found.points,
        absent: &found.absent,
        notes: &found.notes,
        fapu,
        warnings,
    };
    super::print_warnings(&report.warnings);
    if args.json {
        print_json(&report)?;
    } else {
        super::print_text(&text(&report));
    }
    Ok(EXIT_OK)
}

fn text(r: &Report<'_>) -> String {
    use std::fmt::Write as _;
    let mut s = format!(
        "{} feature points on {} from {} landmarks ({}) -> {}\n",
        r.points.len(),
        r.mesh,
        r.scheme,
        r.landmarks,
        r.output
    );
    let _ = writeln!(s, "{:<6} {:<14} provenance", "fp", "vertex");
    for p in r.points {
        let v: Vec<String> = p.vertices.iter().map(u32::to_string).collect();
        let _ = writeln!(
            s,
            "{:<6} {:<14} {}",
            p.id.to_string(),
            v.join(";"),
            p.provenance
        );
    }
    for a in r.absent {
        let _ = writeln!(
            s,
            "absent {:<6} ({}): {}",
            a.id.to_string(),
            a.rule,
            a.reason
        );
    }
    for n in r.notes {
        let _ = writeln!(s, "note: {n}");
    }
    if let Some(f) = r.fapu {
        let _ = writeln!(
            s,
            "FAPU distances: IRISD0 {:.4}  ES0 {:.4}  ENS0 {:.4}  MNS0 {:.4}  MW0 {:.4}",
            f.irisd0, f.es0, f.ens0, f.mns0, f.mw0
        );
    }
    s
}
