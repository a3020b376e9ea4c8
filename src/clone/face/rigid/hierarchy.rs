//! Queries on a face's transform tree: ancestors, the lowest transform enclosing meshes, the
//! roles of a face's transforms, and free names for new transforms.

use std::collections::BTreeMap;

use crate::clone::face::{FaceParts, Part};
use crate::face::FaceModel;

/// `t` and its ancestors, nearest first (stops on a cycle).
pub(in crate::clone::face) fn ancestors(face: &FaceModel, mut t: Option<usize>) -> Vec<usize> {
    let mut out = Vec::new();
    while let Some(i) = t {
        if out.contains(&i) || out.len() > face.transforms.len() {
            break;
        }
        out.push(i);
        t = face.transforms[i].parent;
    }
    out
}

/// Lowest transform enclosing all `meshes`.
pub(super) fn lowest_enclosing(face: &FaceModel, meshes: &[usize]) -> Option<usize> {
    let first = *meshes.first()?;
    let chain = ancestors(face, face.meshes[first].transform);
    chain.into_iter().find(|&t| {
        meshes
            .iter()
            .all(|&m| ancestors(face, face.meshes[m].transform).contains(&t))
    })
}

/// Whether transform `t` is `mesh`'s transform or one of its ancestors.
pub(super) fn encloses(face: &FaceModel, t: usize, mesh: usize) -> bool {
    ancestors(face, face.meshes[mesh].transform).contains(&t)
}

/// Roles of a face's transforms (without changing it).
pub(super) fn roles(face: &FaceModel, parts: &FaceParts) -> (BTreeMap<Part, usize>, Option<usize>) {
    let head = lowest_enclosing(face, &parts.face_meshes());
    let mut map = BTreeMap::new();
    for (&p, meshes) in &parts.parts {
        if let Some(t) = lowest_enclosing(face, meshes) {
            if Some(t) != head {
                map.insert(p, t);
            }
        }
    }
    (map, head)
}

/// `base`, or `base_2`, `base_3`, ... : the first name no transform or mesh of `face` has,
/// nor any node of its scene (the name becomes a DEF there).
pub(super) fn unique_name(face: &FaceModel, base: &str) -> String {
    let mut name = base.to_string();
    let mut k = 1;
    while face.transform_index(&name).is_some()
        || face.mesh_index(&name).is_some()
        || face
            .scene
            .as_ref()
            .is_some_and(|s| s.find_def(&name).is_some())
    {
        k += 1;
        name = format!("{base}_{k}");
    }
    name
}
