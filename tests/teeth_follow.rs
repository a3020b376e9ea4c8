//! Lower teeth follow the jaw whatever the source: cloning a one-mesh head (ICT: teeth and
//! gums inside its skin mesh, no jaw transform) or a face without teeth (CANDIDE-3) onto a
//! face whose lower teeth are their own meshes (alma, bruno) moves them like the chin under
//! open_jaw, thrust_jaw and shift_jaw; the upper teeth stay, the eyeballs never move with
//! the jaw.

use std::sync::OnceLock;

use fbakit::clone::face::{clone_face, split_embedded_parts, CloneOptions, CloneOutcome, Part};
use fbakit::export::picture::strip_fat;
use fbakit::face::FaceModel;
use fbakit::fat::eval::Activation;
use fbakit::fat::TableKey;
use fbakit::spec::{FapId, FeaturePointId};
use glam::Vec3;

#[path = "support/candide.rs"]
mod candide;

fn face(name: &str) -> FaceModel {
    fbakit::face::read(name).unwrap()
}

/// World displacement of every vertex of every mesh at `fap` = `value`.
fn motion(face: &FaceModel, fap: u8, value: f64) -> Vec<Vec<Vec3>> {
    let neutral = face.pose(&[]).unwrap();
    let posed = face
        .pose(&[Activation {
            key: TableKey::LowLevel(FapId::new(fap).unwrap()),
            value,
        }])
        .unwrap();
    neutral
        .iter()
        .zip(&posed)
        .map(|(a, b)| a.iter().zip(b).map(|(p, q)| *q - *p).collect())
        .collect()
}

/// What a clone does to the target's parts under one FAP: the chin's (2.1) displacement and
/// the mean displacement of each part's vertices.
struct Follow {
    chin: Vec3,
    lower: Vec3,
    lower_len: f32,
    upper_len: f32,
    eyes_len: f32,
    tongue_len: f32,
}

fn mean_of(d: &[Vec<Vec3>], meshes: &[usize]) -> (Vec3, f32) {
    let mut sum = Vec3::ZERO;
    let mut len = 0.0;
    let mut n = 0;
    for &m in meshes {
        for v in &d[m] {
            sum += *v;
            len += v.length();
            n += 1;
        }
    }
    assert!(n > 0);
    (sum / n as f32, len / n as f32)
}

fn follow(out: &CloneOutcome, fap: u8, value: f64) -> Follow {
    let face = &out.face;
    let parts = &out.report.target_parts;
    let d = motion(face, fap, value);
    let neutral = face.neutral_world_positions();
    let chin_at = face
        .feature_points
        .position(FeaturePointId::FP_2_1)
        .unwrap();
    // The skin vertex at the chin point.
    let (m, v) = parts
        .skin
        .iter()
        .flat_map(|&m| (0..neutral[m].len()).map(move |v| (m, v)))
        .min_by(|a, b| {
            neutral[a.0][a.1]
                .distance(chin_at)
                .total_cmp(&neutral[b.0][b.1].distance(chin_at))
        })
        .unwrap();
    let of = |p: Part| parts.parts.get(&p).cloned().unwrap_or_default();
    let (lower, lower_len) = mean_of(&d, &of(Part::LowerTeeth));
    let (_, upper_len) = mean_of(&d, &of(Part::UpperTeeth));
    let mut eyes = of(Part::LeftEye);
    eyes.extend(of(Part::RightEye));
    let (_, eyes_len) = mean_of(&d, &eyes);
    let (_, tongue_len) = mean_of(&d, &of(Part::Tongue));
    Follow {
        chin: d[m][v],
        lower,
        lower_len,
        upper_len,
        eyes_len,
        tongue_len,
    }
}

/// ICT's own lower teeth (as the clone cuts them out of its one mesh) under open_jaw at
/// 1024, per unit of its chin's (2.1) displacement.
fn ict_own_ratio() -> f32 {
    let ict = ict();
    let (_, parts) = split_embedded_parts(&strip_fat(ict));
    let lower: Vec<usize> = parts
        .iter()
        .filter(|s| s.part == Part::LowerTeeth)
        .flat_map(|s| s.source_vertices.iter().map(|&v| v as usize))
        .collect();
    assert!(lower.len() > 100, "{}", lower.len());
    let d = motion(ict, 3, 1024.0);
    let p = &ict.meshes[0].mesh.positions;
    let at = ict.feature_points.position(FeaturePointId::FP_2_1).unwrap();
    let chin = (0..p.len())
        .min_by(|&a, &b| p[a].distance(at).total_cmp(&p[b].distance(at)))
        .unwrap();
    let teeth = lower.iter().map(|&v| d[0][v].length()).sum::<f32>() / lower.len() as f32;
    let ratio = teeth / d[0][chin].length();
    eprintln!("ict's own open_jaw: lower teeth / chin {ratio:.3}");
    ratio
}

/// `out`'s lower teeth under open_jaw at 1024 move between `lo` and `hi` times its chin.
fn check(name: &str, out: &CloneOutcome, lo: f32, hi: f32) {
    let open = follow(out, 3, 1024.0);
    let chin = open.chin.length();
    let ratio = open.lower_len / chin;
    eprintln!(
        "{name} open_jaw: chin {chin:.6}, lower teeth {:.6} ({ratio:.2}x), upper {:.6}, eyes {:.6}",
        open.lower_len, open.upper_len, open.eyes_len
    );
    let thrust = follow(out, 14, 1024.0);
    eprintln!(
        "{name} thrust_jaw: chin {:?}, lower teeth {:?}",
        thrust.chin, thrust.lower
    );
    let shift = follow(out, 15, 1024.0);
    eprintln!(
        "{name} shift_jaw: chin {:?}, lower teeth {:?}",
        shift.chin, shift.lower
    );
    assert!(chin > 0.0, "{name}: the chin moves");
    assert!(
        (lo..=hi).contains(&ratio),
        "{name}: lower teeth {} vs chin {chin}",
        open.lower_len
    );
    assert!(
        open.upper_len < 0.05 * chin,
        "{name}: upper teeth {} vs chin {chin}",
        open.upper_len
    );
    assert_eq!(open.eyes_len, 0.0, "{name}: eyeballs under open_jaw");
    // The tongue rests on the floor of the mouth: the jaw carries it.
    assert!(
        open.tongue_len > 0.5 * chin,
        "{name}: tongue {} vs chin {chin}",
        open.tongue_len
    );
    // A lip FAP (raise_b_midlip) moves the lip, not the teeth or the tongue.
    let lip = follow(out, 5, 512.0);
    eprintln!(
        "{name} raise_b_midlip: lower teeth {:.6}, tongue {:.6}",
        lip.lower_len, lip.tongue_len
    );
    assert!(
        lip.lower_len == 0.0 && lip.tongue_len == 0.0,
        "{name}: a lip FAP"
    );
    // Forward is +z in the face frame; the teeth go the chin's way, by a like amount.
    assert!(
        thrust.chin.z > 0.0,
        "{name}: thrust_jaw moves the chin forward"
    );
    assert!(
        thrust.lower.z > 0.5 * thrust.chin.z,
        "{name}: thrust_jaw: lower teeth {:?} vs chin {:?}",
        thrust.lower,
        thrust.chin
    );
    assert!(
        shift.lower.x * shift.chin.x > 0.0 && shift.lower.x.abs() > 0.5 * shift.chin.x.abs(),
        "{name}: shift_jaw: lower teeth {:?} vs chin {:?}",
        shift.lower,
        shift.chin
    );
}

fn ict() -> &'static FaceModel {
    static F: OnceLock<FaceModel> = OnceLock::new();
    F.get_or_init(|| face("ict"))
}

/// ICT's teeth are inside its skin mesh, with no jaw transform: alma's and bruno's lower
/// teeth (meshes of their own under a transform) follow their cloned chin. ICT's own lower
/// teeth, molars near the hinge among them, move 0.73× its chin on average: the clone's
/// may not move much less.
#[test]
fn ict_onto_alma_and_bruno_moves_their_lower_teeth() {
    let own = ict_own_ratio();
    for name in ["alma", "bruno"] {
        let out = clone_face(ict(), &strip_fat(&face(name)), &CloneOptions::default()).unwrap();
        check(&format!("ict -> {name}"), &out, (0.8 * own).max(0.5), 2.0);
    }
}

/// CANDIDE-3 has no teeth: alma's lower teeth follow alma's cloned chin.
#[test]
fn candide_onto_alma_moves_alma_lower_teeth() {
    let Some(candide) = candide::candide(&[]) else {
        return;
    };
    let out = clone_face(
        &candide,
        &strip_fat(&face("alma")),
        &CloneOptions::default(),
    )
    .unwrap();
    check("candide -> alma", &out, 0.5, 2.0);
}

/// CANDIDE-3 onto ICT's one mesh: the teeth and gums cut out of it (no source inner piece
/// lends them a motion) follow ICT's cloned chin too, folded back into the one mesh.
#[test]
fn candide_onto_ict_moves_its_lower_teeth() {
    let Some(candide) = candide::candide(&[]) else {
        return;
    };
    let out = clone_face(&candide, &strip_fat(ict()), &CloneOptions::default()).unwrap();
    let rows = |part: Part| -> Vec<usize> {
        out.report
            .split_parts
            .iter()
            .filter(|s| s.part == part)
            .flat_map(|s| s.source_vertices.iter().map(|&v| v as usize))
            .collect()
    };
    let (lower, upper) = (rows(Part::LowerTeeth), rows(Part::UpperTeeth));
    assert!(lower.len() > 100 && upper.len() > 100);
    let d = motion(&out.face, 3, 1024.0);
    let p = &out.face.meshes[0].mesh.positions;
    let at = out
        .face
        .feature_points
        .position(FeaturePointId::FP_2_1)
        .unwrap();
    let chin_v = (0..p.len())
        .min_by(|&a, &b| p[a].distance(at).total_cmp(&p[b].distance(at)))
        .unwrap();
    let chin = d[0][chin_v].length();
    let mean = |vs: &[usize]| vs.iter().map(|&v| d[0][v].length()).sum::<f32>() / vs.len() as f32;
    // Vertices on the cut along the lip line are in both rows and move half.
    let only_upper: Vec<usize> = upper
        .iter()
        .copied()
        .filter(|v| !lower.contains(v))
        .collect();
    let (lo, up) = (mean(&lower), mean(&only_upper));
    eprintln!("candide -> ict open_jaw: chin {chin:.6}, lower teeth {lo:.6}, upper {up:.6}");
    assert!(chin > 0.0);
    assert!(
        (0.5..=2.0).contains(&(lo / chin)),
        "lower {lo} vs chin {chin}"
    );
    assert!(up < 0.05 * chin, "upper {up} vs chin {chin}");
}
