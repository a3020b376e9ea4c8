//! What can be wrong with a FAP stream beyond its syntax (syntax errors are located
//! [`crate::error::ParseError`]s).

use std::path::PathBuf;

/// A FAP stream problem. Every variant is bad input (exit code 2).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FapError {
    /// A requested frame rate is not a finite positive number.
    #[error("frame rate {rate} is not a finite positive number")]
    BadFrameRate {
        /// The rate asked for.
        rate: f64,
    },
    /// The stream's own frame rate is not a finite positive number.
    #[error("stream frame rate {rate} is not a finite positive number")]
    BadStreamFrameRate {
        /// The stream's rate.
        rate: f64,
    },
    /// Resampling would make more frames than the limit.
    #[error("resampling would produce more than {limit} frames")]
    TooManyFrames {
        /// [`crate::fap::MAX_RESAMPLED_FRAMES`].
        limit: u64,
    },
    /// A stream read from JSON breaks the standard (frame order, frame rate, or in strict
    /// mode a value out of range).
    #[error("{}: {problem}", file.display())]
    Content {
        /// The stream's file.
        file: PathBuf,
        /// What is wrong ([`crate::fap::FapStream::problems`]).
        problem: String,
    },
}

impl FapError {
    /// Always true: every FAP stream problem is bad input.
    pub fn is_input_error(&self) -> bool {
        true
    }
}
