//! fbakit's own feature-point XML (`specs/feature-points-xml.md`):
//!
//! ```xml
//! <featurePoints version="1" units="m">
//!   <fapu irisd0="0.011" es0="0.064" ens0="0.042" mns0="0.021" mw0="0.052"/>
//!   <point id="3.5" x="0.032" y="0.041" z="0.046" mesh="skin" vertices="12 13"/>
//! </featurePoints>
//! ```
//!
//! Coordinates are in the MPEG-4 face frame (+x the face's left, +y up, +z towards the viewer).
//! The reader is strict: unknown elements or attributes, duplicate points, non-finite numbers
//! and DTDs are located errors.

use std::fmt::Write as _;
use std::path::Path;

use glam::Vec3;
use quick_xml::events::{BytesStart, Event};
use serde::Serialize;

use super::xml_support::{
    attributes, element_name, escape_attr, parse_f32, parse_f64, parse_indices, Attr, XmlCursor,
};
use crate::error::{Error, Result};
use crate::fdp::{FapuDistances, FeaturePoint, FeaturePointSet, VertexBinding};
use crate::spec::FeaturePointId;

/// The only schema version this reader knows.
pub const XML_VERSION: &str = "1";

/// The content of one fbakit feature-point XML file.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct FeaturePointDocument {
    /// Free-text length unit of the coordinates (e.g. `m`, `mm`, `model`).
    pub units: Option<String>,
    /// Explicit FAPU distances that override the ones measured on the points.
    pub fapu: Option<FapuDistances>,
    /// The points.
    pub points: FeaturePointSet,
}

/// Reads an fbakit feature-point XML file.
pub fn read_xml_file(path: &Path) -> Result<FeaturePointDocument> {
    let text = crate::io::read_text(path)?;
    parse_xml(&text, path)
}

/// Parses fbakit feature-point XML text; `file` is used in error locations only.
pub fn parse_xml(text: &str, file: &Path) -> Result<FeaturePointDocument> {
    let mut cur = XmlCursor::new(file, text);
    let mut doc: Option<FeaturePointDocument> = None;
    let mut root_closed = false;
    loop {
        let ev = cur.next()?;
        match ev {
            Event::Decl(_) | Event::Comment(_) | Event::PI(_) => {}
            Event::DocType(_) => {
                return Err(cur.error("no DOCTYPE (DTDs and entities are not supported)"))
            }
            Event::Eof => break,
            Event::Start(e) | Event::Empty(e) if doc.is_some() || root_closed => {
                let _ = e;
                return Err(cur.error("end of document after </featurePoints>"));
            }
            Event::Start(e) => {
                doc = Some(read_root(&mut cur, &e, false)?);
                root_closed = true;
            }
            Event::Empty(e) => {
                doc = Some(read_root(&mut cur, &e, true)?);
                root_closed = true;
            }
            Event::Text(t) if t.as_ref().trim().is_empty() => {}
            _ => return Err(cur.error("a <featurePoints> root element")),
        }
    }
    doc.ok_or_else(|| cur.error_at(text.len(), "a <featurePoints> root element"))
}

fn read_root<'a>(
    cur: &mut XmlCursor<'a>,
    e: &BytesStart<'a>,
    empty: bool,
) -> Result<FeaturePointDocument> {
    if element_name(e) != "featurePoints" {
        return Err(cur.error("a <featurePoints> root element"));
    }
    let mut version = None;
    let mut units = None;
    for a in attributes(cur, e) {
        let a = a?;
        match a.name.as_str() {
            "version" => set_once(cur, &mut version, &a, a.value.to_string())?,
            "units" => set_once(cur, &mut units, &a, a.value.to_string())?,
            "xmlns" => {}
            _ => return Err(unknown_attr(cur, &a, "version, units")),
        }
    }
    match version.as_deref() {
        Some(XML_VERSION) => {}
        Some(v) => {
            return Err(cur.error(format!(
                "version=\"{XML_VERSION}\" (this reader knows no version `{v}`)"
            )))
        }
        None => return Err(cur.error("a version=\"1\" attribute on <featurePoints>")),
    }
    let mut doc = FeaturePointDocument {
        units,
        fapu: None,
        points: FeaturePointSet::new(),
    };
    if empty {
        return Ok(doc);
    }
    let mut fapu_seen = false;
    loop {
        let ev = cur.next()?;
        let (e, is_empty) = match ev {
            Event::End(_) => return Ok(doc),
            Event::Comment(_) | Event::PI(_) => continue,
            Event::Text(t) if t.as_ref().trim().is_empty() => continue,
            Event::Start(e) => (e, false),
            Event::Empty(e) => (e, true),
            _ => return Err(cur.error("<fapu>, <point> or </featurePoints>")),
        };
        match element_name(&e).as_str() {
            "point" => {
                let start = cur.event_start;
                let p = read_point(cur, &e)?;
                if doc.points.contains(p.id) {
                    return Err(cur.error_at(start, format!("each point once ({} repeats)", p.id)));
                }
                doc.points.insert(p);
            }
            "fapu" => {
                if fapu_seen {
                    return Err(cur.error("at most one <fapu> element"));
                }
                fapu_seen = true;
                doc.fapu = Some(read_fapu(cur, &e)?);
            }
            _ => return Err(cur.error("<fapu>, <point> or </featurePoints>")),
        }
        if !is_empty {
            expect_end(cur)?;
        }
    }
}

/// After `<x ...>`: only whitespace or comments up to `</x>`.
fn expect_end(cur: &mut XmlCursor<'_>) -> Result<()> {
    loop {
        match cur.next()? {
            Event::End(_) => return Ok(()),
            Event::Comment(_) => {}
            Event::Text(t) if t.as_ref().trim().is_empty() => {}
            _ => return Err(cur.error("an empty element (no content)")),
        }
    }
}

fn set_once<T>(cur: &XmlCursor<'_>, slot: &mut Option<T>, a: &Attr<'_>, v: T) -> Result<()> {
    if slot.is_some() {
        return Err(cur.error_at(a.offset, format!("the attribute `{}` once", a.name)));
    }
    *slot = Some(v);
    Ok(())
}

fn unknown_attr(cur: &XmlCursor<'_>, a: &Attr<'_>, known: &str) -> Error {
    // Point at the name, which sits just before `="value"`.
    let at = a.offset.saturating_sub(a.name.len() + 2);
    cur.error_at(at, format!("one of the attributes {known}"))
}

fn read_fapu(cur: &XmlCursor<'_>, e: &BytesStart<'_>) -> Result<FapuDistances> {
    const NAMES: [&str; 5] = ["irisd0", "es0", "ens0", "mns0", "mw0"];
    let mut vals: [Option<f64>; 5] = [None; 5];
    for a in attributes(cur, e) {
        let a = a?;
        let Some(k) = NAMES.iter().position(|n| *n == a.name) else {
            return Err(unknown_attr(cur, &a, "irisd0, es0, ens0, mns0, mw0"));
        };
        let v = parse_f64(cur, &a)?;
        if v <= 0.0 {
            return Err(cur.error_at(a.offset, format!("a positive distance for `{}`", a.name)));
        }
        set_once(cur, &mut vals[k], &a, v)?;
    }
    let missing: Vec<&str> = NAMES
        .iter()
        .zip(vals)
        .filter(|(_, v)| v.is_none())
        .map(|(n, _)| *n)
        .collect();
    if !missing.is_empty() {
        return Err(cur.error(format!(
            "all five FAPU distances on <fapu> (missing: {})",
            missing.join(", ")
        )));
    }
    let v = vals.map(|v| v.unwrap_or_default());
    Ok(FapuDistances {
        irisd0: v[0],
        es0: v[1],
        ens0: v[2],
        mns0: v[3],
        mw0: v[4],
    })
}

fn read_point(cur: &XmlCursor<'_>, e: &BytesStart<'_>) -> Result<FeaturePoint> {
    let mut id: Option<FeaturePointId> = None;
    let mut xyz: [Option<f32>; 3] = [None; 3];
    let mut mesh: Option<String> = None;
    let mut vertices: Option<Vec<u32>> = None;
    for a in attributes(cur, e) {
        let a = a?;
        match a.name.as_str() {
            "id" => {
                let v: FeaturePointId = a.value.parse().map_err(|msg: String| {
                    cur.error_at(
                        a.offset,
                        format!("a feature point label such as 3.5 ({msg})"),
                    )
                })?;
                set_once(cur, &mut id, &a, v)?;
            }
            "x" | "y" | "z" => {
                let k = (a.name.as_bytes()[0] - b'x') as usize;
                let v = parse_f32(cur, &a)?;
                set_once(cur, &mut xyz[k], &a, v)?;
            }
            "mesh" => {
                if a.value.trim().is_empty() {
                    return Err(cur.error_at(a.offset, "a non-empty mesh name"));
                }
                set_once(cur, &mut mesh, &a, a.value.to_string())?;
            }
            "vertices" => {
                let v = parse_indices(cur, &a.value, a.offset, "vertices")?;
                if v.is_empty() {
                    return Err(cur.error_at(a.offset, "at least one vertex index"));
                }
                set_once(cur, &mut vertices, &a, v)?;
            }
            _ => return Err(unknown_attr(cur, &a, "id, x, y, z, mesh, vertices")),
        }
    }
    let Some(id) = id else {
        return Err(cur.error("an id attribute on <point>"));
    };
    let position = match xyz {
        [Some(x), Some(y), Some(z)] => Some(Vec3::new(x, y, z)),
        [None, None, None] => None,
        _ => return Err(cur.error(format!("all of x, y, z or none of them on point {id}"))),
    };
    let binding = match (mesh, vertices) {
        (mesh, Some(vertices)) => Some(VertexBinding { mesh, vertices }),
        (Some(_), None) => {
            return Err(cur.error(format!("a vertices attribute with mesh on point {id}")))
        }
        (None, None) => None,
    };
    if position.is_none() && binding.is_none() {
        return Err(cur.error(format!("a position (x, y, z) or vertices on point {id}")));
    }
    Ok(FeaturePoint {
        id,
        position,
        binding,
    })
}

/// The document as XML text (points in label order, numbers in shortest round-trip form).
pub fn to_xml_string(doc: &FeaturePointDocument) -> String {
    let mut s = String::from("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
    s.push_str("<featurePoints version=\"1\"");
    if let Some(u) = &doc.units {
        let _ = write!(s, " units=\"{}\"", escape_attr(u));
    }
    s.push_str(">\n");
    if let Some(f) = &doc.fapu {
        let _ = writeln!(
            s,
            "  <fapu irisd0=\"{}\" es0=\"{}\" ens0=\"{}\" mns0=\"{}\" mw0=\"{}\"/>",
            f.irisd0, f.es0, f.ens0, f.mns0, f.mw0
        );
    }
    for p in doc.points.iter() {
        let _ = write!(s, "  <point id=\"{}\"", p.id);
        if let Some(v) = p.position {
            let _ = write!(s, " x=\"{}\" y=\"{}\" z=\"{}\"", v.x, v.y, v.z);
        }
        if let Some(b) = &p.binding {
            if let Some(m) = &b.mesh {
                let _ = write!(s, " mesh=\"{}\"", escape_attr(m));
            }
            let list: Vec<String> = b.vertices.iter().map(u32::to_string).collect();
            let _ = write!(s, " vertices=\"{}\"", list.join(" "));
        }
        s.push_str("/>\n");
    }
    s.push_str("</featurePoints>\n");
    s
}

/// Writes the document to `path` atomically.
pub fn write_xml_file(path: &Path, doc: &FeaturePointDocument) -> Result<()> {
    crate::io::write_atomic(path, to_xml_string(doc).as_bytes())
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn parse(text: &str) -> Result<FeaturePointDocument> {
        parse_xml(text, Path::new("f.xml"))
    }

    fn err(text: &str) -> String {
        parse(text).unwrap_err().to_string()
    }

    const GOOD: &str = r#"<?xml version="1.0"?>
<!-- a face -->
<featurePoints version="1" units="m">
  <fapu irisd0="0.5" es0="3" ens0="3" mns0="2" mw0="2.5"/>
  <point id="3.5" x="1.5" y="10" z="1"/>
  <point id="2.1" mesh="skin" vertices="12 13"/>
  <point id="9.15" x="0" y="7" z="2" vertices="4"></point>
</featurePoints>
"#;

    #[test]
    fn reads_positions_bindings_and_fapu() {
        let d = parse(GOOD).unwrap();
        assert_eq!(d.units.as_deref(), Some("m"));
        assert_eq!(d.fapu.unwrap().mw0, 2.5);
        assert_eq!(d.points.len(), 3);
        let p = d.points.get("2.1".parse().unwrap()).unwrap();
        assert_eq!(p.position, None);
        let b = p.binding.as_ref().unwrap();
        assert_eq!(
            (b.mesh.as_deref(), b.vertices.as_slice()),
            (Some("skin"), &[12, 13][..])
        );
        let p = d.points.get("9.15".parse().unwrap()).unwrap();
        assert_eq!(p.position, Some(Vec3::new(0.0, 7.0, 2.0)));
        assert_eq!(p.binding, Some(VertexBinding::vertex(4)));
        assert_eq!(parse(&to_xml_string(&d)).unwrap(), d);
    }

    #[test]
    fn located_errors() {
        let head = "<featurePoints version=\"1\">\n";
        let cases: Vec<(String, &str)> = vec![
            (format!("{head}<point id=\"1.1\" x=\"0\" y=\"0\" z=\"0\"/>"), "f.xml:2:12: expected a feature point label"),
            (format!("{head}<point id=\"2.1\" x=\"NaN\" y=\"0\" z=\"0\"/>"), "f.xml:2:20: expected a finite number for `x`, found `NaN`"),
            (format!("{head}<point id=\"2.1\" x=\"1e39\" y=\"0\" z=\"0\"/>"), "f.xml:2:20: expected a coordinate within"),
            (format!("{head}<point id=\"2.1\" x=\"abc\" y=\"0\" z=\"0\"/>"), "f.xml:2:20: expected a finite number"),
            (format!("{head}<point id=\"2.1\" x=\"1\"/>"), "f.xml:2:1: expected all of x, y, z or none"),
            (format!("{head}<point id=\"2.1\"/>"), "f.xml:2:1: expected a position (x, y, z) or vertices"),
            (format!("{head}<point x=\"1\" y=\"1\" z=\"1\"/>"), "f.xml:2:1: expected an id attribute"),
            (format!("{head}<point id=\"2.1\" mesh=\"a\"/>"), "f.xml:2:1: expected a vertices attribute with mesh"),
            (format!("{head}<point id=\"2.1\" vertices=\"1 x\"/>"), "f.xml:2:29: expected vertices: 0-based"),
            (format!("{head}<point id=\"2.1\" vertices=\"1\"/>\n<point id=\"2.1\" vertices=\"2\"/>\n</featurePoints>"), "f.xml:3:1: expected each point once (2.1 repeats)"),
            (format!("{head}<point id=\"2.1\" colour=\"red\" vertices=\"1\"/>"), "f.xml:2:17: expected one of the attributes id, x, y, z, mesh, vertices"),
            (format!("{head}<point id=\"2.1\" vertices=\"1\" vertices=\"2\"/>"), "f.xml:2:40: expected the attribute `vertices` once"),
            (format!("{head}<pt/>"), "f.xml:2:1: expected <fapu>, <point> or </featurePoints>"),
            (format!("{head}hello"), "f.xml:2:1: expected <fapu>, <point> or </featurePoints>"),
            (format!("{head}<point id=\"2.1\" vertices=\"1\">x</point>"), "f.xml:2:30: expected an empty element"),
            (format!("{head}<fapu irisd0=\"1\" es0=\"1\"/>"), "f.xml:2:1: expected all five FAPU distances on <fapu> (missing: ens0, mns0, mw0)"),
            (format!("{head}<fapu irisd0=\"0\" es0=\"1\" ens0=\"1\" mns0=\"1\" mw0=\"1\"/>"), "f.xml:2:15: expected a positive distance for `irisd0`"),
            (format!("{head}<point id=\"2.1\" vertices=\"1\"/>"), "f.xml:2:31: expected the closing tags (the document is truncated)"),
            ("<featurePoints version=\"2\"/>".to_string(), "f.xml:1:1: expected version=\"1\""),
            ("<featurePoints/>".to_string(), "f.xml:1:1: expected a version=\"1\" attribute"),
            ("<fp version=\"1\"/>".to_string(), "f.xml:1:1: expected a <featurePoints> root element"),
            ("".to_string(), "f.xml:1:1: expected a <featurePoints> root element"),
            ("<featurePoints version=\"1\"/><featurePoints version=\"1\"/>".to_string(), "f.xml:1:29: expected end of document"),
            ("<!DOCTYPE x [<!ENTITY a \"b\">]><featurePoints version=\"1\"/>".to_string(), "f.xml:1:1: expected no DOCTYPE"),
            ("<featurePoints version=\"1\" units=\"&a;\"/>".to_string(), "f.xml:1:35: expected only the predefined XML entities"),
            ("<featurePoints version=\"1\"><point id=\"2.1\" vertices=\"1\"></featurePoints>".to_string(), "f.xml:1:57: expected well-formed XML"),
        ];
        let mut failures = Vec::new();
        for (text, want) in cases {
            let e = err(&text);
            if !e.starts_with(want) {
                failures.push(format!("{text:?}\n  got:  {e}\n  want: {want}"));
            }
        }
        assert!(failures.is_empty(), "{}", failures.join("\n"));
    }

    #[test]
    fn deep_nesting_is_bounded() {
        let depth = 100_000;
        let text = format!(
            "<featurePoints version=\"1\">{}{}</featurePoints>",
            "<a>".repeat(depth),
            "</a>".repeat(depth)
        );
        assert!(err(&text).contains("expected <fapu>, <point>"));
        // Nesting inside a point is refused as content.
        let text = format!(
            "<featurePoints version=\"1\"><point id=\"2.1\" vertices=\"1\">{}",
            "<a>".repeat(depth)
        );
        assert!(err(&text).contains("expected an empty element"));
    }

    #[test]
    fn million_attributes_fail_fast() {
        let mut text = String::from("<featurePoints version=\"1\"><point id=\"2.1\"");
        for i in 0..1_000_000 {
            let _ = write!(text, " a{i}=\"1\"");
        }
        text.push_str("/></featurePoints>");
        assert!(err(&text).contains("expected one of the attributes"));
    }

    #[test]
    fn escaped_text_round_trips() {
        let d = FeaturePointDocument {
            units: Some("\"m\" & <cm>\ttab".into()),
            fapu: None,
            points: [FeaturePoint::bound(
                "2.1".parse().unwrap(),
                VertexBinding {
                    mesh: Some("a&b'<".into()),
                    vertices: vec![0],
                },
            )]
            .into_iter()
            .collect(),
        };
        assert_eq!(parse(&to_xml_string(&d)).unwrap(), d);
    }

    fn arb_point() -> impl Strategy<Value = FeaturePoint> {
        let coord = -1.0e6f32..1.0e6f32;
        (
            0usize..84,
            proptest::option::of((coord.clone(), coord.clone(), coord)),
            proptest::option::of((
                proptest::option::of("[a-zA-Z0-9_.&<>\" -]{1,12}"),
                proptest::collection::vec(any::<u32>(), 1..4),
            )),
        )
            .prop_filter("needs position or binding", |(_, p, b)| {
                p.is_some() || b.is_some()
            })
            .prop_map(|(o, p, b)| FeaturePoint {
                id: FeaturePointId::from_ordinal(o).unwrap(),
                position: p.map(|(x, y, z)| Vec3::new(x, y, z)),
                binding: b.map(|(mesh, vertices)| VertexBinding {
                    mesh: mesh.filter(|m| !m.trim().is_empty()),
                    vertices,
                }),
            })
    }

    proptest! {
        #[test]
        fn round_trip(
            points in proptest::collection::vec(arb_point(), 0..20),
            units in proptest::option::of("[ -~]{0,10}"),
            fapu in proptest::option::of((1e-6f64..1e6, 1e-6f64..1e6, 1e-6f64..1e6, 1e-6f64..1e6, 1e-6f64..1e6)),
        ) {
            let d = FeaturePointDocument {
                units,
                fapu: fapu.map(|(a, b, c, d, e)| FapuDistances { irisd0: a, es0: b, ens0: c, mns0: d, mw0: e }),
                points: points.into_iter().collect(),
            };
            let text = to_xml_string(&d);
            let back = parse(&text).unwrap();
            prop_assert_eq!(&back, &d);
            prop_assert_eq!(to_xml_string(&back), text);
        }
    }
}
