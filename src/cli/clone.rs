//! `fbakit clone` (FAT cloning of whole faces) and `fbakit eval` (quality figures).

use std::io::IsTerminal;
use std::path::{Path, PathBuf};

use fbakit::clone::eval::{
    clone_against_truth, compliance, ground_truth_error, self_clone_error_with, ComplianceReport,
    GroundTruthReport,
};
use fbakit::clone::face::{clone_face, CloneOptions, CloneReport, LidCover};
use fbakit::error::{Error, Result, ResultExt};
use fbakit::export::obj_shapes::ObjShapesReport;
use fbakit::face::{FaceFormat, FaceModel};
use fbakit::format::{refuse_overwriting_input, OutputFormat};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use serde::Serialize;

use super::{print_json, print_warnings, MethodArg, EXIT_FAILURE, EXIT_OK};

#[derive(Debug, clap::Args)]
pub struct CloneArgs {
    /// Source face with a FAT: VRML (`.wrl`), or `.obj` with --fp-source.
    pub source: PathBuf,
    /// Target face: VRML (`.wrl`), or `.obj` with --fp-target.
    pub target: PathBuf,
    /// Output: a face file (`.wrl`, `.wrl.gz`), glTF (`.glb`, `.gltf`: the cloned FAT as
    /// morph targets; `.vrm` for a VRM avatar target, written back as one), or an OBJ shape set: `DIR/` (`neutral.obj`, `feature-points.csv` and
    /// one OBJ per morph target) or `OUT.obj` (the neutral, the set in `OUT_shapes/`). An OBJ
    /// target comes back as the user's file with only its `v` lines rewritten.
    #[arg(short, long, value_name = "OUT")]
    pub output: PathBuf,
    /// Surface method.
    #[arg(long, value_enum, default_value_t)]
    pub method: MethodArg,
    /// RBF as in the paper: no FAPU rescaling of the cloned motions.
    #[arg(long)]
    pub rbf_paper: bool,
    /// Do not align the target onto the source (use when both are in the MPEG-4 frame and
    /// the feature points disagree a lot).
    #[arg(long)]
    pub no_align: bool,
    /// Where the source's blink closes its eyes, bring the target's closed lids forward until
    /// they cover its eyeballs from the front (a real head under a cartoon's blink, whose
    /// closed lids lie behind its protruding eyes). `auto` (default): only on an eye whose
    /// closed lids leave it seen differently from how the source's own closed lids leave
    /// the source's — clearly more of it, or a sliver where the source's whole eye stands out —
    /// so a self-clone, or a cartoon whose own blink leaves its eye showing, is kept; `on`
    /// (also `--lid-cover` alone): every eye; `off`: never. `--verbose` says per eye what was
    /// measured and done.
    #[arg(
        long,
        value_enum,
        value_name = "auto|on|off",
        default_value = "auto",
        num_args = 0..=1,
        default_missing_value = "on"
    )]
    pub lid_cover: LidCoverArg,
    /// Feature points of an OBJ source.
    #[arg(long, value_name = "FILE")]
    pub fp_source: Option<PathBuf>,
    /// Feature points of an OBJ target.
    #[arg(long, value_name = "FILE")]
    pub fp_target: Option<PathBuf>,
    /// Print the cloning report as JSON on stdout.
    #[arg(long)]
    pub json: bool,
    /// Exit 1 without writing anything when any FAP failed the guard (a feature point that
    /// does not move, a runaway FAPU rescale), even if it was repaired.
    #[arg(long)]
    pub strict: bool,
    /// Also measure quality: self-clone error of the source, compliance of the output.
    #[arg(long)]
    pub report: bool,
    /// Print the time of each cloning step (always in --json).
    #[arg(short, long)]
    pub verbose: bool,
    /// Morph target names of a .glb/.gltf or OBJ shape-set output: `fat` (the cloned FAT's
    /// keys, `NAME@VALUE` per interval border) or `arkit` (the 52 ARKit blend shapes from their
    /// FAP recipes, as `face export --names arkit`).
    #[arg(long, value_name = "fat|arkit", default_value = "fat")]
    pub names: super::face_export::NamesArg,
    /// A .glb/.gltf output is a new document in metres even when the target was read from
    /// glTF (default: the target's own document, patched).
    #[arg(long)]
    pub new_document: bool,
    #[command(flatten)]
    pub nodes: super::play::NodeArgs,
}

/// `--lid-cover auto|on|off` ([`fbakit::clone::face::LidCover`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum LidCoverArg {
    /// Cover an eye only where the clone's closed lids leave it seen differently
    /// from how the source's leave the source's (more of it, or a sliver).
    #[default]
    Auto,
    /// Cover every eye the source's blink closes.
    On,
    /// Never.
    Off,
}

impl From<LidCoverArg> for LidCover {
    fn from(a: LidCoverArg) -> Self {
        match a {
            LidCoverArg::Auto => LidCover::Auto,
            LidCoverArg::On => LidCover::On,
            LidCoverArg::Off => LidCover::Off,
        }
    }
}

#[derive(Debug, clap::Subcommand)]
pub enum EvalCommand {
    /// FAP compliance of a face's FAT: each translation FAP's feature point at ±512 against
    /// value × FAPU × direction.
    #[command(after_help = "Example:\n  fbakit eval compliance cloned.wrl --json")]
    Compliance(EvalFaceArgs),
    /// Clone a face onto itself and report formula (1) of Fratarcangeli & Schaerf 2005 (%).
    #[command(after_help = "Example:\n  fbakit eval self-clone alma.wrl --method rbf")]
    SelfClone(SelfCloneArgs),
    /// Clone a source onto a face whose true FAT is known and compare with that truth: per
    /// table, Σ‖d_true − d_cloned‖ / Σ‖d_true‖ over every vertex (%), also after the best
    /// non-negative scale of the cloned motion (where things move, apart from how far).
    #[command(
        after_help = "The target is TRUTH without its FAT; TRUTH's own tables are the answer.\n\n\
Examples:\n  fbakit eval ground-truth bruno --source alma\n  \
fbakit eval ground-truth truth.wrl --source src.wrl --method fmc --json\n  \
fbakit eval ground-truth truth.wrl --cloned cloned.wrl"
    )]
    GroundTruth(GroundTruthArgs),
}

#[derive(Debug, clap::Args)]
pub struct GroundTruthArgs {
    /// The face with its true FAT (a face file or a bundled name).
    pub truth: PathBuf,
    /// Source face to clone from (with a FAT).
    #[arg(
        long,
        value_name = "FACE",
        required_unless_present = "cloned",
        conflicts_with = "cloned"
    )]
    pub source: Option<PathBuf>,
    /// Instead of cloning: a face already cloned onto TRUTH's geometry, to measure.
    #[arg(long, value_name = "FACE")]
    pub cloned: Option<PathBuf>,
    /// Surface method(s) to measure (repeat the option); every method when not given.
    #[arg(long, value_enum)]
    pub method: Vec<MethodArg>,
    /// Feature points of an OBJ source.
    #[arg(long, value_name = "FILE")]
    pub fp_source: Option<PathBuf>,
    /// Feature points of an OBJ truth (and of an OBJ --cloned face).
    #[arg(long, value_name = "FILE")]
    pub fp_truth: Option<PathBuf>,
    /// Print JSON.
    #[arg(long)]
    pub json: bool,
}

#[derive(Serialize)]
struct TruthRow {
    method: Option<fbakit::clone::face::Method>,
    seconds: Option<f64>,
    failed_faps: Vec<String>,
    #[serde(flatten)]
    report: GroundTruthReport,
}

fn run_ground_truth(a: GroundTruthArgs) -> Result<u8> {
    let truth = read_face(&a.truth, a.fp_truth.as_deref())?;
    let mut rows = Vec::new();
    if let Some(cloned) = &a.cloned {
        let face = read_face(cloned, a.fp_truth.as_deref())?;
        rows.push(TruthRow {
            method: None,
            seconds: None,
            failed_faps: Vec::new(),
            report: ground_truth_error(&face, &truth)?,
        });
    } else if let Some(source) = &a.source {
        let source = read_face(source, a.fp_source.as_deref())?;
        let methods: Vec<MethodArg> = if a.method.is_empty() {
            <MethodArg as clap::ValueEnum>::value_variants().to_vec()
        } else {
            a.method.clone()
        };
        for m in methods {
            let opts = CloneOptions {
                method: m.into(),
                ..CloneOptions::default()
            };
            let t = std::time::Instant::now();
            let run = clone_against_truth(&source, &truth, &opts)?;
            print_warnings(&run.outcome.report.warnings);
            rows.push(TruthRow {
                method: Some(opts.method),
                seconds: Some(t.elapsed().as_secs_f64()),
                failed_faps: run
                    .outcome
                    .report
                    .failed_faps
                    .iter()
                    .map(|f| f.fap.clone())
                    .collect(),
                report: run.report,
            });
        }
    }
    if a.json {
        print_json(&rows)?;
        return Ok(EXIT_OK);
    }
    for row in &rows {
        let name = row.method.map_or("cloned", |m| m.name());
        let worst = row
            .report
            .worst
            .as_ref()
            .map_or(String::new(), |(k, e)| format!(", worst {k} {e:.1} %"));
        let secs = row
            .seconds
            .map_or(String::new(), |s| format!(" ({s:.2} s)"));
        println!(
            "{name}{secs}: median {:.1} %, mean {:.1} %, median after best scale {:.1} %{worst}",
            row.report.median_all, row.report.mean_all, row.report.median_scaled
        );
        if !row.failed_faps.is_empty() {
            println!("  failed the guard: {}", row.failed_faps.join(", "));
        }
        for k in &row.report.keys {
            println!(
                "  {:<26} {:>7.2} %  scaled {:>7.2} %  skin {:>7.2} %",
                k.key, k.all, k.scaled, k.skin
            );
        }
    }
    Ok(EXIT_OK)
}

#[derive(Debug, clap::Args)]
pub struct EvalFaceArgs {
    /// Face file (`.wrl`, or `.obj` with --fp).
    pub face: PathBuf,
    /// Feature points of an OBJ face.
    #[arg(long, value_name = "FILE")]
    pub fp: Option<PathBuf>,
    /// Print JSON.
    #[arg(long)]
    pub json: bool,
}

#[derive(Debug, clap::Args)]
pub struct SelfCloneArgs {
    #[command(flatten)]
    pub face: EvalFaceArgs,
    /// Surface method.
    #[arg(long, value_enum, default_value_t)]
    pub method: MethodArg,
}

/// Reads a face through the front door; an OBJ face must come with its feature points.
fn read_face(path: &Path, fp: Option<&Path>) -> Result<FaceModel> {
    if fp.is_none() && FaceFormat::of_extension(path) == Some(FaceFormat::Obj) {
        return Err(Error::Usage(format!(
            "{}: an OBJ face needs its feature points (--fp-source / --fp-target / --fp FILE: \
             CSV `fp,x,y,z` or vertex ids, or the XML; `fbakit fp from-landmarks` makes one from \
             iBUG-68 or MediaPipe-468 landmarks)",
            path.display()
        )));
    }
    let face = super::inputs::read_face(path, fp)?;
    // A glTF or VRML face without feature points would fail later as "no skin mesh";
    // say what is missing and how to give it.
    if fp.is_none() && face.feature_points.iter().len() == 0 {
        return Err(Error::Usage(format!(
            "{}: the face has no feature points; give them with --fp-source, --fp-target, --fp-truth or --fp FILE \
             (CSV `fp,x,y,z` or vertex ids, or the XML; `fbakit fp from-landmarks` makes one)",
            path.display()
        )));
    }
    Ok(face)
}

fn bar(steps: u64) -> ProgressBar {
    let pb = ProgressBar::with_draw_target(
        Some(steps),
        if std::io::stderr().is_terminal() {
            ProgressDrawTarget::stderr()
        } else {
            ProgressDrawTarget::hidden()
        },
    );
    if let Ok(style) = ProgressStyle::with_template("{bar:30} {pos}/{len} {msg}") {
        pb.set_style(style);
    }
    pb
}

#[derive(Serialize)]
struct Quality {
    self_clone_error_percent: f64,
    compliance: ComplianceReport,
}

#[derive(Serialize)]
struct Output<'a> {
    output: String,
    report: &'a CloneReport,
    #[serde(skip_serializing_if = "Option::is_none")]
    quality: Option<Quality>,
    /// Warnings from writing the output file.
    write_warnings: Vec<fbakit::error::Diagnostic>,
    #[serde(skip_serializing_if = "Option::is_none")]
    arkit: Option<fbakit::rig::arkit_export::ArkitExportReport>,
    /// What an OBJ shape-set output wrote.
    #[serde(skip_serializing_if = "Option::is_none")]
    shapes: Option<ObjShapesReport>,
}

/// What `clone -o` accepts: face files and OBJ shape sets (`.obj` or a directory).
const CLONE_OUTPUTS: &[OutputFormat] = &[
    OutputFormat::Vrml,
    OutputFormat::VrmlGz,
    OutputFormat::Obj,
    OutputFormat::Glb,
    OutputFormat::Gltf,
    OutputFormat::Directory,
];

pub fn run(args: CloneArgs) -> Result<u8> {
    let format = OutputFormat::resolve(&args.output, CLONE_OUTPUTS, "the cloned face")?;
    let arkit_names = args.names == super::face_export::NamesArg::Arkit;
    let shape_set = matches!(format, OutputFormat::Obj | OutputFormat::Directory);
    if arkit_names && !matches!(format, OutputFormat::Glb | OutputFormat::Gltf) && !shape_set {
        return Err(Error::Usage(format!(
            "{}: --names arkit needs a .glb, .gltf or .obj output or a directory",
            args.output.display()
        )));
    }
    refuse_overwriting_input(&args.output, &[&args.source, &args.target])?;
    let pb = bar(if args.report { 5 } else { 4 });
    pb.set_message("reading source");
    let source = read_face(&args.source, args.fp_source.as_deref())?;
    pb.inc(1);
    pb.set_message("reading target");
    let target = read_face(&args.target, args.fp_target.as_deref())?;
    pb.inc(1);
    pb.set_message("cloning");
    let opts = CloneOptions {
        method: args.method.into(),
        rbf_fapu_rescale: !args.rbf_paper,
        align: !args.no_align,
        lid_cover: args.lid_cover.into(),
        ..CloneOptions::default()
    };
    let outcome = clone_face(&source, &target, &opts).with_context(|| {
        format!(
            "cloning {} onto {}",
            args.source.display(),
            args.target.display()
        )
    })?;
    pb.inc(1);
    if args.strict && !outcome.report.failed_faps.is_empty() {
        pb.finish_and_clear();
        let r = &outcome.report;
        if args.json {
            print_json(&Output {
                output: String::new(),
                report: r,
                quality: None,
                write_warnings: Vec::new(),
                arkit: None,
                shapes: None,
            })?;
        } else {
            print_warnings(&r.warnings);
        }
        eprintln!(
            "error: --strict: {} FAP motion(s) failed the guard; nothing written to {}",
            r.failed_faps.len(),
            args.output.display()
        );
        return Ok(EXIT_FAILURE);
    }
    pb.set_message("writing");
    // glTF holds the cloned FAT as morph targets (static; `fbakit play` animates it), or
    // ARKit-named shapes made from it.
    let export_opts = fbakit::export::ExportOptions {
        names: args.names.into(),
        new_document: args.new_document,
        nodes: args.nodes.rotation_nodes(),
        ..Default::default()
    };
    let mut written = fbakit::export::write(&args.output, &outcome.face, &export_opts)?;
    let arkit = written.arkit.take();
    let shapes = written.shapes.take();
    let write_warnings = std::mem::take(&mut written.warnings);
    pb.inc(1);
    let quality = if args.report {
        pb.set_message("measuring quality");
        let q = Quality {
            self_clone_error_percent: self_clone_error_with(&source, &opts)?,
            compliance: compliance(&outcome.face)?,
        };
        pb.inc(1);
        Some(q)
    } else {
        None
    };
    pb.finish_and_clear();
    let r = &outcome.report;
    if args.json {
        print_json(&Output {
            output: args.output.display().to_string(),
            report: r,
            quality,
            write_warnings,
            arkit,
            shapes,
        })?;
        return Ok(EXIT_OK);
    }
    print_warnings(&r.warnings);
    print_warnings(&write_warnings);
    println!(
        "cloned {} morph targets ({} tables) with {} onto {} skin vertices in {:.3} s -> {}",
        r.motions,
        r.tables,
        r.method.name(),
        r.surface_vertices[1],
        r.timings.total(),
        args.output.display()
    );
    println!(
        "alignment: scale {:.4}, rotation {:.2} deg, rms {:.4}",
        r.alignment.scale,
        r.alignment.angle_degrees(),
        r.alignment_rms
    );
    if args.verbose {
        for (step, s) in &r.timings.steps {
            println!("  {step:<20} {:>8.1} ms", s * 1000.0);
        }
        for eye in &r.lid_cover {
            println!("lid_cover ({}): {eye}", opts.lid_cover.name());
        }
    }
    if let Some(sh) = &shapes {
        println!(
            "{} shapes in {} ({}), neutral {}",
            sh.shapes.len(),
            sh.folder.display(),
            if sh.user_layout {
                "the target's own OBJ, v lines rewritten"
            } else {
                "meshes merged in face coordinates"
            },
            sh.neutral.display()
        );
    }
    if arkit.is_some() {
        println!("{written}");
        super::face_export::print_arkit_details(arkit.as_ref());
    }
    if let Some(q) = quality {
        println!(
            "self-clone error of the source: {:.3e} %",
            q.self_clone_error_percent
        );
        print_compliance(&q.compliance);
    }
    Ok(EXIT_OK)
}

fn print_compliance(c: &ComplianceReport) {
    println!(
        "compliance: {} FAPs, worst {:.3} %, mean {:.3} % (error along the FAP direction)",
        c.faps.len(),
        c.worst * 100.0,
        c.mean * 100.0
    );
}

pub fn run_eval(cmd: EvalCommand) -> Result<u8> {
    match cmd {
        EvalCommand::GroundTruth(a) => return run_ground_truth(a),
        EvalCommand::Compliance(a) => {
            let face = read_face(&a.face, a.fp.as_deref())?;
            let c = compliance(&face)?;
            if a.json {
                print_json(&c)?;
            } else {
                print_compliance(&c);
                for f in &c.faps {
                    println!(
                        "  {:<24} {:<5} along {:>8.3} %  vector {:>8.3} %",
                        f.fap,
                        f.feature_point,
                        f.along_error * 100.0,
                        f.vector_error * 100.0
                    );
                }
                if !c.skipped.is_empty() {
                    println!(
                        "  not measured (no feature point): {}",
                        c.skipped.join(", ")
                    );
                }
            }
        }
        EvalCommand::SelfClone(a) => {
            let face = read_face(&a.face.face, a.face.fp.as_deref())?;
            let opts = CloneOptions {
                method: a.method.into(),
                ..CloneOptions::default()
            };
            let e = self_clone_error_with(&face, &opts)?;
            if a.face.json {
                print_json(
                    &serde_json::json!({ "method": opts.method, "self_clone_error_percent": e }),
                )?;
            } else {
                println!("self-clone error ({}): {e:.3e} %", opts.method.name());
            }
        }
    }
    Ok(EXIT_OK)
}
