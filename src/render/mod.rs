//! CPU software renderer: shaded images of faces as PNG files, contact sheets, turntables
//! and the cloning grid.
//!
//! The API takes plain data — [`RenderMesh`] borrows positions and triangles — so any face
//! model can be drawn. [`render`] is a z-buffer rasteriser: fixed-point edge functions with
//! the top-left fill rule (triangles sharing an edge cover each pixel exactly once), depth
//! interpolated perspective-correctly, optional back-face culling, Lambert key and fill
//! lights with a little Blinn specular, flat or smooth (perspective-correct vertex normal)
//! shading, optional supersampling, and gamma-correct output: mesh colours are sRGB, shading
//! and filtering happen in linear light. Horizontal bands of the image are rasterised in
//! parallel with `rayon`; each band draws its triangles in input order, so the output is the
//! same bytes whatever the thread count.
//!
//! Frame: the MPEG-4 face frame (+x the face's own left, +y up, +z towards the viewer), so
//! [`Camera::framing`] with yaw and pitch 0 looks at the face from +z.
//!
//! ```no_run
//! use fbakit::render::{fan_triangulate, render, Camera, RenderMesh, RenderOptions};
//! let face = fbakit::synth::alma();
//! let tris: Vec<Vec<[u32; 3]>> = face.meshes.iter().map(|m| fan_triangulate(&m.polygons)).collect();
//! let meshes: Vec<RenderMesh> = face.meshes.iter().zip(&tris)
//!     .map(|(m, t)| RenderMesh::new(&m.positions, t, m.colour)).collect();
//! let bounds = fbakit::render::bounds(&meshes).unwrap();
//! let image = render(&meshes, &Camera::framing(&bounds, 0.0, 0.0), &RenderOptions::default());
//! image.write_png("alma.png".as_ref()).unwrap();
//! ```

mod colour;
mod error;
pub mod font;
mod image;
mod raster;
#[cfg(test)]
mod tests;

use glam::Vec3;

pub use self::image::{
    contact_sheet, grid, Image, ImageStats, PixelRect, MAX_IMAGE_SIDE, THUMBNAIL_SIDE,
};
pub use colour::{linear_to_srgb, srgb_to_linear};
pub use error::RenderError;
pub use raster::render;

use crate::mesh::Aabb;

/// A triangle mesh to draw, borrowed from whatever model holds it.
#[derive(Clone, Copy, Debug)]
pub struct RenderMesh<'a> {
    /// Vertex positions in the world (face) frame.
    pub positions: &'a [Vec3],
    /// Triangles, counter-clockwise seen from the outside. Triangles with an index out of
    /// range or a non-finite corner are skipped.
    pub triangles: &'a [[u32; 3]],
    /// Vertex normals for smooth shading; when absent (or not one per position),
    /// area-weighted normals are computed.
    pub normals: Option<&'a [Vec3]>,
    /// Diffuse colour, sRGB components in `[0, 1]`.
    pub colour: [f32; 3],
    /// Colour of the back faces (the inside of a surface, seen through an opening such as
    /// the mouth), sRGB; `None` draws them in `colour`, darkened.
    pub inside_colour: Option<[f32; 3]>,
}

impl<'a> RenderMesh<'a> {
    /// A mesh without normals.
    pub fn new(positions: &'a [Vec3], triangles: &'a [[u32; 3]], colour: [f32; 3]) -> Self {
        RenderMesh {
            positions,
            triangles,
            normals: None,
            colour,
            inside_colour: None,
        }
    }
}

/// Splits polygons into triangles as fans from their first corner (right for the convex
/// triangles and quads of face meshes); polygons with fewer than three corners are dropped.
pub fn fan_triangulate(polygons: &[Vec<u32>]) -> Vec<[u32; 3]> {
    let mut out = Vec::with_capacity(polygons.iter().map(|p| p.len().saturating_sub(2)).sum());
    for p in polygons {
        for k in 1..p.len().saturating_sub(1) {
            out.push([p[0], p[k], p[k + 1]]);
        }
    }
    out
}

/// Bounds of every finite position of `meshes` (`None` if there is none).
pub fn bounds(meshes: &[RenderMesh]) -> Option<Aabb> {
    meshes
        .iter()
        .filter_map(|m| Aabb::of_points(m.positions))
        .reduce(|a, b| Aabb {
            min: a.min.min(b.min),
            max: a.max.max(b.max),
        })
}

/// How 3D points map to the image plane.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Projection {
    /// Pinhole camera; `fov` is the full angle in radians across the shorter image side
    /// (the vertical field of view for landscape and square images).
    Perspective {
        /// Field of view in radians, in `(0, π)`.
        fov: f32,
    },
    /// Parallel projection; `extent` world units span the shorter image side.
    Orthographic {
        /// World units across the shorter image side.
        extent: f32,
    },
}

/// A look-at camera.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// Eye position.
    pub eye: Vec3,
    /// Point the camera looks at (drawn at the image centre).
    pub target: Vec3,
    /// Approximate up direction (made orthogonal to the view direction).
    pub up: Vec3,
    /// Perspective or orthographic.
    pub projection: Projection,
    /// Perspective only: triangles with a corner closer to the eye than this (along the view
    /// direction) are skipped rather than clipped.
    pub near: f32,
}

/// Field of view of [`Camera::framing`]: a moderate telephoto, like a portrait lens.
const FRAMING_FOV_DEGREES: f32 = 25.0;
/// Fraction of the shorter image side the framed bounds may fill.
const FRAMING_FILL: f32 = 0.92;

/// Orthonormal view basis (right, up, backward = towards the eye).
pub(crate) struct ViewBasis {
    pub right: Vec3,
    pub up: Vec3,
    pub back: Vec3,
}

impl Camera {
    /// A camera at `eye` looking at `target`.
    pub fn look_at(eye: Vec3, target: Vec3, up: Vec3, projection: Projection) -> Camera {
        Camera {
            eye,
            target,
            up,
            projection,
            near: (eye - target).length() * 1e-3,
        }
    }

    /// The unit direction from the target towards an eye at `yaw` (about +y, positive
    /// towards +x, the face's left) and `pitch` (positive from above), both in radians.
    fn orbit_direction(yaw: f32, pitch: f32) -> Vec3 {
        let pitch = pitch.clamp(-1.55, 1.55);
        Vec3::new(
            yaw.sin() * pitch.cos(),
            pitch.sin(),
            yaw.cos() * pitch.cos(),
        )
    }

    /// Largest lateral extent (along right/up) and nearest-corner depth offset of `bounds`
    /// seen along `dir`, per corner, measured from the bounds' centre.
    fn corner_offsets(bounds: &Aabb, dir: Vec3) -> impl Iterator<Item = (f32, f32)> {
        let basis = basis_of(-dir, Vec3::Y);
        let c = bounds.center();
        let (lo, hi) = (bounds.min, bounds.max);
        (0..8).map(move |i| {
            let p = Vec3::new(
                if i & 1 == 0 { lo.x } else { hi.x },
                if i & 2 == 0 { lo.y } else { hi.y },
                if i & 4 == 0 { lo.z } else { hi.z },
            ) - c;
            let lateral = p.dot(basis.right).abs().max(p.dot(basis.up).abs());
            (lateral, p.dot(dir))
        })
    }

    /// A perspective camera orbiting `bounds` at `yaw` and `pitch` (radians; 0, 0 looks
    /// from +z towards −z, the MPEG-4 front view) and far enough away that every corner of
    /// the box fits in the view with a small margin. The box centre is at the image centre.
    pub fn framing(bounds: &Aabb, yaw: f32, pitch: f32) -> Camera {
        let fov = FRAMING_FOV_DEGREES.to_radians();
        let distance = Self::framing_distance(bounds, yaw, pitch, fov);
        Self::orbit(
            bounds,
            yaw,
            pitch,
            distance,
            Projection::Perspective { fov },
        )
    }

    /// Like [`Camera::framing`] with a parallel projection.
    pub fn framing_orthographic(bounds: &Aabb, yaw: f32, pitch: f32) -> Camera {
        let dir = Self::orbit_direction(yaw, pitch);
        let lateral = Self::corner_offsets(bounds, dir)
            .map(|(l, _)| l)
            .fold(0.0f32, f32::max);
        let extent = (2.0 * lateral / FRAMING_FILL).max(1e-6);
        let distance = bounds.diagonal().max(1e-3) * 2.0;
        Self::orbit(
            bounds,
            yaw,
            pitch,
            distance,
            Projection::Orthographic { extent },
        )
    }

    /// Eye distance from the centre of `bounds` at which all its corners fit in `fov`.
    fn framing_distance(bounds: &Aabb, yaw: f32, pitch: f32, fov: f32) -> f32 {
        let t = (fov * 0.5).tan() * FRAMING_FILL;
        let dir = Self::orbit_direction(yaw, pitch);
        Self::corner_offsets(bounds, dir)
            .map(|(lateral, towards)| towards + lateral / t)
            .fold(1e-3f32, f32::max)
    }

    fn orbit(bounds: &Aabb, yaw: f32, pitch: f32, distance: f32, projection: Projection) -> Camera {
        let target = bounds.center();
        let mut cam = Camera::look_at(
            target + Self::orbit_direction(yaw, pitch) * distance,
            target,
            Vec3::Y,
            projection,
        );
        cam.near = distance * 1e-2;
        cam
    }

    pub(crate) fn basis(&self) -> ViewBasis {
        basis_of(self.target - self.eye, self.up)
    }

    /// Where `p` lands in an image of `width × height` pixels (x right, y down, pixel
    /// centres at +0.5), or `None` if it is behind the near plane.
    pub fn project(&self, p: Vec3, width: u32, height: u32) -> Option<(f32, f32)> {
        let b = self.basis();
        let (w, h) = (width as f32, height as f32);
        let short = w.min(h);
        let d = p - self.eye;
        let (x, y, dist) = (d.dot(b.right), d.dot(b.up), -d.dot(b.back));
        let scale = match self.projection {
            Projection::Perspective { fov } => {
                if dist < self.near {
                    return None;
                }
                short * 0.5 / (fov * 0.5).tan() / dist
            }
            Projection::Orthographic { extent } => short / extent,
        };
        Some((w * 0.5 + x * scale, h * 0.5 - y * scale))
    }
}

/// Right-handed view basis for looking along `forward` with `up` roughly up; falls back to
/// sane axes when the inputs are degenerate.
fn basis_of(forward: Vec3, up: Vec3) -> ViewBasis {
    let f = forward.try_normalize().unwrap_or(Vec3::NEG_Z);
    let right = f
        .cross(up)
        .try_normalize()
        .or_else(|| f.cross(Vec3::Y).try_normalize())
        .unwrap_or(Vec3::X);
    ViewBasis {
        right,
        up: right.cross(f),
        back: -f,
    }
}

/// Lighting, with directions in the camera frame (x right, y up, z towards the viewer) so
/// that a turntable keeps the same studio lighting while the head turns.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Light {
    /// Direction towards the key light.
    pub key_direction: Vec3,
    /// Key light intensity.
    pub key_intensity: f32,
    /// Direction towards the fill light.
    pub fill_direction: Vec3,
    /// Fill light intensity.
    pub fill_intensity: f32,
    /// Light reaching every surface.
    pub ambient: f32,
    /// Strength of the key light's Blinn-Phong highlight.
    pub specular: f32,
    /// Blinn-Phong exponent.
    pub shininess: f32,
}

impl Default for Light {
    /// Key from the upper left front, a weak fill from the right, a little ambient.
    fn default() -> Self {
        Light {
            key_direction: Vec3::new(-0.45, 0.55, 0.75),
            key_intensity: 0.9,
            fill_direction: Vec3::new(0.75, 0.05, 0.5),
            fill_intensity: 0.3,
            ambient: 0.12,
            specular: 0.12,
            shininess: 24.0,
        }
    }
}

/// Flat (one normal per triangle) or smooth (interpolated vertex normals) shading.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Shading {
    /// Faceted.
    Flat,
    /// Gouraud-free Phong-style: vertex normals interpolated per pixel.
    #[default]
    Smooth,
}

/// Everything about a frame except the scene and the camera.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RenderOptions {
    /// Width in pixels (clamped to `1..=MAX_IMAGE_SIDE`).
    pub width: u32,
    /// Height in pixels (clamped to `1..=MAX_IMAGE_SIDE`).
    pub height: u32,
    /// Flat or smooth.
    pub shading: Shading,
    /// Background, sRGB with alpha.
    pub background: [u8; 4],
    /// Samples per pixel along each axis: 1 (none) or 2 (4 samples per pixel); clamped to
    /// `1..=4`, and lowered so the sample grid stays within `MAX_IMAGE_SIDE` on each side.
    pub supersample: u32,
    /// Skip triangles facing away from the camera. Off by default: back faces seen through
    /// openings (inside the mouth) are drawn darkened instead of leaving holes.
    pub cull_back_faces: bool,
    /// Lights.
    pub light: Light,
}

impl Default for RenderOptions {
    fn default() -> Self {
        RenderOptions {
            width: 512,
            height: 512,
            shading: Shading::Smooth,
            background: [46, 48, 56, 255],
            supersample: 2,
            cull_back_faces: false,
            light: Light::default(),
        }
    }
}

impl RenderOptions {
    /// Default options at `width × height`.
    pub fn sized(width: u32, height: u32) -> RenderOptions {
        RenderOptions {
            width,
            height,
            ..RenderOptions::default()
        }
    }
}

/// Renders the meshes from cameras orbiting `bounds` at each yaw in `angles` (radians, 0 =
/// front, positive turns the camera towards the face's left), all at the same distance so
/// the head keeps its size from frame to frame.
pub fn turntable(
    meshes: &[RenderMesh],
    bounds: &Aabb,
    angles: &[f32],
    opts: &RenderOptions,
) -> Vec<Image> {
    let fov = FRAMING_FOV_DEGREES.to_radians();
    let distance = angles
        .iter()
        .map(|&a| Camera::framing_distance(bounds, a, 0.0, fov))
        .fold(1e-3f32, f32::max);
    angles
        .iter()
        .map(|&a| {
            let cam = Camera::orbit(bounds, a, 0.0, distance, Projection::Perspective { fov });
            render(meshes, &cam, opts)
        })
        .collect()
}
