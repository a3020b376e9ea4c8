//! fbakit's own FATs pinned as snapshots (`fbakit::snapshot`), reviewed once: the real head's
//! rig FAT and cloned FATs of every method. And the determinism promise: every writer gives
//! the same bytes on 1, 2 and 8 threads, and faces keep their snapshot through a write and a
//! read (VRML exactly; an OBJ morph set, which merges meshes, from its first write on).

use std::path::Path;
use std::sync::OnceLock;

use fbakit::clone::face::{clone_face, CloneOptions, Method};
use fbakit::face::FaceModel;
use fbakit::snapshot::{diff, snapshot, DiffOptions, SnapshotOptions, Tolerance, VertexMatch};

fn alma() -> &'static FaceModel {
    static FACE: OnceLock<FaceModel> = OnceLock::new();
    FACE.get_or_init(|| fbakit::face::read("alma").unwrap())
}

fn bruno() -> &'static FaceModel {
    static FACE: OnceLock<FaceModel> = OnceLock::new();
    FACE.get_or_init(|| fbakit::face::read("bruno").unwrap())
}

/// bruno's FAT cloned onto alma (stripped of hers) by `method`.
fn cloned(method: Method) -> FaceModel {
    let mut target = alma().clone();
    target.fat = Default::default();
    let opts = CloneOptions {
        method,
        ..CloneOptions::default()
    };
    clone_face(bruno(), &target, &opts).unwrap().face
}

/// Cloned FATs go through least squares and sparse solvers whose last bits may differ
/// between CPUs (SIMD paths): pinned on a coarser grid than the default.
fn coarse() -> SnapshotOptions {
    SnapshotOptions {
        tolerance: Tolerance::Relative(1e-3),
    }
}

#[test]
fn cloned_fat_snapshots() {
    for method in [Method::Fmc, Method::Rbf, Method::Fit] {
        let face = cloned(method);
        insta::assert_snapshot!(
            format!("bruno_onto_alma_{}", method.name()),
            snapshot(&face, &coarse())
        );
    }
}

#[test]
fn rig_fat_snapshot() {
    let ict = fbakit::face::read("ict").unwrap();
    insta::assert_snapshot!("ict_rig_fat", snapshot(&ict, &coarse()));
}

/// Everything written for one cloned face, as bytes, on a pool of `threads` threads.
fn outputs(threads: usize, dir: &Path) -> Vec<(String, Vec<u8>)> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    pool.install(|| {
        let mut out = Vec::new();
        for method in [Method::Fmc, Method::Rbf, Method::Fit] {
            let face = cloned(method);
            for ext in ["wrl", "wrl.gz", "glb", "gltf", "obj"] {
                let path = dir.join(format!("{threads}-{}.{ext}", method.name()));
                fbakit::export::write_face(&path, &face).unwrap();
                out.push((
                    format!("{} .{ext}", method.name()),
                    std::fs::read(&path).unwrap(),
                ));
            }
            out.push((
                format!("{} snapshot", method.name()),
                snapshot(&face, &SnapshotOptions::default()).into_bytes(),
            ));
            let report = diff(alma(), &face, &DiffOptions::default());
            out.push((
                format!("{} diff json", method.name()),
                serde_json::to_vec_pretty(&report).unwrap(),
            ));
        }
        let (stream, _) = fbakit::fap::read_stream_file(
            "samples/speech.fap",
            &fbakit::fap::ReadOptions::lenient(),
        )
        .unwrap();
        out.push((
            "speech.fap".into(),
            fbakit::fap::write_fap_string(&stream).into_bytes(),
        ));
        let json = dir.join(format!("{threads}-speech.json"));
        fbakit::fap::write_stream_file(&json, &stream).unwrap();
        out.push(("speech.json".into(), std::fs::read(&json).unwrap()));
        // A morph set: OBJs and the feature-point CSV.
        let set = dir.join(format!("{threads}-morphs"));
        fbakit::face::morphs::write_morph_set(alma(), &set, None).unwrap();
        let mut files: Vec<_> = std::fs::read_dir(&set)
            .unwrap()
            .map(|e| e.unwrap().path())
            .collect();
        files.sort();
        for f in files {
            let name = f.file_name().unwrap().to_string_lossy().into_owned();
            out.push((name, std::fs::read(&f).unwrap()));
        }
        out
    })
}

#[test]
fn writers_are_byte_identical_across_thread_counts() {
    let dir = tempfile::tempdir().unwrap();
    let one = outputs(1, dir.path());
    for threads in [2, 8] {
        let other = outputs(threads, dir.path());
        assert_eq!(one.len(), other.len());
        for ((name, a), (_, b)) in one.iter().zip(&other) {
            assert!(a == b, "{name} differs between 1 and {threads} threads");
        }
    }
}

#[test]
fn snapshots_survive_a_write_and_a_read() {
    let dir = tempfile::tempdir().unwrap();
    let opts = SnapshotOptions::default();
    for face in [alma(), &cloned(Method::Rbf)] {
        let original = snapshot(face, &opts);
        for ext in ["wrl", "wrl.gz"] {
            let path = dir.path().join(format!("face.{ext}"));
            fbakit::export::write_face(&path, face).unwrap();
            let back = fbakit::face::read(&path).unwrap();
            assert_eq!(original, snapshot(&back, &opts), ".{ext}");
        }
    }
    // glTF that fbakit generates keeps every table, transform tables included (as nodes and
    // the `transformTables` record), the face's units, mesh order and polygons.
    let bruno_face = bruno();
    let cloned_face = cloned(Method::Rbf);
    for (name, face) in [
        ("alma", alma()),
        ("bruno", bruno_face),
        ("clone", &cloned_face),
    ] {
        let original = snapshot(face, &opts);
        for ext in ["glb", "gltf"] {
            let path = dir.path().join(format!("{name}.{ext}"));
            fbakit::export::write_face(&path, face).unwrap();
            let back = fbakit::face::read(&path).unwrap();
            assert_eq!(original, snapshot(&back, &opts), "{name}.{ext}");
            let report = diff(face, &back, &DiffOptions::default());
            assert!(report.is_equal(), "{name}.{ext}: {report}");
            // Written again, it is its own document patched: the same face.
            let again = dir.path().join(format!("{name}-again.{ext}"));
            fbakit::export::write_face(&again, &back).unwrap();
            let back2 = fbakit::face::read(&again).unwrap();
            assert_eq!(original, snapshot(&back2, &opts), "{name}-again.{ext}");
        }
    }
    let transforms = |f: &FaceModel| {
        f.fat
            .tables
            .iter()
            .filter(|t| !t.transforms.is_empty())
            .count()
    };
    assert!(transforms(alma()) > 0 && transforms(bruno_face) > 0);
}

#[test]
fn a_patched_rig_keeps_its_fat_through_a_write_and_a_read() {
    // The real head's glTF is patched, not generated: its FAT comes back equal as animation;
    // rates whose single-precision offsets cannot show them exactly read back one float step
    // off, so the snapshot text is stable from the first write on.
    let dir = tempfile::tempdir().unwrap();
    let opts = SnapshotOptions::default();
    let ict = fbakit::face::read("ict").unwrap();
    let first = dir.path().join("ict.glb");
    fbakit::export::write_face(&first, &ict).unwrap();
    let back = fbakit::face::read(&first).unwrap();
    let report = diff(&ict, &back, &DiffOptions::default());
    assert!(report.is_equal(), "{report}");
    let second = dir.path().join("ict-again.glb");
    fbakit::export::write_face(&second, &back).unwrap();
    let back2 = fbakit::face::read(&second).unwrap();
    assert_eq!(snapshot(&back, &opts), snapshot(&back2, &opts));
}

#[test]
fn obj_morph_sets_are_stable_after_the_first_write() {
    let dir = tempfile::tempdir().unwrap();
    let opts = SnapshotOptions::default();
    // An OBJ morph set merges the meshes (a new layout): its snapshot is stable from the
    // first write on, and it still animates like the original (compared by nearest vertex).
    let morphs = |face: &FaceModel, name: &str| -> FaceModel {
        let set = dir.path().join(name);
        fbakit::face::morphs::write_morph_set(face, &set, None).unwrap();
        let options = fbakit::face::morphs::MorphSetOptions {
            feature_points: Some(set.join("feature-points.csv")),
            manifest: None,
            tolerance: None,
        };
        fbakit::face::morphs::face_from_morph_set(&set.join("neutral.obj"), &set, &options)
            .unwrap()
            .0
    };
    let first = morphs(alma(), "first");
    let second = morphs(&first, "second");
    assert_eq!(snapshot(&first, &opts), snapshot(&second, &opts));
    let nearest = DiffOptions {
        vertex_match: VertexMatch::Nearest,
        ..DiffOptions::default()
    };
    let report = diff(alma(), &first, &nearest);
    let worst = report
        .tables
        .iter()
        .map(|t| t.max_difference)
        .fold(0.0, f64::max);
    assert!(
        report.tables.iter().all(|t| t.only_in.is_none()),
        "{report}"
    );
    assert!(worst <= report.tolerance.absolute, "{report}");
}
