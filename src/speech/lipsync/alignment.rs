//! Dynamic time warping between two feature sequences in bounded memory.
//!
//! The warp is found coarse to fine (the FastDTW scheme of Salvador and Chan, 2007): the
//! sequences are halved until a full cost matrix is small, aligned there, and the path is
//! projected one level finer and searched again only within `radius` frames of it. Each
//! level keeps one direction byte per searched cell and two rows of costs, so memory grows
//! linearly with the length (about 40 bytes per 10 ms frame at the finest level) instead
//! of with its square. Steps are the symmetric ones (a diagonal step costs the local
//! distance twice), so neither sequence is favoured.

/// Cells of the largest full matrix searched (the coarsest level).
const FULL_CELLS: usize = 4_000_000;
/// Half-width, in frames of each level, of the corridor around the projected path.
pub const DEFAULT_RADIUS: usize = 12;

const DIAG: u8 = 0;
const UP: u8 = 1;
const LEFT: u8 = 2;

/// A warping path: pairs (row in `a`, column in `b`) from (0, 0) to the last of each,
/// each step advancing one or both.
#[derive(Clone, Debug, PartialEq)]
pub struct WarpPath {
    /// The pairs, in order.
    pub pairs: Vec<(u32, u32)>,
    /// Mean local distance along the path.
    pub mean_distance: f64,
}

/// The distance between two frames.
pub fn distance<const N: usize>(a: &[f32; N], b: &[f32; N]) -> f32 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y) * (x - y))
        .sum::<f32>()
        .sqrt()
}

/// Aligns `a` with `b` (both non-empty); `None` when either is empty.
pub fn warp<const N: usize>(
    a: &[[f32; N]],
    b: &[[f32; N]],
    radius: usize,
    penalty: f32,
) -> Option<WarpPath> {
    if a.is_empty() || b.is_empty() {
        return None;
    }
    let pairs = fast_dtw(a, b, radius.max(1), penalty.max(0.0));
    let total: f64 = pairs
        .iter()
        .map(|&(i, j)| f64::from(distance(&a[i as usize], &b[j as usize])))
        .sum();
    let mean_distance = total / pairs.len() as f64;
    Some(WarpPath {
        pairs,
        mean_distance,
    })
}

fn halve<const N: usize>(x: &[[f32; N]]) -> Vec<[f32; N]> {
    x.chunks(2)
        .map(|c| {
            let mut out = [0f32; N];
            for f in c {
                for (o, v) in out.iter_mut().zip(f) {
                    *o += v / c.len() as f32;
                }
            }
            out
        })
        .collect()
}

fn fast_dtw<const N: usize>(
    a: &[[f32; N]],
    b: &[[f32; N]],
    radius: usize,
    penalty: f32,
) -> Vec<(u32, u32)> {
    let (n, m) = (a.len(), b.len());
    if n.saturating_mul(m) <= FULL_CELLS || n < 4 * radius || m < 4 * radius {
        let band: Vec<(usize, usize)> = if n.saturating_mul(m) <= FULL_CELLS {
            vec![(0, m - 1); n]
        } else {
            // One side is tiny: a diagonal band wide enough to hold any monotone path.
            diagonal_band(n, m, 4 * radius)
        };
        return banded_dtw(a, b, &band, penalty);
    }
    let coarse = fast_dtw(&halve(a), &halve(b), radius, penalty);
    let band = project(&coarse, n, m, radius);
    banded_dtw(a, b, &band, penalty)
}

/// Rows' column ranges around the straight line from (0, 0) to (n − 1, m − 1).
fn diagonal_band(n: usize, m: usize, half: usize) -> Vec<(usize, usize)> {
    let slope = if n > 1 {
        (m - 1) as f64 / (n - 1) as f64
    } else {
        0.0
    };
    (0..n)
        .map(|i| {
            let c = (i as f64 * slope).round() as usize;
            let lo = c.saturating_sub(half + slope.ceil() as usize);
            let hi = (c + half + slope.ceil() as usize).min(m - 1);
            (lo, hi)
        })
        .collect()
}

/// The finer level's column range per row: every coarse cell's 2×2 block, widened by
/// `radius` on each side.
fn project(coarse: &[(u32, u32)], n: usize, m: usize, radius: usize) -> Vec<(usize, usize)> {
    let mut band = vec![(usize::MAX, 0usize); n];
    for &(ci, cj) in coarse {
        let (ci, cj) = (ci as usize, cj as usize);
        let lo = (2 * cj).saturating_sub(radius);
        let hi = (2 * cj + 1 + radius).min(m - 1);
        let rows = (2 * ci).saturating_sub(radius)..=(2 * ci + 1 + radius).min(n - 1);
        for r in &mut band[rows] {
            r.0 = r.0.min(lo);
            r.1 = r.1.max(hi);
        }
    }
    // Every row is covered (the coarse path visits every coarse row); keep the ends open.
    band[0].0 = 0;
    band[n - 1].1 = m - 1;
    for r in &mut band {
        if r.0 > r.1 {
            *r = (0, m - 1);
        }
    }
    band
}

/// DTW restricted to `band[i]` = (first, last) column of row `i`.
fn banded_dtw<const N: usize>(
    a: &[[f32; N]],
    b: &[[f32; N]],
    band: &[(usize, usize)],
    penalty: f32,
) -> Vec<(u32, u32)> {
    let n = a.len();
    let mut offsets = Vec::with_capacity(n + 1);
    let mut total = 0usize;
    for &(lo, hi) in band {
        offsets.push(total);
        total += hi + 1 - lo;
    }
    offsets.push(total);
    let mut dirs = vec![DIAG; total];
    let mut prev: Vec<f32> = Vec::new();
    let mut prev_lo = 0usize;
    let mut cur: Vec<f32> = Vec::new();
    for i in 0..n {
        let (lo, hi) = band[i];
        cur.clear();
        cur.resize(hi + 1 - lo, f32::INFINITY);
        for j in lo..=hi {
            let d = distance(&a[i], &b[j]);
            let k = j - lo;
            if i == 0 && j == 0 {
                cur[k] = d;
                continue;
            }
            let up = if i > 0 && j >= prev_lo && j - prev_lo < prev.len() {
                prev[j - prev_lo] + d + penalty
            } else {
                f32::INFINITY
            };
            let diag = if i > 0 && j > prev_lo && j - 1 - prev_lo < prev.len() {
                prev[j - 1 - prev_lo] + 2.0 * d
            } else {
                f32::INFINITY
            };
            let left = if k > 0 {
                cur[k - 1] + d + penalty
            } else {
                f32::INFINITY
            };
            let (best, dir) = if diag <= up && diag <= left {
                (diag, DIAG)
            } else if up <= left {
                (up, UP)
            } else {
                (left, LEFT)
            };
            cur[k] = best;
            dirs[offsets[i] + k] = dir;
        }
        std::mem::swap(&mut prev, &mut cur);
        prev_lo = lo;
    }
    // Back from the last cell.
    let mut path = Vec::with_capacity(n + b.len());
    let (mut i, mut j) = (n - 1, b.len() - 1);
    loop {
        path.push((i as u32, j as u32));
        if i == 0 && j == 0 {
            break;
        }
        let (lo, hi) = band[i];
        let dir = if j < lo || j > hi {
            // Outside the corridor (cannot happen on a connected band): walk diagonally home.
            DIAG
        } else if i == 0 {
            LEFT
        } else if j == 0 {
            UP
        } else {
            dirs[offsets[i] + j - lo]
        };
        match dir {
            DIAG => {
                i = i.saturating_sub(1);
                j = j.saturating_sub(1);
            }
            UP => i -= 1,
            _ => j -= 1,
        }
    }
    path.reverse();
    path
}

/// The mean distance between frames of `a` and `b` paired without regard to time (a
/// deterministic sample): what a path through unrelated audio would cost.
pub fn unrelated_distance<const N: usize>(a: &[[f32; N]], b: &[[f32; N]]) -> f64 {
    if a.is_empty() || b.is_empty() {
        return 0.0;
    }
    let mut state = 0x9E37_79B9_7F4A_7C15u64;
    let mut next = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        state
    };
    let samples = 4_000;
    let mut sum = 0.0;
    for _ in 0..samples {
        let i = (next() % a.len() as u64) as usize;
        let j = (next() % b.len() as u64) as usize;
        sum += f64::from(distance(&a[i], &b[j]));
    }
    sum / f64::from(samples)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn seq(values: &[f32]) -> Vec<[f32; 1]> {
        values.iter().map(|v| [*v]).collect()
    }

    fn check_path(p: &[(u32, u32)], n: usize, m: usize) {
        assert_eq!(p[0], (0, 0));
        assert_eq!(*p.last().unwrap(), ((n - 1) as u32, (m - 1) as u32));
        for w in p.windows(2) {
            let (di, dj) = (w[1].0 - w[0].0, w[1].1 - w[0].1);
            assert!(di <= 1 && dj <= 1 && di + dj >= 1, "{w:?}");
        }
    }

    #[test]
    fn a_stretched_copy_aligns_onto_itself() {
        let a = seq(&[0.0, 1.0, 2.0, 3.0, 2.0, 1.0, 5.0]);
        // Each value twice.
        let b: Vec<[f32; 1]> = a.iter().flat_map(|v| [*v, *v]).collect();
        let w = warp(&a, &b, 2, 0.0).unwrap();
        check_path(&w.pairs, a.len(), b.len());
        assert_eq!(w.mean_distance, 0.0);
    }

    #[test]
    fn the_coarse_to_fine_search_matches_the_full_one_on_a_long_warp() {
        // A slow sine and a version sped up in its middle: 3000 × 2600 cells is above the
        // full-matrix limit only when the limit is low, so compare against the banded
        // search's own full-band answer.
        let a: Vec<[f32; 2]> = (0..3000)
            .map(|i| [(i as f32 * 0.01).sin(), (i as f32 * 0.023).cos()])
            .collect();
        let b: Vec<[f32; 2]> = (0..2600)
            .map(|j| {
                let t = if j < 1000 {
                    j as f32
                } else if j < 1600 {
                    1000.0 + (j - 1000) as f32 * 1.666
                } else {
                    2000.0 + (j - 1600) as f32
                };
                [(t * 0.01).sin(), (t * 0.023).cos()]
            })
            .collect();
        let fast = fast_dtw(&halve(&a), &halve(&b), 8, 0.0);
        let full = banded_dtw(&halve(&a), &halve(&b), &vec![(0, 1299); 1500], 0.0);
        check_path(&fast, 1500, 1300);
        let cost = |p: &[(u32, u32)]| -> f64 {
            p.iter()
                .map(|&(i, j)| f64::from(distance(&halve(&a)[i as usize], &halve(&b)[j as usize])))
                .sum()
        };
        assert!(
            cost(&fast) <= cost(&full) * 1.05 + 1e-3,
            "{} vs {}",
            cost(&fast),
            cost(&full)
        );
        // And the recursive search on the full sequences stays within a corridor's memory.
        let band = project(&fast, 3000, 2600, 12);
        let cells: usize = band.iter().map(|(lo, hi)| hi + 1 - lo).sum();
        assert!(cells < 3000 * 80, "{cells}");
        let path = banded_dtw(&a, &b, &band, 0.0);
        check_path(&path, 3000, 2600);
        // Row 1300 of `a` (t = 1300) sits at column 1000 + 300 / 1.666 ≈ 1180 of `b`.
        let j = path.iter().find(|p| p.0 == 1300).unwrap().1;
        assert!((j as i64 - 1180).abs() <= 6, "{j}");
    }

    #[test]
    fn empty_sequences_have_no_path() {
        assert!(warp::<1>(&[], &seq(&[1.0]), 4, 0.0).is_none());
        let w = warp(&seq(&[1.0]), &seq(&[1.0, 2.0, 3.0]), 4, 0.0).unwrap();
        check_path(&w.pairs, 1, 3);
        assert!(unrelated_distance(&seq(&[0.0, 1.0]), &seq(&[0.0, 1.0])) > 0.3);
    }
}
