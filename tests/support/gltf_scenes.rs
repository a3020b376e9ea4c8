//! Test scenes for the glTF exporter and a small accessor reader to check what was written.
#![allow(dead_code)]

use fbakit::gltf::json::{self, Root};
use fbakit::gltf::{
    AnimationData, ChannelData, ChannelValues, GltfDocument, Interpolation, MaterialData, MeshData,
    NodeData, SceneBuilder,
};
use glam::{Quat, Vec2, Vec3};

/// The eight corners of a unit cube centred on the origin.
pub fn cube_positions() -> Vec<Vec3> {
    (0..8)
        .map(|i| {
            Vec3::new(
                if i & 1 == 0 { -0.5 } else { 0.5 },
                if i & 2 == 0 { -0.5 } else { 0.5 },
                if i & 4 == 0 { -0.5 } else { 0.5 },
            )
        })
        .collect()
}

/// Twelve outward-facing (counter-clockwise) triangles of [`cube_positions`].
pub fn cube_triangles() -> Vec<[u32; 3]> {
    vec![
        [0, 2, 3],
        [0, 3, 1], // -z
        [4, 5, 7],
        [4, 7, 6], // +z
        [0, 1, 5],
        [0, 5, 4], // -y
        [2, 6, 7],
        [2, 7, 3], // +y
        [0, 4, 6],
        [0, 6, 2], // -x
        [1, 3, 7],
        [1, 7, 5], // +x
    ]
}

/// Dense "jaw_open" offsets: the bottom four vertices move down and forward.
pub fn jaw_offsets() -> Vec<Vec3> {
    cube_positions()
        .iter()
        .map(|p| {
            if p.y < 0.0 {
                Vec3::new(0.0, -0.25, 0.05)
            } else {
                Vec3::ZERO
            }
        })
        .collect()
}

/// Sparse "smile" target: vertices 3 and 7 (top, +x) move up; 7 is listed twice to check
/// that repeated vertices add up.
pub const SMILE_VERTICES: [u32; 3] = [7, 3, 7];
/// Offsets of [`SMILE_VERTICES`].
pub const SMILE_OFFSETS: [Vec3; 3] = [
    Vec3::new(0.0, 0.05, 0.0),
    Vec3::new(0.02, 0.1, 0.0),
    Vec3::new(0.0, 0.05, 0.0),
];

/// Keyframe times of the "talk" animation.
pub const TALK_TIMES: [f32; 3] = [0.0, 0.5, 1.0];

/// A head ("skin" cube, 2 morph targets) with a small rotated "eye_left" child, and two
/// animations: "talk" (skin weights + eye rotation, shared keyframe times) and "nod" (head
/// rotation, STEP).
pub fn two_mesh_scene() -> GltfDocument {
    let mut s = SceneBuilder::new("face");
    let uvs: Vec<Vec2> = cube_positions()
        .iter()
        .map(|p| Vec2::new(p.x + 0.5, p.y + 0.5))
        .collect();
    let mut skin = MeshData::new("skin", cube_positions(), cube_triangles())
        .with_uvs(uvs)
        .with_material(MaterialData {
            base_color: [0.9, 0.7, 0.6, 1.0],
            ..Default::default()
        })
        .with_dense_target("jaw_open", jaw_offsets())
        .with_sparse_target("smile", &SMILE_VERTICES[..], &SMILE_OFFSETS[..]);
    skin.morph_normals = true;
    let skin = s.add_mesh(skin).unwrap();
    let eye_positions: Vec<Vec3> = cube_positions().iter().map(|p| *p * 0.1).collect();
    let eye = s
        .add_mesh(
            MeshData::new("eye", eye_positions, cube_triangles()).with_material(MaterialData {
                base_color: [0.1, 0.2, 0.8, 1.0],
                double_sided: true,
                ..Default::default()
            }),
        )
        .unwrap();
    let head = s.add_node(NodeData::new("head").with_mesh(skin)).unwrap();
    let eye_node = s
        .add_node(
            NodeData::new("eye_left")
                .with_parent(head)
                .with_mesh(eye)
                .with_translation(Vec3::new(0.2, 0.2, 0.55))
                .with_rotation(Quat::from_rotation_y(0.1)),
        )
        .unwrap();
    s.add_animation(AnimationData {
        name: "talk".into(),
        channels: vec![
            ChannelData {
                node: head,
                times: TALK_TIMES.to_vec(),
                values: ChannelValues::Weights(vec![0.0, 0.0, 1.0, 0.5, 0.0, 1.0]),
                interpolation: Interpolation::Linear,
            },
            ChannelData {
                node: eye_node,
                times: TALK_TIMES.to_vec(),
                values: ChannelValues::Rotation(vec![
                    Quat::IDENTITY,
                    Quat::from_rotation_y(0.3),
                    Quat::from_rotation_x(-0.2),
                ]),
                interpolation: Interpolation::Linear,
            },
        ],
    })
    .unwrap();
    s.add_animation(AnimationData {
        name: "nod".into(),
        channels: vec![ChannelData {
            node: head,
            times: vec![0.0, 0.25],
            values: ChannelValues::Rotation(vec![Quat::IDENTITY, Quat::from_rotation_x(0.2)]),
            interpolation: Interpolation::Step,
        }],
    })
    .unwrap();
    s.build().unwrap()
}

/// One triangle with one sparse morph target and a two-key weights animation (for the JSON
/// snapshot).
pub fn tiny_scene() -> GltfDocument {
    let mut s = SceneBuilder::new("tiny");
    let mesh = s
        .add_mesh(
            MeshData::new("tri", vec![Vec3::ZERO, Vec3::X, Vec3::Y], vec![[0, 1, 2]])
                .with_sparse_target("lift", vec![2], vec![Vec3::new(0.0, 0.5, 0.0)]),
        )
        .unwrap();
    let node = s.add_node(NodeData::new("tri").with_mesh(mesh)).unwrap();
    s.add_animation(AnimationData {
        name: "lift".into(),
        channels: vec![ChannelData {
            node,
            times: vec![0.0, 1.0],
            values: ChannelValues::Weights(vec![0.0, 1.0]),
            interpolation: Interpolation::Linear,
        }],
    })
    .unwrap();
    s.build().unwrap()
}

/// A `side × side` grid in the z = 0 plane (more than 65 535 vertices for side >= 256), with a
/// sparse target moving the first row (with normal deltas).
pub fn grid_scene(side: u32) -> GltfDocument {
    let positions: Vec<Vec3> = (0..side * side)
        .map(|i| Vec3::new((i % side) as f32, (i / side) as f32, 0.0) * 0.01)
        .collect();
    let mut triangles = Vec::new();
    for y in 0..side - 1 {
        for x in 0..side - 1 {
            let i = y * side + x;
            triangles.push([i, i + 1, i + side + 1]);
            triangles.push([i, i + side + 1, i + side]);
        }
    }
    let row: Vec<u32> = (0..side).collect();
    let lift = vec![Vec3::new(0.0, 0.0, 0.1); side as usize];
    let mut s = SceneBuilder::new("grid");
    let mut grid =
        MeshData::new("grid", positions, triangles).with_sparse_target("lift", row, lift);
    // Lifting one row tilts the neighbouring normals: sparse NORMAL deltas at u32 scale.
    grid.morph_normals = true;
    let mesh = s.add_mesh(grid).unwrap();
    s.add_node(NodeData::new("grid").with_mesh(mesh)).unwrap();
    s.build().unwrap()
}

/// Size in bytes of one component of `component_type`.
pub fn component_size(component_type: u32) -> usize {
    match component_type {
        json::UNSIGNED_BYTE => 1,
        json::UNSIGNED_SHORT => 2,
        json::UNSIGNED_INT | json::FLOAT => 4,
        t => panic!("unexpected componentType {t}"),
    }
}

/// Number of components of an accessor `type`.
pub fn component_count(kind: &str) -> usize {
    match kind {
        "SCALAR" => 1,
        "VEC2" => 2,
        "VEC3" => 3,
        "VEC4" | "MAT2" => 4,
        "MAT3" => 9,
        "MAT4" => 16,
        t => panic!("unexpected type {t}"),
    }
}

fn read_component(bytes: &[u8], component_type: u32) -> f64 {
    match component_type {
        json::UNSIGNED_BYTE => bytes[0] as f64,
        json::UNSIGNED_SHORT => u16::from_le_bytes([bytes[0], bytes[1]]) as f64,
        json::UNSIGNED_INT => u32::from_le_bytes(bytes[..4].try_into().unwrap()) as f64,
        json::FLOAT => f32::from_le_bytes(bytes[..4].try_into().unwrap()) as f64,
        t => panic!("unexpected componentType {t}"),
    }
}

/// The bytes of buffer view `view`, with its range checked against the buffer.
pub fn view_bytes<'b>(root: &Root, bin: &'b [u8], view: u32) -> &'b [u8] {
    let v = &root.buffer_views[view as usize];
    assert_eq!(v.buffer, 0);
    let start = v.byte_offset as usize;
    let end = start + v.byte_length as usize;
    assert!(end <= bin.len(), "view {view} runs past the buffer");
    assert!(end as u32 <= root.buffers[0].byte_length);
    &bin[start..end]
}

fn read_components(bytes: &[u8], component_type: u32, n: usize) -> Vec<f64> {
    let size = component_size(component_type);
    assert_eq!(
        bytes.len(),
        n * size,
        "view length matches the accessor exactly"
    );
    bytes
        .chunks(size)
        .map(|c| read_component(c, component_type))
        .collect()
}

/// All components of accessor `index` (sparse substitution applied), as f64.
pub fn read_accessor(root: &Root, bin: &[u8], index: u32) -> Vec<f64> {
    let a = &root.accessors[index as usize];
    let n = a.count as usize * component_count(&a.kind);
    let mut values = match a.buffer_view {
        Some(v) => read_components(view_bytes(root, bin, v), a.component_type, n),
        None => vec![0.0; n],
    };
    if let Some(sp) = &a.sparse {
        let idx = read_components(
            view_bytes(root, bin, sp.indices.buffer_view),
            sp.indices.component_type,
            sp.count as usize,
        );
        let k = component_count(&a.kind);
        let vals = read_components(
            view_bytes(root, bin, sp.values.buffer_view),
            a.component_type,
            sp.count as usize * k,
        );
        assert!(
            idx.windows(2).all(|w| w[0] < w[1]),
            "sparse indices increase"
        );
        for (j, &i) in idx.iter().enumerate() {
            values[i as usize * k..(i as usize + 1) * k].copy_from_slice(&vals[j * k..(j + 1) * k]);
        }
    }
    values
}

/// Checks every accessor's `min`/`max` (when present) against its data.
pub fn assert_bounds_exact(root: &Root, bin: &[u8]) {
    for (i, a) in root.accessors.iter().enumerate() {
        if a.min.is_empty() && a.max.is_empty() {
            continue;
        }
        let k = component_count(&a.kind);
        let values = read_accessor(root, bin, i as u32);
        for c in 0..k {
            let col = values.iter().skip(c).step_by(k);
            let min = col.clone().copied().fold(f64::INFINITY, f64::min);
            let max = col.copied().fold(f64::NEG_INFINITY, f64::max);
            assert_eq!(a.min[c] as f64, min, "accessor {i} min[{c}]");
            assert_eq!(a.max[c] as f64, max, "accessor {i} max[{c}]");
        }
    }
}
