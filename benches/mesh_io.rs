//! OBJ read/write throughput on a generated 50 000-vertex mesh (divan reports bytes/s).

use std::path::Path;

use divan::counter::BytesCount;
use divan::Bencher;
use fbakit::mesh::obj::{parse_obj, write_obj_string, ObjScene};
use fbakit::mesh::{Mesh, Polygons};
use glam::{Vec2, Vec3};

fn main() {
    divan::main();
}

/// A 224 × 224 height-field grid (50 176 vertices, ~100 k triangles) with uvs.
fn grid_scene() -> ObjScene {
    const N: u32 = 224;
    let mut positions = Vec::new();
    let mut uvs = Vec::new();
    for j in 0..N {
        for i in 0..N {
            let (x, y) = (i as f32 / N as f32, j as f32 / N as f32);
            positions.push(Vec3::new(
                x * 2.0 - 1.0,
                y * 2.0 - 1.0,
                (x * 7.1).sin() * (y * 3.3).cos() * 0.1,
            ));
            uvs.push(Vec2::new(x, y));
        }
    }
    let mut tris = Vec::new();
    for j in 0..N - 1 {
        for i in 0..N - 1 {
            let a = j * N + i;
            tris.push([a, a + 1, a + N + 1]);
            tris.push([a, a + N + 1, a + N]);
        }
    }
    let mut mesh = Mesh::from_triangles("grid", positions, &tris);
    mesh.uvs = uvs;
    mesh.uv_polygons = Some(Polygons::from_triangles(&tris));
    ObjScene {
        mesh,
        material_libraries: Vec::new(),
    }
}

#[divan::bench]
fn write_obj_50k(bencher: Bencher) {
    let scene = grid_scene();
    let bytes = write_obj_string(&scene).unwrap().len();
    bencher
        .counter(BytesCount::new(bytes))
        .bench(|| write_obj_string(divan::black_box(&scene)).unwrap());
}

#[divan::bench]
fn read_obj_50k(bencher: Bencher) {
    let text = write_obj_string(&grid_scene()).unwrap();
    bencher
        .counter(BytesCount::new(text.len()))
        .bench(|| parse_obj(divan::black_box(&text), Path::new("grid.obj")).unwrap());
}
