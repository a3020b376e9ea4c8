//! Reading blendshape rigs: the ICT-FaceKit folder (neutral + 57 full-mesh shape OBJs,
//! 26 719 vertices each; skipped when `../shared/data/ict-facekit` is absent), a glb rig, and
//! a generated ~30 MB avatar glb (meshes and morph targets, no FAT built; the target is under
//! 0.2 s).

use std::path::{Path, PathBuf};

fn main() {
    divan::main();
}

fn ict_dir() -> Option<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/data/ict-facekit");
    dir.is_dir().then_some(dir)
}

#[divan::bench(sample_count = 5)]
fn ict_obj_folder(bencher: divan::Bencher) {
    let Some(dir) = ict_dir() else {
        eprintln!("skipping: ../shared/data/ict-facekit is absent");
        return;
    };
    bencher.bench(|| fbakit::rig::read_rig(divan::black_box(&dir)).unwrap());
}

#[divan::bench(sample_count = 5)]
fn ict_as_glb(bencher: divan::Bencher) {
    let Some(dir) = ict_dir() else {
        eprintln!("skipping: ../shared/data/ict-facekit is absent");
        return;
    };
    let rig = fbakit::rig::read_rig(&dir).unwrap();
    let bytes = fbakit::rig::gltf_write::rig_to_gltf(&rig)
        .unwrap()
        .to_glb()
        .unwrap();
    bencher.bench(|| {
        fbakit::rig::gltf_read::read_gltf_bytes(divan::black_box(&bytes), Path::new("ict.glb"))
            .unwrap()
    });
}

/// A ~30 MB avatar: a 540 x 540 grid (291 600 vertices) with normals, UVs, 32-bit indices
/// and four dense morph targets.
fn avatar_glb() -> Vec<u8> {
    use fbakit::gltf::{MeshData, NodeData, SceneBuilder};
    use glam::{Vec2, Vec3};
    let side = 540u32;
    let mut positions = Vec::new();
    let mut uvs = Vec::new();
    for y in 0..side {
        for x in 0..side {
            let (u, v) = (x as f32 / (side - 1) as f32, y as f32 / (side - 1) as f32);
            positions.push(Vec3::new(
                u - 0.5,
                v - 0.5,
                0.1 * (u * 6.0).sin() * (v * 4.0).cos(),
            ));
            uvs.push(Vec2::new(u, v));
        }
    }
    let mut triangles = Vec::new();
    for y in 0..side - 1 {
        for x in 0..side - 1 {
            let i = y * side + x;
            triangles.push([i, i + 1, i + side + 1]);
            triangles.push([i, i + side + 1, i + side]);
        }
    }
    let normals = vec![Vec3::Z; positions.len()];
    let mut mesh = MeshData::new("avatar", positions.clone(), triangles)
        .with_normals(normals)
        .with_uvs(uvs);
    for t in 0..4 {
        let offsets: Vec<Vec3> = positions
            .iter()
            .map(|p| Vec3::new(0.0, 0.0, 0.01 * (t as f32 + 1.0) * p.x))
            .collect();
        mesh = mesh.with_dense_target(format!("shape{t}"), offsets);
    }
    let mut scene = SceneBuilder::new("avatar");
    let m = scene.add_mesh(mesh).unwrap();
    scene
        .add_node(NodeData::new("avatar").with_mesh(m))
        .unwrap();
    scene.build().unwrap().to_glb().unwrap()
}

#[divan::bench(sample_count = 10)]
fn avatar_30mb_glb(bencher: divan::Bencher) {
    let bytes = avatar_glb();
    eprintln!("avatar glb: {:.1} MB", bytes.len() as f64 / 1e6);
    bencher.bench(|| {
        fbakit::rig::gltf_read::read_gltf_bytes(divan::black_box(&bytes), Path::new("avatar.glb"))
            .unwrap()
    });
}

/// Writing the same avatar back as a patch (buffers merged, JSON copied, GLB assembled).
#[divan::bench(sample_count = 5)]
fn avatar_30mb_patch_write(bencher: divan::Bencher) {
    let bytes = avatar_glb();
    let rig = fbakit::rig::gltf_read::read_gltf_bytes(&bytes, Path::new("avatar.glb")).unwrap();
    let face = rig.to_face();
    let source = face.gltf_source.clone().unwrap();
    bencher.bench(|| {
        let export =
            fbakit::export::gltf_patch::patch_face(&face, &source, None, &Default::default())
                .unwrap();
        export.document.to_glb().unwrap()
    });
}
