//! What can be wrong with a stream played on a face.

/// A playback problem. Every variant is bad input (exit code 2).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PlayerError {
    /// The stream's frame rate is out of range.
    #[error("stream frame rate {rate} is not a number in (0, {max}]")]
    StreamFrameRate {
        /// The stream's rate.
        rate: f64,
        /// [`crate::fap::MAX_FRAME_RATE`].
        max: f64,
    },
    /// A frame number beyond what a stream may hold.
    #[error("stream has frame number {frame}, more than {limit} frames")]
    FrameNumberTooLarge {
        /// The frame number.
        frame: u64,
        /// [`crate::fap::MAX_RESAMPLED_FRAMES`].
        limit: u64,
    },
    /// A frame range that selects no frame.
    #[error("frame range {start}..{end} selects nothing of the {total} frames")]
    EmptyFrameRange {
        /// First frame asked for.
        start: usize,
        /// End (exclusive).
        end: usize,
        /// Frames the stream has.
        total: usize,
    },
    /// More frames than an animation clip holds.
    #[error("frames {start}..{end} are {count} frames, more than the {limit} an animation holds")]
    TooManyFrames {
        /// First frame.
        start: usize,
        /// End (exclusive).
        end: usize,
        /// Frames in the range.
        count: usize,
        /// [`crate::export::budget::MAX_PLAYED_FRAMES`].
        limit: usize,
    },
}

impl PlayerError {
    /// Always true: every playback problem is bad input.
    pub fn is_input_error(&self) -> bool {
        true
    }
}
