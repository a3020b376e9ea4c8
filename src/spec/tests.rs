//! Every compiled table row is pinned against the CSV it came from.

use super::*;

const FAP_CSV: &str = include_str!("../../specs/fap-table.csv");
const FP_CSV: &str = include_str!("../../specs/feature-points.csv");
const VISEME_CSV: &str = include_str!("../../specs/visemes.csv");
const EXPRESSION_CSV: &str = include_str!("../../specs/expressions.csv");

fn rows(text: &str) -> Vec<csv::StringRecord> {
    csv::Reader::from_reader(text.as_bytes())
        .records()
        .map(|r| r.expect("spec CSV is well-formed"))
        .collect()
}

#[test]
fn fap_table_matches_csv() {
    let rows = rows(FAP_CSV);
    assert_eq!(rows.len(), NUM_FAPS);
    for (row, id) in rows.iter().zip(FapId::all()) {
        let info = id.info();
        assert_eq!(row[0].parse::<u8>().unwrap(), info.number, "row {row:?}");
        assert_eq!(&row[1], info.name);
        assert_eq!(&row[2], info.description);
        let fapu = match &row[3] {
            "-" => None,
            s => Some(s.parse::<FapuKind>().unwrap()),
        };
        assert_eq!(fapu, info.fapu, "FAPU of FAP {}", info.number);
        let dir = match &row[4] {
            "-" => None,
            "U" => Some(Directionality::Unidirectional),
            "B" => Some(Directionality::Bidirectional),
            other => panic!("unknown directionality {other}"),
        };
        assert_eq!(
            dir, info.directionality,
            "directionality of FAP {}",
            info.number
        );
        let motion = info
            .positive_motion
            .map(PositiveMotion::word)
            .unwrap_or("-");
        assert_eq!(&row[5], motion, "positive motion of FAP {}", info.number);
        assert_eq!(row[6].parse::<u8>().unwrap(), info.group);
        let fps: Vec<String> = row[7]
            .split(';')
            .filter(|s| !s.is_empty())
            .map(|sub| format!("{}.{}", &row[6], sub))
            .collect();
        let ours: Vec<String> = info.feature_points.iter().map(|p| p.to_string()).collect();
        assert_eq!(fps, ours, "feature points of FAP {}", info.number);
        assert_eq!(row[8].parse::<u16>().unwrap(), info.quant_step);
    }
}

#[test]
fn feature_point_table_matches_csv() {
    let rows = rows(FP_CSV);
    assert_eq!(rows.len(), NUM_FEATURE_POINTS);
    for (ordinal, row) in rows.iter().enumerate() {
        let id: FeaturePointId = row[0].parse().unwrap();
        assert_eq!(id.ordinal(), ordinal, "label order of {id}");
        assert_eq!(row[1].parse::<u8>().unwrap(), id.group());
        assert_eq!(row[2].parse::<u8>().unwrap(), id.index());
        let info = id.info();
        assert_eq!(info.id, id);
        assert_eq!(&row[3], info.description);
        let side = match &row[4] {
            "L" => Side::Left,
            "R" => Side::Right,
            "M" => Side::Middle,
            other => panic!("unknown side {other}"),
        };
        assert_eq!(side, info.side, "side of {id}");
        assert_eq!(&row[5], info.region);
        assert_eq!(&row[6], info.fapu_use);
        let moved: Vec<u8> = row[7]
            .split(';')
            .filter(|s| !s.is_empty())
            .map(|s| s.parse().unwrap())
            .collect();
        assert_eq!(moved, info.moved_by, "moved_by of {id}");
        assert_eq!(&row[8], info.notes);
    }
}

#[test]
fn visemes_and_expressions_match_csv() {
    let v = rows(VISEME_CSV);
    assert_eq!(v.len(), Viseme::COUNT);
    for row in &v {
        let vis = Viseme::new(row[0].parse().unwrap()).unwrap();
        assert_eq!(&row[1], vis.label());
        let ph: Vec<&str> = row[2].split(';').collect();
        if vis.number() == 0 {
            assert!(vis.phonemes().is_empty());
        } else {
            assert_eq!(ph, vis.phonemes());
        }
    }
    let e = rows(EXPRESSION_CSV);
    assert_eq!(e.len(), Expression::ALL.len());
    for row in &e {
        let ex = Expression::new(row[0].parse().unwrap()).unwrap();
        assert_eq!(&row[1], ex.name());
    }
}

#[test]
fn fap_moves_and_point_moved_by_agree() {
    // The two tables state the FAP→FP relation from both ends; they must agree.
    for id in FapId::low_level() {
        for fp in id.info().feature_points {
            assert!(
                fp.info().moved_by.contains(&id.number()),
                "FAP {} moves {fp} but {fp} does not list it",
                id.number()
            );
        }
    }
    for fp in FeaturePointId::all() {
        for &n in fp.info().moved_by {
            let fap = FapId::new(n).unwrap();
            assert!(
                fap.info().feature_points.contains(&fp),
                "{fp} lists FAP {n}"
            );
        }
    }
}

#[test]
fn ids_parse_and_display() {
    assert_eq!("2.1".parse::<FeaturePointId>().unwrap().to_string(), "2.1");
    assert_eq!("11.6".parse::<FeaturePointId>().unwrap().ordinal(), 83);
    for bad in ["1.1", "2.15", "12.1", "2", "2.0", "x.y", "", "3.-1", "9.16"] {
        assert!(bad.parse::<FeaturePointId>().is_err(), "{bad} accepted");
    }
    for fp in FeaturePointId::all() {
        assert_eq!(fp.to_string().parse::<FeaturePointId>().unwrap(), fp);
        assert_eq!(FeaturePointId::from_ordinal(fp.ordinal()), Some(fp));
    }
    assert_eq!("open_jaw".parse::<FapId>().unwrap(), FapId::OPEN_JAW);
    assert_eq!("3".parse::<FapId>().unwrap(), FapId::OPEN_JAW);
    assert_eq!(
        FapId::from_bifs_field_name("stretch_l_corner")
            .unwrap()
            .number(),
        6
    );
    assert_eq!(
        FapId::from_bifs_field_name("stretch_l_cornerlip")
            .unwrap()
            .number(),
        53
    );
    assert_eq!(FapId::from_name("stretch_l_cornerlip").unwrap().number(), 6);
    assert!("0".parse::<FapId>().is_err());
    assert!("69".parse::<FapId>().is_err());
    assert!("300".parse::<FapId>().is_err());
    for id in FapId::all() {
        assert_eq!(FapId::from_name(id.name()), Some(id));
        if !id.is_high_level() {
            assert_eq!(FapId::from_bifs_field_name(bifs_field_name(id)), Some(id));
        }
        assert_eq!(FapId::from_index(id.index()), Some(id));
    }
}

#[test]
fn directions_are_unit_vectors_in_the_mpeg4_frame() {
    let open_jaw = FapId::OPEN_JAW.info();
    assert_eq!(open_jaw.direction(), Some(Vec3::NEG_Y));
    // Face's own left is +x.
    assert_eq!(FapId::new(6).unwrap().info().direction(), Some(Vec3::X));
    assert_eq!(FapId::new(7).unwrap().info().direction(), Some(Vec3::NEG_X));
    assert_eq!(FapId::new(14).unwrap().info().direction(), Some(Vec3::Z));
    for id in FapId::low_level() {
        let info = id.info();
        match (info.direction(), info.rotation_axis()) {
            (Some(d), None) => assert!((d.length() - 1.0).abs() < 1e-6),
            (None, Some(a)) => assert!((a.length() - 1.0).abs() < 1e-6),
            (None, None) => assert!(
                matches!(id.number(), 29 | 30 | 47),
                "FAP {} has neither direction nor axis",
                id.number()
            ),
            (Some(_), Some(_)) => panic!("FAP {} has both", id.number()),
        }
    }
    // Every AU FAP except tongue_roll is a rotation with an axis.
    for n in [23, 24, 25, 26, 48, 49, 50] {
        assert!(FapId::new(n).unwrap().info().rotation_axis().is_some());
    }
    assert!(!FapId::OPEN_JAW.info().accepts(-1.0));
    assert!(FapId::new(4).unwrap().info().accepts(-1.0));
    assert!(!FapId::new(4).unwrap().info().accepts(f64::NAN));
}

#[test]
fn rotation_axes_follow_the_direction_words() {
    // A positive yaw turns the gaze (+z) towards the face's left (+x): right-handed about +y.
    let yaw =
        glam::Quat::from_axis_angle(FapId::new(23).unwrap().info().rotation_axis().unwrap(), 0.1);
    assert!((yaw * Vec3::Z).x > 0.0);
    // A positive pitch turns the gaze down.
    let pitch =
        glam::Quat::from_axis_angle(FapId::new(25).unwrap().info().rotation_axis().unwrap(), 0.1);
    assert!((pitch * Vec3::Z).y < 0.0);
    // A positive roll tips the top of the head to the face's right (−x).
    let roll =
        glam::Quat::from_axis_angle(FapId::new(50).unwrap().info().rotation_axis().unwrap(), 0.1);
    assert!((roll * Vec3::Y).x < 0.0);
}

#[test]
fn group_sizes_and_label_order() {
    let mut counts = [0usize; 12];
    for fp in FeaturePointId::all() {
        counts[fp.group() as usize] += 1;
    }
    assert_eq!(&counts[2..], &[14, 14, 6, 4, 4, 1, 10, 15, 10, 6]);
    let all: Vec<_> = FeaturePointId::all().collect();
    let mut sorted = all.clone();
    sorted.sort();
    assert_eq!(all, sorted, "label order is (group, index) order");
}

#[test]
fn visemes_and_expressions_lookup() {
    assert_eq!(Viseme::from_label("PP"), Viseme::new(1));
    assert_eq!(Viseme::from_label("viseme_7"), Viseme::new(7));
    assert_eq!(Viseme::shapes().count(), 14);
    assert!(Viseme::new(15).is_none());
    assert_eq!(Expression::from_name("Joy"), Some(Expression::Joy));
    assert_eq!(Expression::basic().count(), 6);
    assert_eq!(Expression::new(7), None);
}

#[test]
fn named_feature_point_constants_match_the_table() {
    let labels: Vec<String> = super::feature_point_ids::NAMED
        .iter()
        .map(|id| id.to_string())
        .collect();
    let table: Vec<String> = FeaturePointId::all().map(|id| id.to_string()).collect();
    assert_eq!(labels, table);
    assert_eq!(FeaturePointId::FP_7_1.to_string(), "7.1");
    assert_eq!(FeaturePointId::FP_11_6.to_string(), "11.6");
}
