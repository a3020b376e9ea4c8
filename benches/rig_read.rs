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
