//! Outputs made for people to look at, built on the face and player modules.
//!
//! - [`viewer`]: one self-contained HTML page that shows a face in the browser, plays a FAP
//!   stream on it and poses it live with FAP sliders (`fbakit view`).

pub mod viewer;
