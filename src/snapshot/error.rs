//! What can stop a comparison or a snapshot.

use std::fmt;

/// Which of the two inputs of a diff.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Side {
    /// The first input (`A`).
    A,
    /// The second input (`B`).
    B,
}

impl fmt::Display for Side {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Side::A => "a",
            Side::B => "b",
        })
    }
}

/// A comparison or snapshot problem. Every variant is bad input (exit code 2).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SnapshotError {
    /// A face has no Facial Animation Table to compare or snapshot.
    #[error("{face} has no FAT (Facial Animation Tables) to compare")]
    NoFat {
        /// The face's name.
        face: String,
    },
    /// The two faces' vertices do not correspond one to one.
    #[error(
        "{a} and {b} have different vertex layouts ({detail}); compare them with \
         `--match nearest` (each vertex of A against the nearest neutral vertex of B)"
    )]
    LayoutMismatch {
        /// Face A's name.
        a: String,
        /// Face B's name.
        b: String,
        /// What differs (mesh counts, vertex counts).
        detail: String,
    },
    /// A tolerance that is not a positive finite number.
    #[error("--tolerance `{given}` is not a positive finite number (absolute, e.g. 0.001, or relative to the face size, e.g. 1e-4x)")]
    BadTolerance {
        /// What was given.
        given: String,
    },
    /// A face without vertices (no size for a relative tolerance, nothing to match).
    #[error("{face} has no vertices")]
    EmptyFace {
        /// The face's name.
        face: String,
    },
}

impl SnapshotError {
    /// Always true: every problem is in the input.
    pub fn is_input_error(&self) -> bool {
        true
    }
}
