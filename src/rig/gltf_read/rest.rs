//! The rest pose as rendered: node world matrices, and for skinned meshes their joints'
//! `world × inverseBind` matrices blended per vertex (glTF 2.0 §3.7.3; absent inverse bind
//! matrices are identity). A skin whose joints all carry the same matrix (the usual export:
//! an armature with a 0.01 scale or a z-up turn) places every vertex with that one matrix.

use ::gltf::accessor::{DataType, Dimensions};
use ::gltf::mesh::Semantic;
use ::gltf::{Accessor, Document, Primitive, Skin};
use glam::{Mat3, Mat4};

use super::Reader;
use crate::error::{Diagnostic, Result};

/// Deepest parent chain followed when placing nodes outside the scene walk.
const MAX_CHAIN: usize = 256;

/// How a mesh instance's vertices are placed in the world frame.
pub(super) enum Placement {
    /// One matrix (the node's world matrix, or a skin whose joints agree).
    Matrix(Mat4),
    /// A skin's joint matrices (`world × inverseBind`), blended per vertex.
    Joints(Vec<Mat4>),
}

/// World matrix of every node at rest. Chains deeper than 256 or cyclic (which the scene
/// walk refuses for shown nodes) and non-finite results place a node at identity.
pub(super) fn node_world_matrices(doc: &Document) -> Vec<Mat4> {
    let n = doc.nodes().len();
    let mut parent = vec![None; n];
    for node in doc.nodes() {
        for c in node.children() {
            parent[c.index()] = Some(node.index());
        }
    }
    let local: Vec<Mat4> = doc
        .nodes()
        .map(|n| Mat4::from_cols_array_2d(&n.transform().matrix()))
        .collect();
    (0..n)
        .map(|i| {
            let mut m = local[i];
            let mut at = parent[i];
            let mut depth = 0;
            while let Some(p) = at {
                depth += 1;
                if depth > MAX_CHAIN {
                    return Mat4::IDENTITY;
                }
                m = local[p] * m;
                at = parent[p];
            }
            if m.is_finite() {
                m
            } else {
                Mat4::IDENTITY
            }
        })
        .collect()
}

/// Whether all matrices agree (to a relative 1e-5), so one of them places every vertex.
fn common(list: &[Mat4]) -> Option<Mat4> {
    let first = *list.first()?;
    let scale = first
        .to_cols_array()
        .iter()
        .fold(0.0f32, |a, v| a.max(v.abs()))
        .max(1e-6);
    list.iter()
        .all(|m| m.abs_diff_eq(first, scale * 1e-5))
        .then_some(first)
}

impl Placement {
    /// The placement of one primitive of `n` vertices: one matrix, or (for skins whose joints
    /// differ) identity plus a matrix per vertex to apply after reading.
    pub(super) fn for_primitive(
        &self,
        reader: &mut Reader,
        prim: &Primitive,
        at: &str,
        n: usize,
    ) -> Result<(Mat4, Option<Vec<Mat4>>)> {
        let joints = match self {
            Placement::Matrix(m) => return Ok((*m, None)),
            Placement::Joints(j) => j,
        };
        if let Some(m) = common(joints) {
            return Ok((m, None));
        }
        let (Some(ja), Some(wa)) = (
            prim.get(&Semantic::Joints(0)),
            prim.get(&Semantic::Weights(0)),
        ) else {
            reader.rig.warnings.push(Diagnostic::warning(format!(
                "{}: {at}: skinned without JOINTS_0/WEIGHTS_0; read in its bind pose",
                reader.file.display()
            )));
            return Ok((Mat4::IDENTITY, None));
        };
        reader.check_plain(
            &ja,
            &format!("{at}.attributes.JOINTS_0"),
            (Dimensions::Vec4, &[DataType::U8, DataType::U16]),
            n,
        )?;
        reader.check_plain(
            &wa,
            &format!("{at}.attributes.WEIGHTS_0"),
            (
                Dimensions::Vec4,
                &[DataType::U8, DataType::U16, DataType::F32],
            ),
            n,
        )?;
        let buffers = reader.buffers;
        let r = prim.reader(|b| buffers.get(b.index()).map(|v| v.as_slice()));
        let (Some(js), Some(ws)) = (r.read_joints(0), r.read_weights(0)) else {
            return Ok((Mat4::IDENTITY, None));
        };
        let mut out = Vec::with_capacity(n);
        for (j, w) in js.into_u16().zip(ws.into_f32()) {
            let sum: f32 = w.iter().sum();
            let mut m = Mat4::ZERO;
            for k in 0..4 {
                if w[k] != 0.0 {
                    let jm = joints.get(j[k] as usize).copied().unwrap_or(Mat4::IDENTITY);
                    m += jm * w[k];
                }
            }
            out.push(if sum > 0.0 && sum.is_finite() {
                m * (1.0 / sum)
            } else {
                Mat4::IDENTITY
            });
        }
        out.resize(n, Mat4::IDENTITY);
        Ok(match common(&out) {
            Some(m) => (m, None),
            None => (Mat4::IDENTITY, Some(out)),
        })
    }
}

impl Reader<'_> {
    /// The joint matrices of `skin` at rest.
    pub(super) fn skin_rest(&mut self, skin: &Skin) -> Result<Placement> {
        let at = format!("skins[{}]", skin.index());
        let joints: Vec<usize> = skin.joints().map(|j| j.index()).collect();
        let mut ibm = vec![Mat4::IDENTITY; joints.len()];
        if let Some(acc) = skin.inverse_bind_matrices() {
            let at = format!("{at}.inverseBindMatrices");
            if acc.count() < joints.len() {
                return Err(self.err(
                    &at,
                    format!("{} matrices for {} joints", acc.count(), joints.len()),
                ));
            }
            self.check_plain(&acc, &at, (Dimensions::Mat4, &[DataType::F32]), acc.count())?;
            let buffers = self.buffers;
            let r = skin.reader(|b| buffers.get(b.index()).map(|v| v.as_slice()));
            if let Some(list) = r.read_inverse_bind_matrices() {
                for (slot, m) in ibm.iter_mut().zip(list) {
                    let m = Mat4::from_cols_array_2d(&m);
                    if m.is_finite() {
                        *slot = m;
                    }
                }
            }
        }
        Ok(Placement::Joints(
            joints
                .iter()
                .zip(&ibm)
                .map(|(&j, b)| self.node_world.get(j).copied().unwrap_or(Mat4::IDENTITY) * *b)
                .collect(),
        ))
    }

    /// Checks an accessor read directly by the crate (joints, weights, matrices): its shape,
    /// at least `count` elements, and byte ranges inside the buffers (sparse ones included).
    /// `types` are the component types the crate's reader takes for it (it panics on others:
    /// float joints, say).
    fn check_plain(
        &self,
        acc: &Accessor,
        at: &str,
        (dims, types): (Dimensions, &[DataType]),
        count: usize,
    ) -> Result<()> {
        let at = format!("{at} (accessors[{}])", acc.index());
        let type_ok = acc.dimensions() == dims && types.contains(&acc.data_type());
        if !type_ok {
            return Err(self.err(
                &at,
                format!("unexpected {:?} of {:?}", acc.dimensions(), acc.data_type()),
            ));
        }
        let n = acc.count();
        if n < count || n == 0 || n > super::MAX_ACCESSOR_COUNT {
            return Err(self.err(&at, format!("count {n}, expected {count}")));
        }
        if let Some(view) = acc.view() {
            self.data.check_range(
                &at,
                view.length(),
                view.stride(),
                acc.offset(),
                n,
                acc.size(),
            )?;
        }
        if let Some(sparse) = acc.sparse() {
            let k = sparse.count();
            if k == 0 || k > n {
                return Err(self.err(
                    &format!("{at}.sparse"),
                    format!("count {k} outside 1..={n}"),
                ));
            }
            let idx = sparse.indices();
            self.data.check_range(
                &format!("{at}.sparse.indices"),
                idx.view().length(),
                idx.view().stride(),
                idx.offset(),
                k,
                idx.index_type().size(),
            )?;
            let vals = sparse.values();
            self.data.check_range(
                &format!("{at}.sparse.values"),
                vals.view().length(),
                vals.view().stride(),
                vals.offset(),
                k,
                acc.size(),
            )?;
        }
        Ok(())
    }

    /// Places rig mesh `mesh` (read in its own space) by one matrix per vertex: positions,
    /// normals and the deltas of every shape on it.
    pub(super) fn place_per_vertex(&mut self, mesh: usize, matrices: &[Mat4]) {
        let linear = |v: usize| Mat3::from_mat4(matrices.get(v).copied().unwrap_or(Mat4::IDENTITY));
        let m = &mut self.rig.meshes[mesh].mesh;
        for (v, p) in m.positions.iter_mut().enumerate() {
            if let Some(mat) = matrices.get(v) {
                *p = mat.transform_point3(*p);
            }
        }
        if m.normals.len() == m.positions.len() {
            for (v, nrm) in m.normals.iter_mut().enumerate() {
                let l = linear(v);
                if l.determinant().abs() > 1e-12 {
                    *nrm = (l.inverse().transpose() * *nrm).normalize_or_zero();
                }
            }
        }
        for shape in &mut self.rig.shapes {
            for d in shape.deltas.iter_mut().filter(|d| d.mesh == mesh) {
                for (&v, o) in d.vertices.iter().zip(d.offsets.iter_mut()) {
                    *o = linear(v as usize) * *o;
                }
            }
        }
    }
}
