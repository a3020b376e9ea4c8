//! The names most programs need, in one import:
//!
//! ```
//! use fbakit::prelude::*;
//!
//! let alma = face::read("alma")?;                   // any face file, or a bundled face
//! let bruno = face::read("bruno")?;
//! let target = FaceModel { fat: Fat::default(), ..bruno };
//! let cloned = clone_face(&alma, &target, &CloneOptions::default())?.face;
//! let stream = read_stream_file("samples/speech.fap", &ReadOptions::lenient())?.0;
//! let mut player = Player::new(&cloned, &stream, &PlayOptions::default())?;
//! let mut frame = player.new_frame();
//! while player.next_frame(&mut frame) { /* frame.pose holds the posed meshes */ }
//! let out = std::env::temp_dir().join("fbakit-prelude-bruno.glb");
//! let report = export::write(&out, &cloned, &ExportOptions::default())?; // warnings inside
//! println!("{report}");
//! # Ok::<(), fbakit::error::Error>(())
//! ```

pub use crate::clone::face::{clone_face, CloneOptions, Method};
pub use crate::error::{Diagnostic, Error, Result};
pub use crate::export::{self, ExportOptions, ExportReport, ShapeNames};
pub use crate::face::{self, FaceModel, FacePose, FaceReadOptions};
pub use crate::fap::{self, read_stream_file, FapFrame, FapStream, ReadOptions};
pub use crate::fat::eval::Activation;
pub use crate::fat::{Fat, TableKey};
pub use crate::fdp::{Fapu, FeaturePointSet};
pub use crate::format::OutputFormat;
pub use crate::glam::{self, Affine3A, Quat, Vec3};
pub use crate::player::{PlayOptions, Player, PlayerFrame};
pub use crate::spec::{Expression, FapId, FeaturePointId, Viseme};
