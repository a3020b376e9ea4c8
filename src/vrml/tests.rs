//! Unit tests of the grammar rules and the scene model.

use super::*;

fn parse(body: &str) -> Scene {
    parse_vrml_str(&format!("#VRML V2.0 utf8\n{body}")).unwrap_or_else(|e| panic!("{e}"))
}

fn err(body: &str) -> String {
    parse_vrml_str(&format!("#VRML V2.0 utf8\n{body}"))
        .unwrap_err()
        .to_string()
}

fn round_trip(scene: &Scene) {
    let text = write_vrml_string(scene);
    let again = parse_vrml_str(&text).unwrap_or_else(|e| panic!("{e}\n{text}"));
    assert_eq!(&again, scene, "{text}");
}

#[test]
fn header_is_required_and_named() {
    let e = parse_vrml_str("Group {}").unwrap_err().to_string();
    assert!(
        e.starts_with("<input>:1:1: expected the header `#VRML V2.0 utf8`"),
        "{e}"
    );
    let e = parse_vrml_str("#VRML V1.0 ascii\n")
        .unwrap_err()
        .to_string();
    assert!(e.contains("found `#VRML V1.0 ascii`"), "{e}");
    assert!(parse_vrml_str("#VRML V2.0 utf8 by some exporter\n").is_ok());
    assert_eq!(parse_vrml_str("#VRML V2.0 utf8").unwrap().nodes.len(), 0);
}

#[test]
fn typed_fields_of_known_nodes() {
    let s = parse(
        "Transform { translation 1 2 3 rotation 0 1 0 1.57 scale 2 2 2
           children [ Shape { appearance Appearance { material Material { diffuseColor 1 0 0 shininess .5 } }
             geometry IndexedFaceSet { coord Coordinate { point [ 0 0 0, 1 0 0, 0 1 0 ] }
               coordIndex [ 0 1 2 -1 ] solid FALSE creaseAngle 1 } } ] }",
    );
    let t = NodeId(0);
    assert_eq!(scene_type(&s, t), "Transform");
    assert_eq!(s.get_sfvec3f(t, "translation"), Some([1.0, 2.0, 3.0]));
    assert_eq!(s.get_sfrotation(t, "rotation"), Some([0.0, 1.0, 0.0, 1.57]));
    let ifs = s.nodes_of_type("IndexedFaceSet").next().unwrap();
    assert_eq!(s.get_mfint32(ifs, "coordIndex"), Some(&[0, 1, 2, -1][..]));
    assert_eq!(s.get_sfbool(ifs, "solid"), Some(false));
    assert_eq!(s.get_sffloat(ifs, "creaseAngle"), Some(1.0));
    let coord = s.get_sfnode(ifs, "coord").unwrap();
    assert_eq!(s.get_mfvec3f(coord, "point").unwrap()[1], [1.0, 0.0, 0.0]);
    let mat = s.nodes_of_type("Material").next().unwrap();
    assert_eq!(
        s.field(mat, "diffuseColor"),
        Some(&FieldValue::SFColor([1.0, 0.0, 0.0]))
    );
    round_trip(&s);
}

fn scene_type(s: &Scene, id: NodeId) -> &str {
    &s.node(id).type_name
}

#[test]
fn single_values_for_mf_fields_and_hex_ints() {
    let s = parse("IndexedFaceSet { coordIndex 5 colorIndex 0x10 } WorldInfo { info \"a\" }");
    assert_eq!(s.get_mfint32(NodeId(0), "coordIndex"), Some(&[5][..]));
    assert_eq!(s.get_mfint32(NodeId(0), "colorIndex"), Some(&[16][..]));
    assert_eq!(
        s.get_mfstring(NodeId(1), "info").unwrap(),
        &["a".to_string()]
    );
    round_trip(&s);
}

#[test]
fn strings_times_images_and_vec2() {
    let s = parse(
        r#"WorldInfo { title "say \"hi\" \\ # not a comment" }
           TimeSensor { cycleInterval 1e10 startTime 0.125 }
           PixelTexture { image 2 1 3 0xFF0000 0x00FF00 }
           TextureCoordinate { point [ 0 0, 1 0.5 ] }"#,
    );
    assert_eq!(
        s.get_sfstring(NodeId(0), "title"),
        Some("say \"hi\" \\ # not a comment")
    );
    assert_eq!(
        s.field(NodeId(1), "cycleInterval"),
        Some(&FieldValue::SFTime(1e10))
    );
    match s.field(NodeId(2), "image") {
        Some(FieldValue::SFImage(img)) => assert_eq!(img.pixels, vec![0xFF0000, 0x00FF00]),
        other => panic!("{other:?}"),
    }
    assert_eq!(s.get_mfvec2f(NodeId(3), "point").unwrap()[1], [1.0, 0.5]);
    round_trip(&s);
}

#[test]
fn sf_image_declared_size_does_not_allocate() {
    let e = err("PixelTexture { image 100000 100000 4 1 2 }");
    assert!(e.contains("10000000000 SFImage pixel values"), "{e}");
    let e = err("PixelTexture { image 1 1 5 0 }");
    assert!(e.contains("component count in 0..=4"), "{e}");
}

#[test]
fn mpeg4_face_nodes_are_typed() {
    let s = parse(
        "DEF M IndexedFaceSet { coord Coordinate { point [ 0 0 0 ] } }
         Face { fap FAP { viseme Viseme { viseme_select1 3 viseme_def TRUE } open_jaw 100
                          stretch_l_cornerlip -20 expression Expression { init_face TRUE } }
           fdp FDP { useOrthoTexture TRUE faceDefTables [
             FaceDefTables { fapID 3 faceDefMesh FaceDefMesh { faceSceneGraphNode USE M
               intervalBorders [ 0 1000 ] coordIndex [ 0 ] displacements [ 0 -0.001 0 ] }
               faceDefTransform FaceDefTransform { fieldId 1 rotationDef 1 0 0 0.001 } } ] }
           fit FIT { FAPs [ 3 4 ] numeratorCoefs [ 0.5 ] } }",
    );
    let fap = s.nodes_of_type("FAP").next().unwrap();
    assert_eq!(s.get_sfint32(fap, "open_jaw"), Some(100));
    assert_eq!(s.get_sfint32(fap, "stretch_l_cornerlip"), Some(-20));
    let mesh = s.nodes_of_type("FaceDefMesh").next().unwrap();
    let target = s.get_sfnode(mesh, "faceSceneGraphNode").unwrap();
    assert_eq!(target, s.find_def("M").unwrap());
    assert_eq!(
        s.get_mfvec3f(mesh, "displacements").unwrap(),
        &[[0.0, -0.001, 0.0]]
    );
    round_trip(&s);
}

#[test]
fn unknown_field_of_a_known_node_lists_valid_fields() {
    let e = err("IndexedFaceSet {\n  coords [ 0 0 0 ] }");
    assert!(
        e.starts_with(
            "<input>:3:3: expected a field name of IndexedFaceSet (color, coord, normal,"
        ),
        "{e}"
    );
    assert!(e.ends_with("found `coords [ 0 0 0 ] }`"), "{e}");
    let e = err("FAP { stretch_l_corner_o 1 }");
    assert!(
        e.contains("a field name of FAP (viseme, expression, open_jaw"),
        "{e}"
    );
}

#[test]
fn bad_values_are_located() {
    let e = err("Transform { translation 1 2 }");
    assert!(
        e.contains("2:29: expected an SFVec3f value (3 finite numbers), found `}`"),
        "{e}"
    );
    let e = err("Coordinate { point [ 0 0 0, 1 1e99 1 ] }");
    assert!(
        e.contains("2:31: expected an SFVec3f value (3 finite numbers) or `]`"),
        "{e}"
    );
    let e = err("Coordinate { point [ 0 0 nan ] }");
    assert!(e.contains("found `nan ] }`"), "{e}");
    let e = err("IndexedFaceSet { coordIndex [ 1 2.5 ] }");
    assert!(
        e.contains("an SFInt32 value (a 32-bit integer) or `]`, found `2.5 ] }`"),
        "{e}"
    );
    let e = err("IndexedFaceSet { solid yes }");
    assert!(e.contains("an SFBool value (TRUE or FALSE)"), "{e}");
    let e = err("WorldInfo { title \"open }");
    assert!(e.contains("an SFString value (a quoted string)"), "{e}");
    let e = err("Group { children [ Shape {} ");
    assert!(e.contains("found end of input"), "{e}");
    let e = err("Group ");
    assert!(e.contains("`{` to open the body of Group"), "{e}");
    let e = err("Group { bboxSize 1 1 1 bboxSize 2 2 2 }");
    assert!(
        e.contains("at most once (`bboxSize` is already set)"),
        "{e}"
    );
    let e = err("Group {} }");
    assert!(
        e.contains("expected a node, PROTO, EXTERNPROTO or ROUTE, found `}`"),
        "{e}"
    );
}

#[test]
fn def_use_shares_nodes_and_is_written_as_use() {
    let s = parse(
        "DEF A Coordinate { point [ 1 2 3 ] }
         IndexedFaceSet { coord USE A }
         IndexedLineSet { coord USE A }",
    );
    let a = s.find_def("A").unwrap();
    assert_eq!(s.get_sfnode(NodeId(1), "coord"), Some(a));
    assert_eq!(s.get_sfnode(NodeId(2), "coord"), Some(a));
    assert_eq!(s.nodes.len(), 3, "USE does not copy");
    let text = write_vrml_string(&s);
    assert_eq!(text.matches("USE A").count(), 2, "{text}");
    assert_eq!(text.matches("DEF A").count(), 1, "{text}");
    round_trip(&s);
}

#[test]
fn use_errors() {
    let e = err("Group { children [ USE Nope ] }");
    assert!(
        e.contains("2:24: expected a name defined earlier with DEF, found `Nope ] }`"),
        "{e}"
    );
    let e = err("DEF A Group { children [ Group { children USE A } ] }");
    assert!(e.contains("a USE outside the definition of `A`"), "{e}");
}

#[test]
fn redefined_def_rebinds_for_later_uses() {
    let s = parse(
        "DEF A Coordinate { point 1 1 1 } IndexedFaceSet { coord USE A }
         DEF A Coordinate { point 2 2 2 } IndexedFaceSet { coord USE A }",
    );
    assert_eq!(s.get_sfnode(NodeId(1), "coord"), Some(NodeId(0)));
    assert_eq!(s.get_sfnode(NodeId(3), "coord"), Some(NodeId(2)));
    assert_eq!(s.find_def("A"), Some(NodeId(2)));
    round_trip(&s);
}

#[test]
fn unknown_nodes_are_kept_generically() {
    let s = parse(
        r#"Foo { a 1 0x1F -2.50 b "s" TRUE c [ 1, 2, Bar { x NULL } USE D ] d Baz {} e [] f USE D }"#
            .replace("USE D ] d", "] d")
            .replace("f USE D", "f NULL")
            .as_str(),
    );
    let foo = NodeId(0);
    assert_eq!(
        s.field(foo, "a"),
        Some(&FieldValue::Untyped {
            bracketed: false,
            items: vec![
                UntypedItem::Number("1".into()),
                UntypedItem::Number("0x1F".into()),
                UntypedItem::Number("-2.50".into())
            ]
        })
    );
    assert_eq!(s.children(foo).len(), 2);
    round_trip(&s);
    let e = err("Foo { a 1e999 }");
    assert!(
        e.contains("expected a finite number, found `1e999 }`"),
        "{e}"
    );
    let e = err("Foo { a bar }");
    assert!(e.contains("expected a field value, found `bar }`"), "{e}");
}

#[test]
fn proto_and_externproto_are_kept_verbatim() {
    let proto = "PROTO Face [ field SFFloat x 1 # ] comment\n field MFString s [ \"}\" ] ] {\n  Group { children [] } }";
    let ext = "EXTERNPROTO Ext [ field SFInt32 n ] [ \"a.wrl#Ext\", \"b.wrl\" ]";
    let s = parse(&format!("{proto}\n{ext}\nFace {{ x 2 }} Ext {{ n 3 }}"));
    assert_eq!(
        s.statements[0],
        Statement::Proto {
            name: "Face".into(),
            text: proto.into()
        }
    );
    assert_eq!(
        s.statements[1],
        Statement::ExternProto {
            name: "Ext".into(),
            text: ext.into()
        }
    );
    // A PROTO named like a built-in node makes its instances generic.
    assert!(matches!(
        s.field(NodeId(0), "x"),
        Some(FieldValue::Untyped { .. })
    ));
    round_trip(&s);
    let e = err("PROTO P [ field SFInt32 x 1 { }");
    assert!(e.contains("a matching `]` for this `[`"), "{e}");
}

#[test]
fn routes_and_unsupported_constructs() {
    let s =
        parse("DEF T TimeSensor {} DEF X Transform {} ROUTE T . fraction_changed TO X.set_scale");
    assert_eq!(
        s.routes().next().unwrap(),
        &Route {
            from_node: "T".into(),
            from_field: "fraction_changed".into(),
            to_node: "X".into(),
            to_field: "set_scale".into()
        }
    );
    round_trip(&s);
    let e = err("ROUTE T.a TO X.b");
    assert!(
        e.contains("2:7: expected a DEF name defined before this ROUTE"),
        "{e}"
    );
    let e = err("Script { url \"x.js\" }");
    assert!(e.contains("Script nodes are not supported"), "{e}");
    let e = err("DEF T TimeSensor {} Group { ROUTE T.a TO T.b }");
    assert!(
        e.contains("ROUTE inside a node body is not supported"),
        "{e}"
    );
}

#[test]
fn comments_and_commas_are_separators() {
    let s = parse("# c1\nCoordinate { # c2\n point [ 1,2,3, # c3\n 4 5 6 ] } # end");
    assert_eq!(
        s.get_mfvec3f(NodeId(0), "point").unwrap(),
        &[[1.0, 2.0, 3.0], [4.0, 5.0, 6.0]]
    );
}

#[test]
fn nesting_is_bounded_without_stack_overflow() {
    let deep = "Group { children [ ".repeat(100_000);
    let e = err(&deep);
    assert!(e.contains("at most 256 levels of nested nodes"), "{e}");
    // Exactly at the limit is accepted and round-trips.
    let ok = format!(
        "{}{}",
        "Group { children [ ".repeat(MAX_DEPTH),
        " ] } ".repeat(MAX_DEPTH)
    );
    let s = parse(&ok);
    assert_eq!(s.nodes.len(), MAX_DEPTH);
    round_trip(&s);
    let visits = s.depth_first();
    assert_eq!(visits.last().unwrap().path.len(), MAX_DEPTH);
}

#[test]
fn locations_and_paths_for_messages() {
    let s = parse("DEF Head Transform {\n  children Shape { geometry IndexedFaceSet {} } }");
    let ifs = s.nodes_of_type("IndexedFaceSet").next().unwrap();
    assert_eq!(s.node(ifs).location.to_string(), "<input>:3:29");
    assert_eq!(s.node(NodeId(0)).location.line, 2);
    let visits = s.depth_first();
    let v = visits.iter().find(|v| v.id == ifs).unwrap();
    assert_eq!(
        s.path_string(&v.path),
        "Transform(DEF Head) > Shape > IndexedFaceSet"
    );
}

#[test]
fn depth_first_visits_uses_without_descending() {
    let s = parse("DEF S Shape { geometry Box {} } Group { children [ USE S Shape {} ] }");
    let order: Vec<(usize, bool)> = s
        .depth_first()
        .iter()
        .map(|v| (v.id.0, v.via_use))
        .collect();
    assert_eq!(
        order,
        vec![(0, false), (1, false), (2, false), (0, true), (3, false)]
    );
}

#[test]
fn non_utf8_file_is_a_located_error() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("bad.wrl");
    std::fs::write(&p, b"#VRML V2.0 utf8\nGroup { \xff }").unwrap();
    let e = read_vrml_file(&p).unwrap_err().to_string();
    assert!(e.contains("bad.wrl:2:9: expected UTF-8 text"), "{e}");
    let out = dir.path().join("out.wrl");
    let s = parse("Group {}");
    write_vrml_file(&out, &s).unwrap();
    assert_eq!(read_vrml_file(&out).unwrap(), s);
}
