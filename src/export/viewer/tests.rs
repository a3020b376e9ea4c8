use crate::export::gltf::export_face;
use std::path::Path;
use std::sync::OnceLock;

use super::*;
use crate::fap::{read_stream_file, ReadOptions};
use crate::fat::interval_weights;
use crate::gltf::container::base64_decode;
use crate::gltf::parse_glb;
use crate::player::{PlayOptions, Player};

fn alma() -> &'static FaceModel {
    static FACE: OnceLock<FaceModel> = OnceLock::new();
    FACE.get_or_init(|| crate::synth::alma().to_face_model())
}

fn speech_frames() -> &'static (Vec<AnimationFrame>, f64) {
    static FRAMES: OnceLock<(Vec<AnimationFrame>, f64)> = OnceLock::new();
    FRAMES.get_or_init(|| {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("samples/speech.fap");
        let (stream, _) = read_stream_file(&path, &ReadOptions::lenient()).unwrap();
        let player = Player::new(alma(), &stream, &PlayOptions::default()).unwrap();
        (player.animation().unwrap(), player.fps())
    })
}

fn speech_page() -> &'static ViewerPage {
    static PAGE: OnceLock<ViewerPage> = OnceLock::new();
    PAGE.get_or_init(|| {
        let (frames, fps) = speech_frames();
        let anim = ViewerAnimation {
            frames,
            fps: *fps,
            name: "speech.fap",
        };
        ViewerPage::new(alma(), Some(&anim)).unwrap()
    })
}

/// The text between `<script ... id="ID">` and its `</script>`.
fn script_body<'a>(html: &'a str, id: &str) -> &'a str {
    let open = format!("id=\"{id}\">");
    let start = html.find(&open).unwrap() + open.len();
    let len = html[start..].find("</script>").unwrap();
    &html[start..start + len]
}

fn page_model(html: &str) -> serde_json::Value {
    serde_json::from_str(script_body(html, "fbakit-data")).unwrap()
}

#[test]
fn template_has_each_marker_once_in_fill_order() {
    let markers = [
        "<!--FBAKIT:TITLE-->",
        "<!--FBAKIT:STYLE-->",
        "<!--FBAKIT:DATA-->",
        "<!--FBAKIT:GLB-->",
        "<!--FBAKIT:THREE-->",
        "<!--FBAKIT:SCRIPT-->",
    ];
    let mut last = 0;
    for m in markers {
        assert_eq!(PAGE_TEMPLATE.matches(m).count(), 1, "{m}");
        let at = PAGE_TEMPLATE.find(m).unwrap();
        assert!(at > last, "{m} out of order");
        last = at;
    }
}

#[test]
fn embedded_scripts_cannot_end_their_script_element() {
    for (name, text) in [("three", THREE_BUNDLE), ("viewer", PAGE_SCRIPT)] {
        let lower = text.to_ascii_lowercase();
        assert!(!lower.contains("</script"), "{name} contains </script");
        assert!(!lower.contains("<!--"), "{name} contains <!--");
    }
    assert!(!PAGE_STYLE.to_ascii_lowercase().contains("</style"));
}

#[test]
fn page_is_one_file_with_no_remote_references() {
    let html = &speech_page().html;
    assert!(html.starts_with("<!DOCTYPE html>"));
    assert!(!html.contains("<!--FBAKIT:"), "a marker was left unfilled");
    // Nothing is loaded from elsewhere: no src/href attributes, no module imports.
    for needle in [" src=", " href=", "import(", "<link", "@import"] {
        assert!(!html.contains(needle), "page contains `{needle}`");
    }
    // The only URLs are XML namespace names inside three.js, never fetched.
    let mut rest = html.as_str();
    while let Some(at) = rest.find("://") {
        let before = &rest[at.saturating_sub(5)..at];
        let after = &rest[at..(at + 30).min(rest.len())];
        assert!(
            !(before.ends_with("http") || before.ends_with("https"))
                || after.starts_with("://www.w3.org/"),
            "remote URL in page: {before}{after}"
        );
        rest = &rest[at + 3..];
    }
}

#[test]
fn page_embeds_a_valid_animated_glb() {
    let page = speech_page();
    let bytes = base64_decode(script_body(&page.html, "fbakit-glb").trim()).unwrap();
    assert_eq!(&bytes[..4], b"glTF");
    let declared = u32::from_le_bytes(bytes[8..12].try_into().unwrap()) as usize;
    assert_eq!(declared, bytes.len());
    assert_eq!(bytes.len(), page.glb_bytes);
    let chunks = parse_glb(&bytes).unwrap();
    let json: serde_json::Value = serde_json::from_slice(chunks.json).unwrap();
    assert_eq!(json["animations"][0]["name"], "play");
    // Mesh nodes the model points at carry morph targets in the glb.
    let model = page_model(&page.html);
    for m in model["meshes"].as_array().unwrap() {
        let node = &json["nodes"][m["node"].as_u64().unwrap() as usize];
        assert_eq!(node["name"], m["mesh"]);
        let mesh = &json["meshes"][node["mesh"].as_u64().unwrap() as usize];
        let targets = mesh["primitives"][0]["targets"]
            .as_array()
            .map_or(0, |t| t.len());
        assert_eq!(targets, m["targets"].as_array().unwrap().len());
    }
}

#[test]
fn sliders_cover_every_key_with_a_table() {
    let model = page_model(&speech_page().html);
    let mut keys: Vec<String> = model["groups"]
        .as_array()
        .unwrap()
        .iter()
        .flat_map(|g| g["keys"].as_array().unwrap().iter())
        .map(|k| k["key"].as_str().unwrap().to_string())
        .collect();
    keys.sort();
    let mut want: Vec<String> = alma().fat.keys().iter().map(|k| k.name()).collect();
    want.sort();
    assert_eq!(keys, want);
    // Groups are the standard's, in order, and the low-level keys sit in their FAP's group.
    let groups = model["groups"].as_array().unwrap();
    let numbers: Vec<u64> = groups
        .iter()
        .map(|g| g["number"].as_u64().unwrap())
        .collect();
    assert!(numbers.windows(2).all(|w| w[0] < w[1]));
    assert!(numbers.iter().all(|n| (1..=10).contains(n)));
    for g in groups {
        for k in g["keys"].as_array().unwrap() {
            let key = TableKey::from_name(k["key"].as_str().unwrap()).unwrap();
            let group = match key {
                TableKey::LowLevel(f) => f.info().group,
                _ => 1,
            };
            assert_eq!(g["number"].as_u64().unwrap(), u64::from(group));
            assert!(k["min"].as_f64().unwrap() < k["max"].as_f64().unwrap());
        }
    }
}

#[test]
fn open_jaw_slider_is_in_mns_and_covers_its_table() {
    let model =
        ViewerModel::new(alma(), &export_face(alma(), None).unwrap().document, None).unwrap();
    let jaw = model
        .groups
        .iter()
        .flat_map(|g| &g.keys)
        .find(|k| k.key == "open_jaw")
        .unwrap();
    assert_eq!(jaw.fapu, Some("MNS"));
    assert_eq!(jaw.min, 0.0, "open_jaw is unidirectional");
    assert!(jaw.max >= 512.0);
    assert_eq!(model.fapu.len(), 6);
    assert!(model.fapu.iter().all(|f| f.unit > 0.0));
    assert!(model.stream.is_none() && model.tracks.is_empty());
}

/// The page's posing rule (weights from the key values of a frame) gives the exporter's
/// animation weights at every frame of the sample stream.
#[test]
fn pose_rule_reproduces_the_exported_weights() {
    let (frames, fps) = speech_frames();
    let anim = ViewerAnimation {
        frames,
        fps: *fps,
        name: "speech",
    };
    let doc = export_face(alma(), Some(frames)).unwrap().document;
    let model = ViewerModel::new(alma(), &doc, Some(&anim)).unwrap();
    let morphs = FaceMorphs::new(alma()).unwrap();
    assert!(!model.tracks.is_empty());
    let mut exported = Vec::new();
    let mut scratch = Vec::new();
    let mut checked = 0;
    for (fi, frame) in frames.iter().enumerate() {
        for m in &model.meshes {
            let mi = alma().mesh_index(&m.mesh).unwrap();
            morphs.weights_into(mi, &frame.activations, &mut exported);
            for (t, &want) in m.targets.iter().zip(&exported) {
                let p = model
                    .tracks
                    .iter()
                    .find(|k| k.key == t.key)
                    .map_or(0.0, |k| f64::from(k.values[fi]));
                interval_weights(&t.borders, p, &mut scratch);
                let got = if p == 0.0 {
                    0.0
                } else {
                    scratch[t.interval] / t.span
                };
                assert!(
                    (got - f64::from(want)).abs() < 1e-4,
                    "frame {fi} {}: {got} vs {want}",
                    t.key
                );
                checked += 1;
            }
        }
    }
    assert!(checked > 1000);
}

#[test]
fn transform_rigs_point_at_transform_nodes_in_slot_order() {
    let doc = export_face(alma(), None).unwrap().document;
    let model = ViewerModel::new(alma(), &doc, None).unwrap();
    assert!(!model.transforms.is_empty(), "alma drives eyes and head");
    for r in &model.transforms {
        let node = &doc.root.nodes[r.node as usize];
        assert_eq!(node.name.as_deref(), Some(r.name.as_str()));
        assert!(node.mesh.is_none());
        let slots: Vec<usize> = r
            .entries
            .iter()
            .map(|e| TableKey::from_name(&e.key).unwrap().slot().unwrap())
            .collect();
        assert!(slots.windows(2).all(|w| w[0] <= w[1]), "{slots:?}");
        for e in &r.entries {
            let len = Vec3::from_array(e.axis).length();
            assert!((len - 1.0).abs() < 1e-5);
        }
    }
    let yaw = model
        .transforms
        .iter()
        .flat_map(|r| &r.entries)
        .find(|e| e.key == "head_yaw")
        .unwrap();
    assert_eq!(yaw.field, TransformField::Rotation);
}

#[test]
fn feature_points_are_bound_to_mesh_nodes_and_frame_the_camera() {
    let doc = export_face(alma(), None).unwrap().document;
    let model = ViewerModel::new(alma(), &doc, None).unwrap();
    assert_eq!(model.feature_points.len(), alma().feature_points.len());
    let lip = model.feature_points.iter().find(|p| p.id == "8.1").unwrap();
    assert!(lip.node.is_some() && !lip.vertices.is_empty());
    let c = Vec3::from_array(model.camera.target);
    for p in &model.feature_points {
        assert!(c.distance(Vec3::from_array(p.position)) <= model.camera.radius * 1.001);
    }
}

/// A face modelled facing −z is framed from its own front: the same box, turned round.
#[test]
fn a_face_turned_round_is_framed_from_its_front() {
    let upright = camera_frame(alma());
    assert_eq!(
        upright.axes,
        [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
    );
    let half = glam::Mat3::from_cols(-Vec3::X, Vec3::Y, -Vec3::Z);
    let turned = crate::clone::face::upright::upright_copy(alma(), half);
    let frame = camera_frame(&turned);
    assert_eq!(
        frame.axes,
        [[-1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, -1.0]]
    );
    assert_eq!(frame.half_extent, upright.half_extent);
    assert_eq!(frame.radius, upright.radius);
    let t = Vec3::from_array(upright.target);
    assert_eq!(Vec3::from_array(frame.target), half * t);
}

#[test]
fn title_is_escaped_and_long_animations_are_refused() {
    let mut face = alma().clone();
    face.name = "<b>&\"x".into();
    let page = ViewerPage::new(&face, None).unwrap();
    assert!(page
        .html
        .contains("<title>&lt;b&gt;&amp;&quot;x · fbakit viewer</title>"));
    let model = page_model(&page.html);
    assert_eq!(model["face"], "<b>&\"x");
    assert!(!script_body(&page.html, "fbakit-data").contains('<'));

    let frame = speech_frames().0[0].clone();
    let frames = vec![frame; MAX_FRAMES + 1];
    let anim = ViewerAnimation {
        frames: &frames,
        fps: 25.0,
        name: "long",
    };
    let err = ViewerPage::new(alma(), Some(&anim)).unwrap_err();
    assert!(err.to_string().contains("at most"), "{err}");
}

#[test]
fn a_face_without_tables_gets_no_sliders() {
    let mut face = alma().clone();
    face.fat = Default::default();
    let page = ViewerPage::new(&face, None).unwrap();
    let model = page_model(&page.html);
    assert!(model["groups"].as_array().unwrap().is_empty());
    assert!(model["transforms"].as_array().unwrap().is_empty());
}
