//! Facial definition parameters: feature points of a face and the FAP units measured on them.

pub mod fapu;

pub use fapu::{Fapu, FapuDistances};
