//! FAT semantics from the standard's interval rule, with hand-computed numbers.

use glam::{DVec3, Quat, Vec3};
use proptest::prelude::*;

use super::eval::{expression_activations, viseme_activations, Activation, FatEvaluator};
use super::morph::{fat_from_morph_targets, fat_to_morph_targets};
use super::validate::{validate_fat, FatEntry};
use super::*;

fn close(a: Vec3, b: Vec3) -> bool {
    (a - b).abs().max_element() < 1e-5
}

/// The fact sheet's worked example: borders -400 0 300 900, one vertex.
fn worked_example() -> FaceDefMesh {
    FaceDefMesh {
        mesh: "skin".into(),
        interval_borders: vec![-400.0, 0.0, 300.0, 900.0],
        coord_index: vec![0],
        displacements: vec![
            Vec3::new(0.0, 0.002, 0.0),
            Vec3::new(0.0, -0.001, 0.0),
            Vec3::new(0.0, -0.003, 0.001),
        ],
    }
}

#[test]
fn interval_rule_matches_the_worked_example() {
    let m = worked_example();
    assert!(close(m.displacement(0, 600.0), Vec3::new(0.0, -1.2, 0.3)));
    assert!(close(m.displacement(0, 100.0), Vec3::new(0.0, -0.1, 0.0)));
    assert!(close(m.displacement(0, -200.0), Vec3::new(0.0, -0.4, 0.0)));
    // Beyond the last border the outermost rate continues.
    assert!(close(m.displacement(0, 1000.0), Vec3::new(0.0, -2.4, 0.7)));
    assert_eq!(m.displacement(0, 0.0), Vec3::ZERO);
}

#[test]
fn interval_rule_own_numbers() {
    let m = worked_example();
    // Exactly at a border: the whole first positive interval.
    assert!(close(m.displacement(0, 300.0), Vec3::new(0.0, -0.3, 0.0)));
    // Below the lowest border: -400 x D0 then 100 more at D0's rate (extended).
    assert!(close(m.displacement(0, -500.0), Vec3::new(0.0, -1.0, 0.0)));
    // Weights: 900 covers 300 of [0,300] and 600 of [300,900].
    let mut w = Vec::new();
    m.interval_weights(900.0, &mut w);
    assert_eq!(w, vec![0.0, 300.0, 600.0]);
    m.interval_weights(-100.0, &mut w);
    assert_eq!(w, vec![-100.0, 0.0, 0.0]);
}

#[test]
fn zero_border_at_the_end_and_negative_values() {
    // Borders -200 -100 0: two negative intervals, nothing for positive values but the
    // last interval's rate extended upward.
    let m = FaceDefMesh {
        mesh: "skin".into(),
        interval_borders: vec![-200.0, -100.0, 0.0],
        coord_index: vec![0],
        displacements: vec![Vec3::new(1.0, 0.0, 0.0), Vec3::new(0.0, 1.0, 0.0)],
    };
    // -150: 100 units in [-100, 0] (rate D1), 50 in [-200, -100] (rate D0), both negative.
    assert!(close(
        m.displacement(0, -150.0),
        Vec3::new(-50.0, -100.0, 0.0)
    ));
    // +10 extends the interval that holds 0 from above: 10 x D1.
    assert!(close(m.displacement(0, 10.0), Vec3::new(0.0, 10.0, 0.0)));
}

fn two_vertex_fat() -> Fat {
    Fat {
        tables: vec![
            FaceDefTable {
                key: TableKey::LowLevel(crate::spec::FapId::OPEN_JAW),
                meshes: vec![FaceDefMesh {
                    mesh: "skin".into(),
                    interval_borders: vec![0.0, 1000.0],
                    coord_index: vec![2, 0],
                    displacements: vec![Vec3::new(0.0, -0.001, 0.0), Vec3::new(0.0, -0.0005, 0.0)],
                }],
                transforms: vec![FaceDefTransform::translation(
                    "jaw",
                    Vec3::new(0.0, -0.002, 0.0),
                )],
            },
            FaceDefTable {
                key: TableKey::LowLevel(crate::spec::FapId::new(23).unwrap()),
                meshes: vec![],
                transforms: vec![FaceDefTransform::rotation("eye_l", Vec3::Y, 1e-5)],
            },
            FaceDefTable {
                key: TableKey::Viseme(crate::spec::Viseme::new(1).unwrap()),
                meshes: vec![FaceDefMesh {
                    mesh: "skin".into(),
                    interval_borders: vec![0.0, 63.0],
                    coord_index: vec![1],
                    displacements: vec![Vec3::new(0.63, 0.0, 0.0) / 63.0],
                }],
                transforms: vec![],
            },
            FaceDefTable {
                key: TableKey::Viseme(crate::spec::Viseme::new(10).unwrap()),
                meshes: vec![FaceDefMesh {
                    mesh: "skin".into(),
                    interval_borders: vec![0.0, 63.0],
                    coord_index: vec![1],
                    displacements: vec![Vec3::new(0.0, 0.63, 0.0) / 63.0],
                }],
                transforms: vec![],
            },
            FaceDefTable {
                key: TableKey::Expression(crate::spec::Expression::Joy),
                meshes: vec![FaceDefMesh {
                    mesh: "skin".into(),
                    interval_borders: vec![0.0, 63.0],
                    coord_index: vec![0],
                    displacements: vec![Vec3::new(0.0, 0.0, 1.0) / 63.0],
                }],
                transforms: vec![],
            },
        ],
    }
}

#[test]
fn evaluator_sums_tables_and_drives_transforms() {
    let fat = two_vertex_fat();
    let mut ev = FatEvaluator::new(&fat, &[("skin", 3)], &["jaw", "eye_l"]).unwrap();
    let mut out = ev.output();
    let v = |n: u8| crate::spec::Viseme::new(n).unwrap();
    let mut acts = vec![
        Activation {
            key: TableKey::LowLevel(crate::spec::FapId::OPEN_JAW),
            value: 500.0,
        },
        Activation {
            key: TableKey::LowLevel(crate::spec::FapId::new(23).unwrap()),
            value: 10_000.0,
        },
    ];
    // Viseme blend 21: a third of viseme 1, two thirds of viseme 10.
    acts.extend(viseme_activations(v(1), v(10), 21.0));
    acts.extend(expression_activations(
        crate::spec::Expression::Joy,
        63.0,
        crate::spec::Expression::Neutral,
        0.0,
    ));
    ev.evaluate(&acts, &mut out);
    let d = &out.displacements[0];
    assert!(close(d[2], Vec3::new(0.0, -0.5, 0.0)));
    // Vertex 0: open_jaw 500 x -0.0005 in y, plus joy at full intensity 1.0 in z.
    assert!(close(d[0], Vec3::new(0.0, -0.25, 1.0)));
    // Vertex 1: 21/63 x 0.63 in x, 42/63 x 0.63 in y.
    assert!(close(d[1], Vec3::new(0.21, 0.42, 0.0)));
    assert!(close(
        out.transforms[0].translation,
        Vec3::new(0.0, -1.0, 0.0)
    ));
    let expected = Quat::from_axis_angle(Vec3::Y, 0.1);
    assert!(out.transforms[1].rotation.angle_between(expected) < 1e-5);
    // A second evaluation starts from neutral again.
    ev.evaluate(&[], &mut out);
    assert!(out.displacements[0].iter().all(|&p| p == Vec3::ZERO));
    assert_eq!(out.transforms[1].rotation, Quat::IDENTITY);
}

#[test]
fn evaluator_rejects_unknown_names_and_bad_indices() {
    let fat = two_vertex_fat();
    let e = FatEvaluator::new(&fat, &[("skin", 2)], &["jaw", "eye_l"]).unwrap_err();
    assert!(
        e.to_string().contains("coordIndex 2 is out of range"),
        "{e}"
    );
    let e = FatEvaluator::new(&fat, &[("face", 3)], &["jaw", "eye_l"]).unwrap_err();
    assert!(e.to_string().contains("unknown mesh `skin`"), "{e}");
    let e = FatEvaluator::new(&fat, &[("skin", 3)], &["jaw"]).unwrap_err();
    assert!(e.to_string().contains("unknown transform `eye_l`"), "{e}");
}

#[test]
fn single_interval_fat_to_morph_targets_and_back_is_lossless() {
    let mut fat = two_vertex_fat();
    // A negative-only table too.
    fat.tables.push(FaceDefTable {
        key: TableKey::LowLevel(crate::spec::FapId::new(4).unwrap()),
        meshes: vec![FaceDefMesh {
            mesh: "skin".into(),
            interval_borders: vec![-300.0, 0.0],
            coord_index: vec![1, 2],
            displacements: vec![Vec3::new(0.1, 0.2, 0.3), Vec3::new(-0.7, 0.0, 1e-7)],
        }],
        transforms: vec![],
    });
    let mts = fat_to_morph_targets(&fat);
    assert_eq!(mts.len(), fat.tables.len());
    let jaw = &mts[0];
    assert_eq!(jaw.value, 1000.0);
    assert_eq!(
        jaw.meshes[0].offsets[0],
        DVec3::new(0.0, -0.001f32 as f64 * 1000.0, 0.0)
    );
    let back = fat_from_morph_targets(&mts).unwrap();
    assert_eq!(back, fat);
}

#[test]
fn multi_interval_fat_round_trips_through_morph_targets() {
    let fat = Fat {
        tables: vec![FaceDefTable {
            key: TableKey::LowLevel(crate::spec::FapId::new(5).unwrap()),
            meshes: vec![worked_example()],
            transforms: vec![],
        }],
    };
    let mts = fat_to_morph_targets(&fat);
    let values: Vec<f64> = mts.iter().map(|m| m.value).collect();
    assert_eq!(values, vec![-400.0, 300.0, 900.0]);
    // The morph target at 900 shows the integral up to 900.
    let o = mts[2].meshes[0].offsets[0];
    assert!(
        (o - DVec3::new(0.0, -2.1, 0.6)).abs().max_element() < 1e-6,
        "{o}"
    );
    let back = fat_from_morph_targets(&mts).unwrap();
    let m = &back.tables[0].meshes[0];
    assert_eq!(m.interval_borders, vec![-400.0, 0.0, 300.0, 900.0]);
    for (a, b) in m.displacements.iter().zip(&worked_example().displacements) {
        assert!(close(*a, *b));
    }
}

#[test]
fn morph_targets_keep_first_appearance_order_whatever_the_vertex_numbers() {
    // Two targets of one key moving overlapping vertex lists in no sorted order: the entry
    // lists vertices as they first appear, a vertex moved twice in one target keeps its last
    // offset, and a vertex missing from a target is still there. Far-apart vertex numbers
    // (a map instead of a table per vertex) give the same entry.
    use super::morph::{MorphMesh, MorphTarget};
    let key = TableKey::LowLevel(crate::spec::FapId::new(3).unwrap());
    let targets = |base: u32| {
        let mesh = |vertices: Vec<u32>, offsets: Vec<DVec3>| MorphMesh {
            mesh: "skin".into(),
            vertices: vertices.into_iter().map(|v| base + v).collect(),
            offsets,
        };
        vec![
            MorphTarget {
                key,
                value: 200.0,
                meshes: vec![mesh(
                    vec![5, 2, 5, 9],
                    vec![DVec3::X, DVec3::Y, DVec3::Z, DVec3::ONE],
                )],
                transforms: vec![],
            },
            MorphTarget {
                key,
                value: -100.0,
                meshes: vec![mesh(vec![7, 2], vec![DVec3::NEG_X, DVec3::NEG_Y])],
                transforms: vec![],
            },
        ]
    };
    let dense = fat_from_morph_targets(&targets(0)).unwrap();
    let m = &dense.tables[0].meshes[0];
    assert_eq!(m.interval_borders, vec![-100.0, 0.0, 200.0]);
    // The negative target comes first (borders ascending).
    assert_eq!(m.coord_index, vec![7, 2, 5, 9]);
    let rates = |a: DVec3, b: DVec3| [(-a / 100.0).as_vec3(), (b / 200.0).as_vec3()];
    let want: Vec<Vec3> = [
        rates(DVec3::NEG_X, DVec3::ZERO),
        rates(DVec3::NEG_Y, DVec3::Y),
        rates(DVec3::ZERO, DVec3::Z),
        rates(DVec3::ZERO, DVec3::ONE),
    ]
    .concat();
    assert_eq!(m.displacements, want);
    let sparse = fat_from_morph_targets(&targets(3_000_000_000)).unwrap();
    let s = &sparse.tables[0].meshes[0];
    let shifted: Vec<u32> = m.coord_index.iter().map(|v| v + 3_000_000_000).collect();
    assert_eq!(s.coord_index, shifted);
    assert_eq!(s.displacements, m.displacements);
}

#[test]
fn morph_targets_with_bad_values_are_rejected() {
    let mut mts = fat_to_morph_targets(&two_vertex_fat());
    mts[0].value = 0.0;
    assert!(fat_from_morph_targets(&mts).is_err());
    let mut mts = fat_to_morph_targets(&two_vertex_fat());
    let dup = mts[0].clone();
    mts.push(dup);
    let e = fat_from_morph_targets(&mts).unwrap_err();
    assert!(e.to_string().contains("same value"), "{e}");
}

#[test]
fn validation_reports_every_problem() {
    let mut fat = two_vertex_fat();
    {
        let m = &mut fat.tables[0].meshes[0];
        m.interval_borders = vec![10.0, 5.0];
        m.coord_index.push(7);
    }
    fat.tables[1].transforms[0].transform = "nowhere".into();
    fat.tables[1].transforms[0].rotation_axis = Vec3::ZERO;
    let problems = validate_fat(&fat, &[("skin", 3)], &["jaw", "eye_l"]);
    let msgs: Vec<String> = problems.iter().map(|p| p.message.clone()).collect();
    let joined = msgs.join("\n");
    assert!(joined.contains("must increase strictly"), "{joined}");
    assert!(joined.contains("must contain 0 exactly once"), "{joined}");
    assert!(joined.contains("2 displacements, expected 3"), "{joined}");
    assert!(
        joined.contains("out of range for `skin` with 3 vertices (first: 7)"),
        "{joined}"
    );
    assert!(joined.contains("`nowhere` is not a Transform"), "{joined}");
    assert!(joined.contains("zero axis"), "{joined}");
    assert_eq!(problems[0].entry, FatEntry::Mesh(0));
    assert!(validate_fat(&two_vertex_fat(), &[("skin", 3)], &["jaw", "eye_l"]).is_empty());
}

#[test]
fn table_keys_from_node_fields_and_names() {
    assert_eq!(
        TableKey::from_node_fields(3, 1).unwrap(),
        TableKey::LowLevel(crate::spec::FapId::OPEN_JAW)
    );
    assert_eq!(
        TableKey::from_node_fields(1, 7).unwrap(),
        TableKey::Viseme(crate::spec::Viseme::new(7).unwrap())
    );
    assert!(TableKey::from_node_fields(1, 0).is_err());
    assert!(TableKey::from_node_fields(1, 15).is_err());
    assert!(TableKey::from_node_fields(2, 7).is_err());
    assert!(TableKey::from_node_fields(69, 1).is_err());
    assert!(TableKey::from_node_fields(-1, 1).is_err());
    let mut slots = std::collections::HashSet::new();
    for key in crate::spec::FapId::low_level()
        .map(TableKey::LowLevel)
        .chain(crate::spec::Viseme::shapes().map(TableKey::Viseme))
        .chain(crate::spec::Expression::basic().map(TableKey::Expression))
    {
        assert!(slots.insert(key.slot().unwrap()));
        assert_eq!(TableKey::from_name(&key.name()), Some(key), "{key}");
        let (fap, sel) = key.node_fields();
        assert_eq!(
            TableKey::from_node_fields(fap as i64, sel as i64).unwrap(),
            key
        );
    }
    assert_eq!(slots.len(), TableKey::SLOTS);
    assert_eq!(slots.iter().max(), Some(&(TableKey::SLOTS - 1)));
    assert_eq!(TableKey::from_name("neutral"), None);
    assert_eq!(TableKey::from_name("viseme"), None);
}

proptest! {
    /// Evaluating a table equals integrating its rate function numerically.
    #[test]
    fn interval_rule_equals_integral(
        mut borders in proptest::collection::vec(-2000i32..2000, 1..6),
        rates in proptest::collection::vec(-1.0f32..1.0, 6),
        p in -3000i32..3000,
    ) {
        borders.push(0);
        borders.sort();
        borders.dedup();
        prop_assume!(borders.len() >= 2);
        let n = borders.len() - 1;
        let m = FaceDefMesh {
            mesh: "m".into(),
            interval_borders: borders.iter().map(|&b| b as f64).collect(),
            coord_index: vec![0],
            displacements: rates[..n].iter().map(|&r| Vec3::new(r, 0.0, 0.0)).collect(),
        };
        // Step integral of the piecewise-constant rate from 0 to p, one unit at a time.
        let rate_at = |x: f64| {
            let j = borders.iter().rposition(|&b| (b as f64) <= x).unwrap_or(0).min(n - 1);
            rates[j] as f64
        };
        let mut expected = 0.0;
        if p >= 0 {
            for x in 0..p { expected += rate_at(x as f64 + 0.5); }
        } else {
            for x in p..0 { expected -= rate_at(x as f64 + 0.5); }
        }
        let got = m.displacement(0, p as f64).x as f64;
        prop_assert!((got - expected).abs() < 1e-3 * (1.0 + expected.abs()), "got {got} expected {expected}");
    }
}
