//! Outputs made from played faces: videos (MP4, GIF, PNG frames) of a FAP stream.

pub mod movie;
pub mod video;
