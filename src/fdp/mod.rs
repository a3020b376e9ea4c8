//! Facial definition parameters: feature points of a face and the FAP units measured on them.
//!
//! - [`feature_points`]: [`FeaturePoint`], [`VertexBinding`], [`FeaturePointSet`].
//! - [`fapu`]: [`Fapu`] and [`FapuDistances`], also measured from feature points.
//! - [`xml`], [`xface`], [`csv`]: the three feature-point file formats; [`read_feature_points`]
//!   picks one by extension or content.
//! - [`landmarks`]: feature points from iBUG-68 / MediaPipe-468 landmarks plus points derived
//!   from the mesh.

mod error;
pub mod fapu;
pub mod feature_points;
pub mod file;
pub mod landmarks;
mod upright;

pub use error::FdpError;
pub use fapu::{Fapu, FapuDistances, FapuMeasurement};
pub use feature_points::{FeaturePoint, FeaturePointSet, VertexBinding};
pub use file::{
    detect_format, parse_feature_points, read_feature_points, read_feature_points_from, FapuSource,
    FeaturePointFile, FeaturePointFormat, FormatExtras,
};
pub mod csv;
pub mod xface;
pub mod xml;
mod xml_support;
