use std::collections::{BTreeMap, HashSet};

use glam::Vec3;

use super::*;
use crate::face::write::merged_mesh;
use crate::fdp::Fapu;

fn fp(s: &str) -> FeaturePointId {
    s.parse().unwrap()
}

/// The bundled face `alma` as one mesh (skin first, so skin vertex ids are unchanged), its
/// true feature-point positions, and 68 iBUG landmark vertices: the preset's landmark rows on
/// alma's own feature-point vertices, the lip-arc landmarks on the lip between them, the rest
/// on distinct unused skin vertices (no rule reads them).
fn alma_ibug() -> (Mesh, BTreeMap<FeaturePointId, Vec3>, Vec<u32>) {
    let face = crate::synth::alma().to_face_model();
    let mesh = merged_mesh(&face, &face.frames().meshes, None).unwrap();
    let truth: BTreeMap<FeaturePointId, Vec3> = face
        .feature_points
        .iter()
        .filter_map(|p| Some((p.id, p.position?)))
        .collect();
    let skin_n = face.meshes[0].mesh.positions.len() as u32;
    let vertex_of = |id: FeaturePointId| face.fp_vertex(id).map(|(_, v)| v).unwrap();
    let mut ids = vec![u32::MAX; 68];
    for row in LandmarkScheme::Ibug68.preset() {
        if row.rule == Rule::Landmark {
            ids[row.landmarks[0]] = vertex_of(row.fp);
        }
    }
    let skin = &face.meshes[0].mesh.positions;
    let nearest = |p: Vec3, used: &HashSet<u32>| {
        (0..skin_n)
            .filter(|v| !used.contains(v))
            .min_by(|&a, &b| {
                skin[a as usize]
                    .distance(p)
                    .total_cmp(&skin[b as usize].distance(p))
            })
            .unwrap()
    };
    let t = |s: &str| truth[&fp(s)];
    // Upper lip arcs pass the Cupid's bow peaks; lower lip arcs are thirds of the chord.
    let arcs = [
        (49, (t("8.4") + t("8.9")) * 0.5),
        (53, (t("8.3") + t("8.10")) * 0.5),
        (55, t("8.3").lerp(t("8.2"), 1.0 / 3.0)),
        (56, t("8.3").lerp(t("8.2"), 2.0 / 3.0)),
        (59, t("8.4").lerp(t("8.2"), 1.0 / 3.0)),
        (58, t("8.4").lerp(t("8.2"), 2.0 / 3.0)),
    ];
    let mut used: HashSet<u32> = ids.iter().copied().filter(|&v| v != u32::MAX).collect();
    for (i, p) in arcs {
        let v = nearest(p, &used);
        used.insert(v);
        ids[i] = v;
    }
    // Spare landmarks on the face (near the nose), like real ones.
    let mut by_distance: Vec<u32> = (0..skin_n).filter(|v| !used.contains(v)).collect();
    by_distance.sort_by(|&a, &b| {
        let d = |v: u32| skin[v as usize].distance(t("9.3"));
        d(a).total_cmp(&d(b))
    });
    let mut spare = by_distance.into_iter();
    for id in ids.iter_mut().filter(|v| **v == u32::MAX) {
        *id = spare.next().unwrap();
    }
    (mesh, truth, ids)
}

#[test]
fn ibug68_on_alma_finds_alma_s_own_points() {
    let (mesh, truth, ids) = alma_ibug();
    let found = feature_points_from_landmarks(&mesh, LandmarkScheme::Ibug68, &ids).unwrap();
    assert!(found.absent.is_empty(), "{:?}", found.absent);
    let es0 = truth[&fp("3.5")].x - truth[&fp("3.6")].x;
    // Tolerances in eye separations: tight where the point is a sharp geometric feature
    // (lid margins, eyeball apex), looser for the proportional cheek and nose rules and for
    // the chin boss (alma's is put at a fixed height above the chin, not where the chin
    // protrudes most).
    let tolerance = [
        ("3.1", 0.03),
        ("3.2", 0.03),
        ("3.3", 0.03),
        ("3.4", 0.03),
        ("3.5", 0.03),
        ("3.6", 0.03),
        ("2.10", 0.15),
        ("5.1", 0.1),
        ("5.2", 0.1),
        ("5.3", 0.1),
        ("5.4", 0.1),
        ("9.1", 0.1),
        ("9.2", 0.1),
        ("9.12", 0.1),
        ("11.4", 0.1),
        ("11.6", 0.1),
    ];
    let mut report = Vec::new();
    for (label, tol) in tolerance {
        let p = found.get(fp(label)).unwrap();
        let d = p.position.distance(truth[&fp(label)]) / es0;
        report.push(format!("{label}: {d:.3}"));
        assert!(
            d <= tol,
            "{label} is {d:.3} eye separations from alma's own point ({:?}); all: {report:?}",
            p.provenance
        );
    }
    // The FAP units measured on the derived points match alma's.
    let ours = Fapu::from_feature_points(&found.feature_point_set()).unwrap();
    let theirs = Fapu::from_feature_points(
        &truth
            .iter()
            .map(|(&id, &p)| crate::fdp::FeaturePoint::at(id, p))
            .collect(),
    )
    .unwrap();
    let (a, b) = (ours.distances, theirs.distances);
    for (name, x, y) in [
        ("IRISD0", a.irisd0, b.irisd0),
        ("ES0", a.es0, b.es0),
        ("ENS0", a.ens0, b.ens0),
        ("MNS0", a.mns0, b.mns0),
        ("MW0", a.mw0, b.mw0),
    ] {
        assert!((x / y - 1.0).abs() < 0.05, "{name}: {x} vs alma's {y}");
    }
    // Provenance: landmark rows name their landmark, derived rows their rule.
    assert_eq!(
        found.get(fp("2.1")).unwrap().provenance,
        Provenance::Landmark {
            landmark: 8,
            name: "iBUG 9".into()
        }
    );
    assert!(matches!(
        found.get(fp("3.1")).unwrap().provenance,
        Provenance::Derived {
            rule: Rule::UpperLidMargin,
            ..
        }
    ));
}

#[test]
fn eyeless_and_skull_less_meshes_fall_back_and_report() {
    // alma's skin alone: no eyeballs (pupils from the lid contour) and, cut to its front
    // half, no skull.
    let (mesh, _, ids) = alma_ibug();
    let face = crate::synth::alma().to_face_model();
    let skin_only = face.meshes[0].mesh.clone();
    let found = feature_points_from_landmarks(&skin_only, LandmarkScheme::Ibug68, &ids).unwrap();
    let pupil = found.get(fp("3.5")).unwrap();
    assert_eq!(pupil.vertices.len(), 4, "{pupil:?}");
    assert!(
        found.notes.iter().any(|n| n.starts_with("3.5")),
        "{:?}",
        found.notes
    );
    // Front half only: the skull rules report absence instead of inventing points.
    let z_cut = mesh.positions[ids[30] as usize].z - 60.0;
    let keep: Vec<bool> = skin_only.positions.iter().map(|p| p.z > z_cut).collect();
    let polys: Vec<Vec<u32>> = skin_only
        .polygons
        .iter()
        .filter(|p| p.iter().all(|&v| keep[v as usize]))
        .map(|p| p.to_vec())
        .collect();
    let front = Mesh {
        polygons: crate::mesh::Polygons::from_lists(polys.iter().map(|p| p.as_slice())),
        ..skin_only.clone()
    };
    let found = feature_points_from_landmarks(&front, LandmarkScheme::Ibug68, &ids).unwrap();
    let absent: Vec<String> = found.absent.iter().map(|a| a.id.to_string()).collect();
    assert_eq!(absent, vec!["11.4", "11.6"], "{:?}", found.absent);
    assert!(found.absent[0].reason.contains("skull"));
}

#[test]
fn bad_landmarks_are_refused() {
    let (mesh, _, ids) = alma_ibug();
    let e = feature_points_from_landmarks(&mesh, LandmarkScheme::Ibug68, &ids[..67]).unwrap_err();
    assert!(e.to_string().contains("expected 68"), "{e}");
    let mut dup = ids.clone();
    dup[5] = dup[4];
    let e = feature_points_from_landmarks(&mesh, LandmarkScheme::Ibug68, &dup).unwrap_err();
    assert!(e.to_string().contains("repeats vertex"), "{e}");
    let mut far = ids.clone();
    far[0] = mesh.positions.len() as u32;
    let e = feature_points_from_landmarks(&mesh, LandmarkScheme::Ibug68, &far).unwrap_err();
    assert!(e.to_string().contains("beyond the mesh"), "{e}");
    let mut nan = mesh.clone();
    nan.positions[7].y = f32::NAN;
    let e = feature_points_from_landmarks(&nan, LandmarkScheme::Ibug68, &ids).unwrap_err();
    assert!(e.to_string().contains("vertex 7 has a non-finite"), "{e}");
    // Left and right eyes swapped: a mirrored face.
    let mut swapped = ids.clone();
    swapped.swap(36, 45);
    swapped.swap(39, 42);
    let e = feature_points_from_landmarks(&mesh, LandmarkScheme::Ibug68, &swapped).unwrap_err();
    assert!(e.to_string().contains("mirrored"), "{e}");
}

#[test]
fn table_carries_the_provenance() {
    let (mesh, _, ids) = alma_ibug();
    let found = feature_points_from_landmarks(&mesh, LandmarkScheme::Ibug68, &ids).unwrap();
    let table = found.table();
    assert_eq!(table.rows.len(), found.points.len());
    let row = table.rows.iter().find(|r| r.fp == fp("9.3")).unwrap();
    assert_eq!(row.description.as_deref(), Some("landmark iBUG 31"));
    // The CSV round-trips to the same bindings.
    let text = crate::fdp::csv::to_csv_string(&table).unwrap();
    let back = crate::fdp::csv::parse_csv(&text, std::path::Path::new("t.csv")).unwrap();
    assert_eq!(back, table);
}
