//! Eyeballs that are vertices of a bigger mesh, turned by the user's eye joints: the VRM /
//! VRoid layout, where one primitive (or several: eye white, iris, highlight) holds both
//! eyeballs skinned to two eye joints.
//!
//! The cloner cuts such a primitive into one eyeball each and bakes each eye's turn (FAPs
//! 23–26) into per-vertex displacements of that eyeball's vertices (a FAT transform covers a
//! whole mesh). When an eye joint carries at least 95 % of the skin weight of the vertices one
//! eye's tables move — in the pupil's mesh and in every other mesh the joint carries any of
//! them (VRoid's iris and highlight primitives, or meshes of their own) — and nothing else of
//! the face beyond strays, the joint shows that motion instead: the displacements at each
//! interval border of the eye's tables are fitted, over all those meshes, by a rotation about
//! one pivot (the eyeball's centre, common to yaw and pitch), the vertices get no morph delta
//! under those tables, and `play` turns the joint by the fitted rotation (interpolated in
//! angle between borders). The fit is recorded in the scene's extras (`nodeParts`,
//! `specs/gltf-fat.md`), from which a reader rebuilds the same per-vertex rows.

use glam::{Affine3A, DMat3, DVec3, Quat, Vec3};
use serde_json::{json, Value};

use super::gltf_carried::ShareReader;
use super::gltf_rotations::{eye_nodes, RotationNodes};
use super::gltf_user_nodes::eye_node_refusal;
use crate::error::Diagnostic;
use crate::face::FaceModel;
use crate::fat::eval::Activation;
use crate::fat::{interval_weights, FaceDefMesh, TableKey};
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

/// The vertices of one face mesh that belong to an eyeball a joint turns.
#[derive(Clone, Debug, PartialEq)]
pub struct PartMesh {
    /// The face mesh.
    pub mesh: usize,
    /// Its vertices in the eyeball (those the eye's tables move), increasing.
    pub vertices: Vec<u32>,
}

/// An eyeball shown by a user's eye joint: vertices of one or several face meshes (VRoid's
/// eye white, iris and highlight primitives), turned about one pivot.
#[derive(Clone, Debug, PartialEq)]
pub struct EyePart {
    /// The glTF node (the eye joint).
    pub node: usize,
    /// The eyeball's vertices, per face mesh (in the face's mesh order).
    pub meshes: Vec<PartMesh>,
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
            "meshes": self.meshes.iter().map(|m| json!({
                "mesh": face.meshes[m.mesh].name,
                "vertices": m.vertices,
            })).collect::<Vec<_>>(),
            "node": self.node,
            "userNode": true,
            "center": [c.x, c.y, c.z],
            "tables": self.turns.iter().map(|t| json!({
                "key": t.key.name(),
                "borders": t.borders,
                "rotations": t.rotations.iter().map(|q| json!([q.x, q.y, q.z, q.w])).collect::<Vec<_>>(),
            })).collect::<Vec<_>>(),
        })
    }
}

/// One face mesh's share of an eyeball while it is fitted: its frame, its vertices the eye's
/// tables move, and those tables' entries on it.
struct BallMesh<'a> {
    mesh: usize,
    frame: Affine3A,
    vertices: Vec<u32>,
    entries: Vec<(TableKey, &'a FaceDefMesh)>,
}

/// The eyeballs of `face` that are vertices of meshes (their eye's tables move them vertex by
/// vertex) and that the user's eye joints turn alone (module docs). An eyeball is every vertex,
/// over the face's meshes, that its eye's yaw and pitch tables move, on the pupil's mesh and on
/// every other mesh the joint carries any of them (VRoid's eye white, iris and highlight).
/// Nodes in `taken` already show something. An eye joint weighted to part of its eyeball in
/// any of those meshes, or to more than it, or an eyeball the FAT does not turn rigidly, is
/// not used: a warning says why, and the motion stays in morph targets.
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
        let Some((pupil_mesh, pupil_vertex)) = face.fp_vertex(pupil) else {
            continue;
        };
        let keys: Vec<TableKey> = [yaw, pitch]
            .into_iter()
            .filter_map(FapId::new)
            .map(TableKey::LowLevel)
            .collect();
        // Per face mesh, the eye's entries on it and the vertices they move.
        let moved: Vec<BallMesh> = face
            .meshes
            .iter()
            .enumerate()
            .map(|(mi, fm)| {
                let entries: Vec<(TableKey, &FaceDefMesh)> = face
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
                    .flat_map(|(_, e)| moved_vertices(e))
                    .collect();
                vertices.sort_unstable();
                vertices.dedup();
                BallMesh {
                    mesh: mi,
                    frame: frames.meshes[mi],
                    vertices,
                    entries,
                }
            })
            .collect();
        if moved[pupil_mesh].vertices.is_empty() {
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
        // The mean share of the moved vertices of each mesh.
        let mean = |b: &BallMesh| {
            let on = &shares[b.mesh];
            b.vertices
                .iter()
                .map(|&v| on.get(v as usize).copied().unwrap_or(0.0))
                .sum::<f32>()
                / b.vertices.len().max(1) as f32
        };
        let ball: Vec<&BallMesh> = moved
            .iter()
            .filter(|b| !b.vertices.is_empty() && (b.mesh == pupil_mesh || mean(b) > STRAY_SHARE))
            .collect();
        let in_ball = |m: usize, v: u32| {
            ball.iter()
                .any(|b| b.mesh == m && b.vertices.binary_search(&v).is_ok())
        };
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
                .find(|&(v, &x)| x > STRAY_SHARE && used[v] && !in_ball(m, v as u32))
                .map(|(v, _)| (m, v as u32))
        });
        let pupil_share = mean(&moved[pupil_mesh]);
        if ball.len() == 1 && pupil_share <= STRAY_SHARE && elsewhere.is_none() {
            if let Some(m) = unreadable {
                warnings.push(refuse(format!(
                    "the skin weights of mesh `{m}` cannot be read"
                )));
            }
            // A joint that moves nothing of the face (an unused bone): nothing to turn.
            continue;
        }
        if pupil_share <= STRAY_SHARE {
            warnings.push(refuse(
                "its meshes and the eyeball the face turns are not the same".into(),
            ));
            continue;
        }
        if let Some(b) = ball.iter().find(|b| mean(b) < EYEBALL_CARRIED) {
            warnings.push(refuse(format!(
                "the eyeball in mesh `{}` is weighted to it by {:.0} % only, not {:.0} %",
                face.meshes[b.mesh].name,
                mean(b) * 100.0,
                EYEBALL_CARRIED * 100.0
            )));
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
        if !in_ball(pupil_mesh, pupil_vertex) {
            warnings.push(refuse(format!("its eyeball holds no pupil {pupil}")));
            continue;
        }
        if json["nodes"][node].get("matrix").is_some() {
            warnings.push(refuse(
                "it is given by a matrix, which glTF cannot animate".into(),
            ));
            continue;
        }
        // The eyeball at rest, face frame, mesh after mesh.
        let rest: Vec<DVec3> = ball
            .iter()
            .flat_map(|b| {
                let positions = &face.meshes[b.mesh].mesh.positions;
                b.vertices.iter().map(move |&v| {
                    let p = positions.get(v as usize).copied().unwrap_or(Vec3::ZERO);
                    b.frame.transform_point3(p).as_dvec3()
                })
            })
            .collect();
        let size =
            crate::fat::bake::part_size(&rest.iter().map(|p| p.as_vec3()).collect::<Vec<_>>());
        match fit_turns(&keys, &ball, &rest, f64::from(size)) {
            Ok((center, turns)) => out.push(EyePart {
                node,
                meshes: ball
                    .iter()
                    .map(|b| PartMesh {
                        mesh: b.mesh,
                        vertices: b.vertices.clone(),
                    })
                    .collect(),
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

/// The vertices `e` moves (a row not all zero).
fn moved_vertices(e: &FaceDefMesh) -> impl Iterator<Item = u32> + '_ {
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
}

/// The rotations fitting every table of `keys` at its borders over all of `ball` (at rest
/// `rest`, face frame, mesh after mesh) and the pivot they share, or the largest miss when
/// one is off by more than [`RIGID_TOLERANCE`] of `size`. A table's borders are those of its
/// entries on every mesh of the ball (the same, as the cloner bakes one part's turn).
fn fit_turns(
    keys: &[TableKey],
    ball: &[&BallMesh],
    rest: &[DVec3],
    size: f64,
) -> Result<(Vec3, Vec<PartTurn>), f64> {
    let n = rest.len() as f64;
    let mean = rest.iter().copied().sum::<DVec3>() / n;
    let mut weights = Vec::new();
    // Per table, per border: (rotation, moved positions).
    type Fits = Vec<(DMat3, Vec<DVec3>)>;
    let mut fitted: Vec<(TableKey, Vec<f64>, Fits)> = Vec::new();
    for &key in keys {
        let mut borders: Vec<f64> = ball
            .iter()
            .flat_map(|b| b.entries.iter().filter(|e| e.0 == key))
            .flat_map(|e| e.1.interval_borders.iter().copied())
            .collect();
        borders.sort_by(f64::total_cmp);
        borders.dedup();
        if borders.len() < 2 {
            continue;
        }
        // Per mesh, per vertex: its rows in this table's entries on the mesh.
        let slots: Vec<Vec<Vec<(&FaceDefMesh, usize)>>> = ball
            .iter()
            .map(|b| {
                b.vertices
                    .iter()
                    .map(|v| {
                        b.entries
                            .iter()
                            .filter(|e| e.0 == key)
                            .filter_map(|&(_, e)| {
                                Some((e, e.coord_index.iter().position(|c| c == v)?))
                            })
                            .collect()
                    })
                    .collect()
            })
            .collect();
        let mut per_border = Vec::with_capacity(borders.len());
        for &p in &borders {
            let mut moved = Vec::with_capacity(rest.len());
            for (b, slots) in ball.iter().zip(&slots) {
                for rows in slots {
                    let mut d = DVec3::ZERO;
                    for &(e, i) in rows {
                        interval_weights(&e.interval_borders, p, &mut weights);
                        let k = e.interval_count();
                        for (j, w) in weights.iter().enumerate().take(k) {
                            let row = e.displacements.get(i * k + j).copied();
                            d += row.unwrap_or(Vec3::ZERO).as_dvec3() * *w;
                        }
                    }
                    let x = rest[moved.len()];
                    moved.push(x + b.frame.transform_vector3(d.as_vec3()).as_dvec3());
                }
            }
            per_border.push((kabsch(rest, &moved, mean), moved));
        }
        fitted.push((key, borders, per_border));
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

    /// An eyeball in two meshes (an eye white and, in a frame of its own, an iris) turned
    /// about its centre by two tables (yaw about y, pitch about x), baked into per-vertex rows
    /// as the cloner bakes them: the fit over both meshes finds the centre and each border's
    /// rotation, and the turn between borders stays on the baked rows within the bake's
    /// tolerance.
    #[test]
    fn baked_turns_are_fitted_back_with_their_pivot() {
        let centre = Vec3::new(0.03, 1.62, 0.08);
        let rest: Vec<Vec3> = (0..40)
            .map(|i| {
                let (a, b) = (i as f32 * 0.7, i as f32 * 1.3);
                centre + 0.012 * Vec3::new(a.sin() * b.cos(), a.sin() * b.sin(), a.cos())
            })
            .collect();
        // The first 25 points are the white (mesh 0), the others the iris (mesh 1, its
        // vertices numbered from 0, placed by a translation).
        let split = 25;
        let iris_frame = Affine3A::from_translation(Vec3::new(0.0, 1.5, 0.0));
        let yaw = TableKey::LowLevel(FapId::new(23).unwrap());
        let pitch = TableKey::LowLevel(FapId::new(25).unwrap());
        let turn = |axis: Vec3| {
            move |p: f64| {
                Affine3A::from_translation(centre)
                    * Affine3A::from_axis_angle(axis, (p * 1e-5) as f32)
                    * Affine3A::from_translation(-centre)
            }
        };
        let bake = |axis: Vec3, points: &[Vec3]| {
            let vertices: Vec<u32> = (0..points.len() as u32).collect();
            bake_motion(
                &BakeRequest {
                    mesh: "eyes",
                    vertices: &vertices,
                    neutral: points,
                    range: (-40000.0, 40000.0),
                    borders: &[],
                    tolerance: 0.01 * 0.024,
                },
                turn(axis),
            )
            .entry
        };
        let (white, iris) = rest.split_at(split);
        let entries: Vec<[FaceDefMesh; 2]> = [Vec3::Y, Vec3::X]
            .into_iter()
            .map(|axis| [bake(axis, white), bake(axis, iris)])
            .collect();
        let counts = [white.len(), iris.len()];
        fn ball(
            entries: &[[FaceDefMesh; 2]],
            keys: [TableKey; 2],
            counts: [usize; 2],
            iris_frame: Affine3A,
        ) -> Vec<BallMesh<'_>> {
            (0..2)
                .map(|m| BallMesh {
                    mesh: m,
                    frame: if m == 0 {
                        Affine3A::IDENTITY
                    } else {
                        iris_frame
                    },
                    vertices: (0..counts[m] as u32).collect(),
                    entries: keys
                        .into_iter()
                        .zip(entries)
                        .map(|(k, e)| (k, &e[m]))
                        .collect(),
                })
                .collect()
        }
        let meshes = ball(&entries, [yaw, pitch], counts, iris_frame);
        let refs: Vec<&BallMesh> = meshes.iter().collect();
        let rest64: Vec<DVec3> = rest.iter().map(|p| p.as_dvec3()).collect();
        let (c, turns) = fit_turns(&[yaw, pitch], &refs, &rest64, 0.024).unwrap();
        assert!(c.distance(centre) < 1e-5, "{c} vs {centre}");
        assert_eq!(turns.len(), 2);
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
                meshes: Vec::new(),
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
        // Rows that are not one turn (the iris pushed forward) are refused.
        let mut bent = entries.clone();
        for (i, d) in bent[0][1].displacements.iter_mut().enumerate() {
            *d += Vec3::Z * 1e-7 * (i % 7) as f32;
        }
        let meshes = ball(&bent, [yaw, pitch], counts, iris_frame);
        let refs: Vec<&BallMesh> = meshes.iter().collect();
        assert!(fit_turns(&[yaw, pitch], &refs, &rest64, 0.024).is_err());
    }
}
