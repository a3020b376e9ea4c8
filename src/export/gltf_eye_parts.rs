//! Eyeballs that are vertices of a bigger mesh, turned by the user's eye joints: the VRM /
//! VRoid layout, where one primitive (or several: eye white, iris, highlight) holds both
//! eyeballs skinned to two eye joints.
//!
//! The cloner cuts such a primitive into one eyeball each and bakes each eye's turn (FAPs
//! 23–26) into per-vertex displacements of that eyeball's vertices (a FAT transform covers a
//! whole mesh). When an eye joint carries at least 95 % of the skin weight of the vertices one
//! eye's tables move, and nothing else of the face beyond strays, the joint shows that motion
//! instead: the displacements at each interval border of the eye's tables are fitted by a
//! rotation about one pivot (the eyeball's centre, common to yaw and pitch), the vertices get
//! no morph delta under those tables, and `play` turns the joint by the fitted rotation
//! (interpolated in angle between borders). The fit is recorded in the scene's extras
//! (`nodeParts`, `specs/gltf-fat.md`), from which a reader rebuilds the same per-vertex rows.

use glam::{Affine3A, DMat3, DVec3, Quat, Vec3};
use serde_json::{json, Value};

use super::gltf_carried::ShareReader;
use super::gltf_rotations::{eye_nodes, RotationNodes};
use super::gltf_user_nodes::eye_node_refusal;
use crate::error::Diagnostic;
use crate::face::FaceModel;
use crate::fat::eval::Activation;
use crate::fat::{interval_weights, TableKey};
use crate::gltf::source::GltfSource;
use crate::mesh::rotation_fit::fit_rotation;
use crate::spec::{FapId, FeaturePointId};

/// Least share of an eyeball's skin weight on its eye joint (as for whole eyeball meshes).
const EYEBALL_CARRIED: f32 = 0.95;
/// Largest share of a vertex outside the eyeball the joint may move.
const STRAY_SHARE: f32 = 1e-3;
/// Share of the eyeball's size the fitted turn may miss a baked displacement by.
const RIGID_TOLERANCE: f64 = 0.01;

/// One eye's tables: (pupil, yaw FAP, pitch FAP).
const EYES: [(FeaturePointId, u8, u8); 2] = [
    (FeaturePointId::FP_3_5, 23, 25),
    (FeaturePointId::FP_3_6, 24, 26),
];

/// The turn of one table shown by the joint: a rotation per interval border.
#[derive(Clone, Debug, PartialEq)]
pub struct PartTurn {
    /// The table (a yaw or pitch FAP of the eye).
    pub key: TableKey,
    /// The entry's interval borders.
    pub borders: Vec<f64>,
    /// The fitted rotation at each border (face frame, identity at 0).
    pub rotations: Vec<Quat>,
}

impl PartTurn {
    /// The rotation at FAP value `p`: the borders' rotations joined by turns at a steady rate,
    /// the outer intervals continued, as the FAT's interval rule continues them.
    pub fn at(&self, p: f64) -> Quat {
        let n = self.borders.len();
        if n < 2 || !p.is_finite() {
            return Quat::IDENTITY;
        }
        let j = (0..n - 1)
            .find(|&j| p <= self.borders[j + 1])
            .unwrap_or(n - 2);
        let (a, b) = (self.borders[j], self.borders[j + 1]);
        let t = ((p - a) / (b - a)) as f32;
        let (qa, mut qb) = (self.rotations[j], self.rotations[j + 1]);
        // The short way between the two (a fitted quaternion's sign is arbitrary).
        if qa.dot(qb) < 0.0 {
            qb = -qb;
        }
        let (axis, angle) = (qa.inverse() * qb).to_axis_angle();
        (qa * Quat::from_axis_angle(axis, angle * t)).normalize()
    }
}

/// An eyeball of a mesh shown by a user's eye joint.
#[derive(Clone, Debug, PartialEq)]
pub struct EyePart {
    /// The glTF node (the eye joint).
    pub node: usize,
    /// The face mesh holding the eyeball.
    pub mesh: usize,
    /// The eyeball's vertices (those the eye's tables move).
    pub vertices: Vec<u32>,
    /// The pivot, in the face frame.
    pub center: Vec3,
    /// One turn per table of the eye.
    pub turns: Vec<PartTurn>,
}

impl EyePart {
    /// The part's motion (face frame) under `activations`: each table's turn about the pivot,
    /// in table order.
    pub fn motion(&self, activations: &[Activation]) -> Affine3A {
        let mut r = Quat::IDENTITY;
        for t in &self.turns {
            for a in activations.iter().filter(|a| a.key == t.key) {
                r = t.at(a.value) * r;
            }
        }
        Affine3A::from_translation(self.center)
            * Affine3A::from_quat(r.normalize())
            * Affine3A::from_translation(-self.center)
    }

    /// Whether it takes the motion of `key`.
    pub fn takes(&self, key: TableKey) -> bool {
        self.turns.iter().any(|t| t.key == key)
    }

    /// The scene-record entry (`nodeParts[]`), lengths × `scale` (file units per face unit).
    pub fn record(&self, face: &FaceModel, scale: f32) -> Value {
        let c = self.center * scale;
        json!({
            "mesh": face.meshes[self.mesh].name,
            "node": self.node,
            "userNode": true,
            "vertices": self.vertices,
            "center": [c.x, c.y, c.z],
            "tables": self.turns.iter().map(|t| json!({
                "key": t.key.name(),
                "borders": t.borders,
                "rotations": t.rotations.iter().map(|q| json!([q.x, q.y, q.z, q.w])).collect::<Vec<_>>(),
            })).collect::<Vec<_>>(),
        })
    }
}

/// The eyeballs of `face` that are vertices of a mesh (their eye's tables move them vertex by
/// vertex) and that the user's eye joints turn alone (module docs). Nodes in `taken` already
/// show something. An eye joint weighted to part of its eyeball, or to more than it, or an
/// eyeball the FAT does not turn rigidly, is not used: a warning says why, and the motion
/// stays in morph targets.
pub fn eye_parts(
    face: &FaceModel,
    source: &GltfSource,
    names: &RotationNodes,
    taken: &[usize],
    warnings: &mut Vec<Diagnostic>,
) -> Vec<EyePart> {
    let (left, right) = eye_nodes(source, names);
    let json = &source.json;
    let reader = ShareReader::new(source);
    let frames = face.frames();
    let mut out = Vec::new();
    for (node, (pupil, yaw, pitch)) in [left, right].into_iter().zip(EYES) {
        let Some(node) = node.filter(|n| !taken.contains(n)) else {
            continue;
        };
        let Some((mesh, pupil_vertex)) = face.fp_vertex(pupil) else {
            continue;
        };
        let fm = &face.meshes[mesh];
        let keys: Vec<TableKey> = [yaw, pitch]
            .into_iter()
            .filter_map(FapId::new)
            .map(TableKey::LowLevel)
            .collect();
        // The eye's entries on the pupil's mesh, and the vertices they move.
        let entries: Vec<(TableKey, &crate::fat::FaceDefMesh)> = face
            .fat
            .tables
            .iter()
            .filter(|t| keys.contains(&t.key))
            .flat_map(|t| {
                t.meshes
                    .iter()
                    .filter(|m| m.mesh == fm.name)
                    .map(move |m| (t.key, m))
            })
            .collect();
        let mut vertices: Vec<u32> = entries
            .iter()
            .flat_map(|(_, e)| {
                let k = e.interval_count();
                e.coord_index
                    .iter()
                    .enumerate()
                    .filter(move |(i, _)| {
                        e.displacements
                            .get(i * k..(i + 1) * k)
                            .is_some_and(|r| r.iter().any(|d| *d != Vec3::ZERO))
                    })
                    .map(|(_, &v)| v)
            })
            .collect();
        vertices.sort_unstable();
        vertices.dedup();
        if vertices.is_empty() {
            continue;
        }
        let refuse = |why: String| eye_node_refusal(source, node, &why);
        // How much of every face vertex the joint moves.
        let mut shares: Vec<Vec<f32>> = Vec::with_capacity(face.meshes.len());
        let mut unreadable = None;
        for m in &face.meshes {
            let n = m.mesh.vertex_count();
            let s = match source.part(&m.name) {
                None => vec![0.0; n],
                Some(p) => match reader.shares(p.node, p.mesh, p.primitive, node) {
                    Some(s) => s.of(n),
                    None => {
                        unreadable.get_or_insert_with(|| m.name.clone());
                        vec![0.0; n]
                    }
                },
            };
            shares.push(s);
        }
        let on = &shares[mesh];
        let mean = vertices
            .iter()
            .map(|&v| on.get(v as usize).copied().unwrap_or(0.0))
            .sum::<f32>()
            / vertices.len() as f32;
        // A vertex in no polygon is not seen and never moves (a sphere's unused pole copies).
        let elsewhere = shares.iter().enumerate().find_map(|(m, s)| {
            if !s.iter().any(|&x| x > STRAY_SHARE) {
                return None;
            }
            let mut used = vec![false; s.len()];
            for &v in face.meshes[m].mesh.polygons.indices() {
                if let Some(u) = used.get_mut(v as usize) {
                    *u = true;
                }
            }
            s.iter()
                .enumerate()
                .find(|&(v, &x)| {
                    x > STRAY_SHARE
                        && used[v]
                        && !(m == mesh && vertices.binary_search(&(v as u32)).is_ok())
                })
                .map(|(v, _)| (m, v as u32))
        });
        if mean <= STRAY_SHARE && elsewhere.is_none() {
            if let Some(m) = unreadable {
                warnings.push(refuse(format!(
                    "the skin weights of mesh `{m}` cannot be read"
                )));
            }
            // A joint that moves nothing of the face (an unused bone): nothing to turn.
            continue;
        }
        if mean < EYEBALL_CARRIED {
            warnings.push(refuse(if mean <= STRAY_SHARE {
                "its meshes and the eyeball the face turns are not the same".into()
            } else {
                format!(
                    "the eyeball in mesh `{}` is weighted to it by {:.0} % only, not {:.0} %",
                    fm.name,
                    mean * 100.0,
                    EYEBALL_CARRIED * 100.0
                )
            }));
            continue;
        }
        if let Some((m, v)) = elsewhere {
            let other = EYES
                .iter()
                .map(|e| e.0)
                .filter(|&p| p != pupil)
                .any(|p| face.fp_vertex(p) == Some((m, v)));
            warnings.push(refuse(if other {
                "it holds both eyes".into()
            } else {
                format!(
                    "it moves mesh `{}` beyond the eyeball (vertex {v})",
                    face.meshes[m].name
                )
            }));
            continue;
        }
        if vertices.binary_search(&pupil_vertex).is_err() {
            warnings.push(refuse(format!("its eyeball holds no pupil {pupil}")));
            continue;
        }
        if json["nodes"][node].get("matrix").is_some() {
            warnings.push(refuse(
                "it is given by a matrix, which glTF cannot animate".into(),
            ));
            continue;
        }
        // The eyeball at rest and each entry's displacements at its borders, face frame.
        let frame = frames.meshes[mesh];
        let rest: Vec<DVec3> = vertices
            .iter()
            .map(|&v| {
                let p = fm
                    .mesh
                    .positions
                    .get(v as usize)
                    .copied()
                    .unwrap_or(Vec3::ZERO);
                frame.transform_point3(p).as_dvec3()
            })
            .collect();
        let size =
            crate::fat::bake::part_size(&rest.iter().map(|p| p.as_vec3()).collect::<Vec<_>>());
        match fit_turns(&entries, &vertices, &rest, frame, f64::from(size)) {
            Ok((center, turns)) => out.push(EyePart {
                node,
                mesh,
                vertices,
                center,
                turns,
            }),
            Err(off) => warnings.push(refuse(format!(
                "the FAT does not turn its eyeball rigidly: off by {:.1} % of its size",
                100.0 * off / f64::from(size).max(f64::MIN_POSITIVE)
            ))),
        }
    }
    out
}

/// The rotations fitting every entry at its borders and the pivot they share, or the largest
/// miss when one is off by more than [`RIGID_TOLERANCE`] of `size`.
fn fit_turns(
    entries: &[(TableKey, &crate::fat::FaceDefMesh)],
    vertices: &[u32],
    rest: &[DVec3],
    frame: Affine3A,
    size: f64,
) -> Result<(Vec3, Vec<PartTurn>), f64> {
    let n = rest.len() as f64;
    let mean = rest.iter().copied().sum::<DVec3>() / n;
    let mut weights = Vec::new();
    // Per entry, per border: (rotation, moved positions).
    type Fits = Vec<(DMat3, Vec<DVec3>)>;
    let mut fitted: Vec<(TableKey, Vec<f64>, Fits)> = Vec::new();
    for &(key, e) in entries {
        let k = e.interval_count();
        let slot: Vec<Option<usize>> = vertices
            .iter()
            .map(|v| e.coord_index.iter().position(|c| c == v))
            .collect();
        let mut per_border = Vec::with_capacity(e.interval_borders.len());
        for &b in &e.interval_borders {
            interval_weights(&e.interval_borders, b, &mut weights);
            let moved: Vec<DVec3> = rest
                .iter()
                .zip(&slot)
                .map(|(&x, s)| {
                    let d = s.map_or(DVec3::ZERO, |i| {
                        (0..k)
                            .map(|j| {
                                e.displacements[i * k + j].as_dvec3()
                                    * weights.get(j).copied().unwrap_or(0.0)
                            })
                            .sum::<DVec3>()
                    });
                    x + frame.transform_vector3(d.as_vec3()).as_dvec3()
                })
                .collect();
            per_border.push((kabsch(rest, &moved, mean), moved));
        }
        fitted.push((key, e.interval_borders.clone(), per_border));
    }
    // The pivot c with R·(x − c) + c = y for every fit: least squares over all borders, held
    // near the eyeball's centroid along an axis every turn shares.
    let mut a = DMat3::ZERO;
    let mut rhs = DVec3::ZERO;
    for (_, _, list) in &fitted {
        for (r, moved) in list {
            let ym = moved.iter().copied().sum::<DVec3>() / n;
            // y = R·x + t with t = ȳ − R·x̄; (I − R)·c = t.
            let t = ym - *r * mean;
            let m = DMat3::IDENTITY - *r;
            a += m.transpose() * m;
            rhs += m.transpose() * t;
        }
    }
    let reg = 1e-9 * (a.x_axis.x + a.y_axis.y + a.z_axis.z).max(1e-30);
    a += DMat3::from_diagonal(DVec3::splat(reg));
    rhs += mean * reg;
    let center = if a.determinant().abs() > 0.0 {
        a.inverse() * rhs
    } else {
        mean
    };
    let mut worst = 0.0f64;
    let mut turns = Vec::new();
    for (key, borders, list) in fitted {
        let mut rotations = Vec::with_capacity(list.len());
        for (r, moved) in &list {
            for (x, y) in rest.iter().zip(moved) {
                worst = worst.max((*r * (*x - center) + center).distance(*y));
            }
            rotations.push(
                Quat::from_mat3(&glam::Mat3::from_cols(
                    r.x_axis.as_vec3(),
                    r.y_axis.as_vec3(),
                    r.z_axis.as_vec3(),
                ))
                .normalize(),
            );
        }
        turns.push(PartTurn {
            key,
            borders,
            rotations,
        });
    }
    if worst > RIGID_TOLERANCE * size {
        return Err(worst);
    }
    Ok((center.as_vec3(), turns))
}

/// The rotation taking `from` (about `mean`) onto `to` (about its own mean), least squares
/// (Kabsch: the polar factor of the covariance, by SVD).
fn kabsch(from: &[DVec3], to: &[DVec3], mean: DVec3) -> DMat3 {
    let n = to.len().max(1) as f64;
    let tm = to.iter().copied().sum::<DVec3>() / n;
    let pairs = from.iter().zip(to).map(|(x, y)| (*x - mean, *y - tm));
    fit_rotation(pairs).map_or(DMat3::IDENTITY, |fit| fit.rotation)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fat::bake::{bake_motion, BakeRequest};

    /// An eyeball turned about its centre by two tables (yaw about y, pitch about x), baked
    /// into per-vertex rows as the cloner bakes them: the fit finds the centre and each
    /// border's rotation, and the turn between borders stays on the baked rows within the
    /// bake's tolerance.
    #[test]
    fn baked_turns_are_fitted_back_with_their_pivot() {
        let centre = Vec3::new(0.03, 1.62, 0.08);
        let rest: Vec<Vec3> = (0..40)
            .map(|i| {
                let (a, b) = (i as f32 * 0.7, i as f32 * 1.3);
                centre + 0.012 * Vec3::new(a.sin() * b.cos(), a.sin() * b.sin(), a.cos())
            })
            .collect();
        let vertices: Vec<u32> = (0..rest.len() as u32).collect();
        let yaw = TableKey::LowLevel(FapId::new(23).unwrap());
        let pitch = TableKey::LowLevel(FapId::new(25).unwrap());
        let turn = |axis: Vec3| {
            move |p: f64| {
                Affine3A::from_translation(centre)
                    * Affine3A::from_axis_angle(axis, (p * 1e-5) as f32)
                    * Affine3A::from_translation(-centre)
            }
        };
        let bake = |axis: Vec3| {
            bake_motion(
                &BakeRequest {
                    mesh: "eyes",
                    vertices: &vertices,
                    neutral: &rest,
                    range: (-40000.0, 40000.0),
                    borders: &[],
                    tolerance: 0.01 * 0.024,
                },
                turn(axis),
            )
            .entry
        };
        let (ey, ep) = (bake(Vec3::Y), bake(Vec3::X));
        let entries = [(yaw, &ey), (pitch, &ep)];
        let rest64: Vec<DVec3> = rest.iter().map(|p| p.as_dvec3()).collect();
        let (c, turns) =
            fit_turns(&entries, &vertices, &rest64, Affine3A::IDENTITY, 0.024).unwrap();
        assert!(c.distance(centre) < 1e-5, "{c} vs {centre}");
        for (t, axis) in turns.iter().zip([Vec3::Y, Vec3::X]) {
            for (b, q) in t.borders.iter().zip(&t.rotations) {
                let want = Quat::from_axis_angle(axis, (*b * 1e-5) as f32);
                assert!(q.angle_between(want) < 1e-4, "{b}: {q} vs {want}");
            }
            // A border's quaternion of the other sign is the same turn.
            let mut flipped = t.clone();
            flipped.rotations[1] = -flipped.rotations[1];
            let mid = (t.borders[1] + t.borders[2]) / 2.0;
            assert!(flipped.at(mid).angle_between(t.at(mid)) < 1e-5);
            // Between borders: the played turn against the true one.
            let part = EyePart {
                node: 0,
                mesh: 0,
                vertices: vertices.clone(),
                center: c,
                turns: vec![t.clone()],
            };
            for p in [-33333.0, -1234.0, 5000.0, 27000.0] {
                let a = [Activation {
                    key: t.key,
                    value: p,
                }];
                let (got, want) = (part.motion(&a), turn(axis)(p));
                for x in &rest {
                    let d = got.transform_point3(*x).distance(want.transform_point3(*x));
                    assert!(d < 1e-4, "{p}: off by {d}");
                }
            }
        }
        // Rows that are not one turn (every vertex pushed forward) are refused.
        let mut bent = ey.clone();
        for (i, d) in bent.displacements.iter_mut().enumerate() {
            *d += Vec3::Z * 1e-7 * (i % 7) as f32;
        }
        let entries = [(yaw, &bent)];
        assert!(fit_turns(&entries, &vertices, &rest64, Affine3A::IDENTITY, 0.024).is_err());
    }
}
