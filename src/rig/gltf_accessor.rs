//! glTF accessors as other tools write them, checked and read without trusting a count:
//! tightly packed or interleaved views (`byteStride`), sparse accessors (on a base view or on
//! zeros), float or integer components (`KHR_mesh_quantization`: normalised values by glTF
//! 2.0 §3.11, `max(c / 127, -1)` for signed bytes, `c / 65535` for unsigned shorts, …;
//! plain integers as their value) and 8/16/32-bit indices.
//!
//! [`AccessorData::check`] runs before any read: type, count and every byte range against the
//! buffers actually loaded, so the readers below index in bounds (they still stop short rather
//! than panic if called unchecked).

use std::path::Path;

use ::gltf::accessor::{DataType, Dimensions};
use ::gltf::Accessor;
use glam::{Vec2, Vec3};

use super::gltf_read::MAX_ACCESSOR_COUNT;
use super::RigError;
use crate::error::{Error, Result};

/// The element an accessor must hold.
#[derive(Clone, Copy, Debug)]
pub(crate) enum Want {
    /// `VEC3` of float or (normalised or not) 8/16-bit integers: positions, normals, morph
    /// deltas.
    Vec3,
    /// `VEC2` of the same: texture coordinates.
    Vec2,
    /// `SCALAR` unsigned 8/16/32-bit integers: indices.
    Index,
    /// `VEC4` unsigned 8/16-bit integers: skin joints (`JOINTS_n`).
    Joints,
    /// `VEC4` of float or normalised unsigned byte/short: skin weights (`WEIGHTS_n`).
    Weights,
}

/// The loaded buffers of one file, read through accessors.
pub(crate) struct AccessorData<'a> {
    /// The file, named in errors.
    pub file: &'a Path,
    /// Buffer bytes by buffer index.
    pub buffers: &'a [Vec<u8>],
}

impl AccessorData<'_> {
    fn err(&self, at: &str, what: impl std::fmt::Display) -> Error {
        RigError::GltfContent {
            file: self.file.to_path_buf(),
            at: at.to_string(),
            what: what.to_string(),
        }
        .into()
    }

    /// Checks type, count and byte ranges of `acc` (at JSON path `at`) so the readers stay in
    /// bounds; `count` is the element count required, if any.
    pub(crate) fn check(
        &self,
        acc: &Accessor,
        at: &str,
        want: Want,
        count: Option<usize>,
    ) -> Result<()> {
        let at = format!("{at} (accessors[{}])", acc.index());
        let attribute_type = matches!(
            acc.data_type(),
            DataType::F32 | DataType::I8 | DataType::U8 | DataType::I16 | DataType::U16
        );
        let ok_type = match want {
            Want::Vec3 => acc.dimensions() == Dimensions::Vec3 && attribute_type,
            Want::Vec2 => acc.dimensions() == Dimensions::Vec2 && attribute_type,
            Want::Index => {
                acc.dimensions() == Dimensions::Scalar
                    && matches!(
                        acc.data_type(),
                        DataType::U8 | DataType::U16 | DataType::U32
                    )
            }
            Want::Joints => {
                acc.dimensions() == Dimensions::Vec4
                    && matches!(acc.data_type(), DataType::U8 | DataType::U16)
            }
            Want::Weights => {
                acc.dimensions() == Dimensions::Vec4
                    && matches!(
                        acc.data_type(),
                        DataType::F32 | DataType::U8 | DataType::U16
                    )
            }
        };
        if !ok_type {
            let wanted = match want {
                Want::Vec3 => "VEC3 of FLOAT or (normalised) byte/short",
                Want::Vec2 => "VEC2 of FLOAT or (normalised) byte/short",
                Want::Index => "SCALAR unsigned byte/short/int",
                Want::Joints => "VEC4 unsigned byte/short",
                Want::Weights => "VEC4 of FLOAT or normalised unsigned byte/short",
            };
            return Err(self.err(
                &at,
                format!(
                    "expected {wanted}, found {:?} of {:?}",
                    acc.dimensions(),
                    acc.data_type()
                ),
            ));
        }
        let n = acc.count();
        if n == 0 || n > MAX_ACCESSOR_COUNT {
            return Err(self.err(&at, format!("count {n} outside 1..={MAX_ACCESSOR_COUNT}")));
        }
        if let Some(c) = count {
            if n != c {
                return Err(self.err(&at, format!("count {n}, expected {c} (one per vertex)")));
            }
        }
        let elem = acc.size();
        if let Some(view) = acc.view() {
            self.check_range(&at, view.length(), view.stride(), acc.offset(), n, elem)?;
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
            let isize = idx.index_type().size();
            self.check_range(
                &format!("{at}.sparse.indices"),
                idx.view().length(),
                idx.view().stride(),
                idx.offset(),
                k,
                isize,
            )?;
            let vals = sparse.values();
            self.check_range(
                &format!("{at}.sparse.values"),
                vals.view().length(),
                vals.view().stride(),
                vals.offset(),
                k,
                elem,
            )?;
        }
        Ok(())
    }

    /// `count` elements of `elem` bytes every `stride` bytes from `offset` fit in `len` bytes.
    pub(super) fn check_range(
        &self,
        at: &str,
        len: usize,
        stride: Option<usize>,
        offset: usize,
        count: usize,
        elem: usize,
    ) -> Result<()> {
        let stride = stride.unwrap_or(elem);
        if stride < elem {
            return Err(self.err(
                at,
                format!("byteStride {stride} is below the element size {elem}"),
            ));
        }
        let end = stride
            .checked_mul(count - 1)
            .and_then(|x| x.checked_add(elem))
            .and_then(|x| x.checked_add(offset));
        if end.is_none_or(|e| e > len) {
            return Err(self.err(at, "data runs past the end of its bufferView"));
        }
        Ok(())
    }

    /// A checked `VEC3` accessor's values (zeros where it has no data).
    pub fn vec3(&self, acc: &Accessor) -> Vec<Vec3> {
        self.floats::<3>(acc).into_iter().map(Vec3::from).collect()
    }

    /// A checked `VEC2` accessor's values.
    pub fn vec2(&self, acc: &Accessor) -> Vec<Vec2> {
        self.floats::<2>(acc).into_iter().map(Vec2::from).collect()
    }

    /// A checked index accessor's values.
    pub fn indices(&self, acc: &Accessor) -> Vec<u32> {
        let n = acc.count();
        let mut out = match acc.view() {
            Some(view) => {
                let (data, stride) = self.view_bytes(&view, acc.size());
                indices_from(data, acc.offset(), stride, n, acc.data_type())
            }
            None => Vec::new(),
        };
        out.resize(n, 0);
        if let Some(sparse) = acc.sparse() {
            let (at, values) = self.sparse_parts(&sparse, acc.size());
            let vals = indices_from(values.0, values.1, values.2, at.len(), acc.data_type());
            for (&i, v) in at.iter().zip(vals) {
                if let Some(slot) = out.get_mut(i as usize) {
                    *slot = v;
                }
            }
        }
        out
    }

    /// A checked accessor's elements as floats: the base view (or zeros), then the sparse
    /// substitutions.
    fn floats<const N: usize>(&self, acc: &Accessor) -> Vec<[f32; N]> {
        let n = acc.count();
        let (ty, norm) = (acc.data_type(), acc.normalized());
        let mut out = match acc.view() {
            Some(view) => {
                let (data, stride) = self.view_bytes(&view, acc.size());
                floats_from::<N>(data, acc.offset(), stride, n, ty, norm)
            }
            None => Vec::new(),
        };
        out.resize(n, [0.0; N]);
        if let Some(sparse) = acc.sparse() {
            let (at, values) = self.sparse_parts(&sparse, acc.size());
            let vals = floats_from::<N>(values.0, values.1, values.2, at.len(), ty, norm);
            for (&i, v) in at.iter().zip(vals) {
                if let Some(slot) = out.get_mut(i as usize) {
                    *slot = v;
                }
            }
        }
        out
    }

    /// The bytes of `view` (empty if out of range) and its stride (`elem` when packed).
    fn view_bytes(&self, view: &::gltf::buffer::View, elem: usize) -> (&[u8], usize) {
        let data = self
            .buffers
            .get(view.buffer().index())
            .and_then(|b| b.get(view.offset()..view.offset().checked_add(view.length())?))
            .unwrap_or(&[]);
        (data, view.stride().unwrap_or(elem))
    }

    /// A sparse accessor's vertex indices, and its values' (bytes, offset, stride).
    fn sparse_parts<'s>(
        &'s self,
        sparse: &::gltf::accessor::sparse::Sparse,
        elem: usize,
    ) -> (Vec<u32>, (&'s [u8], usize, usize)) {
        let k = sparse.count();
        let idx = sparse.indices();
        let ty = match idx.index_type() {
            ::gltf::accessor::sparse::IndexType::U8 => DataType::U8,
            ::gltf::accessor::sparse::IndexType::U16 => DataType::U16,
            ::gltf::accessor::sparse::IndexType::U32 => DataType::U32,
        };
        let (ibytes, istride) = self.view_bytes(&idx.view(), ty.size());
        let at = indices_from(ibytes, idx.offset(), istride, k, ty);
        let vals = sparse.values();
        let (vbytes, vstride) = self.view_bytes(&vals.view(), elem);
        (at, (vbytes, vals.offset(), vstride))
    }
}

/// How many of `count` elements of `elem` bytes every `stride` bytes from `offset` lie
/// inside `len` bytes (all of them for a checked accessor).
fn in_bounds(len: usize, offset: usize, stride: usize, count: usize, elem: usize) -> usize {
    let Some(first_end) = offset.checked_add(elem) else {
        return 0;
    };
    if count == 0 || first_end > len {
        return 0;
    }
    if stride == 0 {
        return count;
    }
    count.min((len - first_end) / stride + 1)
}

/// `count` elements of `N` components of type `ty` (normalised or not) as floats.
fn floats_from<const N: usize>(
    data: &[u8],
    offset: usize,
    stride: usize,
    count: usize,
    ty: DataType,
    normalized: bool,
) -> Vec<[f32; N]> {
    match (ty, normalized) {
        (DataType::F32, _) => gather::<N, 4, _>(data, offset, stride, count, f32::from_le_bytes),
        (DataType::U32, _) => gather::<N, 4, _>(data, offset, stride, count, |b| {
            u32::from_le_bytes(b) as f32
        }),
        (DataType::I8, true) => gather::<N, 1, _>(data, offset, stride, count, |b| {
            (f32::from(b[0] as i8) / 127.0).max(-1.0)
        }),
        (DataType::I8, false) => {
            gather::<N, 1, _>(data, offset, stride, count, |b| f32::from(b[0] as i8))
        }
        (DataType::U8, true) => {
            gather::<N, 1, _>(data, offset, stride, count, |b| f32::from(b[0]) / 255.0)
        }
        (DataType::U8, false) => {
            gather::<N, 1, _>(data, offset, stride, count, |b| f32::from(b[0]))
        }
        (DataType::I16, true) => gather::<N, 2, _>(data, offset, stride, count, |b| {
            (f32::from(i16::from_le_bytes(b)) / 32767.0).max(-1.0)
        }),
        (DataType::I16, false) => gather::<N, 2, _>(data, offset, stride, count, |b| {
            f32::from(i16::from_le_bytes(b))
        }),
        (DataType::U16, true) => gather::<N, 2, _>(data, offset, stride, count, |b| {
            f32::from(u16::from_le_bytes(b)) / 65535.0
        }),
        (DataType::U16, false) => gather::<N, 2, _>(data, offset, stride, count, |b| {
            f32::from(u16::from_le_bytes(b))
        }),
    }
}

/// `count` scalar unsigned integers of type `ty`.
fn indices_from(data: &[u8], offset: usize, stride: usize, count: usize, ty: DataType) -> Vec<u32> {
    let one = |v: [u32; 1]| v[0];
    match ty {
        DataType::U8 | DataType::I8 => {
            gather::<1, 1, _>(data, offset, stride, count, |b| u32::from(b[0]))
        }
        DataType::U16 | DataType::I16 => gather::<1, 2, _>(data, offset, stride, count, |b| {
            u32::from(u16::from_le_bytes(b))
        }),
        DataType::U32 | DataType::F32 => {
            gather::<1, 4, _>(data, offset, stride, count, u32::from_le_bytes)
        }
    }
    .into_iter()
    .map(one)
    .collect()
}

/// Reads up to `count` elements of `N` components of `S` bytes each, converted by `conv`.
fn gather<const N: usize, const S: usize, T: Copy + Default>(
    data: &[u8],
    offset: usize,
    stride: usize,
    count: usize,
    conv: impl Fn([u8; S]) -> T,
) -> Vec<[T; N]> {
    let n = in_bounds(data.len(), offset, stride, count, N * S);
    let mut out = Vec::with_capacity(n);
    for i in 0..n {
        let base = offset + i * stride;
        let mut e = [T::default(); N];
        for (c, slot) in e.iter_mut().enumerate() {
            let at = base + c * S;
            let mut b = [0u8; S];
            b.copy_from_slice(&data[at..at + S]);
            *slot = conv(b);
        }
        out.push(e);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normalised_integers_follow_the_gltf_rules() {
        let bytes: Vec<u8> = [-128i8, -127, 0, 127].iter().map(|&v| v as u8).collect();
        let v = floats_from::<1>(&bytes, 0, 1, 4, DataType::I8, true);
        assert_eq!(v, vec![[-1.0], [-1.0], [0.0], [1.0]]);
        let u: Vec<u8> = [0u16, 65535, 32768]
            .iter()
            .flat_map(|v| v.to_le_bytes())
            .collect();
        let v = floats_from::<1>(&u, 0, 2, 3, DataType::U16, true);
        assert_eq!(v[0], [0.0]);
        assert_eq!(v[1], [1.0]);
        assert!((v[2][0] - 32768.0 / 65535.0).abs() < 1e-7);
        let s: Vec<u8> = [-32768i16, 32767, -5]
            .iter()
            .flat_map(|v| v.to_le_bytes())
            .collect();
        assert_eq!(
            floats_from::<1>(&s, 0, 2, 3, DataType::I16, true)[..2],
            [[-1.0], [1.0]]
        );
        // Not normalised: the integer's value.
        assert_eq!(
            floats_from::<1>(&s, 0, 2, 3, DataType::I16, false)[2],
            [-5.0]
        );
        assert_eq!(
            floats_from::<1>(&[200], 0, 1, 1, DataType::U8, false),
            [[200.0]]
        );
        assert_eq!(
            floats_from::<1>(&[255], 0, 1, 1, DataType::U8, true),
            [[1.0]]
        );
    }

    #[test]
    fn strides_skip_interleaved_bytes_and_short_data_stops_early() {
        // Two VEC3 i8 elements padded to 4 bytes, interleaved with 4 bytes of something else.
        let data = [1u8, 2, 3, 0, 9, 9, 9, 9, 4, 5, 6, 0, 9, 9, 9, 9];
        let v = floats_from::<3>(&data, 0, 8, 2, DataType::I8, false);
        assert_eq!(v, vec![[1.0, 2.0, 3.0], [4.0, 5.0, 6.0]]);
        // A count past the data gives what fits, never a panic.
        assert_eq!(
            floats_from::<3>(&data, 0, 8, 5, DataType::I8, false).len(),
            2
        );
        assert!(floats_from::<3>(&data, 20, 8, 5, DataType::I8, false).is_empty());
    }

    #[test]
    fn indices_of_every_width() {
        assert_eq!(
            indices_from(&[1, 2, 255], 0, 1, 3, DataType::U8),
            [1, 2, 255]
        );
        let w: Vec<u8> = [7u16, 65535].iter().flat_map(|v| v.to_le_bytes()).collect();
        assert_eq!(indices_from(&w, 0, 2, 2, DataType::U16), [7, 65535]);
        let d: Vec<u8> = [70_000u32, 3]
            .iter()
            .flat_map(|v| v.to_le_bytes())
            .collect();
        assert_eq!(indices_from(&d, 0, 4, 2, DataType::U32), [70_000, 3]);
    }
}
