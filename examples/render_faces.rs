//! Renders the procedural faces: a front view of `alma` neutral and with joy + open jaw, a
//! labelled contact sheet of `bruno`'s expressions, a turntable sheet, and a small cloning
//! grid layout (rows = source faces, columns = target faces; each cell shows the target with
//! joy — the synthetic faces have exact FATs, so "cloned" joy is the target's own).
//!
//! Run: `cargo run --release --example render_faces [OUT_DIR]` (default `/tmp/fbakit-render`).
#![allow(dead_code)] // Also included as a module by the tests, which do not call `main`.

use std::path::Path;

use fbakit::fat::eval::Activation;
use fbakit::fat::TableKey;
use fbakit::render::{
    bounds, contact_sheet, fan_triangulate, grid, render, turntable, Camera, Image, RenderMesh,
    RenderOptions,
};
use fbakit::spec::{Expression, FapId};
use fbakit::synth::SynthFace;
use glam::Vec3;

/// A face posed by FAT activations: per-mesh positions and triangles, ready for
/// [`RenderMesh`].
pub struct PosedFace {
    /// Positions per mesh after displacements and transforms.
    pub positions: Vec<Vec<Vec3>>,
    /// Fan-triangulated polygons per mesh.
    pub triangles: Vec<Vec<[u32; 3]>>,
    /// Colour per mesh.
    pub colours: Vec<[f32; 3]>,
}

impl PosedFace {
    /// Borrowed render meshes.
    pub fn meshes(&self) -> Vec<RenderMesh<'_>> {
        self.positions
            .iter()
            .zip(&self.triangles)
            .zip(&self.colours)
            .map(|((p, t), c)| RenderMesh::new(p, t, *c))
            .collect()
    }
}

/// `face` posed by `activations` with the library's one posing rule
/// ([`fbakit::face::FaceModel::pose`]).
pub fn pose(face: &SynthFace, activations: &[Activation]) -> PosedFace {
    let positions = face
        .to_face_model()
        .pose(activations)
        .expect("synthetic FATs are valid");
    PosedFace {
        positions,
        triangles: face
            .meshes
            .iter()
            .map(|m| fan_triangulate(&m.polygons))
            .collect(),
        colours: face.meshes.iter().map(|m| m.colour).collect(),
    }
}

/// Joy at 63 with the jaw open by `jaw` MNS units.
pub fn joy_open_jaw(jaw: f64) -> Vec<Activation> {
    vec![
        Activation {
            key: TableKey::Expression(Expression::Joy),
            value: 63.0,
        },
        Activation {
            key: TableKey::LowLevel(FapId::OPEN_JAW),
            value: jaw,
        },
    ]
}

/// Front view of `posed`, framed on `frame` (the neutral bounds, so poses share a camera).
pub fn front(posed: &PosedFace, frame: &PosedFace, opts: &RenderOptions) -> Image {
    let b = bounds(&frame.meshes()).expect("faces have vertices");
    render(&posed.meshes(), &Camera::framing(&b, 0.0, 0.0), opts)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let dir = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "/tmp/fbakit-render".into());
    let dir = Path::new(&dir);
    std::fs::create_dir_all(dir)?;
    let opts = RenderOptions::sized(384, 384);
    let faces = [fbakit::synth::alma(), fbakit::synth::bruno()];

    let alma = &faces[0];
    let neutral = pose(alma, &[]);
    front(&neutral, &neutral, &opts).write_png(&dir.join("alma_neutral.png"))?;
    let joy = pose(alma, &joy_open_jaw(400.0));
    front(&joy, &neutral, &opts).write_png(&dir.join("alma_joy.png"))?;

    // Bruno's six expressions at full intensity.
    let bruno = &faces[1];
    let bruno_neutral = pose(bruno, &[]);
    let small = RenderOptions::sized(192, 192);
    let mut cells = vec![front(&bruno_neutral, &bruno_neutral, &small)];
    let mut labels = vec!["neutral".to_string()];
    for e in Expression::basic() {
        let p = pose(
            bruno,
            &[Activation {
                key: TableKey::Expression(e),
                value: 63.0,
            }],
        );
        cells.push(front(&p, &bruno_neutral, &small));
        labels.push(e.name().to_string());
    }
    let labels: Vec<&str> = labels.iter().map(String::as_str).collect();
    contact_sheet(&cells, 4, 6, Some(&labels)).write_png(&dir.join("bruno_expressions.png"))?;

    // Turntable of alma with joy.
    let angles: Vec<f32> = (0..8)
        .map(|i| i as f32 * std::f32::consts::TAU / 8.0)
        .collect();
    let b = bounds(&neutral.meshes()).expect("vertices");
    let frames = turntable(&joy.meshes(), &b, &angles, &small);
    let names: Vec<String> = angles
        .iter()
        .map(|a| format!("{:.0} deg", a.to_degrees()))
        .collect();
    let names: Vec<&str> = names.iter().map(String::as_str).collect();
    contact_sheet(&frames, 4, 6, Some(&names)).write_png(&dir.join("alma_turntable.png"))?;

    // Cloning grid layout.
    let posed_joy: Vec<PosedFace> = faces
        .iter()
        .map(|f| pose(f, &joy_open_jaw(300.0)))
        .collect();
    let neutrals = [neutral, bruno_neutral];
    let row: Vec<Image> = posed_joy
        .iter()
        .zip(&neutrals)
        .map(|(p, n)| front(p, n, &small))
        .collect();
    let g = grid(&[row.clone(), row], &["alma", "bruno"], &["alma", "bruno"]);
    g.write_png(&dir.join("cloning_grid.png"))?;
    println!("wrote PNGs to {}", dir.display());
    Ok(())
}
