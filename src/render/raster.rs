//! The z-buffer rasteriser behind [`render`].

use glam::Vec3;
use rayon::prelude::*;

use super::colour::{linear_to_srgb8, srgb8_to_linear, srgb_to_linear};
use super::image::{Image, MAX_IMAGE_SIDE};
use super::{Camera, Light, Projection, RenderMesh, RenderOptions, Shading};
use crate::mesh::geometry::vertex_normals;

/// Sub-pixel precision of snapped vertex coordinates (8 bits): edge functions are then exact
/// integers, which is what makes the fill rule watertight.
const SUBPIXEL_BITS: u32 = 8;
const SUBPIXEL: i64 = 1 << SUBPIXEL_BITS;
/// Vertices farther than this many pixels from the image are not drawn (keeps the i64 edge
/// products far from overflow).
const GUARD_PIXELS: f32 = (1 << 20) as f32;
/// Rows of samples per parallel band.
const BAND_ROWS: usize = 16;
/// Back faces (seen through openings) are shaded this much darker.
const INTERIOR_DARKENING: f32 = 0.35;

/// A vertex after projection.
#[derive(Clone, Copy)]
struct ScreenVertex {
    /// Snapped sample-space coordinates (y down), in 1/256 sample units.
    x: i64,
    y: i64,
    /// Depth key, affine in screen space, larger is nearer: 1/distance (perspective) or
    /// −distance (orthographic).
    depth: f32,
    /// 1/w for perspective-correct attributes (1 for orthographic).
    inv_w: f32,
    /// Unit normal in the view frame.
    normal: Vec3,
    /// Inside the guard band and in front of the near plane.
    usable: bool,
}

/// A triangle ready for scan conversion, oriented so its edge functions are positive inside.
struct SetupTriangle {
    v: [u32; 3],
    area: i64,
    /// Sample bounding box (inclusive), clipped to the image.
    x0: i32,
    x1: i32,
    y0: i32,
    y1: i32,
    /// Unit face normal in the view frame, facing the viewer.
    face_normal: Vec3,
    /// Linear albedo, darkened for back faces.
    albedo: Vec3,
    /// The triangle faces away from the camera (its normals are flipped for shading).
    back: bool,
}

/// One sample of the frame buffer.
#[derive(Clone, Copy)]
struct Sample {
    depth: f32,
    rgb: Vec3,
}

const EMPTY: Sample = Sample {
    depth: f32::NEG_INFINITY,
    rgb: Vec3::ZERO,
};

/// Renders `meshes` seen by `camera` into a new image (see the [module docs](super)).
pub fn render(meshes: &[RenderMesh], camera: &Camera, opts: &RenderOptions) -> Image {
    let width = opts.width.clamp(1, MAX_IMAGE_SIDE);
    let height = opts.height.clamp(1, MAX_IMAGE_SIDE);
    // The sample grid is bounded by MAX_IMAGE_SIDE too: large frames get fewer samples.
    let ss = opts
        .supersample
        .clamp(1, 4)
        .min(MAX_IMAGE_SIDE / width.max(height))
        .max(1);
    let (sw, sh) = ((width * ss) as usize, (height * ss) as usize);

    let (vertices, triangles) = setup(meshes, camera, opts, sw, sh);

    // Bin triangles into bands; each band then draws its own list in input order.
    let bands = sh.div_ceil(BAND_ROWS);
    let mut bins: Vec<Vec<u32>> = vec![Vec::new(); bands];
    for (i, t) in triangles.iter().enumerate() {
        for bin in &mut bins[t.y0 as usize / BAND_ROWS..=t.y1 as usize / BAND_ROWS] {
            bin.push(i as u32);
        }
    }

    let mut samples = vec![EMPTY; sw * sh];
    samples
        .par_chunks_mut(BAND_ROWS * sw)
        .zip(bins.par_iter())
        .enumerate()
        .for_each(|(band, (buf, bin))| {
            let band_y0 = (band * BAND_ROWS) as i32;
            let band_y1 = band_y0 + (buf.len() / sw) as i32 - 1;
            for &ti in bin {
                let t = &triangles[ti as usize];
                raster_triangle(
                    t,
                    &vertices,
                    &opts.light,
                    opts.shading,
                    buf,
                    sw,
                    band_y0,
                    band_y1,
                );
            }
        });

    resolve(&samples, sw, width, height, ss, opts.background)
}

/// Projects every vertex and sets up every drawable triangle, in input order.
fn setup(
    meshes: &[RenderMesh],
    camera: &Camera,
    opts: &RenderOptions,
    sw: usize,
    sh: usize,
) -> (Vec<ScreenVertex>, Vec<SetupTriangle>) {
    let basis = camera.basis();
    let to_view = |v: Vec3| Vec3::new(v.dot(basis.right), v.dot(basis.up), v.dot(basis.back));
    let short = sw.min(sh) as f32;
    let (cx, cy) = (sw as f32 * 0.5, sh as f32 * 0.5);

    let mut vertices = Vec::new();
    let mut triangles = Vec::new();
    for mesh in meshes {
        let base = vertices.len() as u32;
        let computed;
        let normals = match mesh.normals {
            Some(n) if n.len() == mesh.positions.len() => n,
            _ => {
                computed = vertex_normals(mesh.positions, mesh.triangles);
                &computed[..]
            }
        };
        let projected: Vec<ScreenVertex> = mesh
            .positions
            .par_iter()
            .zip(normals.par_iter())
            .map(|(&p, &n)| {
                let v = to_view(p - camera.eye);
                let dist = -v.z;
                let (scale, depth, inv_w, usable) = match camera.projection {
                    Projection::Perspective { fov } => {
                        let f = short * 0.5 / (fov * 0.5).tan();
                        (f / dist, 1.0 / dist, 1.0 / dist, dist >= camera.near)
                    }
                    Projection::Orthographic { extent } => (short / extent, -dist, 1.0, true),
                };
                let (x, y) = (cx + v.x * scale, cy - v.y * scale);
                let usable = usable
                    && p.is_finite()
                    && x.abs() < GUARD_PIXELS
                    && y.abs() < GUARD_PIXELS
                    && depth.is_finite();
                ScreenVertex {
                    x: (x * SUBPIXEL as f32).round() as i64,
                    y: (y * SUBPIXEL as f32).round() as i64,
                    depth,
                    inv_w,
                    normal: to_view(n).normalize_or_zero(),
                    usable,
                }
            })
            .collect();
        vertices.extend(projected);

        let albedo = Vec3::from(mesh.colour.map(srgb_to_linear));
        let inside = mesh.inside_colour.map_or(albedo * INTERIOR_DARKENING, |c| {
            Vec3::from(c.map(srgb_to_linear)) * INTERIOR_DARKENING
        });
        let n = mesh.positions.len() as u32;
        for tri in mesh.triangles {
            if tri.iter().any(|&i| i >= n) {
                continue;
            }
            let idx = tri.map(|i| base + i);
            let [a, b, c] = idx.map(|i| vertices[i as usize]);
            if !(a.usable && b.usable && c.usable) {
                continue;
            }
            let area = edge(&a, &b, c.x, c.y);
            if area == 0 {
                continue;
            }
            // Counter-clockwise in the y-up view is negative in y-down sample space.
            let back = area > 0;
            if back && opts.cull_back_faces {
                continue;
            }
            let v = if back { idx } else { [idx[0], idx[2], idx[1]] };
            let sub = |z: i64, lo: bool| {
                // Sample k has its centre at k·256 + 128.
                let k = (z - SUBPIXEL / 2) as f64 / SUBPIXEL as f64;
                if lo {
                    k.ceil()
                } else {
                    k.floor()
                }
            };
            let xs = [a.x, b.x, c.x];
            let ys = [a.y, b.y, c.y];
            let x0 = sub(*xs.iter().min().unwrap_or(&0), true).max(0.0);
            let x1 = sub(*xs.iter().max().unwrap_or(&0), false).min(sw as f64 - 1.0);
            let y0 = sub(*ys.iter().min().unwrap_or(&0), true).max(0.0);
            let y1 = sub(*ys.iter().max().unwrap_or(&0), false).min(sh as f64 - 1.0);
            if x0 > x1 || y0 > y1 {
                continue;
            }
            let [pa, pb, pc] = tri.map(|i| mesh.positions[i as usize]);
            let mut face_normal = to_view((pb - pa).cross(pc - pa)).normalize_or_zero();
            if back {
                face_normal = -face_normal;
            }
            triangles.push(SetupTriangle {
                v,
                area: area.abs(),
                x0: x0 as i32,
                x1: x1 as i32,
                y0: y0 as i32,
                y1: y1 as i32,
                face_normal,
                albedo: if back { inside } else { albedo },
                back,
            });
        }
    }
    (vertices, triangles)
}

/// Twice the signed area of (a, b, p) in snapped units: positive when p is to the right of
/// a→b in y-down coordinates.
fn edge(a: &ScreenVertex, b: &ScreenVertex, px: i64, py: i64) -> i64 {
    (b.x - a.x) * (py - a.y) - (b.y - a.y) * (px - a.x)
}

/// Top-left rule for a positively oriented triangle in y-down coordinates: pixels exactly on
/// an edge belong to the triangle only if the edge is a top edge (horizontal, going right)
/// or a left edge (going up). Returns the bias subtracted from the edge function.
fn fill_bias(a: &ScreenVertex, b: &ScreenVertex) -> i64 {
    let (dx, dy) = (b.x - a.x, b.y - a.y);
    if dy < 0 || (dy == 0 && dx > 0) {
        0
    } else {
        1
    }
}

#[allow(clippy::too_many_arguments)]
fn raster_triangle(
    t: &SetupTriangle,
    vertices: &[ScreenVertex],
    light: &Light,
    shading: Shading,
    buf: &mut [Sample],
    sw: usize,
    band_y0: i32,
    band_y1: i32,
) {
    let [a, b, c] = t.v.map(|i| vertices[i as usize]);
    let y0 = t.y0.max(band_y0);
    let y1 = t.y1.min(band_y1);
    // Edge i is opposite vertex i: its function is vertex i's barycentric weight × area.
    let edges = [(b, c), (c, a), (a, b)];
    let bias = edges.map(|(p, q)| fill_bias(&p, &q));
    // Step per sample to the right: ∂E/∂x = −(q.y − p.y) in snapped units.
    let step = edges.map(|(p, q)| -(q.y - p.y) * SUBPIXEL);
    let inv_area = 1.0 / t.area as f32;
    let verts = [a, b, c];
    for y in y0..=y1 {
        let py = y as i64 * SUBPIXEL + SUBPIXEL / 2;
        let px = t.x0 as i64 * SUBPIXEL + SUBPIXEL / 2;
        let mut e = [0i64; 3];
        for k in 0..3 {
            e[k] = edge(&edges[k].0, &edges[k].1, px, py) - bias[k];
        }
        let row = (y - band_y0) as usize * sw;
        for x in t.x0..=t.x1 {
            if (e[0] | e[1] | e[2]) >= 0 {
                // Undo the bias so the weights are the true barycentrics.
                let w = [0, 1, 2].map(|k| (e[k] + bias[k]) as f32 * inv_area);
                let depth = w[0] * a.depth + w[1] * b.depth + w[2] * c.depth;
                let s = &mut buf[row + x as usize];
                if depth > s.depth {
                    let normal = match shading {
                        Shading::Flat => t.face_normal,
                        Shading::Smooth => {
                            let pw = [0, 1, 2].map(|k| w[k] * verts[k].inv_w);
                            let n = (verts[0].normal * pw[0]
                                + verts[1].normal * pw[1]
                                + verts[2].normal * pw[2])
                                .normalize_or(t.face_normal);
                            if t.back {
                                -n
                            } else {
                                n
                            }
                        }
                    };
                    *s = Sample {
                        depth,
                        rgb: shade(t.albedo, normal, light),
                    };
                }
            }
            for k in 0..3 {
                e[k] += step[k];
            }
        }
    }
}

/// Lambert key + fill + ambient, plus a Blinn-Phong highlight from the key light, with the
/// viewer along +z of the view frame.
fn shade(albedo: Vec3, n: Vec3, light: &Light) -> Vec3 {
    let key = light.key_direction.normalize_or_zero();
    let fill = light.fill_direction.normalize_or_zero();
    let diffuse = light.ambient
        + light.key_intensity * n.dot(key).max(0.0)
        + light.fill_intensity * n.dot(fill).max(0.0);
    let half = (key + Vec3::Z).normalize_or_zero();
    let spec = if n.dot(key) > 0.0 {
        light.specular * light.key_intensity * n.dot(half).max(0.0).powf(light.shininess)
    } else {
        0.0
    };
    albedo * diffuse + Vec3::splat(spec)
}

/// Averages each pixel's samples in linear light (background samples weighted by the
/// background alpha) and encodes sRGB. Pixels without geometry get exactly the background.
fn resolve(
    samples: &[Sample],
    sw: usize,
    width: u32,
    height: u32,
    ss: u32,
    background: [u8; 4],
) -> Image {
    let bg_rgb = Vec3::new(
        srgb8_to_linear(background[0]),
        srgb8_to_linear(background[1]),
        srgb8_to_linear(background[2]),
    );
    let bg_a = background[3] as f32 / 255.0;
    let n = (ss * ss) as f32;
    let mut rgba = vec![0u8; width as usize * height as usize * 4];
    rgba.par_chunks_mut(width as usize * 4)
        .enumerate()
        .for_each(|(y, row)| {
            for x in 0..width as usize {
                let (mut premul, mut alpha, mut hits) = (Vec3::ZERO, 0.0f32, 0);
                for sy in 0..ss as usize {
                    let line = (y * ss as usize + sy) * sw;
                    for sx in 0..ss as usize {
                        let s = samples[line + x * ss as usize + sx];
                        if s.depth > f32::NEG_INFINITY {
                            premul += s.rgb;
                            alpha += 1.0;
                            hits += 1;
                        } else {
                            premul += bg_rgb * bg_a;
                            alpha += bg_a;
                        }
                    }
                }
                let px = if hits == 0 {
                    background
                } else {
                    let c = premul / alpha;
                    [
                        linear_to_srgb8(c.x),
                        linear_to_srgb8(c.y),
                        linear_to_srgb8(c.z),
                        (alpha / n * 255.0).round() as u8,
                    ]
                };
                row[x * 4..x * 4 + 4].copy_from_slice(&px);
            }
        });
    Image {
        width,
        height,
        rgba,
    }
}
