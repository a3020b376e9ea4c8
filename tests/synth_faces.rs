//! The procedural faces `alma` and `bruno`: geometry sanity, feature points, FAPU and FAT
//! compliance (every FAP moves its feature point by exactly P × FAPU × direction).

use std::collections::HashMap;
use std::sync::OnceLock;

use fbakit::fat::eval::{Activation, FatEvaluator, FatOutput};
use fbakit::fat::validate::validate_fat;
use fbakit::fat::{TableKey, TransformField};
use fbakit::spec::{Expression, FapId, FapuKind, FeaturePointId, Viseme, AU_RADIANS};
use fbakit::synth::{self, names, HeadParams, SynthFace};
use glam::{DVec3, Vec3};

fn faces() -> &'static [SynthFace; 2] {
    static FACES: OnceLock<[SynthFace; 2]> = OnceLock::new();
    FACES.get_or_init(|| [synth::alma(), synth::bruno()])
}

fn fp(s: &str) -> FeaturePointId {
    s.parse().unwrap()
}

/// Position of a mesh vertex after an evaluation: neutral + displacement, then every
/// transform from the mesh's up to the root (neutral transforms are the identity, so each
/// applies its delta about its centre: p → c + R·(p − c)·(1 + Δs) + t).
fn animated(face: &SynthFace, out: &FatOutput, mesh: usize, vertex: u32) -> DVec3 {
    let m = &face.meshes[mesh];
    let mut p =
        (m.positions[vertex as usize] + out.displacements[mesh][vertex as usize]).as_dvec3();
    let mut tf = Some(m.transform);
    while let Some(t) = tf {
        let d = &out.transforms[t];
        let c = face.transforms[t].center.as_dvec3();
        p = c
            + d.rotation.as_dquat() * ((p - c) * (DVec3::ONE + d.scale.as_dvec3()))
            + d.translation.as_dvec3();
        tf = face.transforms[t].parent;
    }
    p
}

fn evaluator(face: &SynthFace) -> (FatEvaluator, FatOutput) {
    let e = FatEvaluator::new(&face.fat, &face.mesh_sizes(), &face.transform_names()).unwrap();
    let o = e.output();
    (e, o)
}

fn fp_displacement(
    face: &SynthFace,
    eval: &mut FatEvaluator,
    out: &mut FatOutput,
    key: TableKey,
    value: f64,
    point: &str,
) -> DVec3 {
    let f = face.feature_point(fp(point)).unwrap();
    eval.evaluate(&[Activation { key, value }], out);
    animated(face, out, f.mesh, f.vertex) - f.position.as_dvec3()
}

#[test]
fn generation_is_deterministic() {
    assert_eq!(synth::alma(), faces()[0]);
    assert_eq!(synth::bruno(), faces()[1]);
}

#[test]
fn vertex_counts_are_in_range() {
    let [alma, bruno] = faces();
    let a = alma.skin_vertex_count();
    let b = bruno.skin_vertex_count();
    assert!((6000..=9000).contains(&a), "alma skin {a}");
    assert!(b >= 25_000, "bruno skin {b}");
    // Different topology: triangles vs quads.
    assert!(alma.meshes[0].polygons.iter().all(|p| p.len() == 3));
    assert!(bruno.meshes[0].polygons.iter().any(|p| p.len() == 4));
}

#[test]
fn every_required_feature_point_is_a_vertex_of_its_mesh() {
    for face in faces() {
        let mut required: Vec<FeaturePointId> = FeaturePointId::all()
            .filter(|id| matches!(id.group(), 2..=10))
            .collect();
        required.extend(["11.1", "11.2", "11.3", "11.4", "11.6"].map(fp));
        for id in required {
            let f = face
                .feature_point(id)
                .unwrap_or_else(|| panic!("{}: no FP {id}", face.name));
            assert_eq!(
                face.meshes[f.mesh].positions[f.vertex as usize], f.position,
                "{id}"
            );
        }
        let mesh_of = |s: &str| {
            face.meshes[face.feature_point(fp(s)).unwrap().mesh]
                .name
                .as_str()
        };
        assert_eq!(mesh_of("3.5"), names::EYE_L);
        assert_eq!(mesh_of("3.6"), names::EYE_R);
        assert_eq!(mesh_of("9.8"), names::TEETH_UPPER);
        assert_eq!(mesh_of("9.10"), names::TEETH_UPPER);
        assert_eq!(mesh_of("9.9"), names::TEETH_LOWER);
        assert_eq!(mesh_of("9.11"), names::TEETH_LOWER);
        for t in ["6.1", "6.2", "6.3", "6.4"] {
            assert_eq!(mesh_of(t), names::TONGUE);
        }
        // No two feature points share a vertex.
        let mut seen = HashMap::new();
        for f in &face.feature_points {
            if let Some(other) = seen.insert((f.mesh, f.vertex), f.id) {
                panic!("{}: {} and {} share a vertex", face.name, other, f.id);
            }
        }
        // Sides: +x is the face's own left.
        for f in &face.feature_points {
            let x = f.position.x;
            match f.id.info().side {
                fbakit::spec::Side::Left => assert!(x > 0.0, "{} {}", face.name, f.id),
                fbakit::spec::Side::Right => assert!(x < 0.0, "{} {}", face.name, f.id),
                fbakit::spec::Side::Middle => assert!(x.abs() < 1e-4, "{} {}", face.name, f.id),
            }
        }
    }
}

#[test]
fn inner_lips_and_teeth_touch_on_the_neutral_face() {
    for face in faces() {
        for (a, b) in [
            ("2.2", "2.3"),
            ("2.6", "2.8"),
            ("2.7", "2.9"),
            ("9.10", "9.11"),
        ] {
            let (fa, fb) = (
                face.feature_point(fp(a)).unwrap(),
                face.feature_point(fp(b)).unwrap(),
            );
            assert_eq!(fa.position, fb.position, "{a}/{b}");
            assert!(fa.vertex != fb.vertex || fa.mesh != fb.mesh);
        }
        // Lids tangent to the iris: the iris ring passes through 3.1 / 3.3.
        let centre = face.transforms[face
            .transform_names()
            .iter()
            .position(|n| *n == names::EYE_L_TF)
            .unwrap()]
        .center;
        let r_lid = (face.feature_point(fp("3.1")).unwrap().position - centre).length();
        let r_ball = (face.feature_point(fp("3.5")).unwrap().position - centre).length();
        assert!(
            (r_lid - r_ball).abs() < 1e-3 * r_ball,
            "{r_lid} vs {r_ball}"
        );
    }
}

#[test]
fn fapu_is_positive_and_plausible() {
    for face in faces() {
        let d = face.fapu().distances;
        assert!(d.irisd0 > 0.0 && d.es0 > 0.0 && d.ens0 > 0.0 && d.mns0 > 0.0 && d.mw0 > 0.0);
        let ratios = [
            d.es0 / d.irisd0,
            d.es0 / d.mw0,
            d.ens0 / d.mns0,
            d.es0 / d.ens0,
        ];
        assert!(
            (4.0..8.0).contains(&ratios[0]),
            "{} ES/IRISD {ratios:?}",
            face.name
        );
        assert!(
            (1.0..1.6).contains(&ratios[1]),
            "{} ES/MW {ratios:?}",
            face.name
        );
        assert!(
            (1.2..3.0).contains(&ratios[2]),
            "{} ENS/MNS {ratios:?}",
            face.name
        );
        assert!(
            (1.1..2.0).contains(&ratios[3]),
            "{} ES/ENS {ratios:?}",
            face.name
        );
        let p = |s: &str| face.feature_point(fp(s)).unwrap().position.as_dvec3();
        assert_eq!(d.irisd0, p("3.1").y - p("3.3").y);
        assert_eq!(d.mw0, p("8.3").x - p("8.4").x);
    }
    let (a, b) = (faces()[0].fapu().distances, faces()[1].fapu().distances);
    assert!(
        b.es0 > a.es0 && b.mw0 > a.mw0,
        "bruno has wider eyes and mouth"
    );
}

#[test]
fn fat_is_complete_and_valid() {
    for face in faces() {
        let problems = validate_fat(&face.fat, &face.mesh_sizes(), &face.transform_names());
        assert!(problems.is_empty(), "{}: {problems:#?}", face.name);
        let keys = face.fat.keys();
        for f in FapId::low_level() {
            assert!(
                keys.contains(&TableKey::LowLevel(f)),
                "{}: no table for {}",
                face.name,
                f.name()
            );
        }
        for v in Viseme::shapes() {
            assert!(keys.contains(&TableKey::Viseme(v)));
        }
        for e in Expression::basic() {
            assert!(keys.contains(&TableKey::Expression(e)));
        }
        assert_eq!(keys.len(), TableKey::SLOTS);
        for t in &face.fat.tables {
            assert!(
                !t.meshes.is_empty() || !t.transforms.is_empty(),
                "{} empty",
                t.key
            );
            for m in &t.meshes {
                assert!(m.displacements.iter().all(|d| d.is_finite()));
                assert!(!m.coord_index.is_empty());
            }
        }
    }
}

#[test]
fn every_translation_fap_moves_its_feature_point_exactly() {
    for face in faces() {
        let fapu = face.fapu();
        let (mut eval, mut out) = evaluator(face);
        let mut checked = 0;
        for f in FapId::low_level() {
            let info = f.info();
            let Some(dir) = info.direction() else {
                continue;
            };
            let unit = fapu.unit(info.fapu.unwrap());
            let point = info.feature_points[0].to_string();
            let values: &[f64] = if info.accepts(-1.0) {
                &[300.0, -200.0, 1500.0]
            } else {
                &[300.0, 700.0, 1500.0]
            };
            for &p in values {
                let got =
                    fp_displacement(face, &mut eval, &mut out, TableKey::LowLevel(f), p, &point);
                let want = dir.as_dvec3() * p * unit;
                if f == FapId::OPEN_JAW {
                    // The chin drops exactly; it also swings back along the jaw arc.
                    assert!(
                        (got.y - want.y).abs() <= 1e-5 * want.length(),
                        "{}: {got} vs {want}",
                        face.name
                    );
                    assert!(got.z < 0.0 && got.x == 0.0);
                } else {
                    assert!(
                        (got - want).length() <= 1e-5 * want.length(),
                        "{} FAP {} {} at {p}: {got} vs {want}",
                        face.name,
                        f.number(),
                        f.name()
                    );
                }
            }
            checked += 1;
        }
        assert_eq!(checked, 66 - 7 - 2 - 1); // all but the 7 angle FAPs, pupils (2) and tongue_roll
    }
}

#[test]
fn eyelids_close_the_eye_and_lips_stay_in_contact() {
    for face in faces() {
        let (mut eval, mut out) = evaluator(face);
        let key = |n| TableKey::LowLevel(FapId::new(n).unwrap());
        let f31 = face.feature_point(fp("3.1")).unwrap();
        let f33 = face.feature_point(fp("3.3")).unwrap();
        eval.evaluate(
            &[
                Activation {
                    key: key(19),
                    value: 512.0,
                },
                Activation {
                    key: key(21),
                    value: 512.0,
                },
            ],
            &mut out,
        );
        let (a, b) = (
            animated(face, &out, 0, f31.vertex),
            animated(face, &out, 0, f33.vertex),
        );
        // Closed: the lid centres meet vertically (the standard's closure rule).
        assert!(
            (a.y - b.y).abs() < 1e-4 * face.fapu().distances.irisd0,
            "{a} {b}"
        );
        // Top lip 100, bottom lip -100: both inner lips move down together.
        eval.evaluate(
            &[
                Activation {
                    key: key(4),
                    value: 100.0,
                },
                Activation {
                    key: key(5),
                    value: -100.0,
                },
            ],
            &mut out,
        );
        for (u, l) in [("2.2", "2.3"), ("2.6", "2.8"), ("2.7", "2.9")] {
            let (fu, fl) = (
                face.feature_point(fp(u)).unwrap(),
                face.feature_point(fp(l)).unwrap(),
            );
            let d = animated(face, &out, 0, fu.vertex) - animated(face, &out, 0, fl.vertex);
            assert!(d.length() < 1e-4, "{d}");
        }
    }
}

#[test]
fn rotations_turn_eyes_and_head_about_their_centres() {
    for face in faces() {
        let (mut eval, mut out) = evaluator(face);
        let key = |n| TableKey::LowLevel(FapId::new(n).unwrap());
        let value = 20_000.0;
        let angle = value * AU_RADIANS;
        let left_centre = face.transforms[1].center.as_dvec3();
        let pupil = face.feature_point(fp("3.5")).unwrap().position.as_dvec3();
        let r = (pupil - left_centre).length();
        // yaw_l_eyeball: gaze turns to the face's left (+x).
        let d = fp_displacement(face, &mut eval, &mut out, key(23), value, "3.5");
        assert!((d.x - r * angle.sin()).abs() < 1e-4 * r, "{d}");
        // pitch_l_eyeball: gaze turns down.
        let d = fp_displacement(face, &mut eval, &mut out, key(25), value, "3.5");
        assert!((d.y + r * angle.sin()).abs() < 1e-4 * r, "{d}");
        // The right eye does not move with the left FAPs.
        let d = fp_displacement(face, &mut eval, &mut out, key(23), value, "3.6");
        assert_eq!(d, DVec3::ZERO);
        for t in &face.fat.table(key(24)).unwrap().transforms {
            assert_eq!(t.field, TransformField::Rotation);
            assert_eq!(t.transform, names::EYE_R_TF);
            assert_eq!(t.rotation_axis, Vec3::Y);
        }
        // Head: 7.1 is the pivot and does not move; the nose tip turns left for yaw.
        let d = fp_displacement(face, &mut eval, &mut out, key(48), value, "7.1");
        assert!(d.length() < 1e-9);
        let d = fp_displacement(face, &mut eval, &mut out, key(49), value, "9.3");
        assert!(d.x > 0.0);
        let d = fp_displacement(face, &mut eval, &mut out, key(48), value, "9.3");
        assert!(d.y < 0.0, "head pitch looks down");
        // Jaw transform carries the lower teeth down with open_jaw; upper teeth stay.
        let d = fp_displacement(
            face,
            &mut eval,
            &mut out,
            TableKey::LowLevel(FapId::OPEN_JAW),
            512.0,
            "9.11",
        );
        assert!(d.y < 0.0);
        let d = fp_displacement(
            face,
            &mut eval,
            &mut out,
            TableKey::LowLevel(FapId::OPEN_JAW),
            512.0,
            "9.10",
        );
        assert_eq!(d, DVec3::ZERO);
    }
}

#[test]
fn pupil_dilation_and_tongue_roll_follow_their_units() {
    for face in faces() {
        let (mut eval, mut out) = evaluator(face);
        let fapu = face.fapu();
        let key = |n| TableKey::LowLevel(FapId::new(n).unwrap());
        // Pupil diameter grows by P × IRISD: every ring vertex moves radially by half.
        let t = face.fat.table(key(29)).unwrap();
        eval.evaluate(
            &[Activation {
                key: key(29),
                value: 100.0,
            }],
            &mut out,
        );
        for &v in &t.meshes[0].coord_index {
            let d = out.displacements[1][v as usize].as_dvec3();
            assert!(
                (d.length() - 50.0 * fapu.unit(FapuKind::Irisd)).abs() < 1e-6,
                "{d}"
            );
            assert_eq!(d.z, 0.0);
        }
        // tongue_roll: both borders rise by |x| × angle.
        let value = 10_000.0;
        let c = face.feature_point(fp("6.1")).unwrap().position.as_dvec3();
        for b in ["6.3", "6.4"] {
            let p = face.feature_point(fp(b)).unwrap().position.as_dvec3();
            let d = fp_displacement(face, &mut eval, &mut out, key(47), value, b);
            assert!(
                (d.y - (p.x - c.x).abs() * value * AU_RADIANS).abs() < 1e-5,
                "{b}: {d}"
            );
        }
    }
}

#[test]
fn high_level_tables_equal_the_low_level_vectors_at_full_strength() {
    for face in faces() {
        let (mut eval, mut out) = evaluator(face);
        let mut low = eval.output();
        // Visemes are the nominal vectors fitted to the face's own lips (face::visemes).
        let model = face.to_face_model();
        let mut cases: Vec<(TableKey, Vec<(FapId, f64)>)> = Viseme::shapes()
            .map(|v| {
                (
                    TableKey::Viseme(v),
                    fbakit::face::visemes::fitted_viseme_faps(&model, v),
                )
            })
            .collect();
        cases.extend(
            Expression::basic().map(|e| (TableKey::Expression(e), synth::expression_faps(e))),
        );
        for (key, faps) in cases {
            assert!(!faps.is_empty());
            for (f, v) in &faps {
                assert!(f.info().accepts(*v), "{key}: {} {v}", f.name());
            }
            let acts: Vec<Activation> = faps
                .iter()
                .map(|&(f, value)| Activation {
                    key: TableKey::LowLevel(f),
                    value,
                })
                .collect();
            eval.evaluate(&acts, &mut low);
            eval.evaluate(&[Activation { key, value: 63.0 }], &mut out);
            let t = face.fat.table(key).unwrap();
            assert!(t
                .meshes
                .iter()
                .all(|m| m.interval_borders == vec![0.0, 63.0]));
            let mut max_disp = 0.0f32;
            for (a, b) in low.displacements.iter().zip(&out.displacements) {
                for (x, y) in a.iter().zip(b) {
                    assert!(
                        (*x - *y).length() <= 1e-5 * (1.0 + x.length()),
                        "{key}: {x} vs {y}"
                    );
                    max_disp = max_disp.max(x.length());
                }
            }
            assert!(max_disp > 0.1, "{key} moves something visibly");
            for (a, b) in low.transforms.iter().zip(&out.transforms) {
                // Compare by what they do to a vector (acos-based angles are noisy near 0 in f32).
                let v = Vec3::new(0.6, 0.8, 0.0);
                assert!((a.rotation * v - b.rotation * v).length() < 1e-5, "{key}");
                assert!((a.translation - b.translation).length() < 1e-5, "{key}");
            }
        }
    }
}

/// Edges as (from, to) in polygon order.
fn directed_edges(polys: &[Vec<u32>]) -> Vec<(u32, u32)> {
    polys
        .iter()
        .flat_map(|p| (0..p.len()).map(move |i| (p[i], p[(i + 1) % p.len()])))
        .collect()
}

fn signed_volume(positions: &[Vec3], polys: &[Vec<u32>]) -> f64 {
    let mut v = 0.0;
    for p in polys {
        let a = positions[p[0] as usize].as_dvec3();
        for w in p[1..].windows(2) {
            v += a.dot(
                positions[w[0] as usize]
                    .as_dvec3()
                    .cross(positions[w[1] as usize].as_dvec3()),
            );
        }
    }
    v / 6.0
}

#[test]
fn meshes_are_consistently_oriented_manifolds() {
    for face in faces() {
        for m in &face.meshes {
            let n = m.positions.len() as u32;
            let mut used = vec![false; n as usize];
            for p in &m.polygons {
                assert!(p.len() == 3 || p.len() == 4, "{}", m.name);
                for &i in p {
                    assert!(i < n, "{}: index {i} out of range", m.name);
                    used[i as usize] = true;
                }
                // Not degenerate: every fan triangle has a real area.
                let a = m.positions[p[0] as usize];
                for w in p[1..].windows(2) {
                    let area = (m.positions[w[0] as usize] - a)
                        .cross(m.positions[w[1] as usize] - a)
                        .length()
                        / 2.0;
                    assert!(
                        area > 1e-4,
                        "{} {}: degenerate polygon {p:?} (area {area})",
                        face.name,
                        m.name
                    );
                }
            }
            assert!(used.iter().all(|&u| u), "{}: unused vertices", m.name);
            // Consistent orientation: each directed edge at most once. Closed parts: every
            // edge has its reverse.
            let edges = directed_edges(&m.polygons);
            let set: std::collections::HashSet<(u32, u32)> = edges.iter().copied().collect();
            assert_eq!(
                set.len(),
                edges.len(),
                "{} {}: a directed edge repeats",
                face.name,
                m.name
            );
            let open = edges
                .iter()
                .filter(|(a, b)| !set.contains(&(*b, *a)))
                .count();
            if m.name == names::SKIN {
                // Borders: the two eye openings and both lips along the slit.
                assert!(
                    open > 0 && open < 500,
                    "{} skin border edges {open}",
                    face.name
                );
            } else {
                assert_eq!(open, 0, "{} {} is not closed", face.name, m.name);
            }
            let vol = signed_volume(&m.positions, &m.polygons);
            assert!(vol > 0.0, "{} {}: signed volume {vol}", face.name, m.name);
        }
        // Skin normals point away from the head centre almost everywhere.
        let m = &face.meshes[0];
        let outward = m
            .polygons
            .iter()
            .filter(|p| {
                let (a, b, c) = (
                    m.positions[p[0] as usize],
                    m.positions[p[1] as usize],
                    m.positions[p[2] as usize],
                );
                (b - a)
                    .cross(c - a)
                    .dot((a + b + c) / 3.0 - Vec3::new(0.0, 0.0, 0.0))
                    > 0.0
            })
            .count();
        assert!(
            outward as f64 > 0.97 * m.polygons.len() as f64,
            "{}: {outward}/{}",
            face.name,
            m.polygons.len()
        );
    }
}

/// FNV-1a over positions quantised to 1e-3 units (robust to last-bit libm differences) and
/// polygon indices.
fn geometry_hash(face: &SynthFace) -> String {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    let mut eat = |x: i64| {
        for b in x.to_le_bytes() {
            h ^= b as u64;
            h = h.wrapping_mul(0x0100_0000_01b3);
        }
    };
    for m in &face.meshes {
        for p in &m.positions {
            for c in p.to_array() {
                eat((c as f64 * 1000.0).round() as i64);
            }
        }
        for poly in &m.polygons {
            for &i in poly {
                eat(i as i64);
            }
        }
    }
    format!("{h:016x}")
}

#[test]
fn summary_snapshot() {
    let summary: Vec<serde_json::Value> = faces().iter().map(|face| {
        let d = face.fapu().distances;
        let r = |x: f64| (x * 1000.0).round() / 1000.0;
        serde_json::json!({
            "name": face.name,
            "meshes": face.meshes.iter().map(|m| format!("{}: {} vertices, {} polygons", m.name, m.positions.len(), m.polygons.len())).collect::<Vec<_>>(),
            "feature_points": face.feature_points.len(),
            "fat_tables": face.fat.tables.len(),
            "moved_vertex_entries": face.fat.tables.iter().map(|t| t.moved_vertex_count()).sum::<usize>(),
            "fapu": { "IRISD0": r(d.irisd0), "ES0": r(d.es0), "ENS0": r(d.ens0), "MNS0": r(d.mns0), "MW0": r(d.mw0) },
            "geometry_hash": geometry_hash(face),
        })
    }).collect();
    insta::assert_json_snapshot!(summary);
}

#[test]
fn presets_differ_in_proportions_and_topology() {
    let (a, b) = (HeadParams::alma(), HeadParams::bruno());
    assert!(b.head_half_width > a.head_half_width && b.nose_length > a.nose_length);
    assert!(b.mouth_half_width > a.mouth_half_width && b.eye_separation > a.eye_separation);
    assert_ne!(a.columns, b.columns);
    assert_ne!(a.polygons, b.polygons);
}

/// Visual check (not run by default): `SYNTH_PREVIEW_DIR=/tmp cargo test --test synth_faces
/// preview -- --ignored` writes flat-shaded orthographic PPM renders of both faces, neutral and
/// animated (open jaw + joy + gaze left), front and side.
#[test]
#[ignore]
fn preview() {
    let Ok(dir) = std::env::var("SYNTH_PREVIEW_DIR") else {
        return;
    };
    for face in faces() {
        let (mut eval, mut out) = evaluator(face);
        for (tag, acts) in [
            ("neutral", vec![]),
            (
                "animated",
                vec![
                    Activation {
                        key: TableKey::LowLevel(FapId::OPEN_JAW),
                        value: 500.0,
                    },
                    Activation {
                        key: TableKey::Expression(Expression::Joy),
                        value: 63.0,
                    },
                    Activation {
                        key: TableKey::LowLevel(FapId::new(23).unwrap()),
                        value: 25_000.0,
                    },
                    Activation {
                        key: TableKey::LowLevel(FapId::new(24).unwrap()),
                        value: 25_000.0,
                    },
                ],
            ),
        ] {
            eval.evaluate(&acts, &mut out);
            for view in ["front", "side"] {
                let (w, h) = (400usize, 500usize);
                let mut img = vec![[40u8, 40, 60]; w * h];
                let mut depth = vec![f64::NEG_INFINITY; w * h];
                let project = |p: DVec3| -> (f64, f64, f64) {
                    let (u, d) = if view == "front" {
                        (p.x, p.z)
                    } else {
                        (p.z, p.x)
                    };
                    (
                        w as f64 / 2.0 + u * 1.5,
                        h as f64 / 2.0 - p.y * 1.5 - 20.0,
                        d,
                    )
                };
                for (mi, m) in face.meshes.iter().enumerate() {
                    let pos: Vec<DVec3> = (0..m.positions.len() as u32)
                        .map(|v| animated(face, &out, mi, v))
                        .collect();
                    for poly in &m.polygons {
                        for k in 1..poly.len() - 1 {
                            let tri = [
                                pos[poly[0] as usize],
                                pos[poly[k] as usize],
                                pos[poly[k + 1] as usize],
                            ];
                            let n = (tri[1] - tri[0]).cross(tri[2] - tri[0]).normalize_or_zero();
                            let view_dir = if view == "front" { DVec3::Z } else { DVec3::X };
                            let shade = n.dot(view_dir.lerp(DVec3::Y, 0.3).normalize());
                            if n.dot(view_dir) <= 0.0 {
                                continue; // back face
                            }
                            let s = shade.clamp(0.1, 1.0);
                            let c = m.colour.map(|c| (c as f64 * s * 255.0) as u8);
                            let pr = tri.map(project);
                            let (x0, x1) = (
                                pr.iter().map(|p| p.0).fold(f64::MAX, f64::min).max(0.0) as usize,
                                pr.iter()
                                    .map(|p| p.0)
                                    .fold(f64::MIN, f64::max)
                                    .min(w as f64 - 1.0) as usize,
                            );
                            let (y0, y1) = (
                                pr.iter().map(|p| p.1).fold(f64::MAX, f64::min).max(0.0) as usize,
                                pr.iter()
                                    .map(|p| p.1)
                                    .fold(f64::MIN, f64::max)
                                    .min(h as f64 - 1.0) as usize,
                            );
                            let area = (pr[1].0 - pr[0].0) * (pr[2].1 - pr[0].1)
                                - (pr[2].0 - pr[0].0) * (pr[1].1 - pr[0].1);
                            if area.abs() < 1e-12 {
                                continue;
                            }
                            for y in y0..=y1 {
                                for x in x0..=x1 {
                                    let (px, py) = (x as f64 + 0.5, y as f64 + 0.5);
                                    let e = |a: (f64, f64, f64), b: (f64, f64, f64)| {
                                        (b.0 - a.0) * (py - a.1) - (px - a.0) * (b.1 - a.1)
                                    };
                                    let (w0, w1, w2) = (
                                        e(pr[1], pr[2]) / area,
                                        e(pr[2], pr[0]) / area,
                                        e(pr[0], pr[1]) / area,
                                    );
                                    if w0 < 0.0 || w1 < 0.0 || w2 < 0.0 {
                                        continue;
                                    }
                                    let d = w0 * pr[0].2 + w1 * pr[1].2 + w2 * pr[2].2;
                                    if d > depth[y * w + x] {
                                        depth[y * w + x] = d;
                                        img[y * w + x] = c;
                                    }
                                }
                            }
                        }
                    }
                }
                let mut bytes = format!("P6\n{w} {h}\n255\n").into_bytes();
                bytes.extend(img.iter().flatten());
                let path = std::path::Path::new(&dir)
                    .join(format!("synth_{}_{tag}_{view}.ppm", face.name));
                fbakit::io::write_atomic(&path, &bytes).unwrap();
            }
        }
    }
}
