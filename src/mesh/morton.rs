//! A spatially coherent order of points (Z-order / Morton curve): points close in the order
//! lie close in space. Batches of nearest-point queries run in this order walk the same
//! parts of a search tree one after the other, so the tree's nodes stay in cache (a
//! subdivided mesh lists its vertices level by level, scattered over the whole surface).

use glam::Vec3;

/// Bits per axis of the quantised coordinates (3 × 10 = 30 bits of key).
const BITS: u32 = 10;

/// Spreads the low 10 bits of `v` to every third bit.
fn spread(v: u32) -> u32 {
    let mut x = v & 0x3ff;
    x = (x | (x << 16)) & 0x0300_00ff;
    x = (x | (x << 8)) & 0x0300_f00f;
    x = (x | (x << 4)) & 0x030c_30c3;
    x = (x | (x << 2)) & 0x0924_9249;
    x
}

/// The indices of `points` sorted along the Z-order curve of their bounding box (ties and
/// non-finite points keep their input order; non-finite points sort as the box's corner).
pub fn morton_order(points: &[Vec3]) -> Vec<u32> {
    let finite = points.iter().filter(|p| p.is_finite());
    let (lo, hi) = finite.fold(
        (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
        |(lo, hi), &p| (lo.min(p), hi.max(p)),
    );
    let extent = (hi - lo).max_element();
    let cells = ((1u32 << BITS) - 1) as f32;
    let scale = if extent.is_finite() && extent > 0.0 {
        cells / extent
    } else {
        0.0
    };
    let key = |p: Vec3| -> u32 {
        if !p.is_finite() {
            return 0;
        }
        let q = ((p - lo) * scale).clamp(Vec3::ZERO, Vec3::splat(cells));
        spread(q.x as u32) | (spread(q.y as u32) << 1) | (spread(q.z as u32) << 2)
    };
    let mut keyed: Vec<(u32, u32)> = points
        .iter()
        .enumerate()
        .map(|(i, &p)| (key(p), i as u32))
        .collect();
    keyed.sort_unstable();
    keyed.into_iter().map(|(_, i)| i).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spread_interleaves_bits() {
        assert_eq!(spread(0b1), 0b1);
        assert_eq!(spread(0b11), 0b1001);
        assert_eq!(spread(0x3ff), 0x0924_9249);
    }

    #[test]
    fn order_is_a_permutation_that_keeps_neighbours_together() {
        // Two clusters listed alternately: the order lists each cluster in one run.
        let pts: Vec<Vec3> = (0..8)
            .map(|i| {
                let base = if i % 2 == 0 {
                    Vec3::ZERO
                } else {
                    Vec3::splat(10.0)
                };
                base + Vec3::new(0.01 * i as f32, 0.0, 0.0)
            })
            .chain([Vec3::NAN])
            .collect();
        let order = morton_order(&pts);
        let mut sorted = order.clone();
        sorted.sort_unstable();
        assert_eq!(sorted, (0..9).collect::<Vec<u32>>());
        let near: Vec<bool> = order
            .iter()
            .filter(|&&i| pts[i as usize].is_finite())
            .map(|&i| pts[i as usize].x < 5.0)
            .collect();
        let switches = near.windows(2).filter(|w| w[0] != w[1]).count();
        assert_eq!(switches, 1, "{order:?}");
    }

    #[test]
    fn empty_and_flat_inputs() {
        assert!(morton_order(&[]).is_empty());
        assert_eq!(morton_order(&[Vec3::ONE; 3]), vec![0, 1, 2]);
    }
}
