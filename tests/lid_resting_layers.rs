//! Eye layers resting on the lids (an eye occlusion, a lacrimal film, corner blends) are
//! transparent in a production head's own materials; fbakit's pictures draw every triangle
//! opaque, so drawn they closed the eyes of the ICT-FaceKit's whole head. They are found by
//! shape and place (`fbakit::clone::face::lid_resting_layers`) and left out of pictures and
//! the viewer. On `../shared` (skipped with a note when absent).

mod support;

use fbakit::clone::face::lid_resting_layers;
use fbakit::export::picture::FaceView;
use fbakit::render::RenderOptions;
use fbakit::spec::FeaturePointId;
use support::ict_full_head::{ict_full_head, vertices_by_material};

/// The layers found are exactly the polygons ICT's artists gave the occlusion, lacrimal-fluid
/// and eye-blend materials — not the lashes, irises, eyeballs or skin.
#[test]
fn ict_layers_are_its_occlusion_tear_film_and_corner_blends() {
    let work = tempfile::tempdir().unwrap();
    let Some((obj, face)) = ict_full_head(work.path()) else {
        return;
    };
    let by_material = vertices_by_material(&obj);
    let mut expected: Vec<u32> = ["M_EyeOcclusion", "M_LacrimalFluid", "M_EyeBlend"]
        .iter()
        .flat_map(|m| by_material[*m].iter().copied())
        .collect();
    expected.sort_unstable();
    expected.dedup();
    assert_eq!(expected.len(), 760);
    let layers = lid_resting_layers(&face);
    assert_eq!(layers.len(), 1, "one mesh");
    assert_eq!(layers[0].mesh, 0);
    assert_eq!(layers[0].vertices, expected);
}

/// The neutral head's picture, framed from its feature points: each pupil point lands on a
/// dark pupil, not on a layer drawn as skin over the eye.
#[test]
fn the_whole_ict_head_is_pictured_with_open_eyes() {
    let work = tempfile::tempdir().unwrap();
    let Some((_, face)) = ict_full_head(work.path()) else {
        return;
    };
    let view = FaceView::new(&face).unwrap();
    let camera = view.face_camera();
    let opts = RenderOptions {
        width: 512,
        height: 512,
        ..RenderOptions::default()
    };
    let image = view.render(&face.neutral_world_positions(), &camera, &opts);
    let luminance = |x: f32, y: f32| {
        let p = image.pixel(x as u32, y as u32).unwrap();
        0.2126 * p[0] as f64 + 0.7152 * p[1] as f64 + 0.0722 * p[2] as f64
    };
    let at = |id: FeaturePointId| {
        let p = face.feature_points.position(id).unwrap();
        camera.project(p, opts.width, opts.height).unwrap()
    };
    // Skin: the nose bridge between the eyes (9.15's neighbourhood) and the cheeks.
    let (sx, sy) = at(FeaturePointId::new(9, 15).unwrap());
    let skin = luminance(sx, sy);
    for id in [FeaturePointId::FP_3_5, FeaturePointId::FP_3_6] {
        let (x, y) = at(id);
        let l = luminance(x, y);
        assert!(
            l < 70.0 && l < 0.5 * skin,
            "pupil {id} at ({x:.0}, {y:.0}) not dark: {l:.0} (skin {skin:.0})"
        );
    }
}
