//! Rendered pictures of faces: played frames, contact sheets, turntables and the cloning grid
//! (seed 000, Figure 11).
//!
//! Everything here is glue over [`crate::render`], [`crate::player`] and [`crate::clone`]:
//! a face is drawn from world (face-frame) positions per mesh, its polygons triangulated once,
//! each mesh in its own colour, from a front camera framed on the *neutral* face so that
//! frames of one face share a camera and motion shows as motion, not as re-framing. Contact
//! sheets and the cloning grid frame the face from its feature points
//! ([`FaceView::face_camera`]), not the whole head with its neck. Eye layers resting on the
//! lids (an eye occlusion, a tear film, corner blends: transparent in the head's own
//! materials) are left out ([`crate::clone::face::lid_resting_layers`]).

pub mod eyes;

use glam::{Mat3, Vec3};

use crate::clone::face::{clone_face, lid_resting_layers, CloneOptions, Method};
use crate::error::Result;
use crate::face::parts::{split_mesh, FacePart};
use crate::face::FaceModel;
use crate::fap::FapStream;
use crate::fat::eval::Activation;
use crate::fat::TableKey;
use crate::mesh::orient::orient_outwards;
use crate::mesh::Aabb;
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
    /// The box around the neutral face's facial feature points
    /// ([`crate::export::movie::feature_point_box`]), when it has enough of them.
    face_box: Option<Aabb>,
    /// For a face modelled turned in its file (facing −z), the turn that stands it up
    /// ([`crate::fdp::FeaturePointSet::upright_turn`]): it is drawn and framed from its own
    /// front, as every upright face is.
    turn: Option<Mat3>,
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
        // A turned face is measured stood up, and every pose drawn turned so (`render`).
        let turn = face.feature_points.upright_turn();
        let upright = turn.map(|t| crate::clone::face::upright::upright_copy(face, t));
        let face = upright.as_ref().unwrap_or(face);
        let neutral = face.neutral_world_positions();
        let eyes = eyes::eyeballs(face, &neutral);
        // Transparent in the user's materials, opaque here: drawn, they close the eyes.
        let layers = lid_resting_layers(face);
        let mut parts = Vec::new();
        for (i, m) in face.meshes.iter().enumerate() {
            let mut triangles = orient_outwards(&m.mesh.triangles(), &neutral[i]);
            if let Some(l) = layers.iter().find(|l| l.mesh == i) {
                triangles.retain(|t| !t.iter().all(|v| l.vertices.binary_search(v).is_ok()));
            }
            let mesh_part = FacePart::of_mesh_name(&m.name);
            // Eyeballs inside another mesh (a one-mesh head) get their own parts first.
            let mut groups: Vec<(FacePart, Vec<[u32; 3]>)> = Vec::new();
            if mesh_part != FacePart::EyeWhite {
                for e in eyes.iter().filter(|e| e.mesh == i) {
                    let (inside, rest): (Vec<[u32; 3]>, Vec<[u32; 3]>) = triangles
                        .into_iter()
                        .partition(|t| t.iter().all(|&v| e.contains(v)));
                    triangles = rest;
                    for t in inside {
                        let c = t.iter().map(|&v| neutral[i][v as usize]).sum::<Vec3>() / 3.0;
                        let part = e.part_at(c);
                        match groups.iter_mut().find(|(p, _)| *p == part) {
                            Some((_, g)) => g.push(t),
                            None => groups.push((part, vec![t])),
                        }
                    }
                }
            }
            groups.extend(split_mesh(
                mesh_part,
                &neutral[i],
                &triangles,
                &face.feature_points,
            ));
            for (part, triangles) in groups {
                // A mesh's colour is its own part's: eyeballs found inside it keep theirs.
                let own = part == mesh_part || mesh_part == FacePart::EyeWhite;
                let colour = match m.color {
                    Some(c) if own && part.takes_mesh_colour() => c,
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
        let neutral_bounds = bounds(&meshes).ok_or_else(|| super::ExportError::NothingToDraw {
            face: face.name.clone(),
        })?;
        Ok(FaceView {
            parts,
            neutral_bounds,
            face_box: super::movie::feature_point_box(face),
            turn,
        })
    }

    /// Bounds of the neutral face in the face frame.
    pub fn neutral_bounds(&self) -> Aabb {
        self.neutral_bounds
    }

    /// The front camera framed on the whole neutral face (every mesh, neck and back of
    /// the head included).
    pub fn front_camera(&self) -> Camera {
        Camera::framing(&self.neutral_bounds, 0.0, 0.0)
    }

    /// The front camera framed on the face itself: the box around its facial feature points
    /// (chin to hairline, cheek to cheek, with a margin; see [`crate::export::movie`]), or
    /// [`FaceView::front_camera`] when the face has too few of them. What contact sheets
    /// and the cloning grid use, so a face fills its cell however long its neck is.
    pub fn face_camera(&self) -> Camera {
        match &self.face_box {
            Some(b) => Camera::framing(b, 0.0, 0.0),
            None => self.front_camera(),
        }
    }

    /// Whether [`FaceView::face_camera`] frames the feature points.
    pub fn framed_on_feature_points(&self) -> bool {
        self.face_box.is_some()
    }

    /// Draws world positions (one list per mesh, as [`crate::face::FacePose::world_positions_into`]
    /// makes them).
    pub fn render(&self, positions: &[Vec<Vec3>], camera: &Camera, opts: &RenderOptions) -> Image {
        match self.turn {
            None => render(&render_meshes(positions, &self.parts), camera, opts),
            Some(t) => {
                let upright: Vec<Vec<Vec3>> = positions
                    .iter()
                    .map(|m| m.iter().map(|&p| t * p).collect())
                    .collect();
                render(&render_meshes(&upright, &self.parts), camera, opts)
            }
        }
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
    frame.pose.world_positions_into(&mut positions);
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
    let camera = view.face_camera();
    let opts = RenderOptions::sized(size.0, size.1);
    let numbers = spread_frames(player.frame_range(), n);
    let mut frame = player.new_frame();
    let mut positions = Vec::new();
    let mut cells = Vec::with_capacity(numbers.len());
    for &k in &numbers {
        player.frame_at(k, &mut frame);
        frame.pose.world_positions_into(&mut positions);
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
        let mut player = Player::new(face, stream, &play.clone())?;
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
    frame.pose.world_positions_into(&mut positions);
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
    crate::clone::eval::without_fat(face)
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
    let positions = face.pose_with(&mut eval, &mut out, &[Activation { key, value }]);
    let mut img = view.render(
        &positions,
        &view.face_camera(),
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
pub(crate) fn cloning_grid_with(
    faces: &[(&str, &FaceModel)],
    key: TableKey,
    value: f64,
    size: u32,
    mut cloned: impl FnMut(usize, usize) -> Result<FaceModel>,
) -> Result<Image> {
    if faces.is_empty() {
        return Err(super::ExportError::NoFaces.into());
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
        let face = crate::synth::alma().to_face_model();
        let s = strip_fat(&face);
        assert!(s.fat.tables.is_empty());
        assert_eq!(s.mesh_sizes(), face.mesh_sizes());
        assert_eq!(s.feature_points, face.feature_points);
    }
}
