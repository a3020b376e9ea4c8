//! Values on a grid, and digests of them.
//!
//! A [`Grid`] has a step of 1, 2 or 5 × 10ⁿ, the largest such step not above the tolerance,
//! so its points print as short decimals. A value is replaced by the nearest grid point
//! (`round(v / step)`). Two values more than one step apart can never land on the same
//! point, so a change above the tolerance always changes what is printed or digested; a
//! change of ε changes it only when the value lies within ε of a midpoint between two grid
//! points (see the guarantee in [`crate::snapshot`]).

use std::fmt::Write;

/// A grid of printable values.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Grid {
    /// Distance between grid points.
    step: f64,
    /// Decimals a grid point needs.
    decimals: usize,
    /// `step` as `mantissa × 10^exponent`, mantissa 1, 2 or 5.
    mantissa: i64,
    exponent: i32,
}

/// What a non-finite value quantises to (never a real grid index).
const NOT_FINITE: i64 = i64::MIN;

impl Grid {
    /// The coarsest 1/2/5 × 10ⁿ grid whose step does not exceed `tolerance` (positive and
    /// finite, else a step of 1e-6).
    pub fn for_tolerance(tolerance: f64) -> Grid {
        let t = if tolerance.is_finite() && tolerance > 0.0 {
            tolerance.clamp(1e-30, 1e30)
        } else {
            1e-6
        };
        let mut exponent = t.log10().floor() as i32;
        // log10 can be off by one ulp at exact powers of ten; settle it on the decimals.
        if 10f64.powi(exponent) > t {
            exponent -= 1;
        }
        if 10f64.powi(exponent + 1) <= t {
            exponent += 1;
        }
        let mantissa = [5i64, 2, 1]
            .into_iter()
            .find(|m| *m as f64 * 10f64.powi(exponent) <= t)
            .unwrap_or(1);
        Grid {
            step: mantissa as f64 * 10f64.powi(exponent),
            decimals: exponent.min(0).unsigned_abs() as usize,
            mantissa,
            exponent,
        }
    }

    /// Distance between grid points.
    pub fn step(&self) -> f64 {
        self.step
    }

    /// Index of the grid point nearest `v` (ties away from zero); a fixed sentinel for
    /// non-finite values.
    pub fn index(&self, v: f64) -> i64 {
        if !v.is_finite() {
            return NOT_FINITE;
        }
        let q = (v / self.step).round();
        if q.abs() >= 9.0e18 {
            // Far outside any face: clamp (still deterministic).
            return if q > 0.0 { i64::MAX } else { i64::MIN + 1 };
        }
        q as i64
    }

    /// The grid point of index `q` as a short decimal (`-0.0125`, `3`, `1500`).
    pub fn format_index(&self, q: i64) -> String {
        if q == NOT_FINITE {
            return ".nan".to_string();
        }
        let units = i128::from(q) * i128::from(self.mantissa);
        let mut s = String::new();
        if self.exponent >= 0 {
            let _ = write!(s, "{}", units * 10i128.pow(self.exponent as u32));
            return s;
        }
        let d = self.decimals;
        let neg = units < 0;
        let digits = units.unsigned_abs().to_string();
        let digits = format!("{digits:0>width$}", width = d + 1);
        let (int, frac) = digits.split_at(digits.len() - d);
        let frac = frac.trim_end_matches('0');
        if neg {
            s.push('-');
        }
        s.push_str(int);
        if !frac.is_empty() {
            s.push('.');
            s.push_str(frac);
        }
        s
    }

    /// `v` on the grid, as a number (the short decimal read back, so it prints the same).
    pub fn snap(&self, v: f64) -> f64 {
        let q = self.index(v);
        if q == NOT_FINITE {
            return f64::NAN;
        }
        self.format_index(q).parse().unwrap_or(f64::NAN)
    }
}

/// 64-bit FNV-1a over bytes (names), and its xor-multiply step over whole 64-bit words
/// (numbers, eight times faster): small, fixed forever (unlike `std`'s hasher) and the same
/// on every platform, which is all a snapshot digest needs (it is not a defence against
/// forgery). Each step is a bijection of the state for a fixed input and of the input for a
/// fixed state, so changing any one fed value always changes the digest.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Digest(u64);

impl Default for Digest {
    fn default() -> Self {
        Digest(0xcbf2_9ce4_8422_2325)
    }
}

impl Digest {
    /// Feeds bytes.
    pub fn bytes(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 ^= u64::from(b);
            self.0 = self.0.wrapping_mul(0x0000_0100_0000_01b3);
        }
    }

    /// Feeds a 64-bit word in one step.
    pub fn word(&mut self, v: u64) {
        self.0 = (self.0 ^ v).wrapping_mul(0x0000_0100_0000_01b3);
    }

    /// Feeds an integer.
    pub fn i64(&mut self, v: i64) {
        self.word(v as u64);
    }

    /// Feeds an f64's exact bits.
    pub fn f64_bits(&mut self, v: f64) {
        self.word(v.to_bits());
    }

    /// Sixteen hex digits.
    pub fn hex(&self) -> String {
        format!("{:016x}", self.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn grid_steps_are_short_decimals_below_the_tolerance() {
        let cases = [
            (1e-4, 1e-4, "0.0001"),
            (2.8e-4, 2e-4, "0.0002"),
            (7e-3, 5e-3, "0.005"),
            (0.5, 0.5, "0.5"),
            (1.0, 1.0, "1"),
            (30.0, 20.0, "20"),
        ];
        for (tol, step, one) in cases {
            let g = Grid::for_tolerance(tol);
            assert!(
                (g.step() - step).abs() < step * 1e-12,
                "{tol}: {}",
                g.step()
            );
            assert!(g.step() <= tol);
            assert_eq!(g.format_index(1), one);
        }
        let g = Grid::for_tolerance(0.002);
        assert_eq!(g.format_index(-6), "-0.012");
        assert_eq!(g.format_index(0), "0");
        assert_eq!(g.snap(0.0123), 0.012);
        assert_eq!(g.format_index(g.index(f64::NAN)), ".nan");
    }

    #[test]
    fn fnv_is_the_published_function() {
        // FNV-1a 64 of "a" is af63dc4c8601ec8c.
        let mut d = Digest::default();
        d.bytes(b"a");
        assert_eq!(d.hex(), "af63dc4c8601ec8c");
    }

    proptest! {
        /// Changing any one fed word changes the digest.
        #[test]
        fn one_changed_word_always_changes_the_digest(
            words in proptest::collection::vec(any::<u64>(), 1..40), at in any::<usize>(), other in any::<u64>()
        ) {
            let at = at % words.len();
            prop_assume!(words[at] != other);
            let digest = |w: &[u64]| {
                let mut d = Digest::default();
                w.iter().for_each(|x| d.word(*x));
                d
            };
            let mut changed = words.clone();
            changed[at] = other;
            prop_assert_ne!(digest(&words), digest(&changed));
        }

        /// A change larger than the tolerance always moves a value to another grid point.
        #[test]
        fn changes_above_tolerance_always_change_the_index(
            v in -1e3f64..1e3, tol in 1e-6f64..1.0, extra in 1.000_001f64..50.0, up in any::<bool>()
        ) {
            let g = Grid::for_tolerance(tol);
            let d = if up { tol * extra } else { -tol * extra };
            prop_assert_ne!(g.index(v), g.index(v + d));
        }

        /// A value at least ε away from every midpoint keeps its grid point under noise ≤ ε.
        #[test]
        fn noise_away_from_midpoints_never_changes_the_index(
            k in -100_000i64..100_000, frac in -0.49f64..0.49, tol in 1e-6f64..1.0, noise in -1.0f64..1.0
        ) {
            let g = Grid::for_tolerance(tol);
            let v = (k as f64 + frac) * g.step();
            // Distance to the nearest midpoint, in steps: 0.5 - |frac|.
            let eps = (0.5 - frac.abs()) * g.step() * 0.99;
            prop_assert_eq!(g.index(v), g.index(v + noise * eps));
        }
    }
}
