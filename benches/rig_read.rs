//! Reading blendshape rigs: the ICT-FaceKit folder (neutral + 57 full-mesh shape OBJs,
//! 26 719 vertices each; skipped when `../shared/data/ict-facekit` is absent) and a glb rig.

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

/// A glb of about 30 MB: one 760 × 760 grid mesh (577 600 vertices with normals and UVs,
/// 1.15 M triangles), the size of a detailed avatar.
fn big_glb() -> Vec<u8> {
    use fbakit::gltf::{MeshData, NodeData, SceneBuilder};
    let n = 760u32;
    let mut positions = Vec::with_capacity((n * n) as usize);
    let mut uvs = Vec::with_capacity((n * n) as usize);
    for i in 0..n {
        for j in 0..n {
            let (u, v) = (i as f32 / (n - 1) as f32, j as f32 / (n - 1) as f32);
            positions.push(glam::Vec3::new(u - 0.5, v - 0.5, (u * 7.0).sin() * 0.01));
            uvs.push(glam::Vec2::new(u, v));
        }
    }
    let mut triangles = Vec::new();
    for i in 0..n - 1 {
        for j in 0..n - 1 {
            let a = i * n + j;
            triangles.push([a, a + n, a + 1]);
            triangles.push([a + 1, a + n, a + n + 1]);
        }
    }
    let mut scene = SceneBuilder::new("avatar");
    let mesh = scene
        .add_mesh(MeshData::new("Body", &positions[..], &triangles[..]).with_uvs(&uvs[..]))
        .unwrap();
    scene
        .add_node(NodeData::new("Body").with_mesh(mesh))
        .unwrap();
    scene.build().unwrap().to_glb().unwrap()
}

/// Reading a 30 MB avatar glb, meshes only (no FAT built), its document kept for patching.
#[divan::bench(sample_count = 5)]
fn avatar_30mb_read(bencher: divan::Bencher) {
    let bytes = big_glb();
    bencher.bench(|| {
        fbakit::rig::gltf_read::read_gltf_bytes(divan::black_box(&bytes), Path::new("a.glb"))
            .unwrap()
    });
}

/// Writing the same avatar back as a patch (buffers merged, JSON copied, GLB assembled).
#[divan::bench(sample_count = 5)]
fn avatar_30mb_patch_write(bencher: divan::Bencher) {
    let bytes = big_glb();
    let rig = fbakit::rig::gltf_read::read_gltf_bytes(&bytes, Path::new("a.glb")).unwrap();
    let face = rig.to_face();
    let source = face.gltf_source.clone().unwrap();
    bencher.bench(|| {
        let export =
            fbakit::export::gltf_patch::patch_face(&face, &source, None, &Default::default())
                .unwrap();
        export.document.to_glb().unwrap()
    });
}
