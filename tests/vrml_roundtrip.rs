//! Round trips of the VRML97 reader/writer: a handwritten face-like file (snapshot of the
//! canonical output) and generated scenes (property test).

use std::path::Path;

use fbakit::vrml::{
    parse_vrml, parse_vrml_str, read_vrml_file, write_vrml_string, FieldValue, Node, NodeId,
    NodeRef, Scene, UntypedItem,
};
use proptest::prelude::*;

const FACE: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/vrml/face.wrl");

#[test]
fn face_file_reads_with_shared_meshes() {
    let s = read_vrml_file(Path::new(FACE)).unwrap();
    let mesh = s.nodes_of_type("FaceDefMesh").next().unwrap();
    let target = s.get_sfnode(mesh, "faceSceneGraphNode").unwrap();
    assert_eq!(s.node(target).type_name, "IndexedFaceSet");
    assert_eq!(Some(target), s.find_def("FaceMesh"));
    assert_eq!(
        s.get_mfint32(mesh, "intervalBorders"),
        Some(&[-100, 0, 1000][..])
    );
    assert_eq!(s.get_mfvec3f(mesh, "displacements").unwrap().len(), 6);
    let coords = s.get_sfnode(target, "coord").unwrap();
    assert_eq!(s.get_mfvec3f(coords, "point").unwrap().len(), 8);
    // The eyes' transforms are the same nodes as in the head, not copies.
    let eyes: Vec<NodeId> = s
        .nodes_of_type("FaceDefTransform")
        .map(|t| s.get_sfnode(t, "faceSceneGraphNode").unwrap())
        .collect();
    assert_eq!(
        eyes,
        vec![
            s.find_def("LeftEye").unwrap(),
            s.find_def("RightEye").unwrap()
        ]
    );
    let visit = s
        .depth_first()
        .into_iter()
        .find(|v| v.id == target && !v.via_use)
        .unwrap();
    assert_eq!(
        s.path_string(&visit.path),
        "Transform(DEF Head) > Shape(DEF Skin) > IndexedFaceSet(DEF FaceMesh)"
    );
    assert_eq!(s.routes().count(), 1);
    let vendor = s.nodes_of_type("VendorMetadata").next().unwrap();
    assert!(matches!(
        s.field(vendor, "ref"),
        Some(FieldValue::Untyped { .. })
    ));
}

#[test]
fn face_file_round_trips_and_matches_snapshot() {
    let s = read_vrml_file(Path::new(FACE)).unwrap();
    let text = write_vrml_string(&s);
    let again = parse_vrml_str(&text).unwrap();
    assert_eq!(again, s);
    // Canonical: writing the re-read scene gives the same text.
    assert_eq!(write_vrml_string(&again), text);
    insta::assert_snapshot!("face_canonical", text);
}

/// A choice stream from proptest drives scene generation (shrinks with the stream).
struct Gen<'a> {
    bytes: &'a [u32],
    at: usize,
}

impl Gen<'_> {
    fn next(&mut self) -> u32 {
        let v = self.bytes.get(self.at).copied().unwrap_or(0);
        self.at += 1;
        v
    }
    fn below(&mut self, n: u32) -> u32 {
        self.next() % n.max(1)
    }
    fn float(&mut self) -> f32 {
        let bits = self.next();
        let f = f32::from_bits(bits);
        if f.is_finite() {
            f
        } else {
            (bits % 2000) as f32 / 7.0
        }
    }
    fn string(&mut self) -> String {
        let alphabet = ['a', 'Z', ' ', '"', '\\', '#', '\n', 'é', ',', '[', '}'];
        (0..self.below(6))
            .map(|_| alphabet[self.below(alphabet.len() as u32) as usize])
            .collect()
    }
}

/// Builds a scene: nested Transform/Group/Shape/IndexedFaceSet/FAP/unknown nodes with DEF
/// names and USEs of finished (never ancestor) nodes.
fn gen_node(g: &mut Gen, s: &mut Scene, depth: usize, defs: &mut Vec<NodeId>) -> NodeRef {
    if !defs.is_empty() && g.below(5) == 0 {
        let id = defs[g.below(defs.len() as u32) as usize];
        return NodeRef { id, is_use: true };
    }
    let kind = if depth > 4 {
        3 + g.below(4)
    } else {
        g.below(7)
    };
    let type_name = [
        "Transform",
        "Group",
        "Shape",
        "IndexedFaceSet",
        "FAP",
        "Material",
        "Thing",
    ][kind as usize];
    let id = s.add_node(Node::new(type_name));
    if g.below(3) == 0 {
        // Reusing names exercises DEF rebinding. A file binds the name at its DEF, before the
        // body, so the old binding is unusable from here on; the node itself becomes usable
        // once finished (a node cannot contain itself).
        let name = format!("N{}", g.below(4));
        defs.retain(|d| s.nodes[d.0].def_name.as_deref() != Some(name.as_str()));
        s.nodes[id.0].def_name = Some(name);
    }
    let mut fields: Vec<(String, FieldValue)> = Vec::new();
    match type_name {
        "Transform" | "Group" => {
            if type_name == "Transform" && g.below(2) == 0 {
                fields.push((
                    "translation".into(),
                    FieldValue::SFVec3f([g.float(), g.float(), g.float()]),
                ));
            }
            let n = g.below(4);
            let kids = (0..n).map(|_| gen_node(g, s, depth + 1, defs)).collect();
            fields.push(("children".into(), FieldValue::MFNode(kids)));
        }
        "Shape" => {
            let geo = gen_node(g, s, depth + 1, defs);
            fields.push(("geometry".into(), FieldValue::SFNode(Some(geo))));
            fields.push(("appearance".into(), FieldValue::SFNode(None)));
        }
        "IndexedFaceSet" => {
            let n = g.below(40) as usize;
            let pts = (0..n).map(|_| [g.float(), g.float(), g.float()]).collect();
            let c = s.add_node(Node::new("Coordinate"));
            s.nodes[c.0]
                .fields
                .push(("point".into(), FieldValue::MFVec3f(pts)));
            fields.push((
                "coord".into(),
                FieldValue::SFNode(Some(NodeRef {
                    id: c,
                    is_use: false,
                })),
            ));
            let idx = (0..g.below(60)).map(|_| g.next() as i32).collect();
            fields.push(("coordIndex".into(), FieldValue::MFInt32(idx)));
            fields.push(("solid".into(), FieldValue::SFBool(g.below(2) == 0)));
        }
        "FAP" => {
            fields.push(("open_jaw".into(), FieldValue::SFInt32(g.next() as i32)));
            fields.push((
                "stretch_l_cornerlip".into(),
                FieldValue::SFInt32(-(g.below(100) as i32)),
            ));
        }
        "Material" => {
            fields.push((
                "diffuseColor".into(),
                FieldValue::SFColor([g.float(), 0.5, 1.0]),
            ));
            fields.push(("shininess".into(), FieldValue::SFFloat(g.float())));
        }
        _ => {
            let items = (0..1 + g.below(4))
                .map(|_| match g.below(4) {
                    0 => UntypedItem::Number(format!("{}", g.next() as i32)),
                    1 => UntypedItem::String(g.string()),
                    2 => UntypedItem::Bool(g.below(2) == 0),
                    _ => UntypedItem::Null,
                })
                .collect();
            fields.push((
                "data".into(),
                FieldValue::Untyped {
                    bracketed: g.below(2) == 0,
                    items,
                },
            ));
            fields.push((
                "label".into(),
                FieldValue::Untyped {
                    bracketed: false,
                    items: vec![UntypedItem::String(g.string())],
                },
            ));
        }
    }
    s.nodes[id.0].fields = fields;
    let name = s.nodes[id.0].def_name.clone();
    // Usable only if no descendant rebound the name (file order decides the binding).
    if name.is_some() && s.nodes[id.0 + 1..].iter().all(|n| n.def_name != name) {
        defs.push(id);
    }
    NodeRef { id, is_use: false }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    #[test]
    fn generated_scenes_round_trip(choices in prop::collection::vec(any::<u32>(), 0..400)) {
        let mut g = Gen { bytes: &choices, at: 0 };
        let mut s = Scene::new();
        let mut defs = Vec::new();
        for _ in 0..1 + g.below(3) {
            let r = gen_node(&mut g, &mut s, 0, &mut defs);
            if !r.is_use {
                s.push_root(r.id);
            }
        }
        let text = write_vrml_string(&s);
        let again = parse_vrml(&text, Path::new("gen.wrl"))
            .map_err(|e| TestCaseError::fail(format!("{e}\n{text}")))?;
        prop_assert_eq!(&again, &s, "{}", text);
        prop_assert_eq!(write_vrml_string(&again), text);
    }
}
