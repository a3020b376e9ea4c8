//! Packing data into the one binary buffer: 4-byte-aligned buffer views, the accessors over
//! them (with exact bounds where glTF wants them), the smallest index type, sparse morph
//! displacements and shared keyframe-time accessors.

use std::collections::HashMap;

use glam::Vec3;

use super::json::{self, Accessor, BufferView};

/// The growing binary buffer with its views and accessors.
#[derive(Default)]
pub(super) struct Layout {
    /// The buffer.
    pub(super) bin: Vec<u8>,
    /// Its views.
    pub(super) views: Vec<BufferView>,
    /// The accessors over them.
    pub(super) accessors: Vec<Accessor>,
    /// Keyframe-time accessors by bit pattern, so channels with equal times share one.
    times: HashMap<Vec<u32>, u32>,
}

/// Component-wise minimum and maximum of `items`.
fn bounds<const N: usize>(items: impl Iterator<Item = [f32; N]>) -> (Vec<f32>, Vec<f32>) {
    let mut min = [f32::INFINITY; N];
    let mut max = [f32::NEG_INFINITY; N];
    for v in items {
        for k in 0..N {
            min[k] = min[k].min(v[k]);
            max[k] = max[k].max(v[k]);
        }
    }
    (min.to_vec(), max.to_vec())
}

impl Layout {
    /// Appends a 4-byte-aligned buffer view filled by `fill`.
    fn view(&mut self, target: Option<u32>, fill: impl FnOnce(&mut Vec<u8>)) -> u32 {
        self.bin.resize(self.bin.len().next_multiple_of(4), 0);
        let start = self.bin.len();
        fill(&mut self.bin);
        self.views.push(BufferView {
            buffer: 0,
            byte_offset: start as u32,
            byte_length: (self.bin.len() - start) as u32,
            target,
        });
        (self.views.len() - 1) as u32
    }

    /// Appends an accessor; returns its index.
    pub(super) fn accessor(&mut self, a: Accessor) -> u32 {
        self.accessors.push(a);
        (self.accessors.len() - 1) as u32
    }

    /// Float tuples (`SCALAR` … `VEC4`) in a new view, with `min`/`max` when `with_bounds`.
    pub(super) fn floats<const N: usize>(
        &mut self,
        data: &[[f32; N]],
        target: Option<u32>,
        with_bounds: bool,
    ) -> u32 {
        let view = self.view(target, |b| {
            b.reserve(data.len() * N * 4);
            for v in data {
                for x in v {
                    b.extend_from_slice(&x.to_le_bytes());
                }
            }
        });
        let (min, max) = if with_bounds {
            bounds(data.iter().copied())
        } else {
            (Vec::new(), Vec::new())
        };
        self.accessor(Accessor {
            buffer_view: Some(view),
            component_type: json::FLOAT,
            count: data.len() as u32,
            kind: ["SCALAR", "VEC2", "VEC3", "VEC4"][N - 1].into(),
            min,
            max,
            sparse: None,
        })
    }

    /// [`Layout::floats`] for vectors.
    pub(super) fn vec3s(&mut self, data: &[Vec3], target: Option<u32>, with_bounds: bool) -> u32 {
        let arrays: Vec<[f32; 3]> = data.iter().map(|v| v.to_array()).collect();
        self.floats(&arrays, target, with_bounds)
    }

    /// Unsigned integers as u8 / u16 / u32 (the smallest allowed by `max_value`).
    pub(super) fn uints(
        &mut self,
        data: &[u32],
        max_value: u32,
        target: Option<u32>,
    ) -> (u32, u32) {
        let (ty, size) = if target.is_none() && max_value <= u8::MAX as u32 {
            (json::UNSIGNED_BYTE, 1)
        } else if max_value < u16::MAX as u32 || (target.is_none() && max_value == 65535) {
            // 65535 is the primitive-restart value of u16 *vertex* indices.
            (json::UNSIGNED_SHORT, 2)
        } else {
            (json::UNSIGNED_INT, 4)
        };
        let view = self.view(target, |b| {
            b.reserve(data.len() * size);
            for &i in data {
                match size {
                    1 => b.push(i as u8),
                    2 => b.extend_from_slice(&(i as u16).to_le_bytes()),
                    _ => b.extend_from_slice(&i.to_le_bytes()),
                }
            }
        });
        (view, ty)
    }

    /// A morph-target displacement accessor over `count` vertices: sparse when that is
    /// smaller than dense, all-zero (no data) when nothing moves.
    pub(super) fn displacement(&mut self, count: u32, vertices: &[u32], offsets: &[Vec3]) -> u32 {
        let nnz = vertices.len();
        let index_size = if count <= 256 {
            1
        } else if count <= 65536 {
            2
        } else {
            4
        };
        if nnz * (12 + index_size) >= count as usize * 12 {
            let mut dense = vec![Vec3::ZERO; count as usize];
            for (&v, &o) in vertices.iter().zip(offsets) {
                dense[v as usize] = o;
            }
            return self.vec3s(&dense, Some(json::ARRAY_BUFFER), true);
        }
        let zeros = (nnz < count as usize).then_some([0.0f32; 3]);
        let (min, max) = bounds(offsets.iter().map(|o| o.to_array()).chain(zeros));
        let sparse = (nnz > 0).then(|| {
            let (indices, component_type) = self.uints(vertices, count - 1, None);
            let values = self.view(None, |b| {
                for o in offsets {
                    for x in o.to_array() {
                        b.extend_from_slice(&x.to_le_bytes());
                    }
                }
            });
            json::Sparse {
                count: nnz as u32,
                indices: json::SparseIndices {
                    buffer_view: indices,
                    component_type,
                },
                values: json::SparseValues {
                    buffer_view: values,
                },
            }
        });
        self.accessor(Accessor {
            buffer_view: None,
            component_type: json::FLOAT,
            count,
            kind: "VEC3".into(),
            min,
            max,
            sparse,
        })
    }

    /// [`Layout::displacement`] without `min`/`max` (only `POSITION` needs them).
    pub(super) fn displacement_no_bounds(
        &mut self,
        count: u32,
        vertices: &[u32],
        offsets: &[Vec3],
    ) -> u32 {
        let a = self.displacement(count, vertices, offsets);
        let acc = &mut self.accessors[a as usize];
        acc.min.clear();
        acc.max.clear();
        a
    }

    /// The keyframe-time accessor of `times`, shared by every channel with the same times.
    pub(super) fn time_accessor(&mut self, times: &[f32]) -> u32 {
        let key: Vec<u32> = times.iter().map(|t| t.to_bits()).collect();
        match self.times.get(&key) {
            Some(&i) => i,
            None => {
                let arrays: Vec<[f32; 1]> = times.iter().map(|&t| [t]).collect();
                let i = self.floats(&arrays, None, true);
                self.times.insert(key, i);
                i
            }
        }
    }
}
