//! Viseme and expression tables of the synthetic faces, defined as low-level FAP vectors.
//!
//! Each viseme / expression is a vector of low-level FAP values (our own choices, below). Its
//! table is a single interval `[0, 63]` whose value at 63 equals the face's low-level FAT
//! evaluated at that vector (mesh displacements divided by 63; transform changes as rotation
//! and translation entries per 1/63).

use glam::Vec3;

use super::SynthFace;
use crate::fat::eval::{Activation, FatEvaluator};
use crate::fat::{FaceDefMesh, FaceDefTable, FaceDefTransform, TableKey, HIGH_LEVEL_FULL};
use crate::spec::{Expression, FapId, Viseme};

/// FAP vectors of visemes 1..=14 as (FAP number, value).
///
/// Lip FAPs: 4 lower_t_midlip, 5 raise_b_midlip, 6/7 stretch corners, 12/13 raise corners,
/// 16/17 push lips, 51/52 outer midlips, 53/54 outer stretch; 3 open_jaw; 43..46 tongue.
const VISEMES: [&[(u8, f64)]; 14] = [
    // 1 p, b, m: lips pressed together (top lip down, bottom lip up: they push into each other).
    &[(4, 60.0), (5, 60.0), (51, 40.0), (52, 40.0)],
    // 2 f, v: lower lip tucked up and back under the upper teeth, upper lip slightly raised.
    &[
        (3, 60.0),
        (4, -80.0),
        (5, 120.0),
        (16, -150.0),
        (52, 60.0),
        (57, 60.0),
        (58, 60.0),
    ],
    // 3 T, D: jaw slightly open, tongue tip forward between the teeth.
    &[(3, 120.0), (45, 300.0), (44, 100.0), (5, -40.0)],
    // 4 t, d: jaw slightly open, tongue tip raised to the ridge.
    &[(3, 100.0), (44, 400.0), (5, -30.0)],
    // 5 k, g: jaw open, back of the tongue raised.
    &[(3, 150.0), (46, 300.0), (5, -40.0)],
    // 6 tS, dZ, S: lips pushed forward and rounded, jaw slightly open.
    &[
        (3, 80.0),
        (16, 300.0),
        (17, 300.0),
        (6, -100.0),
        (7, -100.0),
        (4, -100.0),
        (5, -60.0),
    ],
    // 7 s, z: teeth almost closed, corners stretched.
    &[(3, 50.0), (6, 120.0), (7, 120.0), (53, 100.0), (54, 100.0)],
    // 8 n, l: jaw slightly open, tongue tip up.
    &[(3, 120.0), (44, 450.0), (5, -30.0)],
    // 9 r: lips slightly pushed and rounded.
    &[
        (3, 100.0),
        (16, 150.0),
        (17, 150.0),
        (6, -150.0),
        (7, -150.0),
    ],
    // 10 A: (father): jaw wide open, slight stretch, upper lip up.
    &[(3, 400.0), (6, 60.0), (7, 60.0), (4, -80.0)],
    // 11 e (bet): jaw half open, corners stretched and raised.
    &[(3, 250.0), (6, 200.0), (7, 200.0), (12, 50.0), (13, 50.0)],
    // 12 I (sit): jaw a little open, wide stretch, corners up.
    &[(3, 150.0), (6, 250.0), (7, 250.0), (12, 80.0), (13, 80.0)],
    // 13 Q (hot): jaw open, lips rounded and pushed.
    &[
        (3, 350.0),
        (6, -200.0),
        (7, -200.0),
        (16, 150.0),
        (17, 150.0),
    ],
    // 14 U (book): small round protruded mouth.
    &[
        (3, 150.0),
        (6, -350.0),
        (7, -350.0),
        (16, 300.0),
        (17, 300.0),
        (53, -300.0),
        (54, -300.0),
    ],
];

/// FAP vectors of expressions 1..=6 (joy, sadness, anger, fear, disgust, surprise).
const EXPRESSIONS: [&[(u8, f64)]; 6] = [
    // joy: corners up and back, cheeks lifted, lower lids up, lids slightly closed.
    &[
        (12, 180.0),
        (13, 180.0),
        (59, 180.0),
        (60, 180.0),
        (6, 150.0),
        (7, 150.0),
        (53, 150.0),
        (54, 150.0),
        (41, 300.0),
        (42, 300.0),
        (21, 200.0),
        (22, 200.0),
        (19, 100.0),
        (20, 100.0),
        (33, 50.0),
        (34, 50.0),
    ],
    // sadness: inner brows up, outer down, lids heavy, corners down, chin raised.
    &[
        (31, 250.0),
        (32, 250.0),
        (35, -100.0),
        (36, -100.0),
        (37, 50.0),
        (38, 50.0),
        (19, 150.0),
        (20, 150.0),
        (12, -120.0),
        (13, -120.0),
        (59, -120.0),
        (60, -120.0),
        (18, 100.0),
        (52, 80.0),
    ],
    // anger: brows down and together, eyes wide with tense lower lids, lips pressed, nostrils flared.
    &[
        (31, -200.0),
        (32, -200.0),
        (33, -120.0),
        (34, -120.0),
        (37, 150.0),
        (38, 150.0),
        (19, -150.0),
        (20, -150.0),
        (21, 150.0),
        (22, 150.0),
        (4, 80.0),
        (5, 80.0),
        (61, 100.0),
        (62, 100.0),
    ],
    // fear: brows up and together, eyes wide, jaw a little open, mouth stretched.
    &[
        (31, 300.0),
        (32, 300.0),
        (33, 200.0),
        (34, 200.0),
        (35, 100.0),
        (36, 100.0),
        (37, 100.0),
        (38, 100.0),
        (19, -200.0),
        (20, -200.0),
        (3, 150.0),
        (6, 150.0),
        (7, 150.0),
        (12, -60.0),
        (13, -60.0),
    ],
    // disgust: upper lip raised (more on the left), nose wrinkled, brows down, lower lids up.
    &[
        (4, -150.0),
        (51, -180.0),
        (55, -180.0),
        (56, -120.0),
        (63, 150.0),
        (61, 80.0),
        (62, 80.0),
        (31, -100.0),
        (32, -100.0),
        (21, 150.0),
        (22, 150.0),
        (12, 80.0),
    ],
    // surprise: brows up, upper lids wide open, jaw dropped.
    &[
        (31, 350.0),
        (32, 350.0),
        (33, 350.0),
        (34, 350.0),
        (35, 350.0),
        (36, 350.0),
        (19, -250.0),
        (20, -250.0),
        (3, 500.0),
        (6, -60.0),
        (7, -60.0),
    ],
];

fn to_faps(list: &[(u8, f64)]) -> Vec<(FapId, f64)> {
    list.iter()
        .map(|&(n, v)| (FapId::new(n).expect("low-level FAP number"), v))
        .collect()
}

/// The low-level FAP vector a synthetic face uses for `viseme` (empty for viseme 0).
pub fn viseme_faps(viseme: Viseme) -> Vec<(FapId, f64)> {
    match viseme.number() {
        0 => Vec::new(),
        n => to_faps(VISEMES[n as usize - 1]),
    }
}

/// The low-level FAP vector a synthetic face uses for `expression` (empty for neutral).
pub fn expression_faps(expression: Expression) -> Vec<(FapId, f64)> {
    match expression.number() {
        0 => Vec::new(),
        n => to_faps(EXPRESSIONS[n as usize - 1]),
    }
}

/// Appends the 14 viseme and 6 expression tables, evaluated from the low-level tables.
pub(super) fn add_tables(face: &mut SynthFace) {
    let meshes = face.mesh_sizes();
    let transforms = face.transform_names();
    let mut eval = FatEvaluator::new(&face.fat, &meshes, &transforms)
        .expect("synthetic low-level FAT binds to its face");
    let mut out = eval.output();
    let mut keys: Vec<(TableKey, Vec<(FapId, f64)>)> = Vec::new();
    // The nominal vectors, fitted to this face's own lips (`face::visemes`).
    for (v, faps) in crate::face::visemes::fitted_visemes(&face.to_face_model()) {
        keys.push((TableKey::Viseme(v), faps));
    }
    for e in Expression::basic() {
        keys.push((TableKey::Expression(e), expression_faps(e)));
    }
    let full = HIGH_LEVEL_FULL as f32;
    let mut tables = Vec::new();
    for (key, faps) in keys {
        let acts: Vec<Activation> = faps
            .iter()
            .map(|&(f, value)| Activation {
                key: TableKey::LowLevel(f),
                value,
            })
            .collect();
        eval.evaluate(&acts, &mut out);
        let mut t = FaceDefTable::new(key);
        for (mi, disp) in out.displacements.iter().enumerate() {
            let moved: Vec<(u32, Vec3)> = disp
                .iter()
                .enumerate()
                .filter(|(_, d)| **d != Vec3::ZERO)
                .map(|(v, d)| (v as u32, *d / full))
                .collect();
            if moved.is_empty() {
                continue;
            }
            t.meshes.push(FaceDefMesh {
                mesh: meshes[mi].0.to_string(),
                interval_borders: vec![0.0, HIGH_LEVEL_FULL],
                coord_index: moved.iter().map(|m| m.0).collect(),
                displacements: moved.iter().map(|m| m.1).collect(),
            });
        }
        for (ti, delta) in out.transforms.iter().enumerate() {
            let (axis, angle) = delta.rotation.to_axis_angle();
            if angle.abs() > 0.0 && axis.is_finite() && axis.length_squared() > 0.0 {
                t.transforms.push(FaceDefTransform::rotation(
                    transforms[ti],
                    axis,
                    angle / full,
                ));
            }
            if delta.translation != Vec3::ZERO {
                t.transforms.push(FaceDefTransform::translation(
                    transforms[ti],
                    delta.translation / full,
                ));
            }
        }
        tables.push(t);
    }
    face.fat.tables.extend(tables);
}
