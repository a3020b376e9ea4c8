use std::path::Path;

use glam::Vec3;
use proptest::prelude::*;
use serde_json::json;

use super::gltf_read::read_gltf_bytes;
use super::gltf_write::rig_to_gltf;
use super::*;
use crate::mesh::{Mesh, Polygons};

/// A two-mesh rig: a quad "face" and a triangle "teeth", three shapes.
pub(crate) fn small_rig() -> Rig {
    let face = Mesh {
        name: "face".into(),
        positions: vec![
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
        ],
        polygons: Polygons::from_triangles(&[[0, 1, 2], [0, 2, 3]]),
        ..Mesh::default()
    };
    let teeth = Mesh {
        name: "teeth".into(),
        positions: vec![Vec3::new(0.0, 0.0, -1.0), Vec3::X, Vec3::Y],
        polygons: Polygons::from_triangles(&[[0, 1, 2]]),
        ..Mesh::default()
    };
    Rig {
        name: "small".into(),
        meshes: vec![
            RigMesh {
                name: "face".into(),
                mesh: face,
            },
            RigMesh {
                name: "teeth".into(),
                mesh: teeth,
            },
        ],
        shapes: vec![
            BlendShape {
                name: "jawOpen".into(),
                default_weight: 0.0,
                deltas: vec![
                    ShapeDelta {
                        mesh: 0,
                        vertices: vec![0, 1],
                        offsets: vec![Vec3::new(0.0, -0.5, 0.0), Vec3::new(0.0, -0.25, 0.125)],
                    },
                    ShapeDelta {
                        mesh: 1,
                        vertices: vec![2],
                        offsets: vec![Vec3::new(0.0, -0.5, 0.0)],
                    },
                ],
            },
            BlendShape {
                name: "mouthSmile_L".into(),
                default_weight: 0.25,
                deltas: vec![ShapeDelta {
                    mesh: 0,
                    vertices: vec![2],
                    offsets: vec![Vec3::new(0.1, 0.2, 0.0)],
                }],
            },
            BlendShape {
                name: "unused".into(),
                default_weight: 0.0,
                deltas: vec![],
            },
        ],
        warnings: vec![],
        source: None,
    }
}

fn round_trip(rig: &Rig, glb: bool) -> Rig {
    let doc = rig_to_gltf(rig).unwrap();
    let bytes = if glb {
        doc.to_glb().unwrap()
    } else {
        doc.to_gltf_string().unwrap().into_bytes()
    };
    let name = if glb { "small.glb" } else { "small.gltf" };
    read_gltf_bytes(&bytes, Path::new(name)).unwrap()
}

/// Rigs compare equal up to normals (the writer computes them) and the warnings.
fn assert_same_rig(a: &Rig, b: &Rig) {
    assert_eq!(a.meshes.len(), b.meshes.len());
    for (x, y) in a.meshes.iter().zip(&b.meshes) {
        assert_eq!(x.name, y.name);
        assert_eq!(x.mesh.positions, y.mesh.positions, "mesh {}", x.name);
        assert_eq!(x.mesh.triangles(), y.mesh.triangles(), "mesh {}", x.name);
    }
    let names = |r: &Rig| r.shapes.iter().map(|s| s.name.clone()).collect::<Vec<_>>();
    assert_eq!(names(a), names(b));
    for (x, y) in a.shapes.iter().zip(&b.shapes) {
        assert_eq!(x.default_weight, y.default_weight, "shape {}", x.name);
        assert_eq!(x.deltas, y.deltas, "shape {}", x.name);
    }
}

#[test]
fn glb_and_gltf_round_trip_keep_order_names_and_deltas() {
    let rig = small_rig();
    rig.check().unwrap();
    for glb in [true, false] {
        let back = round_trip(&rig, glb);
        assert_same_rig(&rig, &back);
        assert!(back.warnings.is_empty(), "{:?}", back.warnings);
    }
}

#[test]
fn posed_positions_and_offsets() {
    let rig = small_rig();
    let jaw = rig.shape_index("jawOpen").unwrap();
    let p = rig.posed_positions(0, &[(jaw, 0.5)]);
    assert_eq!(p[0], Vec3::new(0.0, -0.25, 0.0));
    assert_eq!(p[2], Vec3::new(1.0, 1.0, 0.0));
    assert_eq!(rig.shapes[jaw].offset(1, 2), Vec3::new(0.0, -0.5, 0.0));
    assert_eq!(rig.shapes[jaw].offset(1, 0), Vec3::ZERO);
    assert_eq!(rig.shapes[jaw].moved_vertex_count(), 3);
    let face = rig.to_face();
    assert_eq!(face.meshes.len(), 2);
    assert!(face.fat.tables.is_empty());
}

#[test]
fn check_refuses_duplicates_and_bad_deltas() {
    let mut rig = small_rig();
    rig.shapes[1].name = "jawOpen".into();
    assert!(rig.check().unwrap_err().to_string().contains("two shapes"));
    let mut rig = small_rig();
    rig.shapes[0].deltas[1].vertices = vec![3];
    assert!(rig
        .check()
        .unwrap_err()
        .to_string()
        .contains("bad vertex list"));
    let mut rig = small_rig();
    rig.shapes[0].deltas[0].offsets[0].x = f32::NAN;
    assert!(rig.check().unwrap_err().to_string().contains("non-finite"));
    assert!(small_rig().require_shapes(Path::new("x.glb")).is_ok());
    let mut rig = small_rig();
    rig.shapes.clear();
    let e = rig.require_shapes(Path::new("x.glb")).unwrap_err();
    assert!(e.to_string().contains("x.glb: no morph targets"), "{e}");
}

/// A hand-made glTF (JSON, one data-URI buffer) for reader tests.
pub(crate) struct HandGltf {
    pub bin: Vec<u8>,
    pub views: Vec<serde_json::Value>,
    pub accessors: Vec<serde_json::Value>,
}

impl HandGltf {
    pub fn new() -> Self {
        HandGltf {
            bin: Vec::new(),
            views: Vec::new(),
            accessors: Vec::new(),
        }
    }

    fn view(&mut self, bytes: &[u8]) -> usize {
        while self.bin.len() % 4 != 0 {
            self.bin.push(0);
        }
        self.views
            .push(json!({"buffer": 0, "byteOffset": self.bin.len(), "byteLength": bytes.len()}));
        self.bin.extend_from_slice(bytes);
        self.views.len() - 1
    }

    /// A `VEC3` float accessor.
    pub fn vec3(&mut self, v: &[Vec3]) -> usize {
        let bytes: Vec<u8> = v
            .iter()
            .flat_map(|p| p.to_array())
            .flat_map(f32::to_le_bytes)
            .collect();
        let view = self.view(&bytes);
        self.accessors.push(
            json!({"bufferView": view, "componentType": 5126, "count": v.len(), "type": "VEC3"}),
        );
        self.accessors.len() - 1
    }

    /// A sparse `VEC3` accessor of `count` zeros with `values` at `indices` (no bufferView).
    pub fn sparse_vec3(&mut self, count: usize, indices: &[u16], values: &[Vec3]) -> usize {
        let ib: Vec<u8> = indices.iter().flat_map(|i| i.to_le_bytes()).collect();
        let iv = self.view(&ib);
        let vb: Vec<u8> = values
            .iter()
            .flat_map(|p| p.to_array())
            .flat_map(f32::to_le_bytes)
            .collect();
        let vv = self.view(&vb);
        self.accessors.push(json!({
            "componentType": 5126, "count": count, "type": "VEC3",
            "sparse": {"count": indices.len(),
                       "indices": {"bufferView": iv, "componentType": 5123},
                       "values": {"bufferView": vv}}
        }));
        self.accessors.len() - 1
    }

    /// A `u16` index accessor.
    pub fn indices(&mut self, i: &[u16]) -> usize {
        let bytes: Vec<u8> = i.iter().flat_map(|x| x.to_le_bytes()).collect();
        let view = self.view(&bytes);
        self.accessors.push(
            json!({"bufferView": view, "componentType": 5123, "count": i.len(), "type": "SCALAR"}),
        );
        self.accessors.len() - 1
    }

    /// The document with `meshes` and `nodes`, buffer embedded as a data URI.
    pub fn document(&self, meshes: serde_json::Value, nodes: serde_json::Value) -> Vec<u8> {
        let mut b64 = String::new();
        crate::gltf::container::base64_encode_into(&self.bin, &mut b64);
        let n = nodes.as_array().map_or(0, |a| a.len());
        let doc = json!({
            "asset": {"version": "2.0"},
            "scene": 0,
            "scenes": [{"nodes": (0..n).collect::<Vec<_>>()}],
            "nodes": nodes,
            "meshes": meshes,
            "accessors": self.accessors,
            "bufferViews": self.views,
            "buffers": [{"byteLength": self.bin.len(),
                         "uri": format!("data:application/octet-stream;base64,{b64}")}],
        });
        serde_json::to_vec(&doc).unwrap()
    }
}

fn tri() -> Vec<Vec3> {
    vec![Vec3::ZERO, Vec3::X, Vec3::Y]
}

#[test]
fn sparse_targets_node_transforms_and_weights() {
    let mut g = HandGltf::new();
    let pos = g.vec3(&tri());
    let idx = g.indices(&[0, 1, 2]);
    let t0 = g.sparse_vec3(3, &[1], &[Vec3::new(0.0, 0.5, 0.0)]);
    let t1 = g.vec3(&[Vec3::ZERO, Vec3::ZERO, Vec3::new(0.0, 0.0, 1.0)]);
    let meshes = json!([{
        "name": "m",
        "primitives": [{"attributes": {"POSITION": pos}, "indices": idx,
                        "targets": [{"POSITION": t0}, {"POSITION": t1}]}],
        "weights": [0.0, 0.5],
        "extras": {"targetNames": ["up", "out"]}
    }]);
    // Translated by (10, 0, 0) and scaled by 2: positions and deltas in world space.
    let nodes = json!([{"mesh": 0, "translation": [10.0, 0.0, 0.0], "scale": [2.0, 2.0, 2.0]}]);
    let bytes = g.document(meshes, nodes);
    let rig = read_gltf_bytes(&bytes, Path::new("hand.gltf")).unwrap();
    assert_eq!(rig.meshes[0].mesh.positions[1], Vec3::new(12.0, 0.0, 0.0));
    assert_eq!(rig.shapes[0].name, "up");
    assert_eq!(rig.shapes[0].deltas[0].vertices, vec![1]);
    assert_eq!(
        rig.shapes[0].deltas[0].offsets,
        vec![Vec3::new(0.0, 1.0, 0.0)]
    );
    assert_eq!(
        rig.shapes[1].deltas[0].offsets,
        vec![Vec3::new(0.0, 0.0, 2.0)]
    );
    assert_eq!(rig.shapes[1].default_weight, 0.5);
}

fn read_err(meshes: serde_json::Value, g: &HandGltf) -> String {
    let bytes = g.document(meshes, json!([{"mesh": 0}]));
    read_gltf_bytes(&bytes, Path::new("bad.gltf"))
        .unwrap_err()
        .to_string()
}

#[test]
fn bad_rigs_are_located_errors() {
    let mut g = HandGltf::new();
    let pos = g.vec3(&tri());
    let t0 = g.vec3(&[Vec3::X; 3]);
    let prim = json!({"attributes": {"POSITION": pos}, "targets": [{"POSITION": t0}]});
    // Unnamed targets.
    let e = read_err(json!([{"primitives": [prim]}]), &g);
    assert!(
        e.contains("bad.gltf: meshes[0].extras.targetNames") && e.contains("no names"),
        "{e}"
    );
    // Name count != target count.
    let e = read_err(
        json!([{"primitives": [prim], "extras": {"targetNames": ["a", "b"]}}]),
        &g,
    );
    assert!(e.contains("2 names for 1 morph targets"), "{e}");
    // Empty name.
    let e = read_err(
        json!([{"primitives": [prim], "extras": {"targetNames": [""]}}]),
        &g,
    );
    assert!(e.contains("targetNames[0]"), "{e}");
    // NaN position.
    let mut g2 = HandGltf::new();
    let pos = g2.vec3(&[Vec3::ZERO, Vec3::new(f32::NAN, 0.0, 0.0), Vec3::Y]);
    let e = read_err(
        json!([{"primitives": [{"attributes": {"POSITION": pos}}]}]),
        &g2,
    );
    assert!(
        e.contains("meshes[0].primitives[0].attributes.POSITION") && e.contains("vertex 1"),
        "{e}"
    );
    // NaN in a target.
    let mut g3 = HandGltf::new();
    let pos = g3.vec3(&tri());
    let t = g3.vec3(&[Vec3::ZERO, Vec3::ZERO, Vec3::splat(f32::NAN)]);
    let e = read_err(
        json!([{"primitives": [{"attributes": {"POSITION": pos}, "targets": [{"POSITION": t}]}],
                "extras": {"targetNames": ["x"]}}]),
        &g3,
    );
    assert!(
        e.contains("meshes[0].primitives[0].targets[0].POSITION"),
        "{e}"
    );
}

#[test]
fn hostile_counts_are_refused_before_reading() {
    let mut g = HandGltf::new();
    let pos = g.vec3(&tri());
    // Claim a billion vertices.
    g.accessors[pos]["count"] = json!(1_000_000_000u64);
    let e = read_err(
        json!([{"primitives": [{"attributes": {"POSITION": pos}}]}]),
        &g,
    );
    assert!(e.contains("count 1000000000 outside"), "{e}");
    // Claim more than the view holds.
    g.accessors[pos]["count"] = json!(4);
    let e = read_err(
        json!([{"primitives": [{"attributes": {"POSITION": pos}}]}]),
        &g,
    );
    assert!(e.contains("past the end of its bufferView"), "{e}");
    // A target of the wrong length.
    let mut g = HandGltf::new();
    let pos = g.vec3(&tri());
    let t = g.vec3(&[Vec3::X; 2]);
    let e = read_err(
        json!([{"primitives": [{"attributes": {"POSITION": pos}, "targets": [{"POSITION": t}]}],
                "extras": {"targetNames": ["x"]}}]),
        &g,
    );
    assert!(
        e.contains("targets[0].POSITION") && e.contains("count 2, expected 3"),
        "{e}"
    );
    // Not glTF at all.
    let e = read_gltf_bytes(b"{\"asset\": 3}", Path::new("x.gltf")).unwrap_err();
    assert!(e.to_string().starts_with("x.gltf: "), "{e}");
}

#[test]
fn node_cycles_are_refused() {
    let mut g = HandGltf::new();
    let pos = g.vec3(&tri());
    let bytes = g.document(
        json!([{"primitives": [{"attributes": {"POSITION": pos}}]}]),
        json!([{"mesh": 0, "children": [1]}, {"children": [0]}]),
    );
    // The scene lists both nodes; node 0 shows up again as a child of node 1.
    let e = read_gltf_bytes(&bytes, Path::new("c.gltf"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("c.gltf"), "{e}");
}

fn arb_rig() -> impl Strategy<Value = Rig> {
    let coord = -100.0f32..100.0;
    (3usize..12, 1usize..5).prop_flat_map(move |(n, shapes)| {
        let positions = proptest::collection::vec((coord.clone(), coord.clone(), coord.clone()), n);
        let deltas = proptest::collection::vec(
            proptest::collection::vec(
                proptest::option::of((-1.0f32..1.0, -1.0f32..1.0, -1.0f32..1.0)),
                n,
            ),
            shapes,
        );
        (positions, deltas).prop_map(move |(p, d)| {
            let positions: Vec<Vec3> = p.into_iter().map(|(x, y, z)| Vec3::new(x, y, z)).collect();
            let tris: Vec<[u32; 3]> = (0..n as u32 - 2).map(|i| [0, i + 1, i + 2]).collect();
            let mesh = Mesh {
                name: "m".into(),
                positions,
                polygons: Polygons::from_triangles(&tris),
                ..Mesh::default()
            };
            let shapes = d
                .into_iter()
                .enumerate()
                .map(|(k, offs)| {
                    let mut delta = ShapeDelta {
                        mesh: 0,
                        vertices: vec![],
                        offsets: vec![],
                    };
                    for (v, o) in offs.into_iter().enumerate() {
                        if let Some((x, y, z)) = o {
                            let o = Vec3::new(x, y, z);
                            if o != Vec3::ZERO {
                                delta.vertices.push(v as u32);
                                delta.offsets.push(o);
                            }
                        }
                    }
                    BlendShape {
                        name: format!("shape{k}"),
                        default_weight: 0.0,
                        deltas: if delta.vertices.is_empty() {
                            vec![]
                        } else {
                            vec![delta]
                        },
                    }
                })
                .collect();
            Rig {
                name: "p".into(),
                meshes: vec![RigMesh {
                    name: "m".into(),
                    mesh,
                }],
                shapes,
                warnings: vec![],
                source: None,
            }
        })
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]
    #[test]
    fn any_rig_round_trips_through_glb(rig in arb_rig()) {
        let back = round_trip(&rig, true);
        assert_same_rig(&rig, &back);
    }
}
