//! Building a FAT from a rig: the ICT-FaceKit (57 shapes on 26 719 vertices; feature points
//! from its iBUG landmark vertices) through the ARKit map. Skipped when
//! `../shared/data/ict-facekit` is absent.

use std::path::Path;

use fbakit::fdp::{FeaturePoint, FeaturePointSet, VertexBinding};
use fbakit::rig::fap_map::FapMap;
use fbakit::rig::fat_build::face_from_rig;

fn main() {
    divan::main();
}

/// A few landmark-based feature points: enough for the FAPU and the mouth and jaw FAPs.
fn points(rig: &fbakit::rig::Rig, dir: &Path) -> FeaturePointSet {
    let ids: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("vertex_indices.json")).unwrap())
            .unwrap();
    let lm: Vec<u32> = ids["idx_to_landmark_verts"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_u64().unwrap() as u32)
        .collect();
    let pos = &rig.meshes[0].mesh.positions;
    let mut set = FeaturePointSet::new();
    let left = |a: usize, b: usize| {
        let (a, b) = (lm[a - 1], lm[b - 1]);
        if pos[a as usize].x > pos[b as usize].x {
            (a, b)
        } else {
            (b, a)
        }
    };
    let mut put = |label: &str, v: u32| {
        let mut p = FeaturePoint::at(label.parse().unwrap(), pos[v as usize]);
        p.binding = Some(VertexBinding::vertex(v));
        set.insert(p);
    };
    put("2.1", lm[8]);
    put("2.2", lm[62]);
    put("2.3", lm[66]);
    put("9.15", lm[33]);
    let (l, r) = left(49, 55);
    put("8.3", l);
    put("8.4", r);
    let (l, r) = left(61, 65);
    put("2.4", l);
    put("2.5", r);
    // Eye landmarks stand in for lids and pupils (enough for the FAPU).
    let (l, r) = left(44, 38);
    put("3.1", l);
    put("3.2", r);
    let (l, r) = left(48, 42);
    put("3.3", l);
    put("3.4", r);
    let (l, r) = left(46, 37);
    put("3.5", l);
    put("3.6", r);
    set
}

#[divan::bench(sample_count = 5)]
fn ict_fat_from_rig(bencher: divan::Bencher) {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/data/ict-facekit");
    if !dir.is_dir() {
        eprintln!("skipping: ../shared/data/ict-facekit is absent");
        return;
    }
    let rig = fbakit::rig::read_rig(&dir).unwrap();
    let fp = points(&rig, &dir);
    let map = FapMap::arkit();
    bencher.bench(|| face_from_rig(&rig, Some(fp.clone()), &map).unwrap());
}
