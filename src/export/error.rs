//! What can go wrong producing an output (glTF, viewer, pictures, videos, frame folders).
//! FAT binding errors shared with evaluation are [`crate::fat::FatError`]s; a missing
//! `ffmpeg` is [`crate::error::Error::MissingTool`].

use std::path::PathBuf;

use crate::fat::TableKey;

/// An output problem. Every variant is classified as bad input (exit code 2), as before the
/// typed errors: the face, the stream or the options given decide them.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ExportError {
    /// A `coordIndex` entry beyond the mesh's vertices.
    #[error("{key}: coordIndex {index} is out of range for mesh `{mesh}`")]
    CoordIndexOutOfRange {
        /// The table.
        key: TableKey,
        /// The mesh.
        mesh: String,
        /// The index.
        index: u32,
    },
    /// A displacement count that is not `coordIndex × intervals` (or no interval at all).
    #[error("{key}: mesh `{mesh}` has {found} displacements for {vertices} vertices and {intervals} intervals")]
    DisplacementCount {
        /// The table.
        key: TableKey,
        /// The mesh.
        mesh: String,
        /// Displacements in the table.
        found: usize,
        /// Length of `coordIndex`.
        vertices: usize,
        /// Number of intervals.
        intervals: usize,
    },
    /// A `FaceDefTransform` entry with NaN or infinity.
    #[error("{key}: FaceDefTransform of `{transform}` has a non-finite number")]
    NonFiniteTransform {
        /// The table.
        key: TableKey,
        /// The transform.
        transform: String,
    },
    /// Interval borders with NaN or infinity.
    #[error("{key}: interval borders must be finite numbers")]
    NonFiniteBorders {
        /// The table.
        key: TableKey,
    },
    /// An animation longer than the viewer embeds.
    #[error("the animation has {frames} frames; the viewer embeds at most {limit}")]
    TooManyViewerFrames {
        /// Frames in the animation.
        frames: usize,
        /// [`crate::export::viewer::MAX_FRAMES`].
        limit: usize,
    },
    /// The viewer's page template lacks a marker (a build problem).
    #[error("viewer template has no {marker} marker")]
    TemplateMarker {
        /// The marker.
        marker: String,
    },
    /// An output estimated too large ([`crate::export::budget::check`]).
    #[error("{}: frames {start}..{end} are {frames} frames, {over}{advice}", output.display())]
    OverBudget {
        /// The output.
        output: PathBuf,
        /// First frame.
        start: usize,
        /// End frame (exclusive).
        end: usize,
        /// Frames in the span.
        frames: usize,
        /// Which limit is passed, e.g. `about 900 MB, more than the 512 MB output limit`.
        over: String,
        /// What to do, starting with `; ` (empty from the library; the CLI names its options).
        advice: String,
    },
    /// A face with no vertex to draw.
    #[error("face `{face}` has no vertex to draw")]
    NothingToDraw {
        /// The face.
        face: String,
    },
    /// A cloning grid without faces.
    #[error("the cloning grid needs at least one face")]
    NoFaces,
    /// A video frame rate that is not a finite positive number.
    #[error("frame rate {fps} is not a finite positive number")]
    BadFrameRate {
        /// The rate.
        fps: f64,
    },
    /// A video of zero width or height.
    #[error("video frames need a non-zero size")]
    ZeroSize,
    /// A frame whose size differs from the video's.
    #[error("frame of {width}x{height} pixels in a {video_width}x{video_height} video")]
    FrameSize {
        /// The frame's width.
        width: u32,
        /// The frame's height.
        height: u32,
        /// The video's width.
        video_width: u32,
        /// The video's height.
        video_height: u32,
    },
    /// A soundtrack path that is a folder.
    #[error("{}: is a directory, not a sound file", path.display())]
    AudioIsDirectory {
        /// The path.
        path: PathBuf,
    },
    /// A frame was written after `ffmpeg` went away.
    #[error("{} is not running", crate::export::video::FFMPEG)]
    FfmpegNotRunning,
    /// A frame sink used after it was finished.
    #[error("the {sink} sink was already finished")]
    SinkFinished {
        /// `MP4`, `GIF` or `PNG`.
        sink: &'static str,
    },
    /// A GIF larger than the format allows.
    #[error("a GIF is at most {limit} pixels on a side")]
    GifTooLarge {
        /// The limit.
        limit: u32,
    },
}

impl ExportError {
    /// Always true (see the type's docs).
    pub fn is_input_error(&self) -> bool {
        true
    }
}
