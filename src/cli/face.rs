//! `fbakit face info|validate|convert|from-morphs|to-morphs`: face model commands.

use std::path::PathBuf;

use fbakit::error::{Result, Severity};
use fbakit::export::write_face;
use fbakit::face::morphs::{face_from_morph_set, write_morph_set, MorphSetOptions};
use fbakit::face::summary::summarize;
use fbakit::face::validate::validate_face;
use fbakit::face::{read_with, FaceReadOptions};
use fbakit::format::{refuse_overwriting_input, OutputFormat};

use super::{print_json, print_warnings, EXIT_FAILURE, EXIT_OK};

/// Face subcommands.
#[derive(Debug, clap::Subcommand)]
pub enum FaceCommand {
    /// Summarise a face: meshes, feature points, FAPU, FAT coverage.
    #[command(after_help = "Examples:\n  fbakit face info face.wrl\n  \
                            fbakit face info head.obj --fp head.fdp --json\n  \
                            fbakit face info head.obj --fp head.fdp --points   \
                            # fp,x,y,z lines for another file of this head")]
    Info(InfoArgs),
    /// Check a face file and list every problem with its scene path and line.
    /// Exit code 0 when valid, 1 when problems were found, 2 when unreadable.
    #[command(after_help = "Example:\n  fbakit face validate face.wrl")]
    Validate(ValidateArgs),
    /// Convert a face between .wrl, .wrl.gz (.wrz) and .obj (OBJ keeps geometry only: all
    /// meshes merged in face coordinates).
    #[command(
        after_help = "Examples:\n  fbakit face convert face.wrl face.wrl.gz\n  \
                            fbakit face convert head.obj head.wrl --fp head.csv"
    )]
    Convert(ConvertArgs),
    /// Subdivide every mesh of a face (Loop or midpoint); its FAT is carried to the new
    /// vertices exactly, so the denser face plays like the original.
    #[command(
        after_help = "Examples:\n  fbakit face subdivide candide -o candide-dense.wrl --rounds 3\n  \
                            fbakit face subdivide head.obj --fp head.csv --scheme midpoint -o head-fine.obj"
    )]
    Subdivide(super::face_subdivide::SubdivideArgs),
    /// Build a face with a FAT from a neutral OBJ and a folder of morph OBJs.
    #[command(
        long_about = "Build a face with a FAT from a neutral OBJ and a folder of morph OBJs, \
                      each with the neutral's topology and named after what it shows: a FAP \
                      (open_jaw.obj), a viseme (viseme_7.obj) or an expression (joy.obj), \
                      optionally with the FAP value it shows after @ (open_jaw@-512.obj).\n\n\
                      The value of a morph is taken from its name, else from the manifest \
                      (JSON: {\"open_jaw\": 1024}), else the default: 63 for visemes and \
                      expressions (full strength), 20000 (0.2 rad) for rotation FAPs, 512 for \
                      the other FAPs. Several morphs of one key at different values make a \
                      multi-interval table. Vertices that moved no more than the tolerance are \
                      left out. Files that are not .obj, and neutral.obj, are ignored.",
        after_help = "Example:\n  fbakit face from-morphs neutral.obj morphs/ --fp neutral.csv -o face.wrl"
    )]
    FromMorphs(FromMorphsArgs),
    /// Write a face's FAT as morph OBJs (plus neutral.obj and feature-points.csv).
    #[command(
        long_about = "Write one OBJ per table of the face's FAT: by default at each of the \
                      table's non-zero interval borders, or at --value. Each OBJ is the whole \
                      face (meshes merged in face coordinates) with the table's vertex motion \
                      and the motion of the transforms it drives. Files are named like \
                      from-morphs reads them (open_jaw.obj at the default value, \
                      open_jaw@1024.obj otherwise); neutral.obj and feature-points.csv are \
                      written too, so `face from-morphs DIR/neutral.obj DIR --fp \
                      DIR/feature-points.csv` reads the set back.",
        after_help = "Example:\n  fbakit face to-morphs face.wrl morphs/"
    )]
    ToMorphs(ToMorphsArgs),
    /// Export a face with its FAT as an asset: glTF morph targets (the face's own glTF
    /// patched), ARKit shapes, an OBJ shape set or VRML.
    #[command(
        long_about = "Export a face with its FAT as the asset a pipeline needs; OUT's extension \
                      picks it. .glb / .gltf: a face read from glTF comes back as its own \
                      document (every node, material, skin, animation and extra kept, in its \
                      own units) with the FAT added as morph targets; any other face becomes a \
                      new document in metres (transforms as nodes, the FAT as morph targets named \
                      in extras.targetNames). .obj or DIR/: an OBJ shape set (the neutral and one \
                      OBJ per morph target in the face's vertex order). .wrl / .wrl.gz: VRML97 \
                      with the FAT. With --names arkit the morph targets are Apple ARKit's 52 \
                      blend shapes (jawOpen, eyeBlinkLeft, ...), each the face posed with its FAP \
                      recipe (specs/arkit-fap-amplitudes.csv, measured on ICT-FaceKit) minus the \
                      neutral; shapes without a recipe get no target and are listed.",
        after_help = "Examples:\n  fbakit face export alma -o alma.glb\n  \
                      fbakit face export avatar.glb -o avatar_fat.glb --names arkit\n  \
                      fbakit face export samples/faces/bruno.wrl.gz -o bruno_shapes/\n  \
                      fbakit face export alma -o alma-arkit.glb --names arkit --units mm\n  \
                      fbakit face export cloned.glb -o out.glb --head-node mixamorig:Head \\\n    \
                      --eye-nodes mixamorig:LeftEye,mixamorig:RightEye --jaw-node Jaw"
    )]
    Export(super::face_export::FaceExportArgs),
    /// Build a face with a FAP-compliant FAT from a blendshape rig (ARKit names by default).
    #[command(
        long_about = "Build a face with a FAT from a blendshape rig (glTF morph targets or a \
                      folder of shape OBJs). A mapping table says which shapes realise which \
                      FAP and with which sign (--map arkit: the built-in ARKit-52 table, \
                      specs/arkit-fap-map.csv; or a CSV with the columns \
                      fap,positive,negative,reasoning). Each FAP is calibrated on the rig: how \
                      far its feature point moves at shape weight 1 along the FAP's direction, \
                      in the face's FAP unit, so the FAT is FAP-compliant (smile/frown become \
                      the two intervals of one FAP). Eyeball FAPs are measured as rotations. \
                      Visemes and expressions come from named shapes (VRM aa, happy, ...) or \
                      from low-level FAPs. Keys not realised and shapes not used are listed.",
        after_help = "Examples:\n  fbakit face from-rig ../shared/data/ict-facekit --fp ict-fp.csv -o ict.wrl\n  \
                      fbakit face from-rig avatar.glb --fp avatar.xml -o avatar-fat.glb --json\n  \
                      fbakit face from-rig head/ --map my-map.csv --fp head.csv -o head.wrl"
    )]
    FromRig(super::face_from_rig::FromRigArgs),
    /// Compare two faces' FATs as animation, table by table, within a tolerance.
    #[command(
        long_about = "Compare two faces' Facial Animation Tables as animation, not as bytes: \
                      each table (FAP, viseme, expression) is evaluated alone at every non-zero \
                      interval border and at its reference value, and every vertex's \
                      displacement (face frame, transform motion included) is compared. \
                      Reports per table the largest and mean difference (face units and FAP \
                      units), how many vertices differ, tables only in one face, transform \
                      differences, and the neutral geometry, feature points and FAP units. \
                      Faces with different vertex layouts need --match nearest. \
                      Exit codes: 0 equal within the tolerance, 1 different, 2 bad input \
                      (unreadable file, face without a FAT, layouts differ without --match).",
        after_help = "Examples:\n  fbakit face diff expected.wrl out.wrl\n  \
                      fbakit face diff a.wrl b.wrl --tolerance 0.01 --json\n  \
                      fbakit face diff face.wrl rebuilt.wrl --tolerance 1e-3x --match nearest"
    )]
    Diff(super::snapshot::FaceDiffArgs),
    /// Print a deterministic, diff-friendly YAML snapshot of a face and its FAT.
    #[command(
        long_about = "Print a deterministic YAML text of what matters about a face: meshes \
                      (names, vertex and polygon counts, bounds, a digest of the neutral), \
                      transforms, feature points, FAP units, and per table its borders, the \
                      values it is evaluated at, moving vertices, largest and mean \
                      displacement and a digest of its displacements, every number on a grid \
                      of 1, 2 or 5 x 10^n not above --tolerance. A change above the tolerance \
                      always changes the text; noise far below it changes it only for values \
                      lying that close to a grid midpoint (see the library docs of \
                      fbakit::snapshot); compare noisy faces with `face diff` instead.",
        after_help = "Examples:\n  fbakit face snapshot out.wrl > out.snap.yaml\n  \
                      fbakit face snapshot alma --tolerance 0.001 --json"
    )]
    Snapshot(super::snapshot::FaceSnapshotArgs),
}

/// Arguments of `face info`.
#[derive(Debug, clap::Args)]
pub struct InfoArgs {
    /// Face file (.wrl, .wrl.gz, .wrz, .obj, .wfm, .glb, .gltf).
    pub file: PathBuf,
    /// Feature-point file (.xml, .fdp, .csv) whose points replace the face's.
    #[arg(long, value_name = "FILE")]
    pub fp: Option<PathBuf>,
    /// Length unit of the face's coordinates (default: guessed from its eye separation or
    /// height).
    #[arg(long, value_name = "mm|cm|m")]
    pub units: Option<fbakit::face::units::LengthUnit>,
    /// Also list each feature point's position as `fp,x,y,z` lines (the file's world frame and
    /// units): a feature-point CSV another file of the same face can take (`--json` always
    /// has them).
    #[arg(long)]
    pub points: bool,
    /// Print JSON instead of text.
    #[arg(long)]
    pub json: bool,
}

/// Arguments of `face validate`.
#[derive(Debug, clap::Args)]
pub struct ValidateArgs {
    /// Face file.
    pub file: PathBuf,
    /// Print JSON instead of text.
    #[arg(long)]
    pub json: bool,
}

/// Arguments of `face convert`.
#[derive(Debug, clap::Args)]
pub struct ConvertArgs {
    /// Input face file.
    pub input: PathBuf,
    /// Output face file; the format follows its extension.
    pub output: PathBuf,
    /// Feature-point file for the input (needed to give an OBJ face feature points).
    #[arg(long, value_name = "FILE")]
    pub fp: Option<PathBuf>,
    /// Print the report as JSON.
    #[arg(long)]
    pub json: bool,
}

/// Arguments of `face from-morphs`.
#[derive(Debug, clap::Args)]
pub struct FromMorphsArgs {
    /// The neutral face (.obj).
    pub neutral: PathBuf,
    /// Folder of morph OBJs.
    pub morph_dir: PathBuf,
    /// Feature points of the neutral (.xml, .fdp, .csv).
    #[arg(long, value_name = "FILE")]
    pub fp: PathBuf,
    /// Output face (.wrl, .wrl.gz).
    #[arg(short, long, value_name = "FILE")]
    pub output: PathBuf,
    /// JSON object of morph file stem → FAP value.
    #[arg(long, value_name = "FILE")]
    pub manifest: Option<PathBuf>,
    /// Vertices that moved no more than this are left out (default: 1e-6 × the neutral's
    /// bounding-box diagonal).
    #[arg(long)]
    pub tolerance: Option<f64>,
    /// Print the report as JSON.
    #[arg(long)]
    pub json: bool,
}

/// Arguments of `face to-morphs`.
#[derive(Debug, clap::Args)]
pub struct ToMorphsArgs {
    /// Face file with a FAT.
    pub face: PathBuf,
    /// Output folder (created if needed).
    pub dir: PathBuf,
    /// Evaluate every table at this value instead of its reference values.
    #[arg(long, value_name = "P", allow_negative_numbers = true)]
    pub value: Option<f64>,
    /// Print the report as JSON.
    #[arg(long)]
    pub json: bool,
}

/// Runs a face subcommand.
pub fn run(cmd: FaceCommand) -> Result<u8> {
    match cmd {
        FaceCommand::Info(a) => info(a),
        FaceCommand::Validate(a) => validate(a),
        FaceCommand::Convert(a) => convert(a),
        FaceCommand::Subdivide(a) => super::face_subdivide::run(a),
        FaceCommand::FromMorphs(a) => from_morphs(a),
        FaceCommand::ToMorphs(a) => to_morphs(a),
        FaceCommand::Export(a) => super::face_export::run_face_export(a),
        FaceCommand::FromRig(a) => super::face_from_rig::run(a),
        FaceCommand::Diff(a) => super::snapshot::face_diff(a),
        FaceCommand::Snapshot(a) => super::snapshot::face_snapshot_cmd(a),
    }
}

fn info(a: InfoArgs) -> Result<u8> {
    let (face, report) = read_with(
        &a.file,
        &FaceReadOptions::with_feature_points(a.fp.as_deref()),
    )?;
    if let Some(fp) = &a.fp {
        print_warnings(&fbakit::face::attach::snap_warnings(
            &face,
            &report.fp_matches,
            fp,
        ));
    }
    let mut summary = summarize(&face, Some(&report));
    if a.units.is_some() {
        summary.units = fbakit::face::units::unit_of(&face, a.units);
    }
    if a.json {
        print_json(&summary)?;
    } else {
        let mut text = summary.to_text();
        if a.points {
            text.push_str(&summary.feature_points.positions_csv());
        }
        super::print_text(&text);
    }
    Ok(EXIT_OK)
}

fn validate(a: ValidateArgs) -> Result<u8> {
    let (face, report) = read_with(&a.file, &FaceReadOptions::default())?;
    let findings = validate_face(&face, &report);
    let errors = findings
        .iter()
        .filter(|d| d.severity == Severity::Error)
        .count();
    if a.json {
        print_json(&serde_json::json!({
            "file": a.file.display().to_string(),
            "valid": errors == 0,
            "problems": findings,
        }))?;
    } else {
        for d in &findings {
            outln!("{d}");
        }
        if errors == 0 {
            outln!("{}: valid", a.file.display());
        } else {
            outln!(
                "{}: {} problem(s), {} warning(s)",
                a.file.display(),
                errors,
                findings.len() - errors
            );
        }
    }
    Ok(if errors == 0 { EXIT_OK } else { EXIT_FAILURE })
}

fn convert(a: ConvertArgs) -> Result<u8> {
    OutputFormat::resolve(&a.output, OutputFormat::FACES, "`face convert` output")?;
    refuse_overwriting_input(&a.output, &[&a.input])?;
    let face = super::inputs::read_face(&a.input, a.fp.as_deref())?;
    let warnings = write_face(&a.output, &face)?;
    if a.json {
        print_json(&serde_json::json!({
            "output": a.output.display().to_string(),
            "meshes": face.meshes.len(),
            "vertices": face.vertex_count(),
            "tables": face.fat.tables.len(),
            "warnings": warnings,
        }))?;
        return Ok(EXIT_OK);
    }
    print_warnings(&warnings);
    eprintln!(
        "wrote {} ({} meshes, {} vertices, {} FAT tables)",
        a.output.display(),
        face.meshes.len(),
        face.vertex_count(),
        face.fat.tables.len()
    );
    Ok(EXIT_OK)
}

fn from_morphs(a: FromMorphsArgs) -> Result<u8> {
    let options = MorphSetOptions {
        feature_points: Some(a.fp),
        manifest: a.manifest,
        tolerance: a.tolerance,
    };
    let (face, report) = face_from_morph_set(&a.neutral, &a.morph_dir, &options)?;
    let warnings = write_face(&a.output, &face)?;
    if a.json {
        print_json(&serde_json::json!({
            "output": a.output.display().to_string(),
            "tables": face.fat.tables.len(),
            "report": report,
            "warnings": warnings,
        }))?;
        return Ok(EXIT_OK);
    }
    print_warnings(&warnings);
    for m in &report.morphs {
        eprintln!(
            "{}: {} at {} ({:?}), {} vertices",
            m.file.display(),
            m.key,
            m.value,
            m.value_source,
            m.moved_vertices
        );
    }
    for f in &report.ignored {
        eprintln!("ignored {}", f.display());
    }
    eprintln!(
        "wrote {} ({} tables from {} morphs, tolerance {})",
        a.output.display(),
        face.fat.tables.len(),
        report.morphs.len(),
        report.tolerance
    );
    Ok(EXIT_OK)
}

fn to_morphs(a: ToMorphsArgs) -> Result<u8> {
    let face = super::inputs::read_face(&a.face, None)?;
    let written = write_morph_set(&face, &a.dir, a.value)?;
    if a.json {
        print_json(&serde_json::json!({
            "directory": a.dir.display().to_string(),
            "morphs": written,
        }))?;
        return Ok(EXIT_OK);
    }
    eprintln!(
        "wrote {} morph OBJs, neutral.obj and feature-points.csv to {}",
        written.len(),
        a.dir.display()
    );
    Ok(EXIT_OK)
}
