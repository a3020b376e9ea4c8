//! Unit tests of the generator internals (integration tests: `tests/synth_faces.rs`).

use super::*;
use crate::spec::Side;

fn label(s: &str) -> FeaturePointId {
    s.parse().unwrap()
}

#[test]
fn skin_is_exactly_symmetric_and_mirror_is_an_involution() {
    let p = HeadParams::alma();
    let s = skin::build(&p);
    for (v, &m) in s.mirror.iter().enumerate() {
        assert_eq!(s.mirror[m as usize] as usize, v);
        let (a, b) = (s.positions[v], s.positions[m as usize]);
        assert_eq!((a.x, a.y, a.z), (-b.x, b.y, b.z), "vertex {v}");
        assert_eq!(s.lower[v], s.lower[m as usize]);
    }
}

#[test]
fn slit_copies_are_lower_and_coincide_with_the_upper_lip() {
    let s = skin::build(&HeadParams::alma());
    let pairs = [("2.2", "2.3"), ("2.6", "2.8"), ("2.7", "2.9")];
    for (u, l) in pairs {
        let vu = s.feature_points.iter().find(|f| f.0 == label(u)).unwrap().1;
        let vl = s.feature_points.iter().find(|f| f.0 == label(l)).unwrap().1;
        assert_ne!(vu, vl);
        assert!(!s.lower[vu as usize] && s.lower[vl as usize]);
        assert_eq!(s.positions[vu as usize], s.positions[vl as usize]);
    }
    // Corners are shared (upper side) and lie on the slit height.
    let corner = s.fp(FeaturePointId::FP_2_4);
    assert!((corner.y - s.fp(FeaturePointId::FP_2_2).y).abs() < 1e-9);
}

#[test]
fn eyelid_feature_points_lie_on_the_unit_opening() {
    let s = skin::build(&HeadParams::bruno());
    for l in ["3.1", "3.3", "3.7", "3.11", "3.2", "3.4", "3.8", "3.12"] {
        let v = s.feature_points.iter().find(|f| f.0 == label(l)).unwrap().1;
        let e = s.eye_coords[v as usize];
        assert!((e.length() - 1.0).abs() < 1e-9, "{l}: {e}");
    }
    // Every remaining vertex is on or outside the opening.
    assert!(s.eye_coords.iter().all(|e| e.length() > 1.0 - 1e-9));
}

#[test]
fn feature_point_sides_follow_the_standard() {
    let f = alma();
    for fp in &f.feature_points {
        let x = fp.position.x;
        match fp.id.info().side {
            Side::Left => assert!(x > 0.0, "{} at x={x}", fp.id),
            Side::Right => assert!(x < 0.0, "{} at x={x}", fp.id),
            Side::Middle => assert!(x.abs() < 1e-4, "{} at x={x}", fp.id),
        }
    }
}

#[test]
fn upper_and_lower_lip_tables_stay_on_their_side_of_the_slit() {
    let p = HeadParams::alma();
    let s = skin::build(&p);
    let f = generate(&p);
    assert_eq!(f.meshes[0].positions.len(), s.positions.len());
    for (fap, lower_expected) in [
        (4u8, false),
        (8, false),
        (51, false),
        (5, true),
        (10, true),
        (52, true),
        (18, true),
    ] {
        let t = f
            .fat
            .table(crate::fat::TableKey::LowLevel(FapId::new(fap).unwrap()))
            .unwrap();
        for &v in &t.meshes[0].coord_index {
            assert_eq!(
                s.lower[v as usize], lower_expected,
                "FAP {fap} moves vertex {v}"
            );
        }
    }
}

#[test]
fn open_jaw_does_not_move_the_upper_face() {
    let p = HeadParams::alma();
    let s = skin::build(&p);
    let f = generate(&p);
    let t = f
        .fat
        .table(crate::fat::TableKey::LowLevel(FapId::OPEN_JAW))
        .unwrap();
    assert_eq!(t.meshes[0].interval_borders, vec![0.0, 512.0, 1024.0]);
    for &v in &t.meshes[0].coord_index {
        assert!(s.lower[v as usize]);
    }
}

use crate::spec::FapId;

#[test]
fn teeth_sit_behind_the_lips() {
    let f = alma();
    let slit = f.feature_point(label("2.2")).unwrap().position;
    let teeth = f.feature_point(label("9.10")).unwrap().position;
    assert!(teeth.z < slit.z && teeth.z > slit.z - 12.0);
}
