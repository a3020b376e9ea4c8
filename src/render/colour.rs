//! sRGB ↔ linear conversions. Shading and filtering happen in linear light; images store
//! sRGB bytes.

use std::sync::OnceLock;

/// Entries of the linear → sRGB table (fine enough that every byte value is reachable).
const ENCODE_STEPS: usize = 16_384;

/// The exact sRGB transfer function, linear `[0, 1]` → encoded `[0, 1]`.
pub fn linear_to_srgb(v: f32) -> f32 {
    let v = v.clamp(0.0, 1.0);
    if v <= 0.003_130_8 {
        v * 12.92
    } else {
        1.055 * v.powf(1.0 / 2.4) - 0.055
    }
}

/// The exact inverse sRGB transfer function, encoded `[0, 1]` → linear `[0, 1]`.
pub fn srgb_to_linear(v: f32) -> f32 {
    let v = v.clamp(0.0, 1.0);
    if v <= 0.040_45 {
        v / 12.92
    } else {
        ((v + 0.055) / 1.055).powf(2.4)
    }
}

fn decode_table() -> &'static [f32; 256] {
    static T: OnceLock<[f32; 256]> = OnceLock::new();
    T.get_or_init(|| std::array::from_fn(|i| srgb_to_linear(i as f32 / 255.0)))
}

fn encode_table() -> &'static [u8] {
    static T: OnceLock<Vec<u8>> = OnceLock::new();
    T.get_or_init(|| {
        (0..=ENCODE_STEPS)
            .map(|i| (linear_to_srgb(i as f32 / ENCODE_STEPS as f32) * 255.0).round() as u8)
            .collect()
    })
}

/// An sRGB byte as linear light.
pub fn srgb8_to_linear(v: u8) -> f32 {
    decode_table()[v as usize]
}

/// Linear light (clamped to `[0, 1]`, NaN as 0) as an sRGB byte, through a table: the
/// rounding is the same on every platform.
pub fn linear_to_srgb8(v: f32) -> u8 {
    let v = if v.is_nan() { 0.0 } else { v.clamp(0.0, 1.0) };
    encode_table()[(v * ENCODE_STEPS as f32 + 0.5) as usize]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trips_every_byte() {
        for b in 0..=255u8 {
            assert_eq!(linear_to_srgb8(srgb8_to_linear(b)), b, "{b}");
        }
        assert_eq!(linear_to_srgb8(f32::NAN), 0);
        assert_eq!(linear_to_srgb8(7.0), 255);
        assert!((srgb_to_linear(0.5) - 0.214).abs() < 1e-3);
    }
}
