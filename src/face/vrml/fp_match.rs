//! Binding `featurePointsCoord` entries to their nearest mesh vertex when a file has no
//! fbakit record, and the report of each match.

use crate::face::vertex_index::FaceVertexIndex;
use glam::Vec3;
use serde::Serialize;

use crate::face::FaceModel;
use crate::fdp::{FeaturePoint, FeaturePointSet};
use crate::spec::FeaturePointId;

/// How a `featurePointsCoord` entry was matched to a mesh vertex.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FeaturePointMatch {
    /// The point.
    pub id: FeaturePointId,
    /// Mesh it was bound to.
    pub mesh: String,
    /// Vertex it was bound to.
    pub vertex: u32,
    /// Distance between the given position and the vertex.
    pub distance: f32,
}

/// Every `featurePointsCoord` entry (in the standard's label order, at most 84) as a feature
/// point bound to the nearest vertex of any mesh; each match is appended to `matches`.
pub(super) fn bind_to_nearest_vertices(
    points: &[[f32; 3]],
    model: &FaceModel,
    matches: &mut Vec<FeaturePointMatch>,
) -> FeaturePointSet {
    let mut set = FeaturePointSet::new();
    let index = FaceVertexIndex::new(model);
    for (ordinal, p) in points
        .iter()
        .enumerate()
        .take(crate::spec::NUM_FEATURE_POINTS)
    {
        let Some(id) = FeaturePointId::from_ordinal(ordinal) else {
            continue;
        };
        let pos = Vec3::from_array(*p);
        let mut point = FeaturePoint::at(id, pos);
        if let Some((binding, found)) = index.bind(model, id, pos) {
            point.binding = Some(binding);
            matches.push(found);
        }
        set.insert(point);
    }
    set
}
