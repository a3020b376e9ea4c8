//! Pictures and the end-to-end demo: rendered FAP playback frames, contact sheets, the
//! cloning grid (seed 000, Figure 11) and [`run_demo`], which clones the bundled `alma` onto
//! a FAT-less `bruno`, plays the bundled speech stream on both and writes every output.
//!
//! Everything here is glue over [`crate::render`], [`crate::player`] and [`crate::clone`]:
//! a face is drawn from world (face-frame) positions per mesh, its polygons triangulated once,
//! each mesh in its own colour, from a front camera framed on the *neutral* face so that
//! frames of one face share a camera and motion shows as motion, not as re-framing.

use std::fmt;
use std::path::{Path, PathBuf};
use std::time::Instant;

use glam::Vec3;
use serde::Serialize;

use crate::clone::eval::{compliance, ground_truth_error, pose, self_clone_error};
use crate::clone::face::{clone_face, CloneOptions, Method};
use crate::error::{Error, Result};
use crate::face::parts::{split_mesh, FacePart};
use crate::face::FaceModel;
use crate::fap::{read_stream_file, FapStream, ReadOptions};
use crate::fat::eval::Activation;
use crate::fat::{Fat, TableKey};
use crate::mesh::orient::orient_outwards;
use crate::mesh::Aabb;
use crate::player::gltf::export_face;
use crate::player::{PlayOptions, Player, PlayerFrame};
use crate::render::{
    bounds, contact_sheet, grid, render, turntable, Camera, Image, RenderMesh, RenderOptions,
};

/// Colour of meshes that have none (a neutral skin tone, sRGB).
const DEFAULT_COLOUR: [f32; 3] = [0.82, 0.66, 0.56];
/// Padding between contact-sheet cells, in pixels.
const SHEET_PADDING: u32 = 6;
/// Caption colour drawn into grid cells.
const CELL_CAPTION: [u8; 4] = [235, 235, 235, 255];

/// A face prepared for drawing: per mesh, its triangles (wound consistently outwards,
/// [`crate::mesh::orient::orient_outwards`]) grouped by face part with a material each
/// ([`crate::face::parts`]: eye whites with iris and pupil, teeth, tongue, mouth cavity, the
/// inside of the head seen through the lips), and the neutral bounds every frame of this
/// face is framed on.
#[derive(Clone, Debug)]
pub struct FaceView {
    parts: Vec<DrawPart>,
    neutral_bounds: Aabb,
}

/// Triangles of one mesh drawn in one material.
#[derive(Clone, Debug)]
struct DrawPart {
    mesh: usize,
    triangles: Vec<[u32; 3]>,
    colour: [f32; 3],
    inside_colour: Option<[f32; 3]>,
}

impl FaceView {
    /// Triangulates `face`'s meshes, orients and splits them into parts, and measures its
    /// neutral pose. Errors when the face has no finite vertex.
    pub fn new(face: &FaceModel) -> Result<FaceView> {
        let neutral = neutral_positions(face);
        let mut parts = Vec::new();
        for (i, m) in face.meshes.iter().enumerate() {
            let triangles = orient_outwards(&m.mesh.triangles(), &neutral[i]);
            let mesh_part = FacePart::of_mesh_name(&m.name);
            for (part, triangles) in
                split_mesh(mesh_part, &neutral[i], &triangles, &face.feature_points)
            {
                let colour = match m.color {
                    Some(c) if part.takes_mesh_colour() => c,
                    _ if part == FacePart::Skin => DEFAULT_COLOUR,
                    _ => part.default_colour(),
                };
                parts.push(DrawPart {
                    mesh: i,
                    triangles,
                    colour,
                    inside_colour: part.inside_colour(),
                });
            }
        }
        let meshes = render_meshes(&neutral, &parts);
        let neutral_bounds = bounds(&meshes)
            .ok_or_else(|| Error::Invalid(format!("face `{}` has no vertex to draw", face.name)))?;
        Ok(FaceView {
            parts,
            neutral_bounds,
        })
    }

    /// Bounds of the neutral face in the face frame.
    pub fn neutral_bounds(&self) -> Aabb {
        self.neutral_bounds
    }

    /// The front camera framed on the neutral face.
    pub fn front_camera(&self) -> Camera {
        Camera::framing(&self.neutral_bounds, 0.0, 0.0)
    }

    /// Draws world positions (one list per mesh, as [`PlayerFrame::world_positions_into`]
    /// makes them).
    pub fn render(&self, positions: &[Vec<Vec3>], camera: &Camera, opts: &RenderOptions) -> Image {
        render(&render_meshes(positions, &self.parts), camera, opts)
    }

    /// Like [`FaceView::render`] from several yaw angles (radians) at one distance.
    pub fn turntable(
        &self,
        positions: &[Vec<Vec3>],
        angles: &[f32],
        opts: &RenderOptions,
    ) -> Vec<Image> {
        let meshes = render_meshes(positions, &self.parts);
        turntable(&meshes, &self.neutral_bounds, angles, opts)
    }
}

fn render_meshes<'a>(positions: &'a [Vec<Vec3>], parts: &'a [DrawPart]) -> Vec<RenderMesh<'a>> {
    parts
        .iter()
        .filter_map(|p| {
            let pos = positions.get(p.mesh)?;
            Some(RenderMesh {
                inside_colour: p.inside_colour,
                ..RenderMesh::new(pos, &p.triangles, p.colour)
            })
        })
        .collect()
}

/// World positions of every mesh of `face` in its neutral pose.
pub fn neutral_positions(face: &FaceModel) -> Vec<Vec<Vec3>> {
    let frames = face.frames();
    face.meshes
        .iter()
        .enumerate()
        .map(|(i, m)| {
            let w = frames.meshes.get(i).copied().unwrap_or_default();
            m.mesh
                .positions
                .iter()
                .map(|&p| w.transform_point3(p))
                .collect()
        })
        .collect()
}

/// One played frame of `face` as an image: world positions per mesh, triangulated polygons,
/// mesh colours. For many frames build a [`FaceView`] once instead.
pub fn render_face_frame(
    face: &FaceModel,
    frame: &PlayerFrame,
    camera: &Camera,
    opts: &RenderOptions,
) -> Result<Image> {
    let view = FaceView::new(face)?;
    let mut positions = Vec::new();
    frame.world_positions_into(&mut positions);
    Ok(view.render(&positions, camera, opts))
}

/// `n` frame numbers spread evenly over `range` (first and last included).
pub fn spread_frames(range: std::ops::Range<usize>, n: usize) -> Vec<usize> {
    let len = range.len();
    if len == 0 || n == 0 {
        return Vec::new();
    }
    let n = n.min(len);
    if n == 1 {
        return vec![range.start];
    }
    (0..n)
        .map(|k| range.start + k * (len - 1) / (n - 1))
        .collect()
}

/// Renders `n` frames of `player` spread over its range, each `size` pixels square, with the
/// frame numbers.
fn played_cells(
    face: &FaceModel,
    player: &mut Player,
    n: usize,
    size: (u32, u32),
) -> Result<(Vec<Image>, Vec<usize>)> {
    let view = FaceView::new(face)?;
    let camera = view.front_camera();
    let opts = RenderOptions::sized(size.0, size.1);
    let numbers = spread_frames(player.frame_range(), n);
    let mut frame = player.new_frame();
    let mut positions = Vec::new();
    let mut cells = Vec::with_capacity(numbers.len());
    for &k in &numbers {
        player.frame_at(k, &mut frame);
        frame.world_positions_into(&mut positions);
        cells.push(view.render(&positions, &camera, &opts));
    }
    Ok((cells, numbers))
}

/// A one-row contact sheet of `n_frames` frames of `stream` played on `face` (spread evenly
/// over the played range), each cell `size` pixels, captioned `frame N`.
pub fn contact_sheet_for(
    face: &FaceModel,
    stream: &FapStream,
    play: PlayOptions,
    n_frames: usize,
    size: (u32, u32),
) -> Result<Image> {
    contact_sheet_rows(&[(face.name.as_str(), face)], stream, play, n_frames, size)
}

/// A one-row contact sheet of `n_frames` frames spread over `player`'s range, captioned
/// `frame N`.
pub fn contact_sheet_for_player(
    face: &FaceModel,
    player: &mut Player,
    n_frames: usize,
    size: (u32, u32),
) -> Result<Image> {
    let (cells, numbers) = played_cells(face, player, n_frames, size)?;
    let labels: Vec<String> = numbers.iter().map(|k| format!("frame {k}")).collect();
    let labels: Vec<&str> = labels.iter().map(String::as_str).collect();
    Ok(contact_sheet(
        &cells,
        cells.len() as u32,
        SHEET_PADDING,
        Some(&labels),
    ))
}

/// A contact sheet with one row per face: the same `n_frames` frames of `stream` on each,
/// captioned `NAME N` (frame number).
pub fn contact_sheet_rows(
    faces: &[(&str, &FaceModel)],
    stream: &FapStream,
    play: PlayOptions,
    n_frames: usize,
    size: (u32, u32),
) -> Result<Image> {
    let mut cells = Vec::new();
    let mut labels = Vec::new();
    let mut columns = 1;
    for (name, face) in faces {
        let mut player = Player::new(face, stream, play.clone())?;
        let (imgs, numbers) = played_cells(face, &mut player, n_frames, size)?;
        columns = columns.max(imgs.len() as u32);
        cells.extend(imgs);
        labels.extend(numbers.iter().map(|k| {
            if faces.len() == 1 {
                format!("frame {k}")
            } else {
                format!("{name} {k}")
            }
        }));
    }
    let labels: Vec<&str> = labels.iter().map(String::as_str).collect();
    Ok(contact_sheet(&cells, columns, SHEET_PADDING, Some(&labels)))
}

/// `k` views of the first played frame of `player`, turning once around the head, in one
/// labelled sheet (`0 deg`, `45 deg`, …).
pub fn turntable_sheet(
    face: &FaceModel,
    player: &mut Player,
    k: usize,
    size: (u32, u32),
) -> Result<Image> {
    let view = FaceView::new(face)?;
    let mut frame = player.new_frame();
    player.frame_at(player.frame_range().start, &mut frame);
    let mut positions = Vec::new();
    frame.world_positions_into(&mut positions);
    let k = k.clamp(1, 360);
    let angles: Vec<f32> = (0..k)
        .map(|i| i as f32 * std::f32::consts::TAU / k as f32)
        .collect();
    let images = view.turntable(&positions, &angles, &RenderOptions::sized(size.0, size.1));
    let labels: Vec<String> = angles
        .iter()
        .map(|a| format!("{:.0} deg", a.to_degrees()))
        .collect();
    let labels: Vec<&str> = labels.iter().map(String::as_str).collect();
    let columns = (k as f64).sqrt().ceil() as u32;
    Ok(contact_sheet(
        &images,
        columns,
        SHEET_PADDING,
        Some(&labels),
    ))
}

/// `face` without its FAT (and without the source scene): a mesh with feature points, what a
/// cloning target is.
pub fn strip_fat(face: &FaceModel) -> FaceModel {
    let mut f = face.clone();
    f.fat = Fat::default();
    f.scene = None;
    f
}

/// `face` posed with `key` at `value`, drawn front-on at `size` pixels with `caption` at
/// the bottom.
fn posed_cell(
    face: &FaceModel,
    key: TableKey,
    value: f64,
    size: u32,
    caption: &str,
) -> Result<Image> {
    let view = FaceView::new(face)?;
    let mut eval = face.evaluator()?;
    let mut out = eval.output();
    let positions = pose(face, &mut eval, &mut out, &[Activation { key, value }]);
    let mut img = view.render(
        &positions,
        &view.front_camera(),
        &RenderOptions::sized(size, size),
    );
    let scale = (size / 256 + 1).min(4);
    let tw = crate::render::font::text_width(caption) * scale;
    let th = crate::render::font::GLYPH_HEIGHT * scale;
    img.draw_text(
        (i64::from(size) - i64::from(tw)) / 2,
        i64::from(size) - i64::from(th) - 4 * i64::from(scale),
        caption,
        CELL_CAPTION,
        scale,
    );
    Ok(img)
}

/// The cloning grid (seed 000, Figure 11): rows are source faces, columns target faces.
/// Cell (i, j) is face j stripped of its FAT ([`strip_fat`]) with the FAT cloned from face i
/// by `method`, posed with `key` at `value` (e.g. joy at 63); the diagonal is each face with
/// its own FAT. Cells are `size` pixels square and captioned `source→target`.
pub fn cloning_grid(
    faces: &[(&str, &FaceModel)],
    key: TableKey,
    value: f64,
    method: Method,
    size: u32,
) -> Result<Image> {
    let opts = CloneOptions {
        method,
        ..CloneOptions::default()
    };
    cloning_grid_with(faces, key, value, size, |i, j| {
        Ok(clone_face(faces[i].1, &strip_fat(faces[j].1), &opts)?.face)
    })
}

/// [`cloning_grid`] with the off-diagonal faces supplied by `cloned(source, target)`.
fn cloning_grid_with(
    faces: &[(&str, &FaceModel)],
    key: TableKey,
    value: f64,
    size: u32,
    mut cloned: impl FnMut(usize, usize) -> Result<FaceModel>,
) -> Result<Image> {
    if faces.is_empty() {
        return Err(Error::Invalid(
            "the cloning grid needs at least one face".into(),
        ));
    }
    let mut rows = Vec::with_capacity(faces.len());
    for (i, (src, src_face)) in faces.iter().enumerate() {
        let mut row = Vec::with_capacity(faces.len());
        for (j, (dst, _)) in faces.iter().enumerate() {
            let caption = format!("{src}\u{2192}{dst}");
            let cell = if i == j {
                posed_cell(src_face, key, value, size, &caption)?
            } else {
                posed_cell(&cloned(i, j)?, key, value, size, &caption)?
            };
            row.push(cell);
        }
        rows.push(row);
    }
    let names: Vec<&str> = faces.iter().map(|(n, _)| *n).collect();
    let row_labels: Vec<String> = names.iter().map(|n| format!("from {n}")).collect();
    let col_labels: Vec<String> = names.iter().map(|n| format!("to {n}")).collect();
    let row_labels: Vec<&str> = row_labels.iter().map(String::as_str).collect();
    let col_labels: Vec<&str> = col_labels.iter().map(String::as_str).collect();
    Ok(grid(&rows, &row_labels, &col_labels))
}

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
}

impl Default for DemoOptions {
    /// The written outputs use `rbf`: on the bundled faces both methods reach the same
    /// figures (self-clone 0 %, ~31 % against bruno's true FAT), but `fmc`'s 2D projection
    /// leaves visible seams at the chin and the lower eyelids, so the pictures use `rbf`; the
    /// report measures both.
    fn default() -> Self {
        DemoOptions {
            method: Method::Rbf,
            compare_methods: true,
            sheet_frames: 8,
            sheet_cell: 192,
            grid_cell: 256,
            samples_dir: None,
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
    /// Named steps and their seconds.
    pub timings: Vec<(String, f64)>,
    /// Total wall time in seconds.
    pub total_seconds: f64,
    /// Warnings from cloning, playing and exporting.
    pub warnings: Vec<String>,
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

/// A bundled face: `samples/faces/NAME.wrl.gz` when present, else the generator (the file is
/// made from it, so both are the same face).
fn bundled_face(samples: &Path, name: &str) -> Result<(FaceModel, String)> {
    let path = samples.join("faces").join(format!("{name}.wrl.gz"));
    if path.is_file() {
        let (mut face, _) = crate::face::obj_io::read_face(&path, None)?;
        face.name = name.to_string();
        return Ok((face, path.display().to_string()));
    }
    let synth = match name {
        "alma" => crate::synth::alma(),
        _ => crate::synth::bruno(),
    };
    Ok((FaceModel::from_synth(&synth), "built-in generator".into()))
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

fn record(files: &mut Vec<DemoFile>, path: PathBuf, what: &str) -> Result<()> {
    let bytes = std::fs::metadata(&path)
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

/// The end-to-end demo on the bundled samples: source `alma` (full FAT), target `bruno`
/// stripped to meshes and feature points; clones alma→bruno, plays `speech.fap` on alma and
/// on the cloned bruno, and writes into `out_dir` (created):
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
        None => find_samples_dir().ok_or_else(|| {
            Error::Invalid(
                "cannot find the bundled samples (samples/speech.fap); run from the fbakit \
                 checkout"
                    .into(),
            )
        })?,
    };
    let stream_path = samples.join("speech.fap");
    let (stream, stream_warnings) = read_stream_file(&stream_path, &ReadOptions::lenient())?;
    let mut warnings: Vec<String> = stream_warnings.iter().map(|d| d.to_string()).collect();
    let (alma, source_face) = bundled_face(&samples, "alma")?;
    let (truth, target_face) = bundled_face(&samples, "bruno")?;
    let target = strip_fat(&truth);
    clock.lap("load");
    std::fs::create_dir_all(out_dir).map_err(|e| Error::io(out_dir, e))?;

    let other = match opts.method {
        Method::Fmc => Method::Rbf,
        Method::Rbf => Method::Fmc,
    };
    let (main_quality, outcome) = measure(&alma, &target, &truth, opts.method, &mut clock)?;
    let mut quality = vec![main_quality];
    if opts.compare_methods {
        quality.push(measure(&alma, &target, &truth, other, &mut clock)?.0);
    }
    warnings.extend(outcome.report.warnings.iter().cloned());
    let mut bruno = outcome.face;
    bruno.name = "bruno".into();

    let mut files = Vec::new();
    let wrl = out_dir.join("bruno-cloned.wrl");
    crate::face::vrml_io::write_face_file(&wrl, &bruno)?;
    record(
        &mut files,
        wrl,
        "bruno with the FAT cloned from alma (VRML)",
    )?;
    clock.lap("write bruno-cloned.wrl");

    let mut frames = 0;
    let mut fps = stream.frame_rate;
    for (name, face) in [("alma", &alma), ("bruno", &bruno)] {
        let player = Player::new(face, &stream, PlayOptions::default())?;
        frames = player.frame_count();
        fps = player.fps();
        for (key, n) in player.missing_tables() {
            warnings.push(format!("{name}: no table for {key} ({n} frames)"));
        }
        let anim = player.animation()?;
        let export = export_face(face, Some(&anim))?;
        warnings.extend(export.warnings);
        let path = out_dir.join(format!("{name}-speech.glb"));
        export.document.write_glb(&path)?;
        record(
            &mut files,
            path,
            &format!("speech.fap played on {name} (animated glTF)"),
        )?;
    }
    clock.lap("play + write glb");

    let sheet = contact_sheet_rows(
        &[("alma", &alma), ("bruno", &bruno)],
        &stream,
        PlayOptions::default(),
        opts.sheet_frames,
        (opts.sheet_cell, opts.sheet_cell),
    )?;
    let path = out_dir.join("contact-sheet.png");
    sheet.write_png(&path)?;
    record(
        &mut files,
        path,
        "the same speech frames on alma (top) and cloned bruno (bottom)",
    )?;
    clock.lap("contact sheet");

    let clone_opts = CloneOptions {
        method: opts.method,
        ..CloneOptions::default()
    };
    let faces = [("alma", &alma), ("bruno", &truth)];
    let joy = TableKey::Expression(crate::spec::Expression::Joy);
    let grid_image = cloning_grid_with(&faces, joy, 63.0, opts.grid_cell, |i, j| {
        if (i, j) == (0, 1) {
            Ok(bruno.clone())
        } else {
            Ok(clone_face(faces[i].1, &strip_fat(faces[j].1), &clone_opts)?.face)
        }
    })?;
    let path = out_dir.join("cloning-grid.png");
    grid_image.write_png(&path)?;
    record(
        &mut files,
        path,
        "joy at 63 cloned both ways (rows: source, columns: target)",
    )?;
    clock.lap("cloning grid (clone bruno→alma + render)");

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
        timings: clock.steps,
        total_seconds: start.elapsed().as_secs_f64(),
        warnings,
    })
}

impl fmt::Display for DemoReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "fbakit demo: alma's FAT cloned onto bruno ({}), {} played on both",
            self.method.name(),
            self.stream.display()
        )?;
        writeln!(f, "  source alma:  {}", self.source_face)?;
        writeln!(
            f,
            "  target bruno: {} (FAT stripped; {} tables cloned)",
            self.target_face, self.cloned_tables
        )?;
        writeln!(f, "  stream: {} frames at {} fps", self.frames, self.fps)?;
        writeln!(f, "wrote into {}:", self.out_dir.display())?;
        for file in &self.files {
            let name = file.path.file_name().map_or_else(
                || file.path.display().to_string(),
                |n| n.to_string_lossy().into(),
            );
            writeln!(f, "  {name:<18} {:>9} bytes  {}", file.bytes, file.what)?;
        }
        writeln!(f, "quality (alma→bruno):")?;
        writeln!(
            f,
            "  {:<6} {:>16} {:>22} {:>24} {:>9}",
            "method", "self-clone alma", "compliance worst/mean", "vs true FAT all/skin", "clone s"
        )?;
        for q in &self.quality {
            writeln!(
                f,
                "  {:<6} {:>15.3}% {:>13.4} / {:<6.4} {:>14.1}% / {:>4.1}% {:>8.2}",
                q.method.name(),
                q.self_clone_error_percent,
                q.compliance_worst,
                q.compliance_mean,
                q.ground_truth_all_percent,
                q.ground_truth_skin_percent,
                q.clone_seconds
            )?;
        }
        writeln!(f, "timings:")?;
        for (name, s) in &self.timings {
            writeln!(f, "  {name:<42} {s:>7.2} s")?;
        }
        writeln!(f, "  {:<42} {:>7.2} s", "total", self.total_seconds)?;
        for w in &self.warnings {
            writeln!(f, "warning: {w}")?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spread_frames_covers_the_range() {
        assert_eq!(spread_frames(0..75, 4), vec![0, 24, 49, 74]);
        assert_eq!(spread_frames(10..12, 8), vec![10, 11]);
        assert_eq!(spread_frames(5..6, 3), vec![5]);
        assert!(spread_frames(0..0, 3).is_empty());
        assert!(spread_frames(0..10, 0).is_empty());
    }

    #[test]
    fn strip_fat_keeps_geometry() {
        let face = FaceModel::from_synth(&crate::synth::alma());
        let s = strip_fat(&face);
        assert!(s.fat.tables.is_empty());
        assert_eq!(s.mesh_sizes(), face.mesh_sizes());
        assert_eq!(s.feature_points, face.feature_points);
    }
}
