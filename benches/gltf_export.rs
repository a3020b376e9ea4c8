//! glTF export speed: a face-sized mesh (25 000 vertices) with 84 sparse morph targets of
//! ~2 000 moved vertices each and a 250-frame weights animation, to GLB bytes.
//! Target: well under 1 s.

use fbakit::gltf::{
    AnimationData, ChannelData, ChannelValues, Interpolation, MeshData, NodeData, SceneBuilder,
};
use glam::Vec3;

fn main() {
    divan::main();
}

const SIDE_X: u32 = 125;
const SIDE_Y: u32 = 200; // 125 × 200 = 25 000 vertices
const TARGETS: usize = 84;
const MOVED: u32 = 2_000;
const FRAMES: usize = 250;

struct Face {
    positions: Vec<Vec3>,
    triangles: Vec<[u32; 3]>,
    targets: Vec<(Vec<u32>, Vec<Vec3>)>,
    weights: Vec<f32>,
}

fn face() -> Face {
    let n = SIDE_X * SIDE_Y;
    let positions = (0..n)
        .map(|i| {
            Vec3::new(
                (i % SIDE_X) as f32,
                (i / SIDE_X) as f32,
                ((i % 7) as f32).sin(),
            ) * 0.001
        })
        .collect();
    let mut triangles = Vec::new();
    for y in 0..SIDE_Y - 1 {
        for x in 0..SIDE_X - 1 {
            let i = y * SIDE_X + x;
            triangles.push([i, i + 1, i + SIDE_X + 1]);
            triangles.push([i, i + SIDE_X + 1, i + SIDE_X]);
        }
    }
    let targets = (0..TARGETS)
        .map(|t| {
            // Each target moves a band of MOVED vertices (every other vertex of a window).
            let start = (t as u32 * 271) % (n - 2 * MOVED);
            let vertices: Vec<u32> = (0..MOVED).map(|k| start + 2 * k).collect();
            let offsets = vertices
                .iter()
                .map(|&v| Vec3::new(0.0, 0.001 * (v % 13) as f32, 0.002 * t as f32))
                .collect();
            (vertices, offsets)
        })
        .collect();
    let weights = (0..FRAMES * TARGETS)
        .map(|i| ((i % 97) as f32 / 96.0).clamp(0.0, 1.0))
        .collect();
    Face {
        positions,
        triangles,
        targets,
        weights,
    }
}

fn export(f: &Face, morph_normals: bool) -> Vec<u8> {
    let mut mesh = MeshData::new("skin", &f.positions[..], &f.triangles[..]);
    for (i, (v, o)) in f.targets.iter().enumerate() {
        mesh = mesh.with_sparse_target(format!("target_{i}"), &v[..], &o[..]);
    }
    mesh.morph_normals = morph_normals;
    let mut s = SceneBuilder::new("face");
    let m = s.add_mesh(mesh).unwrap();
    let node = s.add_node(NodeData::new("face").with_mesh(m)).unwrap();
    s.add_animation(AnimationData {
        name: "play".into(),
        channels: vec![ChannelData {
            node,
            times: (0..FRAMES).map(|i| i as f32 / 25.0).collect(),
            values: ChannelValues::Weights(f.weights.clone()),
            interpolation: Interpolation::Linear,
        }],
    })
    .unwrap();
    s.build().unwrap().to_glb().unwrap()
}

#[divan::bench(sample_count = 10)]
fn face_to_glb(bencher: divan::Bencher) {
    let f = face();
    bencher.bench(|| export(divan::black_box(&f), false));
}

#[divan::bench(sample_count = 5)]
fn face_to_glb_with_normal_deltas(bencher: divan::Bencher) {
    let f = face();
    bencher.bench(|| export(divan::black_box(&f), true));
}
