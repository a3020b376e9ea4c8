//! Rigid parts by transforms (module docs of [`super`], step 7): the target's head transform
//! is found (never created), its part transforms found or created, their centres installed, and source transforms mapped to
//! them by role ([`RigidPlan`]); [`entries`] then writes the FAT's transform entries.

mod centres;
mod entries;
mod hierarchy;
pub mod standard;

use std::collections::{BTreeMap, BTreeSet, HashMap, HashSet};

use glam::{Affine3A, Vec3};

pub use centres::install_center;
use centres::{install_eye_centres, install_head_centre, install_rotated_part_centres};
pub(super) use hierarchy::ancestors as hierarchy_ancestors;
use hierarchy::{encloses, lowest_enclosing, roles, unique_name};

use super::{CloneReport, FaceParts, Part, Similarity};
use crate::error::{Diagnostic, Result};
use crate::face::{FaceModel, FaceTransform};
use crate::fat::TransformField;

/// Role of a transform in cloning.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
enum Role {
    Part(Part),
    Head,
}

/// The target transforms the source's transform motion maps to.
pub(super) struct RigidPlan {
    /// Target transform per source transform index.
    map: HashMap<usize, (Role, usize)>,
    /// Target tongue transform (for rigid tongue motion).
    tongue: Option<usize>,
    /// The source's head transform when it drives head motion the target has no head
    /// transform for: its head turns (48–50) are re-made by the standard step instead.
    standard_head: Option<usize>,
}

/// What the source FAT drives: transforms it moves or rotates, and the parts that therefore
/// need a transform of their own on the target.
struct SourceDrive<'a> {
    /// Names of the source transforms any table moves.
    driven: HashSet<&'a str>,
    /// Names of the source transforms any table rotates.
    rotated: HashSet<&'a str>,
    /// Parts the target needs a transform for.
    needed: BTreeSet<Part>,
}

impl<'a> SourceDrive<'a> {
    fn of(source: &'a FaceModel, sparts: &FaceParts, sroles: &BTreeMap<Part, usize>) -> Self {
        let driven: HashSet<&str> = source
            .fat
            .tables
            .iter()
            .flat_map(|t| t.transforms.iter().map(|x| x.transform.as_str()))
            .collect();
        let rotated: HashSet<&str> = source
            .fat
            .tables
            .iter()
            .flat_map(|t| t.transforms.iter())
            .filter(|x| x.field == TransformField::Rotation)
            .map(|x| x.transform.as_str())
            .collect();
        let tongue_meshes = tongue_mesh_names(source, sparts);
        let tongue_deformed = source.fat.tables.iter().any(|t| {
            t.meshes
                .iter()
                .any(|m| tongue_meshes.contains(m.mesh.as_str()))
        });
        let mut needed: BTreeSet<Part> = sroles
            .iter()
            .filter(|(_, &t)| driven.contains(source.transforms[t].name.as_str()))
            .map(|(&p, _)| p)
            .collect();
        if tongue_deformed {
            needed.insert(Part::Tongue);
        }
        SourceDrive {
            driven,
            rotated,
            needed,
        }
    }
}

/// Names of the source's tongue meshes.
fn tongue_mesh_names<'a>(source: &'a FaceModel, sparts: &FaceParts) -> HashSet<&'a str> {
    sparts
        .parts
        .get(&Part::Tongue)
        .into_iter()
        .flatten()
        .map(|&m| source.meshes[m].name.as_str())
        .collect()
}

impl RigidPlan {
    /// Prepares the target `face` for rigid motion: its head transform (if any) and part
    /// transforms (created where missing), their centres, and the map from source transforms. Fills `report.rigid` and
    /// warns about created transforms and parts only one face has.
    pub(super) fn install(
        source: &FaceModel,
        sparts: &FaceParts,
        face: &mut FaceModel,
        tparts: &FaceParts,
        frame: &Similarity,
        report: &mut CloneReport,
    ) -> Result<RigidPlan> {
        let (sroles, shead) = roles(source, sparts);
        let drive = SourceDrive::of(source, sparts, &sroles);
        let mut created = Vec::new();
        // The head is the target's own transform enclosing every face mesh, never a new one:
        // a root wrapped around a user's face would change their asset, and it would turn the
        // neck's base with the skull. Without one, the source's head turns are re-made as the
        // standard's per-vertex rotations, faded down the neck (step 10).
        let head = lowest_enclosing(face, &tparts.face_meshes());
        let head_driven =
            shead.is_some_and(|h| drive.driven.contains(source.transforms[h].name.as_str()));
        let standard_head = shead.filter(|&h| {
            head.is_none()
                && source.fat.tables.iter().any(|t| {
                    standard::is_standard_rotation(t.key)
                        && t.transforms
                            .iter()
                            .any(|x| x.transform == source.transforms[h].name)
                })
        });
        let part_tf = part_transforms(face, tparts, head, &drive.needed, &mut created);
        if !created.is_empty() {
            // The kept scene stays: its writer inserts the new transforms where their
            // content sits, so nodes fbakit does not read are not lost.
            report.warnings.push(Diagnostic::warning(format!(
                "created transforms {}",
                created.join(", ")
            )));
        }
        let mut installed = Vec::new();
        install_eye_centres(face, tparts, &part_tf, &mut installed);
        if let Some(head) = head.filter(|_| head_driven) {
            install_head_centre(face, head, &mut installed, &mut report.warnings);
        }
        install_rotated_part_centres(
            source,
            &sroles,
            &drive.rotated,
            face,
            &part_tf,
            frame,
            &mut installed,
        );
        let mut map = part_map(
            source,
            &sroles,
            &part_tf,
            &drive.driven,
            &mut report.warnings,
        );
        if let (Some(sh), Some(head)) = (shead, head) {
            map.entry(sh).or_insert((Role::Head, head));
        }
        report.rigid.part_transforms = part_tf
            .iter()
            .map(|(&p, &t)| (p, face.transforms[t].name.clone()))
            .collect();
        report.rigid.head_transform = head.map(|h| face.transforms[h].name.clone());
        report.rigid.created_transforms = created;
        report.rigid.installed_centres = installed;
        warn_unmatched_parts(sparts, tparts, &mut report.warnings);
        Ok(RigidPlan {
            map,
            tongue: part_tf.get(&Part::Tongue).copied(),
            standard_head,
        })
    }

    /// Whether the source's head turns (48–50) drive a head transform the target does not
    /// have: the clone then re-makes them as the standard's rotations (step 10).
    pub(super) fn remakes_head_turns(&self) -> bool {
        self.standard_head.is_some()
    }
}

/// The transform of each target part: its lowest enclosing transform when that holds only
/// the part (the lower teeth may share theirs with the tongue), else — for `needed` parts — a
/// new transform under that one or the head (a root without either; its name goes to
/// `created`).
fn part_transforms(
    face: &mut FaceModel,
    tparts: &FaceParts,
    head: Option<usize>,
    needed: &BTreeSet<Part>,
    created: &mut Vec<String>,
) -> BTreeMap<Part, usize> {
    let mut part_tf: BTreeMap<Part, usize> = BTreeMap::new();
    for (&p, meshes) in &tparts.parts {
        let low = lowest_enclosing(face, meshes);
        // The enclosing transform when the part's meshes are all it holds; an `Option` so
        // the exclusive case carries its transform and needs no unwrap.
        let exclusive = low.filter(|&t| {
            Some(t) != head
                && (0..face.meshes.len()).all(|m| {
                    !encloses(face, t, m)
                        || meshes.contains(&m)
                        || (p == Part::LowerTeeth
                            && tparts
                                .parts
                                .get(&Part::Tongue)
                                .is_some_and(|x| x.contains(&m)))
                })
        });
        if let Some(t) = exclusive {
            part_tf.insert(p, t);
        } else if needed.contains(&p) {
            let (name, new_t) = add_part_transform(face, p, meshes, low.or(head));
            created.push(name);
            part_tf.insert(p, new_t);
        }
    }
    part_tf
}

/// Adds a transform for part `p` under `parent` (a root for `None`) and moves the part's meshes into it, their
/// world positions unchanged. Returns its name and index.
fn add_part_transform(
    face: &mut FaceModel,
    p: Part,
    meshes: &[usize],
    parent: Option<usize>,
) -> (String, usize) {
    let name = unique_name(face, &format!("{}_tf", p.name()));
    let frames = face.frames();
    let parent_world = parent.map_or(Affine3A::IDENTITY, |t| frames.transforms[t]);
    face.transforms
        .push(FaceTransform::new(name.clone(), parent, Vec3::ZERO));
    let new_t = face.transforms.len() - 1;
    for &m in meshes {
        // Re-express the mesh in the new transform's frame (= the parent's).
        let to_new = parent_world.inverse() * frames.meshes[m];
        if to_new != Affine3A::IDENTITY {
            for q in &mut face.meshes[m].mesh.positions {
                *q = to_new.transform_point3(*q);
            }
        }
        face.meshes[m].transform = Some(new_t);
    }
    (name, new_t)
}

/// Source part transform → target part transform; warns when the source drives a part the
/// target lacks.
fn part_map(
    source: &FaceModel,
    sroles: &BTreeMap<Part, usize>,
    part_tf: &BTreeMap<Part, usize>,
    driven: &HashSet<&str>,
    warnings: &mut Vec<Diagnostic>,
) -> HashMap<usize, (Role, usize)> {
    let mut map = HashMap::new();
    for (&p, &st) in sroles {
        match part_tf.get(&p) {
            Some(&tt) => {
                map.entry(st).or_insert((Role::Part(p), tt));
            }
            None => {
                if driven.contains(source.transforms[st].name.as_str()) {
                    warnings.push(Diagnostic::warning(format!(
                        "target has no {} part: its transform motion is dropped",
                        p.name()
                    )));
                }
            }
        }
    }
    map
}

/// Warns about each part only one of the faces has.
fn warn_unmatched_parts(sparts: &FaceParts, tparts: &FaceParts, warnings: &mut Vec<Diagnostic>) {
    for p in Part::ALL {
        if sparts.parts.contains_key(&p) != tparts.parts.contains_key(&p) {
            let side = if sparts.parts.contains_key(&p) {
                "target"
            } else {
                "source"
            };
            warnings.push(Diagnostic::warning(format!(
                "the {side} face has no {} mesh",
                p.name()
            )));
        }
    }
}
