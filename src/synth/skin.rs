//! The skin: a deformed ellipsoid on a (longitude, latitude) grid with eye holes, a mouth slit
//! and feature bumps, plus the skin feature points.
//!
//! Grid: column `k` (0..columns) has longitude `π·(s(1−c) + c·s³)` with `s = (2k − columns) /
//! columns` (column `columns/2` is the front midline, column 0 the back), row `j` (0..=rows)
//! has latitude `π/2·(t(1−r) + r·t³)`, `t = 2j/rows − 1`; rows 0 and `rows` are single pole
//! vertices. Front features displace along z only (ears along x), so a grid row keeps one `y`
//! except near the eyes, where the parameter plane is warped so that a rectangle of removed
//! cells becomes an elliptical opening whose boundary vertices lie exactly on the ellipse.
//! The mouth slit is one grid row between the two corner columns: its interior vertices are
//! duplicated, the upper lip keeps the originals and the cells below use the copies.

use std::collections::HashSet;

use glam::{DVec2, DVec3};

use super::{HeadParams, PolygonStyle};
use crate::spec::FeaturePointId;

/// The built skin and what the rest of the generator needs to know about it.
pub(super) struct Skin {
    /// Vertex positions, face coordinates.
    pub positions: Vec<DVec3>,
    /// Polygons, CCW from outside.
    pub polygons: Vec<Vec<u32>>,
    /// Mirror image (x → −x) of every vertex.
    pub mirror: Vec<u32>,
    /// True for vertices on the lower-lip side of the mouth slit (rows below it and the slit
    /// copies); the slit corners and everything above are upper side.
    pub lower: Vec<bool>,
    /// Post-warp coordinates normalised to the eye opening on the vertex's side: the opening
    /// boundary is the unit circle, +u towards the outer corner, +v up.
    pub eye_coords: Vec<DVec2>,
    /// Skin feature points.
    pub feature_points: Vec<(FeaturePointId, u32)>,
}

impl Skin {
    /// Position of a skin feature point.
    pub fn fp(&self, id: FeaturePointId) -> DVec3 {
        let v = self
            .feature_points
            .iter()
            .find(|(f, _)| *f == id)
            .map(|(_, v)| *v)
            .unwrap_or_else(|| panic!("skin has no feature point {id}"));
        self.positions[v as usize]
    }
}

pub(super) fn smoothstep(e0: f64, e1: f64, x: f64) -> f64 {
    let t = ((x - e0) / (e1 - e0)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

fn gauss(d: f64, sigma: f64) -> f64 {
    (-(d * d) / (2.0 * sigma * sigma)).exp()
}

/// The analytic head surface for one set of parameters.
struct Shape<'a> {
    p: &'a HeadParams,
    /// Left-eye opening in the parameter plane: centre (|lon|, lat) and half sizes
    /// (inner, outer, down, up).
    eye_centre: DVec2,
    eye_half: [f64; 4],
}

impl Shape<'_> {
    fn ry(&self, lat: f64) -> f64 {
        let p = self.p;
        p.head_bottom + (p.head_top - p.head_bottom) * smoothstep(-0.3, 0.3, lat)
    }

    /// Rectangle-to-ellipse warp of the parameter plane around the left eye (identity far
    /// away). Monotone along every ray from the centre, hence fold-free.
    fn warp(&self, a: f64, lat: f64) -> (f64, f64) {
        let (u, v) = self.eye_normalised(a, lat);
        let nr = u.abs().max(v.abs());
        if nr >= 2.0 || nr == 0.0 {
            return (a, lat);
        }
        let s = nr / u.hypot(v);
        let t = if nr <= 1.0 {
            1.0
        } else {
            smoothstep(0.0, 1.0, 2.0 - nr)
        };
        let k = 1.0 + (s - 1.0) * t;
        self.eye_denormalised(u * k, v * k)
    }

    fn eye_normalised(&self, a: f64, lat: f64) -> (f64, f64) {
        let du = a - self.eye_centre.x;
        let dv = lat - self.eye_centre.y;
        let [inner, outer, down, up] = self.eye_half;
        (
            du / if du < 0.0 { inner } else { outer },
            dv / if dv < 0.0 { down } else { up },
        )
    }

    fn eye_denormalised(&self, u: f64, v: f64) -> (f64, f64) {
        let [inner, outer, down, up] = self.eye_half;
        (
            self.eye_centre.x + u * if u < 0.0 { inner } else { outer },
            self.eye_centre.y + v * if v < 0.0 { down } else { up },
        )
    }

    /// Surface point at parameter (|lon|, lat) after the warp; x >= 0.
    fn surface(&self, a: f64, lat: f64) -> DVec3 {
        let p = self.p;
        let (cl, sl) = (lat.cos().max(0.0), lat.sin());
        let (ca, sa) = (a.cos(), a.sin());
        let rz = p.back_depth + (p.face_depth - p.back_depth) * smoothstep(-0.3, 0.3, ca);
        let y = self.ry(lat) * sl;
        let zb = rz * cl * ca;
        let frontness = smoothstep(-0.2, 0.6, ca);
        let jaw =
            1.0 - (1.0 - p.jaw_ratio) * smoothstep(p.mouth_y + 15.0, p.chin_y - 5.0, y) * frontness;
        let xb = p.head_half_width * cl * sa;
        let x = xb * jaw;
        // Front features displace along z, fading out towards the sides.
        let front = smoothstep(0.15, 0.6, zb / p.face_depth);
        let dz = if front > 0.0 {
            front * self.front_relief(x, y)
        } else {
            0.0
        };
        // Ears: a lump on each side, displacing outwards.
        let er = ((y - p.ear_y) / p.ear_half_height).powi(2)
            + ((zb - p.ear_z) / p.ear_half_depth).powi(2);
        let side = smoothstep(0.55, 0.8, xb / p.head_half_width);
        let dx = if er < 1.0 {
            p.ear_protrusion * (1.0 - er).powf(1.5) * side
        } else {
            0.0
        };
        DVec3::new(x + dx, y, zb + dz)
    }

    /// z relief of the face at (x, y), x >= 0.
    fn front_relief(&self, x: f64, y: f64) -> f64 {
        let p = self.p;
        let xe = p.eye_separation / 2.0;
        let (ea, eb) = (p.eye_half_width, p.eye_half_height);
        let mut dz = 0.0;
        // Eye sockets and brow ridge.
        dz -= 5.0 * gauss(x - xe, 1.3 * ea) * gauss(y - (p.eye_y - 1.0), 2.2 * eb);
        dz += 3.5 * gauss(y - (p.eye_y + p.brow_height), 5.0) * gauss(x - xe, ea + 8.0);
        // Nose: bridge from between the eyes to the tip, steep underside down to 9.15.
        let y_top = p.eye_y - 2.0;
        let y_base = p.nose_bottom_y;
        let y_tip = y_base + 0.2 * (p.eye_y - y_base);
        let nl = p.nose_length;
        let (prof, sigma) = if y >= y_top {
            (0.15 * nl * gauss(y - y_top, 6.0), 4.0)
        } else if y >= y_tip {
            let t = (y_top - y) / (y_top - y_tip);
            (
                nl * (0.15 + 0.85 * t.powf(1.4)),
                4.0 + (0.55 * p.nose_half_width - 4.0) * t,
            )
        } else if y >= y_base {
            let q = (y_tip - y) / (y_tip - y_base);
            (nl * (1.0 - q * q).powf(0.7), 0.55 * p.nose_half_width)
        } else {
            (0.0, 1.0)
        };
        dz += prof * gauss(x, sigma);
        // Nostril wings.
        dz += 0.3
            * nl
            * gauss(x - 0.7 * p.nose_half_width, 0.3 * p.nose_half_width)
            * gauss(y - (y_base + 4.0), 4.0)
            * smoothstep(y_base - 1.5, y_base + 1.5, y);
        // Cheeks and chin.
        dz += 7.0 * gauss(x - (xe + 4.0), 15.0) * gauss(y - (p.nose_bottom_y + 4.0), 15.0);
        dz += 6.0 * gauss(x, 13.0) * gauss(y - (p.chin_y + 14.0), 9.0);
        // Lips: one lump above and one below the slit, equal on the slit, and a shallow groove.
        let h = if y >= p.mouth_y {
            p.upper_lip_height
        } else {
            p.lower_lip_height
        };
        let r2 = (x / (1.1 * p.mouth_half_width)).powi(2) + ((y - p.mouth_y) / (1.4 * h)).powi(2);
        if r2 < 1.0 {
            dz += p.lip_protrusion * (1.0 - r2).powi(2);
        }
        let across = 1.0 - (x / p.mouth_half_width).powi(2);
        if across > 0.0 {
            dz -= 0.35 * p.lip_protrusion * gauss(y - p.mouth_y, 1.2) * across;
        }
        dz
    }
}

fn nearest_index(values: impl Iterator<Item = (usize, f64)>, target: f64) -> usize {
    values
        .min_by(|a, b| (a.1 - target).abs().total_cmp(&(b.1 - target).abs()))
        .map(|(i, _)| i)
        .expect("non-empty")
}

/// Builds the skin of `p`.
// Grid code reads best with explicit (k, j) indices.
#[allow(clippy::needless_range_loop)]
pub(super) fn build(p: &HeadParams) -> Skin {
    use std::f64::consts::{FRAC_PI_2, PI};
    let nu = p.columns;
    let nv = p.rows;
    assert!(
        nu >= 16 && nu % 4 == 0 && nv >= 12 && nv % 2 == 0,
        "grid too small"
    );
    let half = nu / 2;
    let lon = |k: usize| -> f64 {
        let s = (2.0 * k as f64 - nu as f64) / nu as f64;
        let c = p.column_crowding;
        PI * (s * (1.0 - c) + c * s * s * s)
    };
    let lats: Vec<f64> = (0..=nv)
        .map(|j| {
            let t = (2.0 * j as f64 - nv as f64) / nv as f64;
            let r = p.row_crowding;
            FRAC_PI_2 * (t * (1.0 - r) + r * t * t * t)
        })
        .collect();
    let lons: Vec<f64> = (0..nu).map(lon).collect();

    // Choose the eye centre column/row and the opening size in grid cells on the unwarped
    // surface, then set up the warp.
    let mut shape = Shape {
        p,
        eye_centre: DVec2::ZERO,
        eye_half: [1.0; 4],
    };
    let r_e = nearest_index(
        (1..nv).map(|j| (j, shape.ry(lats[j]) * lats[j].sin())),
        p.eye_y,
    );
    let lat_e = lats[r_e];
    let x_at = |shape: &Shape, k: usize, j: usize| shape.surface(lons[k].abs(), lats[j]).x;
    let c_e = nearest_index(
        (half + 1..nu).map(|k| (k, x_at(&shape, k, r_e))),
        p.eye_separation / 2.0,
    );
    let dx_col = x_at(&shape, c_e + 1, r_e) - x_at(&shape, c_e, r_e);
    let dy_row = shape.ry(lats[r_e + 1]) * lats[r_e + 1].sin() - shape.ry(lat_e) * lat_e.sin();
    let m = ((p.eye_half_width / dx_col).round() as usize).max(2);
    let n = ((p.eye_half_height / dy_row).round() as usize).max(1);
    assert!(
        c_e >= half + 2 * m + 2 && c_e + 2 * m < nu && r_e > 2 * n && r_e + 2 * n < nv,
        "eye opening does not fit the grid"
    );
    shape.eye_centre = DVec2::new(lons[c_e], lat_e);
    shape.eye_half = [
        lons[c_e] - lons[c_e - m],
        lons[c_e + m] - lons[c_e],
        lat_e - lats[r_e - n],
        lats[r_e + n] - lat_e,
    ];

    // Mouth slit row and corner columns.
    let j_m = nearest_index(
        (1..nv).map(|j| (j, shape.ry(lats[j]) * lats[j].sin())),
        p.mouth_y,
    );
    let c_l = nearest_index(
        (half + 2..nu).map(|k| (k, x_at(&shape, k, j_m))),
        p.mouth_half_width,
    );
    assert!(
        c_l >= half + 2 && j_m + 2 * n < r_e - 2 * n,
        "mouth does not fit the grid"
    );
    let c_r = nu - c_l;

    // Grid vertices: bottom pole, rows 1..nv-1, top pole, then slit copies.
    let gid = |k: usize, j: usize| -> usize {
        if j == 0 {
            0
        } else if j == nv {
            1 + (nv - 1) * nu
        } else {
            1 + (j - 1) * nu + (k % nu)
        }
    };
    let grid_count = 2 + (nv - 1) * nu;
    let mut positions = vec![DVec3::ZERO; grid_count];
    let mut eye_coords = vec![DVec2::splat(1e3); grid_count];
    let mut mirror = vec![0usize; grid_count];
    let mut lower = vec![false; grid_count];
    positions[0] = DVec3::new(0.0, -shape.ry(-FRAC_PI_2), 0.0);
    positions[grid_count - 1] = DVec3::new(0.0, shape.ry(FRAC_PI_2), 0.0);
    mirror[grid_count - 1] = grid_count - 1;
    for j in 1..nv {
        for k in half..=nu {
            // k == nu stands for column 0 (the back midline, |lon| = π).
            let kk = k % nu;
            let a = if k == nu { PI } else { lons[k] };
            let (wa, wl) = shape.warp(a, lats[j]);
            let mut pos = shape.surface(wa, wl);
            if k == half || k == nu {
                pos.x = 0.0;
            }
            let (u, v) = shape.eye_normalised(wa, wl);
            let g = gid(kk, j);
            positions[g] = pos;
            eye_coords[g] = DVec2::new(u, v);
            let gm = gid((nu - kk) % nu, j);
            positions[gm] = DVec3::new(-pos.x, pos.y, pos.z);
            eye_coords[gm] = DVec2::new(u, v);
            mirror[g] = gm;
            mirror[gm] = g;
            lower[g] = j < j_m;
            lower[gm] = j < j_m;
        }
    }
    // Slit copies of the interior slit vertices (columns strictly between the corners).
    let mut dup_of = vec![usize::MAX; nu];
    for k in c_r + 1..c_l {
        let g = gid(k, j_m);
        dup_of[k] = positions.len();
        positions.push(positions[g]);
        eye_coords.push(eye_coords[g]);
        lower.push(true);
        mirror.push(0);
    }
    for k in c_r + 1..c_l {
        mirror[dup_of[k]] = dup_of[nu - k];
    }

    // Cells.
    let is_eye_cell = |k: usize, j: usize| -> bool {
        let in_rows = j >= r_e - n && j < r_e + n;
        let left = k >= c_e - m && k < c_e + m;
        let kr = nu - c_e; // right eye centre column
        let right = k >= kr - m && k < kr + m;
        in_rows && (left || right)
    };
    let mut quads: Vec<[usize; 4]> = Vec::with_capacity(nu * nv);
    let mut cell_parity: Vec<bool> = Vec::with_capacity(nu * nv);
    for j in 0..nv {
        for k in 0..nu {
            if is_eye_cell(k, j) {
                continue;
            }
            let k1 = (k + 1) % nu;
            let mut top = [gid(k, j + 1), gid(k1, j + 1)];
            if j + 1 == j_m {
                if k > c_r && k < c_l {
                    top[0] = dup_of[k];
                }
                if k1 > c_r && k1 < c_l {
                    top[1] = dup_of[k1];
                }
            }
            quads.push([gid(k, j), gid(k1, j), top[1], top[0]]);
            cell_parity.push((k + j) % 2 == 0);
        }
    }
    let mut polygons: Vec<Vec<usize>> = Vec::with_capacity(quads.len() * 2);
    for (q, parity) in quads.iter().zip(cell_parity) {
        if q[0] == q[1] {
            polygons.push(vec![q[0], q[2], q[3]]); // bottom cap
        } else if q[2] == q[3] {
            polygons.push(vec![q[0], q[1], q[2]]); // top cap
        } else {
            match p.polygons {
                PolygonStyle::Quads => polygons.push(q.to_vec()),
                PolygonStyle::Triangles if parity => {
                    polygons.push(vec![q[0], q[1], q[2]]);
                    polygons.push(vec![q[0], q[2], q[3]]);
                }
                PolygonStyle::Triangles => {
                    polygons.push(vec![q[0], q[1], q[3]]);
                    polygons.push(vec![q[1], q[2], q[3]]);
                }
            }
        }
    }

    // Drop vertices no polygon uses (inside the eye openings) and renumber.
    let mut used = vec![false; positions.len()];
    for poly in &polygons {
        for &v in poly {
            used[v] = true;
        }
    }
    let mut new_index = vec![u32::MAX; positions.len()];
    let mut next = 0u32;
    for (i, &u) in used.iter().enumerate() {
        if u {
            new_index[i] = next;
            next += 1;
        }
    }
    let skin_positions: Vec<DVec3> = keep_used(&positions, &used);
    let skin_eye: Vec<DVec2> = keep_used(&eye_coords, &used);
    let skin_lower: Vec<bool> = keep_used(&lower, &used);
    let skin_mirror: Vec<u32> = mirror
        .iter()
        .zip(&used)
        .filter(|(_, &u)| u)
        .map(|(&m, _)| new_index[m])
        .collect();
    let skin_polygons: Vec<Vec<u32>> = polygons
        .iter()
        .map(|poly| poly.iter().map(|&v| new_index[v]).collect())
        .collect();

    let mut skin = Skin {
        positions: skin_positions,
        polygons: skin_polygons,
        mirror: skin_mirror,
        lower: skin_lower,
        eye_coords: skin_eye,
        feature_points: Vec::new(),
    };
    let at = |k: usize, j: usize| new_index[gid(k, j)];
    let grid_fps = GridLandmarks {
        bottom_pole: new_index[0],
        top_pole: new_index[grid_count - 1],
        lid_top: at(c_e, r_e + n),
        lid_bottom: at(c_e, r_e - n),
        lid_top_outer: at(c_e, r_e + 2 * n),
        lid_bottom_outer: at(c_e, r_e - 2 * n),
        eye_outer: at(c_e + m, r_e),
        eye_inner: at(c_e - m, r_e),
        slit_mid_upper: at(half, j_m),
        slit_mid_lower: new_index[dup_of[half]],
        slit_half_upper: at(half + (c_l - half) / 2, j_m),
        slit_half_lower: new_index[dup_of[half + (c_l - half) / 2]],
        corner: at(c_l, j_m),
        corner_outer: at(c_l + 1, j_m),
    };
    place_feature_points(&mut skin, p, &grid_fps);
    skin
}

fn keep_used<T: Copy>(v: &[T], used: &[bool]) -> Vec<T> {
    v.iter()
        .zip(used)
        .filter(|(_, &u)| u)
        .map(|(x, _)| *x)
        .collect()
}

/// Feature-point vertices fixed by the grid construction (left side / midline).
struct GridLandmarks {
    bottom_pole: u32,
    top_pole: u32,
    lid_top: u32,
    lid_bottom: u32,
    lid_top_outer: u32,
    lid_bottom_outer: u32,
    eye_outer: u32,
    eye_inner: u32,
    slit_mid_upper: u32,
    slit_mid_lower: u32,
    slit_half_upper: u32,
    slit_half_lower: u32,
    corner: u32,
    corner_outer: u32,
}

/// Where a landmark is searched.
#[derive(Clone, Copy)]
enum Plane {
    /// Front-facing vertices, by (x, y) distance.
    Front,
    /// Side vertices (x beyond half the head width), by (y, z) distance.
    Side,
}

#[derive(Clone, Copy, PartialEq)]
enum Half {
    Midline,
    Left,
}

#[derive(Clone, Copy, PartialEq)]
enum Lip {
    Any,
    Upper,
    Lower,
}

/// (left/midline label, mirror label, plane, half, lip side, target in the plane).
type Landmark = (
    FeaturePointId,
    Option<FeaturePointId>,
    Plane,
    Half,
    Lip,
    [f64; 2],
);

fn place_feature_points(skin: &mut Skin, p: &HeadParams, g: &GridLandmarks) {
    let mut used: HashSet<u32> = HashSet::new();
    let mut out: Vec<(FeaturePointId, u32)> = Vec::new();
    // Fixed left/midline points; right ones are mirrors.
    let fixed: [(FeaturePointId, u32, Option<FeaturePointId>); 14] = [
        (FeaturePointId::FP_7_1, g.bottom_pole, None),
        (FeaturePointId::FP_11_4, g.top_pole, None),
        (
            FeaturePointId::FP_3_1,
            g.lid_top,
            Some(FeaturePointId::FP_3_2),
        ),
        (
            FeaturePointId::FP_3_3,
            g.lid_bottom,
            Some(FeaturePointId::FP_3_4),
        ),
        (
            FeaturePointId::FP_3_13,
            g.lid_top_outer,
            Some(FeaturePointId::FP_3_14),
        ),
        (
            FeaturePointId::FP_3_9,
            g.lid_bottom_outer,
            Some(FeaturePointId::FP_3_10),
        ),
        (
            FeaturePointId::FP_3_7,
            g.eye_outer,
            Some(FeaturePointId::FP_3_12),
        ),
        (
            FeaturePointId::FP_3_11,
            g.eye_inner,
            Some(FeaturePointId::FP_3_8),
        ),
        (FeaturePointId::FP_2_2, g.slit_mid_upper, None),
        (FeaturePointId::FP_2_3, g.slit_mid_lower, None),
        (
            FeaturePointId::FP_2_6,
            g.slit_half_upper,
            Some(FeaturePointId::FP_2_7),
        ),
        (
            FeaturePointId::FP_2_8,
            g.slit_half_lower,
            Some(FeaturePointId::FP_2_9),
        ),
        (
            FeaturePointId::FP_2_4,
            g.corner,
            Some(FeaturePointId::FP_2_5),
        ),
        (
            FeaturePointId::FP_8_3,
            g.corner_outer,
            Some(FeaturePointId::FP_8_4),
        ),
    ];
    for (l, v, r) in fixed {
        used.insert(v);
        out.push((l, v));
        if let Some(r) = r {
            let mv = skin.mirror[v as usize];
            used.insert(mv);
            out.push((r, mv));
        }
    }
    // Nose tip: the most protruding midline vertex between the nose base and the eyes.
    let tip = (0..skin.positions.len() as u32)
        .filter(|&v| {
            let q = skin.positions[v as usize];
            q.x == 0.0 && q.z > 0.0 && q.y > p.nose_bottom_y && q.y < p.eye_y
        })
        .max_by(|&a, &b| {
            skin.positions[a as usize]
                .z
                .total_cmp(&skin.positions[b as usize].z)
        })
        .expect("nose");
    used.insert(tip);
    out.push((FeaturePointId::FP_9_3, tip));

    let xe = p.eye_separation / 2.0;
    let (ea, my, mw) = (p.eye_half_width, p.mouth_y, p.mouth_half_width);
    let brow = p.eye_y + p.brow_height;
    let ny = p.nose_bottom_y;
    let bridge_y = p.eye_y - 0.45 * (p.eye_y - ny);
    let (ey, ez, eh, ed) = (p.ear_y, p.ear_z, p.ear_half_height, p.ear_half_depth);
    // (left/midline label, mirror label, plane, half, lip side, target in the plane)
    #[rustfmt::skip]
    let searched: Vec<Landmark> = vec![
        (FeaturePointId::FP_9_15, None, Plane::Front, Half::Midline, Lip::Any, [0.0, ny]),
        (FeaturePointId::FP_2_1, None, Plane::Front, Half::Midline, Lip::Lower, [0.0, p.chin_y]),
        (FeaturePointId::FP_2_10, None, Plane::Front, Half::Midline, Lip::Lower, [0.0, p.chin_y + 13.0]),
        (FeaturePointId::FP_8_1, None, Plane::Front, Half::Midline, Lip::Upper, [0.0, my + p.upper_lip_height]),
        (FeaturePointId::FP_8_2, None, Plane::Front, Half::Midline, Lip::Lower, [0.0, my - p.lower_lip_height]),
        (FeaturePointId::FP_9_12, None, Plane::Front, Half::Midline, Lip::Any, [0.0, bridge_y]),
        (FeaturePointId::FP_11_1, None, Plane::Front, Half::Midline, Lip::Any, [0.0, p.hairline_y]),
        (FeaturePointId::FP_2_11, Some(FeaturePointId::FP_2_12), Plane::Front, Half::Left, Lip::Lower, [13.0, p.chin_y + 6.0]),
        (FeaturePointId::FP_2_13, Some(FeaturePointId::FP_2_14), Plane::Side, Half::Left, Lip::Lower, [my - 14.0, ez + ed + 16.0]),
        (FeaturePointId::FP_4_1, Some(FeaturePointId::FP_4_2), Plane::Front, Half::Left, Lip::Any, [xe - 0.75 * ea, brow - 1.0]),
        (FeaturePointId::FP_4_3, Some(FeaturePointId::FP_4_4), Plane::Front, Half::Left, Lip::Any, [xe + 0.1 * ea, brow + 1.5]),
        (FeaturePointId::FP_4_5, Some(FeaturePointId::FP_4_6), Plane::Front, Half::Left, Lip::Any, [xe + 1.15 * ea, brow - 2.0]),
        (FeaturePointId::FP_5_1, Some(FeaturePointId::FP_5_2), Plane::Front, Half::Left, Lip::Any, [xe + 3.0, 0.5 * (ny + my) + 2.0]),
        (FeaturePointId::FP_5_3, Some(FeaturePointId::FP_5_4), Plane::Front, Half::Left, Lip::Any, [xe + 10.0, p.eye_y - 15.0]),
        (FeaturePointId::FP_8_5, Some(FeaturePointId::FP_8_6), Plane::Front, Half::Left, Lip::Upper, [0.5 * mw, my + 0.75 * p.upper_lip_height]),
        (FeaturePointId::FP_8_7, Some(FeaturePointId::FP_8_8), Plane::Front, Half::Left, Lip::Lower, [0.5 * mw, my - 0.75 * p.lower_lip_height]),
        (FeaturePointId::FP_8_10, Some(FeaturePointId::FP_8_9), Plane::Front, Half::Left, Lip::Upper, [0.2 * mw, my + p.upper_lip_height + 0.8]),
        (FeaturePointId::FP_9_1, Some(FeaturePointId::FP_9_2), Plane::Front, Half::Left, Lip::Any, [p.nose_half_width, ny + 3.0]),
        (FeaturePointId::FP_9_5, Some(FeaturePointId::FP_9_4), Plane::Front, Half::Left, Lip::Any, [0.5 * p.nose_half_width, ny + 0.5]),
        (FeaturePointId::FP_9_7, Some(FeaturePointId::FP_9_6), Plane::Front, Half::Left, Lip::Any, [6.0, p.eye_y - 5.0]),
        (FeaturePointId::FP_9_13, Some(FeaturePointId::FP_9_14), Plane::Front, Half::Left, Lip::Any, [7.0, bridge_y]),
        (FeaturePointId::FP_11_3, Some(FeaturePointId::FP_11_2), Plane::Front, Half::Left, Lip::Any, [xe + ea + 12.0, p.hairline_y - 22.0]),
        (FeaturePointId::FP_10_1, Some(FeaturePointId::FP_10_2), Plane::Side, Half::Left, Lip::Any, [ey + 0.85 * eh, ez]),
        (FeaturePointId::FP_10_3, Some(FeaturePointId::FP_10_4), Plane::Side, Half::Left, Lip::Any, [ey + 0.1 * eh, ez - 0.85 * ed]),
        (FeaturePointId::FP_10_5, Some(FeaturePointId::FP_10_6), Plane::Side, Half::Left, Lip::Any, [ey - 0.9 * eh, ez]),
        (FeaturePointId::FP_10_7, Some(FeaturePointId::FP_10_8), Plane::Side, Half::Left, Lip::Any, [ey - 0.7 * eh, ez + 0.8 * ed]),
        (FeaturePointId::FP_10_9, Some(FeaturePointId::FP_10_10), Plane::Side, Half::Left, Lip::Any, [ey + 0.7 * eh, ez + 0.8 * ed]),
    ];
    let side_x = 0.5 * p.head_half_width;
    for (label, mirror_label, plane, half, lip, target) in searched {
        let target = DVec2::from(target);
        let best = (0..skin.positions.len() as u32)
            .filter(|v| !used.contains(v))
            .filter(|&v| {
                let q = skin.positions[v as usize];
                let lip_ok = match lip {
                    Lip::Any => true,
                    Lip::Upper => !skin.lower[v as usize],
                    Lip::Lower => skin.lower[v as usize],
                };
                let half_ok = match half {
                    Half::Midline => q.x == 0.0,
                    Half::Left => q.x > 0.0,
                };
                let plane_ok = match plane {
                    Plane::Front => q.z > 0.3 * p.face_depth,
                    Plane::Side => q.x > side_x,
                };
                lip_ok && half_ok && plane_ok
            })
            .min_by(|&a, &b| {
                let d = |v: u32| {
                    let q = skin.positions[v as usize];
                    match plane {
                        Plane::Front => DVec2::new(q.x, q.y).distance_squared(target),
                        Plane::Side => DVec2::new(q.y, q.z).distance_squared(target),
                    }
                };
                d(a).total_cmp(&d(b))
            })
            .unwrap_or_else(|| panic!("no skin vertex for feature point {label}"));
        used.insert(best);
        out.push((label, best));
        if let Some(r) = mirror_label {
            let mv = skin.mirror[best as usize];
            used.insert(mv);
            out.push((r, mv));
        }
    }
    // 11.6: back of the skull, on the back midline at eye height.
    let back = (0..skin.positions.len() as u32)
        .filter(|&v| {
            let q = skin.positions[v as usize];
            q.x == 0.0 && q.z < 0.0
        })
        .min_by(|&a, &b| {
            let d = |v: u32| (skin.positions[v as usize].y - p.eye_y).abs();
            d(a).total_cmp(&d(b))
        })
        .expect("back of the head");
    out.push((FeaturePointId::FP_11_6, back));
    out.sort_by_key(|(id, _)| id.ordinal());
    skin.feature_points = out;
}
