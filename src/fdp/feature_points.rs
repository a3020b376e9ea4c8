//! Feature points of one face: where each MPEG-4 point is (a position, a mesh-vertex binding,
//! or both), kept in the standard's label order.

use std::collections::BTreeMap;

use glam::Vec3;
use serde::{Deserialize, Serialize};

use crate::error::Result;
use crate::spec::FeaturePointId;

/// The mesh vertex (or vertices) a feature point sits on.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct VertexBinding {
    /// Mesh name or alias; `None` for a single-mesh face.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mesh: Option<String>,
    /// 0-based vertex indices: one vertex, or several whose mean is the point.
    pub vertices: Vec<u32>,
}

impl VertexBinding {
    /// A binding to one vertex of an unnamed mesh.
    pub fn vertex(index: u32) -> VertexBinding {
        VertexBinding {
            mesh: None,
            vertices: vec![index],
        }
    }
}

/// One feature point: its label plus what is known about where it is.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FeaturePoint {
    /// The MPEG-4 label, e.g. 3.5.
    pub id: FeaturePointId,
    /// Position in the model's frame (MPEG-4 face frame when the file says so).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub position: Option<Vec3>,
    /// The mesh vertices the point is attached to.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub binding: Option<VertexBinding>,
}

impl FeaturePoint {
    /// A point known by position only.
    pub fn at(id: FeaturePointId, position: Vec3) -> FeaturePoint {
        FeaturePoint {
            id,
            position: Some(position),
            binding: None,
        }
    }

    /// A point known by vertex binding only.
    pub fn bound(id: FeaturePointId, binding: VertexBinding) -> FeaturePoint {
        FeaturePoint {
            id,
            position: None,
            binding: Some(binding),
        }
    }
}

/// The feature points of one face, at most one per label, iterated in label order (2.1, 2.2,
/// …, 2.10, …, 11.6).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(transparent)]
pub struct FeaturePointSet {
    points: BTreeMap<FeaturePointId, FeaturePoint>,
}

impl FeaturePointSet {
    /// An empty set.
    pub fn new() -> FeaturePointSet {
        FeaturePointSet::default()
    }

    /// The point with this label.
    pub fn get(&self, id: FeaturePointId) -> Option<&FeaturePoint> {
        self.points.get(&id)
    }

    /// Mutable access to the point with this label.
    pub fn get_mut(&mut self, id: FeaturePointId) -> Option<&mut FeaturePoint> {
        self.points.get_mut(&id)
    }

    /// Position of the point with this label, if the point exists and has one.
    pub fn position(&self, id: FeaturePointId) -> Option<Vec3> {
        self.points.get(&id).and_then(|p| p.position)
    }

    /// Adds or replaces a point; returns the point it replaced.
    pub fn insert(&mut self, point: FeaturePoint) -> Option<FeaturePoint> {
        self.points.insert(point.id, point)
    }

    /// Removes a point.
    pub fn remove(&mut self, id: FeaturePointId) -> Option<FeaturePoint> {
        self.points.remove(&id)
    }

    /// True if a point with this label is present.
    pub fn contains(&self, id: FeaturePointId) -> bool {
        self.points.contains_key(&id)
    }

    /// The points in label order.
    pub fn iter(&self) -> impl DoubleEndedIterator<Item = &FeaturePoint> + ExactSizeIterator {
        self.points.values()
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.points.len()
    }

    /// True if there are no points.
    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }

    /// The standard's points that are not in this set, in label order.
    pub fn missing(&self) -> Vec<FeaturePointId> {
        FeaturePointId::all()
            .filter(|id| !self.points.contains_key(id))
            .collect()
    }

    /// True if some point has a binding but no position (positions must be resolved from a
    /// mesh before anything geometric, such as FAPUs, can be computed).
    pub fn needs_mesh(&self) -> bool {
        self.iter()
            .any(|p| p.position.is_none() && p.binding.is_some())
    }

    /// Fills the position of every bound point from mesh vertices (the mean when several
    /// vertices are bound). `lookup(mesh, index)` returns the vertex or `None` when the mesh is
    /// unknown or the index out of range. A position already present is replaced: the mesh is
    /// the authority once it is given. Returns how many positions were set.
    ///
    /// Every failing point is reported in one error naming the point, mesh and index.
    pub fn resolve_positions(
        &mut self,
        lookup: impl Fn(Option<&str>, u32) -> Option<Vec3>,
    ) -> Result<usize> {
        let mut problems = Vec::new();
        let mut resolved = Vec::new();
        for point in self.points.values() {
            let Some(binding) = &point.binding else {
                continue;
            };
            if binding.vertices.is_empty() {
                problems.push(format!("point {} is bound to no vertex", point.id));
                continue;
            }
            let mut sum = glam::DVec3::ZERO;
            let mut ok = true;
            for &v in &binding.vertices {
                match lookup(binding.mesh.as_deref(), v) {
                    Some(p) => sum += p.as_dvec3(),
                    None => {
                        problems.push(format!(
                            "point {}: vertex {v} of mesh {} not found (unknown mesh or index out of range)",
                            point.id,
                            binding.mesh.as_deref().map_or("<default>".to_string(), |m| format!("`{m}`")),
                        ));
                        ok = false;
                        break;
                    }
                }
            }
            if ok {
                let mean = (sum / binding.vertices.len() as f64).as_vec3();
                resolved.push((point.id, mean));
            }
        }
        if !problems.is_empty() {
            let shown = problems.len().min(10);
            let more = if problems.len() > shown {
                format!("; and {} more", problems.len() - shown)
            } else {
                String::new()
            };
            return Err(super::FdpError::Unplaceable {
                problems: format!("{}{more}", problems[..shown].join("; ")),
            }
            .into());
        }
        let n = resolved.len();
        for (id, pos) in resolved {
            if let Some(p) = self.points.get_mut(&id) {
                p.position = Some(pos);
            }
        }
        Ok(n)
    }
}

impl FromIterator<FeaturePoint> for FeaturePointSet {
    fn from_iter<T: IntoIterator<Item = FeaturePoint>>(iter: T) -> Self {
        let mut set = FeaturePointSet::new();
        for p in iter {
            set.insert(p);
        }
        set
    }
}

impl<'a> IntoIterator for &'a FeaturePointSet {
    type Item = &'a FeaturePoint;
    type IntoIter = std::collections::btree_map::Values<'a, FeaturePointId, FeaturePoint>;
    fn into_iter(self) -> Self::IntoIter {
        self.points.values()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fp(s: &str) -> FeaturePointId {
        s.parse().unwrap()
    }

    #[test]
    fn ordered_by_label_and_missing_lists_the_rest() {
        let mut set = FeaturePointSet::new();
        set.insert(FeaturePoint::at(fp("2.10"), Vec3::ZERO));
        set.insert(FeaturePoint::at(fp("2.2"), Vec3::ONE));
        set.insert(FeaturePoint::at(fp("11.1"), Vec3::ONE));
        let order: Vec<String> = set.iter().map(|p| p.id.to_string()).collect();
        assert_eq!(order, ["2.2", "2.10", "11.1"]);
        let missing = set.missing();
        assert_eq!(missing.len(), 84 - 3);
        assert_eq!(missing[0], fp("2.1"));
        assert!(!missing.contains(&fp("2.10")));
        assert_eq!(set.position(fp("2.2")), Some(Vec3::ONE));
        assert_eq!(set.position(fp("2.1")), None);
    }

    #[test]
    fn resolves_single_and_mean_vertices() {
        let verts = [
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::new(0.0, 4.0, 0.0),
        ];
        let mut set = FeaturePointSet::new();
        set.insert(FeaturePoint::bound(
            fp("3.5"),
            VertexBinding {
                mesh: None,
                vertices: vec![0, 1, 2],
            },
        ));
        set.insert(FeaturePoint::bound(fp("2.1"), VertexBinding::vertex(2)));
        set.insert(FeaturePoint::at(fp("9.3"), Vec3::X));
        assert!(set.needs_mesh());
        let n = set
            .resolve_positions(|_, i| verts.get(i as usize).copied())
            .unwrap();
        assert_eq!(n, 2);
        assert!(!set.needs_mesh());
        let p = set.position(fp("3.5")).unwrap();
        assert!((p - Vec3::new(2.0 / 3.0, 4.0 / 3.0, 0.0)).length() < 1e-6);
        assert_eq!(set.position(fp("2.1")), Some(Vec3::new(0.0, 4.0, 0.0)));
        assert_eq!(set.position(fp("9.3")), Some(Vec3::X), "unbound untouched");
    }

    #[test]
    fn resolve_errors_name_point_mesh_and_index_and_change_nothing() {
        let mut set = FeaturePointSet::new();
        set.insert(FeaturePoint::bound(fp("2.1"), VertexBinding::vertex(0)));
        set.insert(FeaturePoint::bound(
            fp("8.3"),
            VertexBinding {
                mesh: Some("skin".into()),
                vertices: vec![7],
            },
        ));
        let before = set.clone();
        let e = set
            .resolve_positions(|mesh, i| (mesh.is_none() && i == 0).then_some(Vec3::ONE))
            .unwrap_err()
            .to_string();
        assert!(e.contains("point 8.3: vertex 7 of mesh `skin`"), "{e}");
        assert_eq!(set, before);
    }

    #[test]
    fn json_view_uses_labels() {
        let mut set = FeaturePointSet::new();
        set.insert(FeaturePoint::at(fp("3.5"), Vec3::new(1.0, 2.0, 3.0)));
        let json = serde_json::to_string(&set).unwrap();
        assert_eq!(json, r#"{"3.5":{"id":"3.5","position":[1.0,2.0,3.0]}}"#);
        let back: FeaturePointSet = serde_json::from_str(&json).unwrap();
        assert_eq!(back, set);
    }
}
