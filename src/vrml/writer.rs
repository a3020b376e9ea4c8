//! The canonical VRML97 writer: header, 2-space indentation, one field per line, DEF names
//! kept, `USE name` for shared nodes, MF values wrapped at [`LINE_WIDTH`], numbers in
//! shortest round-trip form (integers without a fraction), strings escaped.

use std::fmt::Write as _;
use std::path::Path;

use super::model::{FieldValue, NodeRef, Scene, Statement, UntypedItem};
use super::parser::{HEADER, MAX_DEPTH};
use crate::error::Result;

/// Lines of MF values are filled up to this many characters (indentation included).
pub const LINE_WIDTH: usize = 100;

/// The scene as canonical VRML97 text.
///
/// Each node is written in full at its first reference and as `USE name` at later ones when it
/// has a DEF name (parsed scenes always satisfy this). Scenes built in code that nest deeper
/// than [`MAX_DEPTH`] or contain a node inside itself are cut there with a `#` comment, since a
/// file cannot express them.
pub fn write_vrml_string(scene: &Scene) -> String {
    let mut w = Writer {
        scene,
        out: String::with_capacity(1024),
        written: vec![false; scene.nodes.len()],
        open: Vec::new(),
    };
    w.out.push_str(HEADER);
    w.out.push('\n');
    for s in &scene.statements {
        w.out.push('\n');
        match s {
            Statement::Node(r) => {
                w.node(*r, 0);
                w.out.push('\n');
            }
            Statement::Proto { text, .. } | Statement::ExternProto { text, .. } => {
                w.out.push_str(text);
                w.out.push('\n');
            }
            Statement::Route(r) => {
                let _ = writeln!(
                    w.out,
                    "ROUTE {}.{} TO {}.{}",
                    r.from_node, r.from_field, r.to_node, r.to_field
                );
            }
        }
    }
    w.out
}

/// Writes the scene's canonical text to `path` atomically.
pub fn write_vrml_file(path: &Path, scene: &Scene) -> Result<()> {
    crate::io::write_atomic(path, write_vrml_string(scene).as_bytes())
}

/// Formats an f32 in its shortest round-trip form: `2`, `0.1`, `1e-7`, `3.4028235e38`.
pub fn format_f32(out: &mut String, v: f32) {
    let a = v.abs();
    if a != 0.0 && !(1e-5..1e16).contains(&a) {
        let _ = write!(out, "{v:e}");
    } else {
        let _ = write!(out, "{v}");
    }
}

/// Formats an f64 in its shortest round-trip form.
pub fn format_f64(out: &mut String, v: f64) {
    let a = v.abs();
    if a != 0.0 && !(1e-5..1e16).contains(&a) {
        let _ = write!(out, "{v:e}");
    } else {
        let _ = write!(out, "{v}");
    }
}

/// Writes `s` as a quoted VRML string (`"` and `\` escaped).
pub fn format_string(out: &mut String, s: &str) {
    out.push('"');
    for c in s.chars() {
        if c == '"' || c == '\\' {
            out.push('\\');
        }
        out.push(c);
    }
    out.push('"');
}

fn format_floats(out: &mut String, v: &[f32]) {
    for (i, x) in v.iter().enumerate() {
        if i > 0 {
            out.push(' ');
        }
        format_f32(out, *x);
    }
}

struct Writer<'s> {
    scene: &'s Scene,
    out: String,
    written: Vec<bool>,
    open: Vec<usize>,
}

impl Writer<'_> {
    fn indent(&mut self, level: usize) {
        for _ in 0..level {
            self.out.push_str("  ");
        }
    }

    /// Writes a node reference at the current position (indentation already written).
    fn node(&mut self, r: NodeRef, level: usize) {
        let Some(node) = self.scene.nodes.get(r.id.0) else {
            self.out.push_str("NULL");
            return;
        };
        if let (true, Some(def)) = (self.written[r.id.0], &node.def_name) {
            let _ = write!(self.out, "USE {def}");
            return;
        }
        if self.open.len() >= MAX_DEPTH || self.open.contains(&r.id.0) {
            // Only reachable for scenes built in code; see write_vrml_string.
            self.out
                .push_str("Group {} # omitted: too deep or contains itself");
            return;
        }
        self.written[r.id.0] = true;
        if let Some(def) = &node.def_name {
            let _ = write!(self.out, "DEF {def} ");
        }
        self.out.push_str(&node.type_name);
        if node.fields.is_empty() {
            self.out.push_str(" {}");
            return;
        }
        self.out.push_str(" {\n");
        self.open.push(r.id.0);
        for (name, value) in &node.fields {
            self.indent(level + 1);
            self.out.push_str(name);
            self.out.push(' ');
            self.value(value, level + 1);
            self.out.push('\n');
        }
        self.open.pop();
        self.indent(level);
        self.out.push('}');
    }

    fn value(&mut self, v: &FieldValue, level: usize) {
        use FieldValue as V;
        let mut item = String::new();
        match v {
            V::SFBool(b) => self.out.push_str(if *b { "TRUE" } else { "FALSE" }),
            V::SFInt32(i) => {
                let _ = write!(self.out, "{i}");
            }
            V::SFFloat(f) => format_f32(&mut self.out, *f),
            V::SFTime(t) => format_f64(&mut self.out, *t),
            V::SFString(s) => format_string(&mut self.out, s),
            V::SFVec2f(a) => format_floats(&mut self.out, a),
            V::SFVec3f(a) | V::SFColor(a) => format_floats(&mut self.out, a),
            V::SFRotation(a) => format_floats(&mut self.out, a),
            V::SFImage(img) => {
                let _ = write!(self.out, "{} {} {}", img.width, img.height, img.components);
                let items = img.pixels.iter().map(|p| format!("0x{p:X}"));
                self.wrapped(items, level, " ");
            }
            V::SFNode(None) => self.out.push_str("NULL"),
            V::SFNode(Some(r)) => self.node(*r, level),
            V::MFInt32(v) => self.mf(v, level, false, |o, x| {
                let _ = write!(o, "{x}");
            }),
            V::MFFloat(v) => self.mf(v, level, false, |o, x| format_f32(o, *x)),
            V::MFTime(v) => self.mf(v, level, false, |o, x| format_f64(o, *x)),
            V::MFString(v) => self.mf(v, level, true, |o, x| format_string(o, x)),
            V::MFVec2f(v) => self.mf(v, level, true, |o, x| format_floats(o, x)),
            V::MFVec3f(v) | V::MFColor(v) => self.mf(v, level, true, |o, x| format_floats(o, x)),
            V::MFRotation(v) => self.mf(v, level, true, |o, x| format_floats(o, x)),
            V::MFNode(v) => self.mf_node(v.iter().map(|r| Some(*r)), v.len(), level),
            V::Untyped { bracketed, items } => {
                let has_node = items.iter().any(|i| matches!(i, UntypedItem::Node(_)));
                if has_node && (*bracketed || items.len() != 1) {
                    let refs: Vec<Option<NodeRef>> = items
                        .iter()
                        .map(|i| match i {
                            UntypedItem::Node(r) => Some(*r),
                            _ => None,
                        })
                        .collect();
                    // Scalars mixed with nodes are written on their own lines.
                    self.out.push_str("[\n");
                    for (i, r) in items.iter().zip(refs) {
                        self.indent(level + 1);
                        match r {
                            Some(r) => self.node(r, level + 1),
                            None => untyped_scalar(&mut self.out, i),
                        }
                        self.out.push('\n');
                    }
                    self.indent(level);
                    self.out.push(']');
                } else if let (false, [UntypedItem::Node(r)]) = (*bracketed, items.as_slice()) {
                    self.node(*r, level);
                } else {
                    let texts = items.iter().map(|i| {
                        item.clear();
                        untyped_scalar(&mut item, i);
                        item.clone()
                    });
                    if *bracketed {
                        self.bracketed(texts.collect(), level, " ");
                    } else {
                        let texts: Vec<String> = texts.collect();
                        let mut first = true;
                        self.wrapped_from_here(texts.into_iter(), &mut first, level, " ");
                    }
                }
            }
        }
    }

    fn mf<T>(&mut self, v: &[T], level: usize, comma: bool, mut f: impl FnMut(&mut String, &T)) {
        let sep = if comma { ", " } else { " " };
        // Short values stay on the field's line.
        let mut inline = String::new();
        for (i, x) in v.iter().enumerate() {
            if i > 0 {
                inline.push_str(sep);
            }
            f(&mut inline, x);
            if inline.len() > LINE_WIDTH {
                break;
            }
        }
        let line_start = self.out.rfind('\n').map_or(0, |p| p + 1);
        let used = self.out.len() - line_start;
        if v.is_empty() {
            self.out.push_str("[]");
        } else if used + inline.len() + 4 <= LINE_WIDTH {
            self.out.push_str("[ ");
            self.out.push_str(&inline);
            self.out.push_str(" ]");
        } else {
            self.out.push_str("[\n");
            let mut line_len = 0;
            let mut buf = String::new();
            let width = LINE_WIDTH - 2 * (level + 1);
            for (i, x) in v.iter().enumerate() {
                buf.clear();
                f(&mut buf, x);
                if comma && i + 1 < v.len() {
                    buf.push(',');
                }
                if line_len > 0 && line_len + 1 + buf.len() > width {
                    self.out.push('\n');
                    line_len = 0;
                }
                if line_len == 0 {
                    self.indent(level + 1);
                } else {
                    self.out.push(' ');
                    line_len += 1;
                }
                self.out.push_str(&buf);
                line_len += buf.len();
            }
            self.out.push('\n');
            self.indent(level);
            self.out.push(']');
        }
    }

    fn bracketed(&mut self, texts: Vec<String>, level: usize, sep: &str) {
        let total: usize = texts.iter().map(|t| t.len() + sep.len()).sum();
        if texts.is_empty() {
            self.out.push_str("[]");
        } else if total + 2 * level + 40 <= LINE_WIDTH {
            self.out.push_str("[ ");
            self.out.push_str(&texts.join(sep));
            self.out.push_str(" ]");
        } else {
            self.out.push_str("[\n");
            self.indent(level + 1);
            let mut first = true;
            self.wrapped_from_here(texts.into_iter(), &mut first, level + 1, sep);
            self.out.push('\n');
            self.indent(level);
            self.out.push(']');
        }
    }

    /// Appends items after the current text, each preceded by a separator.
    fn wrapped(&mut self, items: impl Iterator<Item = String>, level: usize, sep: &str) {
        let mut first = false;
        self.wrapped_from_here(items, &mut first, level, sep);
    }

    /// Appends items separated by `sep`, breaking lines (indented at `level`) past the width.
    fn wrapped_from_here(
        &mut self,
        items: impl Iterator<Item = String>,
        first: &mut bool,
        level: usize,
        sep: &str,
    ) {
        for t in items {
            let line_start = self.out.rfind('\n').map_or(0, |p| p + 1);
            let used = self.out.len() - line_start;
            if !*first {
                if used + sep.len() + t.len() > LINE_WIDTH {
                    self.out.push('\n');
                    self.indent(level);
                } else {
                    self.out.push_str(sep);
                }
            }
            *first = false;
            self.out.push_str(&t);
        }
    }

    fn mf_node(&mut self, refs: impl Iterator<Item = Option<NodeRef>>, len: usize, level: usize) {
        if len == 0 {
            self.out.push_str("[]");
            return;
        }
        self.out.push_str("[\n");
        for r in refs {
            self.indent(level + 1);
            match r {
                Some(r) => self.node(r, level + 1),
                None => self.out.push_str("NULL"),
            }
            self.out.push('\n');
        }
        self.indent(level);
        self.out.push(']');
    }
}

fn untyped_scalar(out: &mut String, item: &UntypedItem) {
    match item {
        UntypedItem::Number(t) => out.push_str(t),
        UntypedItem::String(s) => format_string(out, s),
        UntypedItem::Bool(b) => out.push_str(if *b { "TRUE" } else { "FALSE" }),
        UntypedItem::Null => out.push_str("NULL"),
        UntypedItem::Node(_) => out.push_str("NULL"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_are_shortest_round_trip() {
        let mut s = String::new();
        for v in [
            2.0f32,
            0.1,
            -0.5,
            1e-7,
            3.402_823_5e38,
            1e20,
            123456.79,
            1e-45,
        ] {
            s.clear();
            format_f32(&mut s, v);
            assert_eq!(s.parse::<f32>().unwrap(), v, "{s}");
        }
        s.clear();
        format_f32(&mut s, 2.0);
        assert_eq!(s, "2");
        s.clear();
        format_f32(&mut s, 1e-7);
        assert_eq!(s, "1e-7");
        s.clear();
        format_f64(&mut s, 0.1);
        assert_eq!(s, "0.1");
    }

    #[test]
    fn strings_are_escaped() {
        let mut s = String::new();
        format_string(&mut s, "a\"b\\c");
        assert_eq!(s, r#""a\"b\\c""#);
    }
}
