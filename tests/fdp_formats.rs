//! Feature-point files end to end: the real Xface and CANDIDE-3 data, round trips, the
//! `fbakit fapu` command and hostile inputs.

use std::path::{Path, PathBuf};

use fbakit::fdp::csv::{parse_csv, to_csv_string};
use fbakit::fdp::xml::{parse_xml, to_xml_string, FeaturePointDocument};
use fbakit::fdp::{read_feature_points, Fapu, FapuSource, FeaturePointFormat, FormatExtras};
use fbakit::spec::{FapId, FeaturePointId};
use glam::Vec3;

mod support;

const MANIFEST: &str = env!("CARGO_MANIFEST_DIR");

fn shared(rel: &str) -> Option<PathBuf> {
    let p = Path::new(MANIFEST).join("../shared/data").join(rel);
    if p.exists() {
        Some(p)
    } else {
        eprintln!("note: {} not found; skipping", p.display());
        None
    }
}

fn fp(s: &str) -> FeaturePointId {
    s.parse().unwrap()
}

#[test]
fn alice_fdp_loads_with_the_readme_counts() {
    let Some(path) = shared("xface-alice-fdp/alice.fdp") else {
        return;
    };
    let file = read_feature_points(&path).unwrap();
    assert_eq!(file.format, FeaturePointFormat::XfaceFdp);
    let d = file.fapu.unwrap();
    assert_eq!(
        (d.es0, d.irisd0, d.ens0, d.mns0, d.mw0),
        (69.0, 16.0, 51.0, 30.0, 50.0)
    );
    let FormatExtras::XfaceFdp(x) = &file.extras else {
        panic!("xface extras")
    };
    assert_eq!(x.fdps.len(), 35);
    assert_eq!(x.entities.len(), 29);
    let cat = |c: &str| x.entities.iter().filter(|e| e.category == c).count();
    assert_eq!(
        (cat("Expression"), cat("Modifier"), cat("Viseme")),
        (8, 5, 16)
    );
    assert!(x
        .entities
        .iter()
        .any(|e| e.meshes[0].file == "alice_PhonemeB,M,P.wrl"));
    let rest = x.entities.iter().find(|e| e.alias == "Rest").unwrap();
    assert_eq!(rest.binds.len(), 6);
    assert_eq!(rest.binds[1].pivot.unwrap().x, -33.8);
    assert_eq!(x.translation.unwrap().z, -659.0);
    assert_eq!(x.version.as_deref(), Some("0.2"));
    // 35 elements, 2.1 and 3.1 twice: 33 distinct points, all on the skin mesh.
    assert_eq!(file.points.len(), 33);
    assert_eq!(x.primary_mesh(), Some("alice.wrl_3"));
    assert_eq!(x.fdps.iter().filter(|f| !f.primary).count(), 2);
    for id in ["2.1", "3.1"] {
        let b = file.points.get(fp(id)).unwrap().binding.as_ref().unwrap();
        assert_eq!(b.mesh.as_deref(), Some("alice.wrl_3"), "{id}");
    }
    // 3.5 exists only on the eye mesh, so that is its binding.
    let b = file
        .points
        .get(fp("3.5"))
        .unwrap()
        .binding
        .as_ref()
        .unwrap();
    assert_eq!(
        (b.mesh.as_deref(), b.vertices.as_slice()),
        (Some("alice.wrl_1"), &[19][..])
    );
    // fap is 0-based: fap="2" on 2.1 is open_jaw (FAP 3); 8.7 carries fap="57" = FAP 58.
    let first = &x.fdps[0];
    assert_eq!((first.id, first.index), (fp("2.1"), 2395));
    assert_eq!(first.influences[0].fap, FapId::OPEN_JAW);
    assert_eq!(first.influences[0].weight, 0.3);
    let f87 = x.fdps.iter().find(|f| f.id == fp("8.7")).unwrap();
    assert_eq!(f87.influences[0].fap.number(), 58);
    let (source, m) = file.fapu().unwrap();
    assert_eq!(source, FapuSource::File);
    assert_eq!(m.fapu.distances.mw0, 50.0);
}

/// Vertex list of a CANDIDE `.wfm` file: the count after `# VERTEX LIST:`, then `x y z` lines.
/// (Test-local: the real `.wfm` reader lives elsewhere.)
fn wfm_vertices(text: &str) -> Vec<Vec3> {
    let mut lines = text.lines().skip_while(|l| !l.starts_with("# VERTEX LIST"));
    lines.next();
    let n: usize = lines.next().unwrap().trim().parse().unwrap();
    lines
        .take(n)
        .map(|l| {
            let v: Vec<f32> = l.split_whitespace().map(|t| t.parse().unwrap()).collect();
            Vec3::new(v[0], v[1], v[2])
        })
        .collect()
}

#[test]
fn candide3_csv_gives_the_readme_fapus() {
    let (Some(csv), Some(wfm)) = (
        shared("candide3/feature-points.csv"),
        shared("candide3/candide3.wfm"),
    ) else {
        return;
    };
    let mut file = read_feature_points(&csv).unwrap();
    assert_eq!(file.format, FeaturePointFormat::Csv);
    let FormatExtras::Csv(table) = &file.extras else {
        panic!("csv extras")
    };
    assert_eq!(table.rows.len(), 83);
    assert_eq!(file.points.len(), 67, "67 mapped, 16 absent");
    let text = String::from_utf8_lossy(&std::fs::read(wfm).unwrap()).into_owned();
    let verts = wfm_vertices(&text);
    assert_eq!(verts.len(), 113);
    assert!(file.points.needs_mesh());
    let n = file
        .points
        .resolve_positions(|mesh, i| {
            assert!(mesh.is_none());
            verts.get(i as usize).copied()
        })
        .unwrap();
    assert_eq!(n, 67);
    // The pupil is the mean of the four iris-box corners.
    let pupil = file.points.position(fp("3.5")).unwrap();
    let mean = (verts[67] + verts[68] + verts[71] + verts[72]) / 4.0;
    assert!((pupil - mean).length() < 1e-6);
    let m = Fapu::measure(&file.points).unwrap();
    let d = m.fapu.distances;
    let close = |a: f64, b: f64| (a - b).abs() < 5e-4;
    assert!(close(d.mw0, 0.492), "MW0 {}", d.mw0);
    assert!(close(d.mns0, 0.196), "MNS0 {}", d.mns0);
    assert!(close(d.ens0, 0.4225), "ENS0 {}", d.ens0);
    assert!(close(d.es0, 0.613), "ES0 {}", d.es0);
    // The README's IRISD 0.085 is the report's iris-box height; the MPEG-4 eyelid distance
    // 3.1.y - 3.3.y is 0.082 on this mesh.
    assert!(close(d.irisd0, 0.082), "IRISD0 {}", d.irisd0);
    assert!(m.notes.is_empty());
    // A vertex index past the mesh names point and index.
    let mut broken = file.points.clone();
    let e = broken.resolve_positions(|_, i| verts.get(i as usize).filter(|_| i < 60).copied());
    assert!(
        e.unwrap_err().to_string().contains("point 2.2: vertex 87"),
        "2.2 -> 87"
    );
}

#[test]
fn candide3_csv_round_trips() {
    let Some(csv) = shared("candide3/feature-points.csv") else {
        return;
    };
    let text = std::fs::read_to_string(&csv).unwrap();
    let t = parse_csv(&text, &csv).unwrap();
    let written = to_csv_string(&t).unwrap();
    assert_eq!(parse_csv(&written, Path::new("w.csv")).unwrap(), t);
}

#[test]
fn sample_xml_round_trips_and_measures() {
    let path = Path::new(MANIFEST).join("samples/feature-points-example.xml");
    let file = read_feature_points(&path).unwrap();
    assert_eq!(file.format, FeaturePointFormat::FbakitXml);
    assert_eq!(file.points.len(), 21);
    let text = std::fs::read_to_string(&path).unwrap();
    let doc = parse_xml(&text, &path).unwrap();
    let again = parse_xml(&to_xml_string(&doc), Path::new("w.xml")).unwrap();
    assert_eq!(again, doc);
    let (source, m) = file.fapu().unwrap();
    assert_eq!(source, FapuSource::FeaturePoints);
    let d = m.fapu.distances;
    assert_eq!(
        (d.irisd0, d.es0, d.ens0, d.mns0, d.mw0),
        (11.0, 64.0, 42.0, 21.0, 52.0)
    );
}

#[test]
fn write_and_read_files_atomically() {
    let dir = tempfile::tempdir().unwrap();
    let doc = FeaturePointDocument {
        units: Some("m".into()),
        fapu: None,
        points: [fbakit::fdp::FeaturePoint::at(
            fp("3.5"),
            Vec3::new(0.03, 0.0, 0.02),
        )]
        .into_iter()
        .collect(),
    };
    let p = dir.path().join("fp.xml");
    fbakit::fdp::xml::write_xml_file(&p, &doc).unwrap();
    assert_eq!(fbakit::fdp::xml::read_xml_file(&p).unwrap(), doc);
    let table = fbakit::fdp::csv::FeaturePointTable::from_set(&fbakit::fdp::FeaturePointSet::new());
    let c = dir.path().join("fp.csv");
    fbakit::fdp::csv::write_csv_file(&c, &table).unwrap();
    assert_eq!(fbakit::fdp::csv::read_csv_file(&c).unwrap(), table);
}

// --- CLI ---------------------------------------------------------------------------------

fn fbakit(args: &[&str]) -> (i32, String, String) {
    let out = support::cli::fbakit(args);
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8(out.stdout).unwrap(),
        String::from_utf8(out.stderr).unwrap(),
    )
}

#[test]
fn cli_fapu_on_alice() {
    if shared("xface-alice-fdp/alice.fdp").is_none() {
        return;
    }
    let f = "../shared/data/xface-alice-fdp/alice.fdp";
    let (code, out, err) = fbakit(&["fapu", f]);
    assert_eq!(code, 0, "{err}");
    insta::assert_snapshot!("fapu_alice_text", out);
    let (code, out, _) = fbakit(&["fapu", f, "--json"]);
    assert_eq!(code, 0);
    insta::assert_snapshot!("fapu_alice_json", out);
}

#[test]
fn cli_fapu_on_sample() {
    let f = "samples/feature-points-example.xml";
    let (code, out, err) = fbakit(&["fapu", f]);
    assert_eq!(code, 0, "{err}");
    insta::assert_snapshot!("fapu_sample_text", out);
    let (code, out, _) = fbakit(&["fapu", f, "--json"]);
    assert_eq!(code, 0);
    insta::assert_snapshot!("fapu_sample_json", out);
}

#[test]
fn cli_fapu_places_vertex_bound_points_on_a_mesh() {
    // A square "face" whose vertices carry the five FAPU point pairs at known distances.
    let dir = tempfile::tempdir().unwrap();
    let obj = dir.path().join("face.obj");
    std::fs::write(
        &obj,
        "v 0.3 1 0\nv -0.3 1 0\nv 0.3 0.9 0\nv 0 0.5 0\nv 0 0.2 0\nv 0.25 0.2 0\nv -0.25 0.2 0\nf 1 2 3\nf 4 5 6\nf 4 7 5\n",
    )
    .unwrap();
    // 3.5/3.6 pupils (1, 2), 3.1/3.3 lids (1, 3), 9.15 nose (4), 2.2 lip (5), 8.3/8.4 corners (6, 7).
    let csv = dir.path().join("fp.csv");
    std::fs::write(
        &csv,
        "fp,vertices\n3.5,0\n3.6,1\n3.1,0\n3.3,2\n9.15,3\n2.2,4\n8.3,5\n8.4,6\n",
    )
    .unwrap();
    let (code, out, err) = fbakit(&[
        "fapu",
        csv.to_str().unwrap(),
        "--mesh",
        obj.to_str().unwrap(),
        "--json",
    ]);
    assert_eq!(code, 0, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(v["source"], "feature-points");
    let d = |i: usize| v["units"][i]["distance"].as_f64().unwrap();
    // IRISD0 0.1, ES0 0.6, ENS0 0.5, MNS0 0.3, MW0 0.5 (f32 coordinates).
    for (i, want) in [(0, 0.1), (1, 0.6), (2, 0.5), (3, 0.3), (4, 0.5)] {
        assert!((d(i) - want).abs() < 1e-6, "unit {i}: {} vs {want}", d(i));
    }
}

#[test]
fn cli_fapu_failures_exit_2_with_a_reason() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("fp.csv");
    std::fs::write(&csv, "fp,vertices\n3.5,1\n").unwrap();
    let (code, out, err) = fbakit(&["fapu", csv.to_str().unwrap()]);
    assert_eq!((code, out.as_str()), (2, ""));
    assert!(err.contains("pass --mesh MESH"), "{err}");
    let (code, _, err) = fbakit(&["fapu", csv.to_str().unwrap(), "--mesh", "face.obj"]);
    assert_eq!(code, 2, "a missing mesh is bad input");
    assert!(err.contains("face.obj"), "{err}");
    let xml = dir.path().join("fp.xml");
    std::fs::write(&xml, "<featurePoints version=\"1\">\n<point id=\"3.5\" x=\"1\" y=\"0\" z=\"0\"/>\n</featurePoints>\n").unwrap();
    let (code, _, err) = fbakit(&["fapu", xml.to_str().unwrap()]);
    assert_eq!(code, 2);
    assert!(
        err.contains("2.2 (for MNS0)") && err.contains("9.15 (for ENS0, MNS0)"),
        "{err}"
    );
    std::fs::write(
        &xml,
        "<featurePoints version=\"1\">\n<point id=\"3.5\" x=\"nan\"",
    )
    .unwrap();
    let (code, _, err) = fbakit(&["fapu", xml.to_str().unwrap()]);
    assert_eq!(code, 2);
    assert!(err.contains("fp.xml:2:"), "{err}");
    let (code, _, err) = fbakit(&["fapu", "no-such-file.xml"]);
    assert_eq!(code, 2, "{err}");
}

// --- Hostile inputs ----------------------------------------------------------------------

#[test]
fn hostile_inputs_are_errors_not_panics() {
    let dir = tempfile::tempdir().unwrap();
    let write = |name: &str, bytes: &[u8]| {
        let p = dir.path().join(name);
        std::fs::write(&p, bytes).unwrap();
        p
    };
    // Non-UTF-8.
    let p = write(
        "bad.xml",
        b"<featurePoints version=\"1\">\n<point id=\"\xff\"/>",
    );
    let e = read_feature_points(&p).unwrap_err().to_string();
    assert!(e.contains("bad.xml:2:") && e.contains("UTF-8"), "{e}");
    // Deep nesting, both XML formats.
    let deep = format!("<xfdp>{}", "<a>".repeat(1_000_000));
    let e = read_feature_points(write("deep.fdp", deep.as_bytes())).unwrap_err();
    assert!(e.to_string().contains("nesting"), "{e}");
    let deep = format!(
        "<featurePoints version=\"1\">{}",
        "<point>".repeat(1_000_000)
    );
    assert!(read_feature_points(write("deep.xml", deep.as_bytes())).is_err());
    // A million attributes on an Xface element (unknown ones are skipped, linearly).
    let mut many = String::from("<xfdp><fdp affects=\"m\" index=\"1\" name=\"2.1\"");
    for i in 0..1_000_000 {
        many.push_str(&format!(" a{i}=\"{i}\""));
    }
    many.push_str("/></xfdp>");
    let f = read_feature_points(write("many.fdp", many.as_bytes())).unwrap();
    assert_eq!(f.points.len(), 1);
    // Truncated documents.
    for (name, text) in [
        (
            "t1.xml",
            "<featurePoints version=\"1\"><point id=\"2.1\" x=\"1",
        ),
        (
            "t2.fdp",
            "<xfdp><fdp affects=\"m\" index=\"1\" name=\"2.1\"><indices>1 2",
        ),
        ("t3.csv", "fp,vertices,combine\n2.1,1;2,sing"),
    ] {
        assert!(
            read_feature_points(write(name, text.as_bytes())).is_err(),
            "{name}"
        );
    }
    // Huge numbers and NaN.
    for (name, text) in [
        ("h1.xml", "<featurePoints version=\"1\"><point id=\"2.1\" x=\"1e999\" y=\"0\" z=\"0\"/></featurePoints>"),
        ("h2.xml", "<featurePoints version=\"1\"><point id=\"2.1\" x=\"inf\" y=\"0\" z=\"0\"/></featurePoints>"),
        ("h3.xml", "<featurePoints version=\"1\"><point id=\"2.1\" vertices=\"4294967296\"/></featurePoints>"),
        ("h4.fdp", "<xfdp><head><fapu ENS0=\"NaN\" ES0=\"1\" IRISD0=\"1\" MNS0=\"1\" MW0=\"1\"/></head></xfdp>"),
        ("h5.fdp", "<xfdp><fdp affects=\"m\" index=\"99999999999999999999\" name=\"2.1\"/></xfdp>"),
        ("h6.csv", "fp,vertices\n2.1,1;99999999999999999999\n"),
        ("h7.fdp", "<xfdp><fdp affects=\"m\" index=\"1\" name=\"2.1\"><influence fap=\"300\"/></fdp></xfdp>"),
    ] {
        let e = read_feature_points(write(name, text.as_bytes())).unwrap_err().to_string();
        assert!(e.contains(name), "{name}: {e}");
    }
}

#[test]
fn fuzz_regressions_replay() {
    for target in ["fdp_xml", "xface_fdp", "fp_csv"] {
        let dir = Path::new(MANIFEST)
            .join("tests/fuzz-regressions")
            .join(target);
        let Ok(entries) = std::fs::read_dir(&dir) else {
            continue;
        };
        for entry in entries {
            let path = entry.unwrap().path();
            let bytes = std::fs::read(&path).unwrap();
            let Ok(text) = std::str::from_utf8(&bytes) else {
                continue;
            };
            let name = match target {
                "fdp_xml" => "f.xml",
                "xface_fdp" => "f.fdp",
                _ => "f.csv",
            };
            // Must not panic; the result itself does not matter.
            let _ = fbakit::fdp::parse_feature_points(text, Path::new(name));
        }
    }
}
