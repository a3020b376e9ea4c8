//! The bundled sample faces `alma` and `bruno`, embedded in the library as the gzip VRML
//! files in `samples/faces/` (made by [`crate::synth`]; a test pins them to the generator),
//! so every command reads them by name through the one face reader.

use super::vrml::FaceReadReport;
use super::FaceModel;
use crate::error::Result;

/// A face shipped inside fbakit.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BundledFace {
    /// `alma`: ~7.9k skin vertices (triangles), full FAT.
    Alma,
    /// `bruno`: ~26.5k skin vertices (quads), full FAT.
    Bruno,
}

impl BundledFace {
    /// The names [`BundledFace::from_name`] accepts.
    pub const NAMES: [&'static str; 2] = ["alma", "bruno"];

    /// The bundled face called `name`, if any.
    pub fn from_name(name: &str) -> Option<BundledFace> {
        match name {
            "alma" => Some(BundledFace::Alma),
            "bruno" => Some(BundledFace::Bruno),
            _ => None,
        }
    }

    /// Its name.
    pub fn name(self) -> &'static str {
        match self {
            BundledFace::Alma => "alma",
            BundledFace::Bruno => "bruno",
        }
    }

    /// The embedded `.wrl.gz` file.
    pub fn bytes(self) -> &'static [u8] {
        match self {
            BundledFace::Alma => include_bytes!("../../samples/faces/alma.wrl.gz"),
            BundledFace::Bruno => include_bytes!("../../samples/faces/bruno.wrl.gz"),
        }
    }

    /// Reads it.
    pub fn read(self) -> Result<(FaceModel, FaceReadReport)> {
        super::read::read_bytes(
            &format!("{}.wrl.gz", self.name()),
            self.bytes(),
            &super::read::FaceReadOptions::default(),
        )
    }
}
