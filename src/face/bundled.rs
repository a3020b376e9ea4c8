//! The faces shipped inside fbakit, embedded in the library so every command reads them by
//! name through the one face reader:
//!
//! - `alma` and `bruno`: the procedural gzip VRML faces in `samples/faces/` (made by
//!   [`crate::synth`]; a test pins them to the generator), each with an exact FAT;
//! - `ict`: a real scanned head, `samples/faces/ict-head/`, derived from the ICT-FaceKit
//!   (MIT licence beside it; made by `examples/make_ict_sample.rs`): a glTF blendshape rig with
//!   ARKit-named shapes and its MPEG-4 feature points, whose FAT is built on reading by
//!   [`crate::rig::fat_build::face_from_rig`] (FAP-compliant by calibration). Centimetres.

use std::path::Path;

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
    /// `ict`: the ICT-FaceKit head (24.6k vertices; face, skull, mouth, teeth, eyes), FAT
    /// from its ARKit shapes.
    Ict,
}

impl BundledFace {
    /// The names [`BundledFace::from_name`] accepts.
    pub const NAMES: [&'static str; 3] = ["alma", "bruno", "ict"];

    /// The bundled face called `name`, if any.
    pub fn from_name(name: &str) -> Option<BundledFace> {
        match name {
            "alma" => Some(BundledFace::Alma),
            "bruno" => Some(BundledFace::Bruno),
            "ict" => Some(BundledFace::Ict),
            _ => None,
        }
    }

    /// Its name.
    pub fn name(self) -> &'static str {
        match self {
            BundledFace::Alma => "alma",
            BundledFace::Bruno => "bruno",
            BundledFace::Ict => "ict",
        }
    }

    /// Its face file, relative to the `samples/` folder.
    pub fn sample_file(self) -> &'static str {
        match self {
            BundledFace::Alma => "faces/alma.wrl.gz",
            BundledFace::Bruno => "faces/bruno.wrl.gz",
            BundledFace::Ict => "faces/ict-head/ict-head.glb",
        }
    }

    /// Its feature-point file relative to `samples/`, for faces whose file has none.
    pub fn sample_feature_points(self) -> Option<&'static str> {
        match self {
            BundledFace::Ict => Some("faces/ict-head/ict-head-fp.csv"),
            _ => None,
        }
    }

    /// The embedded face file.
    pub fn bytes(self) -> &'static [u8] {
        match self {
            BundledFace::Alma => include_bytes!("../../samples/faces/alma.wrl.gz"),
            BundledFace::Bruno => include_bytes!("../../samples/faces/bruno.wrl.gz"),
            BundledFace::Ict => include_bytes!("../../samples/faces/ict-head/ict-head.glb"),
        }
    }

    /// The embedded feature-point file, for faces whose file has none.
    fn feature_point_text(self) -> Option<&'static str> {
        match self {
            BundledFace::Ict => Some(include_str!("../../samples/faces/ict-head/ict-head-fp.csv")),
            _ => None,
        }
    }

    /// Reads it.
    pub fn read(self) -> Result<(FaceModel, FaceReadReport)> {
        let Some(fp_text) = self.feature_point_text() else {
            return super::read::read_bytes(
                self.bytes(),
                format!("{}.wrl.gz", self.name()),
                &super::read::FaceReadOptions::default(),
            );
        };
        let glb = Path::new(self.sample_file());
        let rig = crate::rig::gltf_read::read_gltf_bytes(self.bytes(), glb)?;
        let fp_file = self.sample_feature_points().unwrap_or_default();
        let points = crate::fdp::parse_feature_points(fp_text, Path::new(fp_file))?.points;
        let (mut face, _) = crate::rig::fat_build::face_from_rig(
            &rig,
            Some(points),
            &crate::rig::fap_map::FapMap::arkit(),
        )?;
        face.name = self.name().to_string();
        Ok((face, FaceReadReport::default()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_bundled_face_reads_with_a_fat() {
        for name in BundledFace::NAMES {
            let face = BundledFace::from_name(name).unwrap().read().unwrap().0;
            assert_eq!(face.name, name);
            assert!(
                face.fat.tables.len() >= 50,
                "{name}: {}",
                face.fat.tables.len()
            );
            crate::fdp::Fapu::from_feature_points(&face.feature_points).unwrap();
        }
    }

    #[test]
    fn ict_is_a_real_head_in_metres() {
        let face = BundledFace::Ict.read().unwrap().0;
        assert_eq!(face.vertex_count(), 24591);
        let unit = crate::face::units::unit_of(&face, None).unwrap();
        assert_eq!(unit.unit, crate::face::units::LengthUnit::M, "{unit:?}");
    }
}
