//! One 512×512 frame of `bruno` (≈26.5 k skin vertices, quads fan-triangulated, plus eyes,
//! teeth and tongue), front view, smooth shading; target < 50 ms without supersampling.

use divan::Bencher;
use fbakit::render::{bounds, fan_triangulate, render, Camera, RenderMesh, RenderOptions};
use fbakit::synth::SynthFace;
use glam::Vec3;

fn main() {
    divan::main();
}

struct Scene {
    positions: Vec<Vec<Vec3>>,
    triangles: Vec<Vec<[u32; 3]>>,
    colours: Vec<[f32; 3]>,
}

fn scene() -> Scene {
    let face: SynthFace = fbakit::synth::bruno();
    Scene {
        positions: face.meshes.iter().map(|m| m.positions.clone()).collect(),
        triangles: face
            .meshes
            .iter()
            .map(|m| fan_triangulate(&m.polygons))
            .collect(),
        colours: face.meshes.iter().map(|m| m.colour).collect(),
    }
}

#[divan::bench(args = [1, 2])]
fn bruno_512(bencher: Bencher, supersample: u32) {
    let s = scene();
    let meshes: Vec<RenderMesh> = (0..s.positions.len())
        .map(|i| RenderMesh::new(&s.positions[i], &s.triangles[i], s.colours[i]))
        .collect();
    let camera = Camera::framing(&bounds(&meshes).unwrap(), 0.0, 0.0);
    let opts = RenderOptions {
        supersample,
        ..RenderOptions::sized(512, 512)
    };
    bencher.bench_local(|| render(divan::black_box(&meshes), &camera, &opts));
}
