//! ASCII FAP streams (`.fap`): the model, a strict/lenient reader, a canonical writer, the
//! standard's hold semantics as a dense timeline, resampling and FAP-to-motion conversion.
//!
//! ```
//! use std::path::Path;
//! use fbakit::fap::{parse_fap, write_fap_string, ReadOptions};
//! let mask = "0 0 1 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 \
//!             0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0";
//! let text = format!("2.1 demo 25 1\n{mask}\n0 120\n");
//! let (stream, warnings) = parse_fap(&text, Path::new("demo.fap"), &ReadOptions::strict()).unwrap();
//! assert!(warnings.is_empty());
//! assert_eq!(stream.frames[0].value(fbakit::spec::FapId::OPEN_JAW), Some(120.0));
//! assert_eq!(write_fap_string(&stream), text);
//! ```

mod convert;
mod error;
mod model;
mod parse;
mod summary;
mod timeline;
mod write;

pub use convert::{is_json_path, read, read_stream_file, read_with, write_stream_file};
pub use error::FapError;
pub use model::{
    ExpressionParams, FapFrame, FapMask, FapStream, VisemeParams, DEFAULT_VERSION,
    MAX_ABS_FAP_VALUE, MAX_FRAME_RATE, NUM_LOW_LEVEL,
};
pub use parse::{
    parse_fap, read_fap_file, read_fap_from, validate_fap_file, validate_fap_str, ReadMode,
    ReadOptions, MAX_DECLARED_FRAMES,
};
pub use summary::{summarize, FapSummary, FapUsage};
pub use timeline::{
    displacement, resample, DenseFrame, FapMotion, FapTimeline, MAX_RESAMPLED_FRAMES,
};
pub use write::{write_fap_file, write_fap_string};
