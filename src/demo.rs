//! The end-to-end demo application (`fbakit demo`): clones the bundled `alma` onto a
//! FAT-less `bruno` (cartoon to cartoon), the real ICT-FaceKit head's FAT (`ict`, built from
//! its ARKit shapes) onto a second real head (`samples/faces/ict-identity/`, another identity
//! of ICT's linear model: real to real, measured against that head's true FAT) and alma onto
//! the ICT head (cartoon to real); plays the bundled speech stream on every face and writes
//! every output, with quality figures and timings. It is glue over [`crate::clone`],
//! [`crate::player`] and [`crate::export`].

use std::fmt;
use std::path::{Path, PathBuf};
use std::time::Instant;

use serde::Serialize;

use crate::clone::eval::{compliance, ground_truth_error, self_clone_error};
use crate::clone::face::{clone_face, CloneOptions, Method};
use crate::error::{Diagnostic, Error, Result};
use crate::export::gltf::export_face;
use crate::export::picture::{cloning_grid_with, contact_sheet_rows, strip_fat};
use crate::face::{BundledFace, FaceModel};
use crate::fap::{read_stream_file, ReadOptions};
use crate::fat::TableKey;
use crate::io::AtomicDir;
use crate::player::{PlayOptions, Player};
use crate::rig::fap_map::FapMap;
use crate::rig::fat_build::face_from_rig;

/// The second real head under `samples/`: its neutral mesh (metres) and feature points.
pub const IDENTITY_HEAD: &str = "faces/ict-identity/ict-identity.glb";
/// Its feature points.
pub const IDENTITY_FEATURE_POINTS: &str = "faces/ict-identity/ict-identity-fp.csv";

/// Settings of [`run_demo`].
#[derive(Clone, Debug, PartialEq)]
pub struct DemoOptions {
    /// Cloning method for the written outputs.
    pub method: Method,
    /// Also clone with the other method and report its quality figures (costs a second
    /// clone and self-clone).
    pub compare_methods: bool,
    /// Frames per face on the contact sheet.
    pub sheet_frames: usize,
    /// Side of a contact-sheet cell in pixels.
    pub sheet_cell: u32,
    /// Side of a cloning-grid cell in pixels.
    pub grid_cell: u32,
    /// Where `speech.fap` and `faces/` are; `None` searches (see [`find_samples_dir`]).
    pub samples_dir: Option<PathBuf>,
    /// Also show the real heads: the ICT head's FAT cloned onto the second real head, and
    /// alma's onto the ICT head.
    pub real_head: bool,
}

impl Default for DemoOptions {
    /// The written outputs use the library's default method ([`Method::default`]); the
    /// report measures every method on alma→bruno.
    fn default() -> Self {
        DemoOptions {
            method: Method::default(),
            compare_methods: true,
            sheet_frames: 8,
            sheet_cell: 256,
            grid_cell: 256,
            samples_dir: None,
            real_head: true,
        }
    }
}

impl DemoOptions {
    /// A lighter configuration for tests: one method, four small frames, small grid cells.
    pub fn quick() -> DemoOptions {
        DemoOptions {
            method: Method::Fmc,
            compare_methods: false,
            sheet_frames: 4,
            sheet_cell: 96,
            grid_cell: 128,
            ..DemoOptions::default()
        }
    }
}

/// One file the demo wrote.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct DemoFile {
    /// Path as written.
    pub path: PathBuf,
    /// Size in bytes.
    pub bytes: u64,
    /// What it shows.
    pub what: String,
}

/// Quality figures of cloning alma onto bruno with one method.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct MethodQuality {
    /// The method.
    pub method: Method,
    /// Formula (1) of Fratarcangeli & Schaerf for alma cloned onto itself, percent.
    pub self_clone_error_percent: f64,
    /// Worst FAP compliance error (along the FAP direction, relative) of the cloned bruno.
    pub compliance_worst: f64,
    /// Mean FAP compliance error of the cloned bruno.
    pub compliance_mean: f64,
    /// Displacement error against bruno's true FAT, all meshes, mean over keys, percent.
    pub ground_truth_all_percent: f64,
    /// The same on the skin meshes only, percent.
    pub ground_truth_skin_percent: f64,
    /// Seconds the alma→bruno clone took.
    pub clone_seconds: f64,
}

/// The real head part of the demo: alma's FAT cloned onto the ICT-FaceKit head.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RealHeadReport {
    /// Where the head came from.
    pub origin: String,
    /// Its vertices.
    pub vertices: usize,
    /// Tables of its own FAT (built from its ARKit shapes).
    pub rig_tables: usize,
    /// Tables cloned from alma.
    pub cloned_tables: usize,
    /// Worst FAP compliance error of the cloned FAT (along the FAP direction, relative).
    pub compliance_worst: f64,
    /// Mean FAP compliance error of the cloned FAT.
    pub compliance_mean: f64,
    /// Displacement error of the cloned FAT against the head's own rig FAT (keys both
    /// have), percent: how far alma's procedural motion is from the artist's shapes, not a
    /// cloning error alone.
    pub vs_rig_fat_percent: f64,
    /// Seconds the alma→head clone took.
    pub clone_seconds: f64,
}

/// The real-to-real part of the demo: the ICT head's own FAT (from its ARKit shapes) cloned
/// onto a second real head, another identity of ICT's linear face model, whose true FAT is
/// built the same way from its own shapes (its neutral plus the same expression deltas).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RealToRealReport {
    /// Where the target head came from.
    pub origin: String,
    /// Its vertices.
    pub vertices: usize,
    /// Tables of the source's FAT (the ICT head's, from its shapes).
    pub source_tables: usize,
    /// Tables of the target's true FAT.
    pub truth_tables: usize,
    /// Tables cloned.
    pub cloned_tables: usize,
    /// Worst FAP compliance error of the cloned FAT (along the FAP direction, relative).
    pub compliance_worst: f64,
    /// Mean FAP compliance error of the cloned FAT.
    pub compliance_mean: f64,
    /// Displacement error of the cloned FAT against the true one, all meshes, mean over
    /// keys, percent.
    pub truth_mean_all_percent: f64,
    /// The same on the skin, percent.
    pub truth_mean_skin_percent: f64,
    /// Median over keys, all meshes, percent.
    pub truth_median_all_percent: f64,
    /// The key with the largest error and that error, percent.
    pub truth_worst: Option<(String, f64)>,
    /// For scale: the source's FAT copied onto the target unchanged (same vertices, rates
    /// not adapted), against the truth, mean over keys, percent.
    pub copied_mean_all_percent: f64,
    /// Seconds the clone took.
    pub clone_seconds: f64,
}

/// What [`run_demo`] did.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct DemoReport {
    /// Output directory.
    pub out_dir: PathBuf,
    /// Method of the written outputs.
    pub method: Method,
    /// Where the faces came from (file paths, or "built-in generator").
    pub source_face: String,
    /// Target face origin.
    pub target_face: String,
    /// The FAP stream played.
    pub stream: PathBuf,
    /// Frames played per face, and their rate.
    pub frames: usize,
    /// Frames per second of the stream.
    pub fps: f64,
    /// Tables the cloned bruno has.
    pub cloned_tables: usize,
    /// Files written, in order.
    pub files: Vec<DemoFile>,
    /// Quality per method (the output method first).
    pub quality: Vec<MethodQuality>,
    /// The real head, when [`DemoOptions::real_head`] is set.
    pub real_head: Option<RealHeadReport>,
    /// The real-to-real clone, when [`DemoOptions::real_head`] is set.
    pub real_to_real: Option<RealToRealReport>,
    /// Named steps and their seconds.
    pub timings: Vec<(String, f64)>,
    /// Total wall time in seconds.
    pub total_seconds: f64,
    /// Warnings from cloning, playing and exporting.
    pub warnings: Vec<Diagnostic>,
}

/// The bundled samples folder: `./samples` when it holds `speech.fap` (running from the
/// checkout), else the crate's own `samples/` (its path at build time).
pub fn find_samples_dir() -> Option<PathBuf> {
    let candidates = [
        PathBuf::from("samples"),
        Path::new(env!("CARGO_MANIFEST_DIR")).join("samples"),
    ];
    candidates
        .into_iter()
        .find(|d| d.join("speech.fap").is_file())
}

/// A bundled face: its file under `samples/` when present (the user may have changed it),
/// else the copy embedded in the library.
fn bundled_face(samples: &Path, face: BundledFace) -> Result<(FaceModel, String)> {
    let path = samples.join(face.sample_file());
    if path.is_file() {
        let fp = face.sample_feature_points().map(|f| samples.join(f));
        let opts = crate::face::FaceReadOptions::with_feature_points(fp.as_deref());
        let mut model = crate::face::read_with(&path, &opts)?.0;
        model.name = face.name().to_string();
        return Ok((model, path.display().to_string()));
    }
    Ok((face.read()?.0, "embedded sample".into()))
}

/// `warnings` with `name: ` in front of each message.
fn prefixed<'a>(
    name: &'a str,
    warnings: &'a [Diagnostic],
) -> impl Iterator<Item = Diagnostic> + 'a {
    warnings.iter().map(move |w| Diagnostic {
        message: format!("{name}: {}", w.message),
        ..w.clone()
    })
}

struct Clock {
    steps: Vec<(String, f64)>,
    at: Instant,
}

impl Clock {
    fn new() -> Clock {
        Clock {
            steps: Vec::new(),
            at: Instant::now(),
        }
    }
    fn lap(&mut self, name: &str) {
        let now = Instant::now();
        self.steps
            .push((name.to_string(), (now - self.at).as_secs_f64()));
        self.at = now;
    }
}

/// Records the file `name` written into `dir` (its size from the temporary folder, its path
/// the final one).
fn record(files: &mut Vec<DemoFile>, dir: &AtomicDir, name: &str, what: &str) -> Result<()> {
    let path = dir.path().join(name);
    let bytes = std::fs::metadata(dir.temp_path().join(name))
        .map_err(|e| Error::io(&path, e))?
        .len();
    files.push(DemoFile {
        path,
        bytes,
        what: what.into(),
    });
    Ok(())
}

/// Quality of cloning `source` onto the stripped `target` with `method` (and the clone).
fn measure(
    source: &FaceModel,
    target: &FaceModel,
    truth: &FaceModel,
    method: Method,
    clock: &mut Clock,
) -> Result<(MethodQuality, crate::clone::face::CloneOutcome)> {
    let opts = CloneOptions {
        method,
        ..CloneOptions::default()
    };
    let m = method.name();
    let t = Instant::now();
    let outcome = clone_face(source, target, &opts)?;
    let clone_seconds = t.elapsed().as_secs_f64();
    clock.lap(&format!("clone alma→bruno ({m})"));
    let self_clone = self_clone_error(source, method)?;
    clock.lap(&format!("self-clone alma ({m})"));
    let c = compliance(&outcome.face)?;
    let gt = ground_truth_error(&outcome.face, truth)?;
    clock.lap(&format!("compliance + ground truth ({m})"));
    Ok((
        MethodQuality {
            method,
            self_clone_error_percent: self_clone,
            compliance_worst: c.worst,
            compliance_mean: c.mean,
            ground_truth_all_percent: gt.mean_all,
            ground_truth_skin_percent: gt.mean_skin,
            clone_seconds,
        },
        outcome,
    ))
}

/// The second real head (`samples/`[`IDENTITY_HEAD`]) with its true FAT: the ICT head's rig
/// (`ict-head.glb`) with the identity's neutral in place of ICT's. ICT's model is linear, so
/// an expression's delta applies to every identity unchanged: the identity's own ARKit shapes
/// are its neutral plus the deltas `ict-head.glb` carries, and its FAT is built from them as
/// the ICT head's is, calibrated on its own feature points.
pub fn identity_head(samples: &Path) -> Result<(FaceModel, String)> {
    let rig_path = samples.join(BundledFace::Ict.sample_file());
    let head_path = samples.join(IDENTITY_HEAD);
    let mut rig = crate::rig::gltf_read::read_gltf(&rig_path)?;
    let head = crate::rig::gltf_read::read_gltf(&head_path)?;
    let same_mesh = rig.meshes.len() == 1
        && head.meshes.len() == 1
        && rig.meshes[0].mesh.vertex_count() == head.meshes[0].mesh.vertex_count();
    if !same_mesh {
        return Err(DemoError::IdentityMismatch {
            head: head_path,
            rig: rig_path,
        }
        .into());
    }
    let [ours] = <[crate::rig::RigMesh; 1]>::try_from(head.meshes).map_err(|_| {
        Error::from(DemoError::IdentityMismatch {
            head: head_path.clone(),
            rig: rig_path.clone(),
        })
    })?;
    rig.meshes[0] = ours;
    rig.name = "ict-identity".into();
    // Outputs are new files, not patches of ICT's glb.
    rig.source = None;
    let points = crate::fdp::read_feature_points(samples.join(IDENTITY_FEATURE_POINTS))?.points;
    let (mut face, _) = face_from_rig(&rig, Some(points), &FapMap::arkit())?;
    face.name = "ict-identity".into();
    Ok((face, head_path.display().to_string()))
}

/// One kind of warning and how often it came ([`group_warnings`]).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct WarningKind {
    /// The first warning of the kind, as written.
    pub first: String,
    /// How many distinct warnings are of this kind.
    pub count: usize,
}

/// The kind of a warning: its text with the face name in front (`NAME: `) removed and every
/// word holding a digit or an underscore (numbers, feature points, FAP and table names)
/// replaced, so "FAP close_t_l_eyelid at -1024: …" and "FAP close_t_r_eyelid at 1024: …" are
/// one kind.
fn warning_kind(message: &str) -> String {
    let text = match message.split_once(": ") {
        Some((head, rest)) if !head.contains(' ') => rest,
        _ => message,
    };
    text.split_whitespace()
        .map(|w| {
            if w.chars().any(|c| c.is_ascii_digit() || c == '_') {
                "#"
            } else {
                w
            }
        })
        .collect::<Vec<_>>()
        .join(" ")
}

/// Distinct warnings grouped by kind, in the order each kind first came.
pub fn group_warnings(warnings: &[Diagnostic]) -> Vec<WarningKind> {
    let mut seen = std::collections::HashSet::new();
    let mut kinds: Vec<(String, WarningKind)> = Vec::new();
    for w in warnings {
        let text = w.message.trim().to_string();
        if !seen.insert(text.clone()) {
            continue;
        }
        let kind = warning_kind(&text);
        match kinds.iter_mut().find(|(k, _)| *k == kind) {
            Some((_, g)) => g.count += 1,
            None => kinds.push((
                kind,
                WarningKind {
                    first: text,
                    count: 1,
                },
            )),
        }
    }
    kinds.into_iter().map(|(_, g)| g).collect()
}

/// Why the demo cannot run. Bad input or setup (exit code 2), like every content error.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum DemoError {
    /// The bundled samples are not beside the working directory.
    #[error("cannot find the bundled samples (samples/speech.fap); run from the fbakit checkout")]
    SamplesNotFound,
    /// The second real head is not the ICT head's mesh with other positions. (Its triangles
    /// may split quads along other diagonals: glTF triangulation follows the shape.)
    #[error(
        "{}: expected ICT-FaceKit's head mesh with the vertices of {} (remake it \
         with `cargo run --release --example make_ict_identity_sample`)",
        head.display(),
        rig.display()
    )]
    IdentityMismatch {
        /// The identity head file.
        head: PathBuf,
        /// The ICT rig it must match.
        rig: PathBuf,
    },
}

impl DemoError {
    /// Always true.
    pub fn is_input_error(&self) -> bool {
        true
    }
}

/// The end-to-end demo on the bundled samples: source `alma` (full FAT), target `bruno`
/// stripped to meshes and feature points; clones alma→bruno, plays `speech.fap` on alma and
/// on the cloned bruno, and writes into `out_dir` (all files or none: a temporary sibling
/// renamed into place; an earlier demo's folder is replaced):
///
/// - `bruno-cloned.wrl` — bruno with the cloned FAT;
/// - `alma-speech.glb`, `bruno-speech.glb` — the speech animation on each face;
/// - `contact-sheet.png` — the same frames of both animations, a row per face;
/// - `cloning-grid.png` — alma and bruno cloned both ways, showing joy.
///
/// The report holds the files, quality figures (self-clone error, compliance, error
/// against bruno's true FAT) and timings.
pub fn run_demo(out_dir: &Path, opts: &DemoOptions) -> Result<DemoReport> {
    let start = Instant::now();
    let mut clock = Clock::new();
    let samples = match &opts.samples_dir {
        Some(d) => d.clone(),
        None => find_samples_dir().ok_or(DemoError::SamplesNotFound)?,
    };
    let stream_path = samples.join("speech.fap");
    let (stream, stream_warnings) = read_stream_file(&stream_path, &ReadOptions::lenient())?;
    let mut warnings: Vec<Diagnostic> = stream_warnings;
    let (alma, source_face) = bundled_face(&samples, BundledFace::Alma)?;
    let (truth, target_face) = bundled_face(&samples, BundledFace::Bruno)?;
    let target = strip_fat(&truth);
    clock.lap("load");
    // Every file or none: written into a temporary sibling renamed into place at the end. An
    // earlier demo's folder is replaced; a folder holding other files is refused.
    let dir = crate::io::open_frame_dir(out_dir, |n| {
        [".wrl", ".glb", ".png"].iter().any(|e| n.ends_with(e))
    })?;

    let (main_quality, outcome) = measure(&alma, &target, &truth, opts.method, &mut clock)?;
    let mut quality = vec![main_quality];
    if opts.compare_methods {
        for other in [Method::Fit, Method::Fmc, Method::Rbf] {
            if other != opts.method {
                quality.push(measure(&alma, &target, &truth, other, &mut clock)?.0);
            }
        }
    }
    warnings.extend(prefixed("bruno", &outcome.report.warnings));
    let mut bruno = outcome.face;
    bruno.name = "bruno".into();

    // The real heads: the ICT head with its own FAT (from its ARKit shapes) cloned onto a
    // second real head (real to real, against that head's true FAT), and alma's FAT cloned
    // onto the ICT head (cartoon to real, against the head's own rig FAT).
    let clone_opts = CloneOptions {
        method: opts.method,
        ..CloneOptions::default()
    };
    let method_name = opts.method.name();
    let mut heads: Vec<(String, FaceModel)> = Vec::new();
    let (real_head, real_to_real) = if opts.real_head {
        let (ict, origin) = bundled_face(&samples, BundledFace::Ict)?;
        clock.lap("load ict-head (FAT from its rig)");
        let (truth, identity_origin) = identity_head(&samples)?;
        clock.lap("load ict-identity (true FAT from its shapes)");

        let t = Instant::now();
        let cloned = clone_face(&ict, &strip_fat(&truth), &clone_opts)?;
        let clone_seconds = t.elapsed().as_secs_f64();
        clock.lap(&format!("clone ict-head→ict-identity ({method_name})"));
        warnings.extend(prefixed("ict-identity", &cloned.report.warnings));
        let c = compliance(&cloned.face)?;
        let gt = ground_truth_error(&cloned.face, &truth)?;
        // For scale: the ICT head's FAT on the identity's vertices, unchanged.
        let mut copied = truth.clone();
        copied.fat = ict.fat.clone();
        let (from, to) = (ict.meshes[0].name.clone(), truth.meshes[0].name.clone());
        for t in &mut copied.fat.tables {
            for m in &mut t.meshes {
                if m.mesh == from {
                    m.mesh = to.clone();
                }
            }
        }
        let copied_gt = ground_truth_error(&copied, &truth)?;
        clock.lap("compliance + vs true FAT (ict-identity)");
        let r2r = RealToRealReport {
            origin: identity_origin,
            vertices: truth.vertex_count(),
            source_tables: ict.fat.tables.len(),
            truth_tables: truth.fat.tables.len(),
            cloned_tables: cloned.face.fat.tables.len(),
            compliance_worst: c.worst,
            compliance_mean: c.mean,
            truth_mean_all_percent: gt.mean_all,
            truth_mean_skin_percent: gt.mean_skin,
            truth_median_all_percent: gt.median_all,
            truth_worst: gt.worst.clone(),
            copied_mean_all_percent: copied_gt.mean_all,
            clone_seconds,
        };
        let mut identity_cloned = cloned.face;
        identity_cloned.name = "ict-identity".into();

        // ICT's closed lids cover its eyes; alma's lie behind her protruding eyes, so her
        // blink carried over straight would show ICT's corneas through the closed lids: the
        // default `lid_cover` (auto) covers them.
        let t = Instant::now();
        let cloned = clone_face(&alma, &strip_fat(&ict), &clone_opts)?;
        let clone_seconds = t.elapsed().as_secs_f64();
        clock.lap(&format!("clone alma→ict-head ({method_name})"));
        warnings.extend(prefixed("ict-head-from-alma", &cloned.report.warnings));
        let c = compliance(&cloned.face)?;
        let vs_rig = ground_truth_error(&cloned.face, &ict)?;
        clock.lap("compliance + vs rig FAT (ict-head-from-alma)");
        let report = RealHeadReport {
            origin,
            vertices: ict.vertex_count(),
            rig_tables: ict.fat.tables.len(),
            cloned_tables: cloned.face.fat.tables.len(),
            compliance_worst: c.worst,
            compliance_mean: c.mean,
            vs_rig_fat_percent: vs_rig.mean_all,
            clone_seconds,
        };
        let mut head_cloned = cloned.face;
        head_cloned.name = "ict-head-from-alma".into();
        heads.push(("ict-head".into(), ict));
        heads.push(("ict-identity".into(), identity_cloned));
        heads.push(("ict-head-from-alma".into(), head_cloned));
        (Some(report), Some(r2r))
    } else {
        (None, None)
    };

    let mut files = Vec::new();
    let wrl = "bruno-cloned.wrl";
    dir.write_file(wrl, |p| crate::face::vrml::write_face_file(p, &bruno))?;
    record(
        &mut files,
        &dir,
        wrl,
        "bruno with the FAT cloned from alma (VRML)",
    )?;
    clock.lap("write bruno-cloned.wrl");

    let mut frames = 0;
    let mut fps = stream.frame_rate;
    let mut played: Vec<(&str, &FaceModel)> = vec![("alma", &alma), ("bruno", &bruno)];
    played.extend(heads.iter().map(|(n, f)| (n.as_str(), f)));
    for &(name, face) in &played {
        let player = Player::new(face, &stream, &PlayOptions::default())?;
        frames = player.frame_count();
        fps = player.fps();
        for (key, n) in player.missing_tables() {
            warnings.push(Diagnostic::warning(format!(
                "{name}: no table for {key} ({n} frames)"
            )));
        }
        let anim = player.animation()?;
        let export = export_face(face, Some(&anim))?;
        warnings.extend(
            export
                .warnings
                .iter()
                .map(|w| Diagnostic::warning(format!("{name}: {}", w.message))),
        );
        let file = format!("{name}-speech.glb");
        dir.write_file(&file, |p| export.document.write_glb(p))?;
        let what = match name {
            "alma" => "speech.fap on alma with its own FAT (animated glTF)".to_string(),
            "bruno" => "speech.fap on bruno with alma's FAT cloned onto it".to_string(),
            "ict-head" => {
                "speech.fap on the ICT head with its own FAT (from its ARKit shapes)".to_string()
            }
            "ict-identity" => {
                "speech.fap on the second real head with the ICT head's FAT cloned onto it"
                    .to_string()
            }
            "ict-head-from-alma" => {
                "speech.fap on the ICT head with alma's FAT cloned onto it".to_string()
            }
            _ => format!("speech.fap played on {name} (animated glTF)"),
        };
        record(&mut files, &dir, &file, &what)?;
    }
    clock.lap("play + write glb");

    let sheet = contact_sheet_rows(
        &played,
        &stream,
        PlayOptions::default(),
        opts.sheet_frames,
        (opts.sheet_cell, opts.sheet_cell),
    )?;
    dir.write_file("contact-sheet.png", |p| sheet.write_png(p))?;
    record(
        &mut files,
        &dir,
        "contact-sheet.png",
        if played.len() > 2 {
            "the same speech frames, a row per .glb above"
        } else {
            "the same speech frames on alma (top) and cloned bruno (bottom)"
        },
    )?;
    clock.lap("contact sheet");

    let faces = [("alma", &alma), ("bruno", &truth)];
    let joy = TableKey::Expression(crate::spec::Expression::Joy);
    let grid_image = cloning_grid_with(&faces, joy, 63.0, opts.grid_cell, |i, j| {
        if (i, j) == (0, 1) {
            Ok(bruno.clone())
        } else {
            Ok(clone_face(faces[i].1, &strip_fat(faces[j].1), &clone_opts)?.face)
        }
    })?;
    dir.write_file("cloning-grid.png", |p| grid_image.write_png(p))?;
    record(
        &mut files,
        &dir,
        "cloning-grid.png",
        "joy at 63 cloned both ways (rows: source, columns: target)",
    )?;
    clock.lap("cloning grid (clone bruno→alma + render)");
    dir.commit()?;

    Ok(DemoReport {
        out_dir: out_dir.to_path_buf(),
        method: opts.method,
        source_face,
        target_face,
        stream: stream_path,
        frames,
        fps,
        cloned_tables: bruno.fat.tables.len(),
        files,
        quality,
        real_head,
        real_to_real,
        timings: clock.steps,
        total_seconds: start.elapsed().as_secs_f64(),
        warnings,
    })
}

impl DemoReport {
    /// The time of each step, one line each (the CLI prints it with `--verbose`).
    pub fn timings_text(&self) -> String {
        let mut out = String::from("timings:\n");
        for (name, s) in &self.timings {
            out.push_str(&format!("  {name:<42} {s:>7.2} s\n"));
        }
        out.push_str(&format!(
            "  {:<42} {:>7.2} s\n",
            "total", self.total_seconds
        ));
        out
    }
}

/// The report without the step timings ([`DemoReport::timings_text`]) and warnings
/// ([`DemoReport::warnings`], [`group_warnings`]), which a command line prints apart: what
/// was cloned, the files, then one table of figures.
impl fmt::Display for DemoReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "fbakit demo: FATs cloned between faces ({}), {} ({} frames at {} fps) played on each",
            self.method.name(),
            self.stream.display(),
            self.frames,
            self.fps
        )?;
        writeln!(
            f,
            "  cartoon to cartoon: alma → bruno ({} tables)",
            self.cloned_tables
        )?;
        if let Some(r) = &self.real_to_real {
            writeln!(
                f,
                "  real to real:       the ICT head ({} tables from its ARKit shapes) → a second \
                 real head ({})",
                r.source_tables, r.origin
            )?;
        }
        if let Some(h) = &self.real_head {
            writeln!(
                f,
                "  cartoon to real:    alma → the ICT head ({} vertices)",
                h.vertices
            )?;
        }
        writeln!(f, "wrote into {}:", self.out_dir.display())?;
        for file in &self.files {
            let name = file.path.file_name().map_or_else(
                || file.path.display().to_string(),
                |n| n.to_string_lossy().into(),
            );
            writeln!(f, "  {name:<30} {:>9} bytes  {}", file.bytes, file.what)?;
        }
        writeln!(
            f,
            "figures (compliance: FAP motion error at the feature points, 0 = exact; vs truth: \
             motion error against the target's true FAT, mean over tables):"
        )?;
        writeln!(
            f,
            "  {:<26} {:<6} {:>22} {:>21} {:>8}",
            "clone", "method", "compliance worst/mean", "vs truth all/skin", "clone s"
        )?;
        let row = |f: &mut fmt::Formatter<'_>,
                   what: &str,
                   method: Method,
                   c: (f64, f64),
                   truth: String,
                   secs: f64| {
            writeln!(
                f,
                "  {what:<26} {:<6} {:>13.4} / {:<6.4} {truth:>21} {secs:>8.2}",
                method.name(),
                c.0,
                c.1
            )
        };
        for q in &self.quality {
            row(
                f,
                "alma → bruno",
                q.method,
                (q.compliance_worst, q.compliance_mean),
                format!(
                    "{:.1}% / {:.1}%",
                    q.ground_truth_all_percent, q.ground_truth_skin_percent
                ),
                q.clone_seconds,
            )?;
        }
        if let Some(r) = &self.real_to_real {
            row(
                f,
                "ICT head → second head",
                self.method,
                (r.compliance_worst, r.compliance_mean),
                format!(
                    "{:.1}% / {:.1}%",
                    r.truth_mean_all_percent, r.truth_mean_skin_percent
                ),
                r.clone_seconds,
            )?;
        }
        if let Some(h) = &self.real_head {
            row(
                f,
                "alma → ICT head",
                self.method,
                (h.compliance_worst, h.compliance_mean),
                format!("({:.1}%)", h.vs_rig_fat_percent),
                h.clone_seconds,
            )?;
        }
        let self_clone: Vec<String> = self
            .quality
            .iter()
            .map(|q| format!("{} {:.3}%", q.method.name(), q.self_clone_error_percent))
            .collect();
        writeln!(
            f,
            "  alma cloned onto itself (formula 1 of Fratarcangeli & Schaerf): {}",
            self_clone.join(", ")
        )?;
        if let Some(r) = &self.real_to_real {
            writeln!(
                f,
                "  second head: truth is its own FAT from its shapes (ICT's model is linear); \
                 median {:.1}%{}; the ICT head's FAT copied unchanged would be {:.1}%",
                r.truth_median_all_percent,
                r.truth_worst
                    .as_ref()
                    .map(|(k, e)| format!(", worst {k} {e:.1}%"))
                    .unwrap_or_default(),
                r.copied_mean_all_percent
            )?;
        }
        if self.real_head.is_some() {
            writeln!(
                f,
                "  (alma → ICT head: against the head's own rig FAT, an artist's motion, not a \
                 cloning truth)"
            )?;
        }
        writeln!(f, "total {:.2} s", self.total_seconds)?;
        Ok(())
    }
}
