//! The mesh as the derivation rules see it: a face frame from the landmarks, the skin (the
//! connected parts that carry landmarks), front-view ray casts on the skin and the other parts
//! (eyeballs, teeth, lashes) as separate components.

use glam::{DVec3, Vec3};

use crate::mesh::spatial::VertexIndex;
use crate::mesh::Mesh;

/// An orthonormal face frame: +x towards the face's left, +y up, +z forward (out of the
/// face), origin between the eyes. Derivations work in it so a rotated head gives the same
/// points.
#[derive(Clone, Copy, Debug)]
pub(super) struct FaceFrame {
    origin: Vec3,
    x: Vec3,
    y: Vec3,
    z: Vec3,
}

impl FaceFrame {
    /// The frame from the eye centres, the mouth centre and the nose tip. Errors when the
    /// points are degenerate or give a mirrored face (nose behind the eyes' line).
    pub fn from_points(
        left_eye: Vec3,
        right_eye: Vec3,
        mouth: Vec3,
        nose_tip: Vec3,
    ) -> Result<FaceFrame, String> {
        let eyes = (left_eye + right_eye) * 0.5;
        let x = (left_eye - right_eye).normalize_or_zero();
        let up = eyes - mouth;
        let y = (up - x * up.dot(x)).normalize_or_zero();
        if x == Vec3::ZERO || y == Vec3::ZERO {
            return Err(
                "the eye corners and mouth corners landmarks coincide or are collinear".into(),
            );
        }
        let z = x.cross(y);
        // The eyes-to-mouth line leans with the face (mouth forward of the eyes), so a head
        // already upright in its own axes keeps them: only a clearly rotated head is
        // re-framed by the landmarks.
        let snap = SNAP_DEGREES.to_radians().cos();
        let frame = if x.dot(Vec3::X) > snap && y.dot(Vec3::Y) > snap {
            FaceFrame {
                origin: eyes,
                x: Vec3::X,
                y: Vec3::Y,
                z: Vec3::Z,
            }
        } else {
            FaceFrame {
                origin: eyes,
                x,
                y,
                z,
            }
        };
        if frame.to_local(nose_tip).z <= 0.0 {
            return Err("the nose tip is behind the eyes for a face whose left is the landmarks' left: the mesh is mirrored or the landmarks are not in the scheme's order".into());
        }
        Ok(frame)
    }

    /// A point in frame coordinates.
    pub fn to_local(self, p: Vec3) -> Vec3 {
        let d = p - self.origin;
        Vec3::new(d.dot(self.x), d.dot(self.y), d.dot(self.z))
    }
}

/// Largest angle (degrees) between the landmark frame and the mesh's own axes for which the
/// mesh's axes are used as they are.
pub(super) const SNAP_DEGREES: f32 = 25.0;

/// A front-view ray hit on the skin.
#[derive(Clone, Copy, Debug)]
pub(super) struct Hit {
    /// The hit point in frame coordinates.
    pub point: Vec3,
}

/// The mesh in the face frame, split into the skin and the other parts.
pub(super) struct Skin {
    /// Every vertex in frame coordinates.
    pub local: Vec<Vec3>,
    /// Connected component of every vertex.
    pub component: Vec<u32>,
    /// Number of components.
    pub component_count: usize,
    /// Per component: part of the skin.
    pub skin_component: Vec<bool>,
    /// Skin triangles (vertex indices into `local`).
    triangles: Vec<[u32; 3]>,
    grid: Grid,
    skin_vertices: Vec<u32>,
    skin_index: VertexIndex,
}

impl Skin {
    /// Splits `mesh` into components and takes as skin every component holding one of the
    /// `landmark_vertices`.
    pub fn new(mesh: &Mesh, frame: &FaceFrame, landmark_vertices: &[u32]) -> Skin {
        let local: Vec<Vec3> = mesh.positions.iter().map(|&p| frame.to_local(p)).collect();
        let (component, component_count) = crate::mesh::components::connected_components(mesh, &[]);
        let mut skin_component = vec![false; component_count];
        for &v in landmark_vertices {
            if let Some(&c) = component.get(v as usize) {
                skin_component[c as usize] = true;
            }
        }
        let (all, _) = crate::mesh::geometry::triangulate(&mesh.positions, &mesh.polygons);
        let triangles: Vec<[u32; 3]> = all
            .into_iter()
            .filter(|t| skin_component[component[t[0] as usize] as usize])
            .collect();
        let grid = Grid::new(&local, &triangles);
        let skin_vertices: Vec<u32> = (0..local.len() as u32)
            .filter(|&v| skin_component[component[v as usize] as usize])
            .collect();
        let skin_points: Vec<Vec3> = skin_vertices.iter().map(|&v| local[v as usize]).collect();
        let skin_index = VertexIndex::new(&skin_points);
        Skin {
            local,
            component,
            component_count,
            skin_component,
            triangles,
            grid,
            skin_vertices,
            skin_index,
        }
    }

    /// The front-most skin point on the line through (x, y) along the frame's z.
    pub fn front(&self, x: f32, y: f32) -> Option<Hit> {
        let mut best: Option<Hit> = None;
        for &t in self.grid.cell(x, y) {
            let [a, b, c] = self.triangles[t as usize].map(|v| self.local[v as usize]);
            if let Some(z) = triangle_z(a, b, c, x, y) {
                if best.is_none_or(|h| z > h.point.z) {
                    best = Some(Hit {
                        point: Vec3::new(x, y, z),
                    });
                }
            }
        }
        best
    }

    /// The skin vertex nearest to a frame-coordinate point.
    pub fn nearest_skin_vertex(&self, p: Vec3) -> Option<u32> {
        self.skin_index
            .nearest_vertex(p)
            .map(|(i, _)| self.skin_vertices[i as usize])
    }

    /// All skin vertices.
    pub fn skin_vertices(&self) -> &[u32] {
        &self.skin_vertices
    }
}

/// The z of the triangle's plane at (x, y) when (x, y) lies inside its xy projection.
fn triangle_z(a: Vec3, b: Vec3, c: Vec3, x: f32, y: f32) -> Option<f32> {
    let (a, b, c) = (a.as_dvec3(), b.as_dvec3(), c.as_dvec3());
    let (x, y) = (x as f64, y as f64);
    let det = (b.x - a.x) * (c.y - a.y) - (c.x - a.x) * (b.y - a.y);
    if det.abs() < 1e-18 {
        return None;
    }
    let u = ((x - a.x) * (c.y - a.y) - (c.x - a.x) * (y - a.y)) / det;
    let v = ((b.x - a.x) * (y - a.y) - (x - a.x) * (b.y - a.y)) / det;
    let eps = 1e-9;
    if u < -eps || v < -eps || u + v > 1.0 + eps {
        return None;
    }
    Some((a.z + u * (b.z - a.z) + v * (c.z - a.z)) as f32)
}

/// Least-squares sphere through points: (centre, radius, RMS distance to the sphere).
pub(super) fn fit_sphere(points: &[Vec3]) -> Option<(Vec3, f32, f32)> {
    if points.len() < 4 {
        return None;
    }
    // |p|² = 2 c·p + k, linear in (c, k); solved by normal equations in f64.
    let mean = points.iter().map(|p| p.as_dvec3()).sum::<DVec3>() / points.len() as f64;
    let mut ata = nalgebra::Matrix4::<f64>::zeros();
    let mut atb = nalgebra::Vector4::<f64>::zeros();
    for p in points {
        let q = p.as_dvec3() - mean;
        let row = nalgebra::Vector4::new(2.0 * q.x, 2.0 * q.y, 2.0 * q.z, 1.0);
        ata += row * row.transpose();
        atb += row * q.length_squared();
    }
    let sol = ata.lu().solve(&atb)?;
    let c = DVec3::new(sol[0], sol[1], sol[2]);
    let r2 = sol[3] + c.length_squared();
    if !r2.is_finite() || r2 <= 0.0 {
        return None;
    }
    let r = r2.sqrt();
    let rms = (points
        .iter()
        .map(|p| {
            let d = (p.as_dvec3() - mean - c).length() - r;
            d * d
        })
        .sum::<f64>()
        / points.len() as f64)
        .sqrt();
    Some(((c + mean).as_vec3(), r as f32, rms as f32))
}

/// A uniform grid over the xy bounds of the skin triangles, each cell listing the triangles
/// whose bounding box meets it.
struct Grid {
    min: (f32, f32),
    cell: f32,
    nx: usize,
    ny: usize,
    start: Vec<u32>,
    items: Vec<u32>,
}

/// Upper bound on grid entries (a hostile mesh of huge triangles makes the grid coarser
/// instead of allocating without bound).
const MAX_GRID_ENTRIES: usize = 1 << 25;

impl Grid {
    fn new(local: &[Vec3], triangles: &[[u32; 3]]) -> Grid {
        let (mut lo, mut hi) = ((f32::MAX, f32::MAX), (f32::MIN, f32::MIN));
        for t in triangles {
            for &v in t {
                let p = local[v as usize];
                lo = (lo.0.min(p.x), lo.1.min(p.y));
                hi = (hi.0.max(p.x), hi.1.max(p.y));
            }
        }
        if triangles.is_empty() || !(hi.0 >= lo.0 && hi.1 >= lo.1) {
            return Grid {
                min: (0.0, 0.0),
                cell: 1.0,
                nx: 0,
                ny: 0,
                start: vec![0],
                items: Vec::new(),
            };
        }
        let extent = (hi.0 - lo.0).max(hi.1 - lo.1).max(f32::MIN_POSITIVE);
        let mut side = ((triangles.len() as f64).sqrt() as usize).clamp(1, 512);
        loop {
            let cell = extent / side as f32 * 1.0001;
            let nx = (((hi.0 - lo.0) / cell) as usize + 1).min(side + 1);
            let ny = (((hi.1 - lo.1) / cell) as usize + 1).min(side + 1);
            let span = |t: &[u32; 3]| {
                let (mut a, mut b) = ((f32::MAX, f32::MAX), (f32::MIN, f32::MIN));
                for &v in t {
                    let p = local[v as usize];
                    a = (a.0.min(p.x), a.1.min(p.y));
                    b = (b.0.max(p.x), b.1.max(p.y));
                }
                let c = |v: f32, o: f32, n: usize| (((v - o) / cell) as usize).min(n - 1);
                (
                    c(a.0, lo.0, nx),
                    c(b.0, lo.0, nx),
                    c(a.1, lo.1, ny),
                    c(b.1, lo.1, ny),
                )
            };
            let total: usize = triangles
                .iter()
                .map(|t| {
                    let (x0, x1, y0, y1) = span(t);
                    (x1 - x0 + 1) * (y1 - y0 + 1)
                })
                .sum();
            if total > MAX_GRID_ENTRIES && side > 1 {
                side /= 2;
                continue;
            }
            let mut count = vec![0u32; nx * ny + 1];
            for t in triangles {
                let (x0, x1, y0, y1) = span(t);
                for j in y0..=y1 {
                    for i in x0..=x1 {
                        count[j * nx + i + 1] += 1;
                    }
                }
            }
            for k in 1..count.len() {
                count[k] += count[k - 1];
            }
            let mut fill = count.clone();
            let mut items = vec![0u32; total];
            for (ti, t) in triangles.iter().enumerate() {
                let (x0, x1, y0, y1) = span(t);
                for j in y0..=y1 {
                    for i in x0..=x1 {
                        let k = j * nx + i;
                        items[fill[k] as usize] = ti as u32;
                        fill[k] += 1;
                    }
                }
            }
            return Grid {
                min: lo,
                cell,
                nx,
                ny,
                start: count,
                items,
            };
        }
    }

    fn cell(&self, x: f32, y: f32) -> &[u32] {
        if self.nx == 0 || !x.is_finite() || !y.is_finite() {
            return &[];
        }
        let fx = (x - self.min.0) / self.cell;
        let fy = (y - self.min.1) / self.cell;
        if fx < 0.0 || fy < 0.0 || fx >= self.nx as f32 || fy >= self.ny as f32 {
            return &[];
        }
        let k = fy as usize * self.nx + fx as usize;
        &self.items[self.start[k] as usize..self.start[k + 1] as usize]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 2×2 square at z = 1 in front of a 2×2 square at z = 0 with a hole in the front one.
    fn two_layers() -> Mesh {
        let mut p = Vec::new();
        let mut tris = Vec::new();
        for (z, skip_centre) in [(0.0f32, false), (1.0, true)] {
            let base = p.len() as u32;
            for j in 0..3 {
                for i in 0..3 {
                    p.push(Vec3::new(i as f32 - 1.0, j as f32 - 1.0, z));
                }
            }
            // Four unit cells per layer; the front layer drops the cell at (0..1, 0..1).
            for j in 0..2u32 {
                for i in 0..2u32 {
                    if skip_centre && i == 1 && j == 1 {
                        continue;
                    }
                    let v = base + j * 3 + i;
                    tris.push([v, v + 1, v + 4]);
                    tris.push([v, v + 4, v + 3]);
                }
            }
        }
        Mesh::from_triangles("t", p, &tris)
    }

    #[test]
    fn front_cast_sees_the_front_layer_and_the_hole() {
        let mesh = two_layers();
        let frame = FaceFrame {
            origin: Vec3::ZERO,
            x: Vec3::X,
            y: Vec3::Y,
            z: Vec3::Z,
        };
        let skin = Skin::new(&mesh, &frame, &[0, 9]);
        // Two layers plus the front corner vertex that only the dropped cell used.
        assert_eq!(skin.component_count, 3);
        assert_eq!(skin.skin_component.iter().filter(|&&s| s).count(), 2);
        assert_eq!(skin.front(-0.5, -0.5).unwrap().point.z, 1.0);
        // The hole in the front layer shows the back layer.
        assert_eq!(skin.front(0.5, 0.5).unwrap().point.z, 0.0);
        assert!(skin.front(3.0, 0.0).is_none());
        // Only the back layer as skin.
        let back = Skin::new(&mesh, &frame, &[0]);
        assert_eq!(back.front(-0.5, -0.5).unwrap().point.z, 0.0);
        assert_eq!(back.nearest_skin_vertex(Vec3::new(1.0, 1.0, 1.0)), Some(8));
    }

    #[test]
    fn frame_rejects_mirrored_faces() {
        let f = FaceFrame::from_points(
            Vec3::new(3.0, 0.0, 0.0),
            Vec3::new(-3.0, 0.0, 0.0),
            Vec3::new(0.0, -6.0, 0.0),
            Vec3::new(0.0, -3.0, 2.0),
        )
        .unwrap();
        assert!((f.to_local(Vec3::new(1.0, 2.0, 3.0)) - Vec3::new(1.0, 2.0, 3.0)).length() < 1e-6);
        // Left and right swapped: the nose points backwards in the implied frame.
        let e = FaceFrame::from_points(
            Vec3::new(-3.0, 0.0, 0.0),
            Vec3::new(3.0, 0.0, 0.0),
            Vec3::new(0.0, -6.0, 0.0),
            Vec3::new(0.0, -3.0, 2.0),
        )
        .unwrap_err();
        assert!(e.contains("mirrored"), "{e}");
    }

    #[test]
    fn sphere_fit_recovers_a_sphere() {
        let c = Vec3::new(1.0, -2.0, 0.5);
        let mut pts = Vec::new();
        for i in 0..20 {
            for j in 1..10 {
                let (t, p) = (i as f32 * 0.314, j as f32 * 0.314);
                pts.push(c + 1.5 * Vec3::new(p.sin() * t.cos(), p.sin() * t.sin(), p.cos()));
            }
        }
        let (fc, r, rms) = fit_sphere(&pts).unwrap();
        assert!((fc - c).length() < 1e-4 && (r - 1.5).abs() < 1e-4 && rms < 1e-4);
        assert!(fit_sphere(&pts[..3]).is_none());
    }
}
