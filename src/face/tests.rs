//! Face model: VRML round trips, feature-point matching, validation with locations.

use std::path::Path;

use glam::Vec3;

use super::validate::validate_face;
use super::vrml::{face_from_scene, write_face_string, FaceFileKind};
use super::*;
use crate::error::Severity;
use crate::spec::FeaturePointId;

fn read_str(text: &str) -> (FaceModel, super::vrml::FaceReadReport) {
    let scene = crate::vrml::parse_vrml(text, Path::new("t.wrl")).expect("parses");
    face_from_scene(scene, "t").expect("reads")
}

fn fp(s: &str) -> FeaturePointId {
    s.parse().unwrap()
}

#[test]
fn synthetic_face_round_trips_through_vrml() {
    let face = crate::synth::alma().to_face_model();
    face.check_structure().unwrap();
    let text = write_face_string(&face).unwrap();
    let (back, report) = read_str(&text);
    assert_eq!(report.kind, FaceFileKind::Face);
    assert!(report.diagnostics.is_empty(), "{:?}", report.diagnostics);
    assert_eq!(back.meshes.len(), face.meshes.len());
    for (a, b) in back.meshes.iter().zip(&face.meshes) {
        assert_eq!(a.name, b.name);
        assert_eq!(a.transform, b.transform, "{}", a.name);
        assert_eq!(a.color, b.color, "{}", a.name);
        assert_eq!(a.mesh.positions, b.mesh.positions, "{}", a.name);
        assert_eq!(a.mesh.polygons, b.mesh.polygons, "{}", a.name);
        assert_eq!(a.mesh.flags, b.mesh.flags, "{}", a.name);
        assert_eq!(a.mesh.uvs, b.mesh.uvs, "{}", a.name);
        assert_eq!(a.mesh.normals, b.mesh.normals, "{}", a.name);
        assert_eq!(a.mesh.name, b.mesh.name, "{}", a.name);
        assert_eq!(a.mesh, b.mesh, "{}", a.name);
    }
    assert_eq!(back.transforms, face.transforms);
    assert_eq!(back.fat, face.fat);
    assert_eq!(back.feature_points, face.feature_points);
    assert_eq!(back, face);
    // Writing the re-read face (now scene-backed) gives the same text again.
    let again = write_face_string(&back).unwrap();
    assert_eq!(again, text);
    assert!(validate_face(&back, &report).is_empty());
    // FAPU measured on the re-read feature points equals the generator's.
    assert_eq!(back.fapu().unwrap(), crate::synth::alma().fapu());
}

const PLAIN: &str = r#"#VRML V2.0 utf8
# A face file without fbakit's record: feature points are matched to vertices.
DEF Light DirectionalLight { direction 0 0 -1 }
Transform {
  translation 0 1 0
  children [
    Shape {
      appearance Appearance { material Material { diffuseColor 0.8 0.6 0.5 } }
      geometry IndexedFaceSet {
        coord Coordinate { point [ 0 0 0, 1 0 0, 1 1 0, 0 1 0 ] }
        coordIndex [ 0 1 2 3 -1 ]
      }
    }
  ]
}
Face {
  fdp FDP {
    featurePointsCoord Coordinate { point [ 0 1.01 0, 1 2 0 ] }
  }
}
"#;

#[test]
fn plain_geometry_gets_names_and_points_match_the_nearest_vertex() {
    let (face, report) = read_str(PLAIN);
    assert_eq!(face.transforms.len(), 1);
    assert_eq!(face.meshes.len(), 1);
    assert_eq!(face.meshes[0].color, Some([0.8, 0.6, 0.5]));
    assert_eq!(face.meshes[0].mesh.polygons.len(), 1);
    let frames = face.frames();
    assert_eq!(
        face.vertex_world(&frames, 0, 2),
        Some(Vec3::new(1.0, 2.0, 0.0))
    );
    // 2.1 at (0, 1.01, 0) is vertex 0 at world (0, 1, 0), 0.01 away; 2.2 is exactly vertex 2.
    assert_eq!(report.fp_matches.len(), 2);
    assert_eq!(report.fp_matches[0].vertex, 0);
    assert!((report.fp_matches[0].distance - 0.01).abs() < 1e-6);
    assert_eq!(report.fp_matches[1].vertex, 2);
    assert_eq!(face.fp_vertex(fp("2.2")), Some((0, 2)));
    // Round trip in patch mode keeps the light and the names given at read time.
    let text = write_face_string(&face).unwrap();
    assert!(text.contains("DEF Light DirectionalLight"), "{text}");
    let (back, _) = read_str(&text);
    assert_eq!(back, face);
}

const BROKEN: &str = r#"#VRML V2.0 utf8
Transform {
  children [
    Shape {
      geometry DEF skin IndexedFaceSet {
        coord Coordinate { point [ 0 0 0, 1 0 0, 0 1 0 ] }
        coordIndex [ 0 1 5 -1, 0 1 -1 ]
      }
    }
  ]
}
DEF jaw Transform { }
Face {
  fdp FDP {
    faceDefTables [
      FaceDefTables {
        fapID 3
        faceDefMesh [
          FaceDefMesh {
            faceSceneGraphNode USE skin
            intervalBorders [ 100 0 ]
            coordIndex [ 0 9 ]
            displacements [ 0 -1 0 ]
          }
        ]
      }
      FaceDefTables { fapID 1 highLevelSelect 15 }
      FaceDefTables {
        fapID 48
        faceDefTransform [ FaceDefTransform { faceSceneGraphNode USE jaw fieldId 7 } ]
      }
    ]
  }
}
"#;

#[test]
fn validation_names_path_and_line_of_every_problem() {
    let (face, report) = read_str(BROKEN);
    let problems = validate_face(&face, &report);
    let text: Vec<String> = problems.iter().map(|d| d.to_string()).collect();
    let all = text.join("\n");
    // The mesh: an out-of-range index and a two-corner polygon, with its path.
    assert!(all.contains("t.wrl:5:16: error: Transform(DEF transform_0) > Shape > IndexedFaceSet(DEF skin): 1 coordIndex value(s) beyond its 3 points"), "{all}");
    assert!(
        all.contains("1 polygon(s) with fewer than 3 corners"),
        "{all}"
    );
    // The table: borders not increasing, displacement count, index 9 out of range — at the
    // FaceDefMesh node's line.
    assert!(all.contains("t.wrl:19:11: error: FDP > faceDefTables #1 (FAP 3 open_jaw) > FaceDefMesh #1: intervalBorders must increase strictly"), "{all}");
    assert!(all.contains("1 displacements, expected 2"), "{all}");
    assert!(all.contains("(first: 9)"), "{all}");
    // highLevelSelect out of range and an unknown fieldId, at their nodes.
    assert!(
        all.contains("t.wrl:27:7: error: FaceDefTables: highLevelSelect 15 is not a viseme 1..=14"),
        "{all}"
    );
    assert!(
        all.contains("fieldId 7 is not 1 (rotation), 2 (scale) or 3 (translation)"),
        "{all}"
    );
    assert!(
        problems
            .iter()
            .filter(|d| d.severity == Severity::Error)
            .count()
            >= 7,
        "{all}"
    );
}

#[test]
fn transforms_compose_like_vrml() {
    let mut t = FaceTransform::new("eye", None, Vec3::new(1.0, 0.0, 0.0));
    t.rotation = glam::Quat::from_rotation_y(std::f32::consts::FRAC_PI_2);
    t.translation = Vec3::new(0.0, 2.0, 0.0);
    // Rotating (2,0,0) about the centre (1,0,0) by 90° about +y gives (1,0,-1); then +2 in y.
    let p = t.local_matrix().transform_point3(Vec3::new(2.0, 0.0, 0.0));
    assert!((p - Vec3::new(1.0, 2.0, -1.0)).length() < 1e-6, "{p}");
}
