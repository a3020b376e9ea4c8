//! Rendering problems.

/// A rendering problem. Every variant is classified as bad input (exit code 2).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum RenderError {
    /// An image whose pixel buffer does not match its size.
    #[error("image of {width}×{height} has {bytes} bytes of pixels")]
    PixelCount {
        /// Width in pixels.
        width: u32,
        /// Height in pixels.
        height: u32,
        /// Bytes in the RGBA buffer.
        bytes: usize,
    },
}

impl RenderError {
    /// Always true.
    pub fn is_input_error(&self) -> bool {
        true
    }
}
