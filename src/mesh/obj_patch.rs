//! A user's OBJ text with new vertex positions: every `v` statement rewritten in place, every
//! other byte (groups, `usemtl`/`mtllib`, `vt`, `vn`, faces, comments, line endings) kept. This
//! is how fbakit hands an OBJ back — neutral and morph targets — in the user's own layout,
//! rather than re-serialising the mesh it read (which would drop comments and reorder
//! statements).
//!
//! A `v` line whose vertex is already at its position is kept as it is. A rewritten one keeps
//! what follows the three coordinates (a `w`, or `r g b` vertex colours) and a trailing
//! comment; a statement continued over several lines (`\`) becomes one line. Coordinates are
//! printed in Rust's shortest round-trip form.

use glam::Vec3;

/// Counts of the statements that fix a mesh's layout in an OBJ text.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ObjLayout {
    /// `v` statements.
    pub vertices: usize,
    /// `f` statements.
    pub faces: usize,
}

/// One logical statement: its physical lines (with their endings) as one slice of the text.
fn statements(text: &str) -> impl Iterator<Item = &str> {
    let mut rest = text;
    std::iter::from_fn(move || {
        if rest.is_empty() {
            return None;
        }
        let mut end = 0;
        loop {
            let line_end = rest[end..].find('\n').map_or(rest.len(), |i| end + i + 1);
            let line = rest[end..line_end].trim_end_matches(['\n', '\r']);
            let content = line.split('#').next().unwrap_or("");
            end = line_end;
            if !content.trim_end().ends_with('\\') || end >= rest.len() {
                break;
            }
        }
        let (s, r) = rest.split_at(end);
        rest = r;
        Some(s)
    })
}

/// The keyword of a statement (its first token, after a BOM and blanks).
fn keyword(statement: &str) -> &str {
    statement
        .trim_start_matches('\u{feff}')
        .split_whitespace()
        .next()
        .unwrap_or("")
}

/// How many `v` and `f` statements `text` has.
pub fn obj_layout(text: &str) -> ObjLayout {
    let mut out = ObjLayout::default();
    for s in statements(text) {
        match keyword(s) {
            "v" => out.vertices += 1,
            "f" => out.faces += 1,
            _ => {}
        }
    }
    out
}

/// `text` with its `k`-th `v` statement moved to `positions[k]` (module docs); `None` when the
/// text has not exactly `positions.len()` `v` statements. To write many poses of one text,
/// parse it once with [`ObjVertexLines::parse`].
pub fn patch_vertex_lines(text: &str, positions: &[Vec3]) -> Option<String> {
    ObjVertexLines::parse(text).with_positions(positions)
}

/// An OBJ text cut at its `v` statements, once, so that each new set of positions costs only
/// the rewritten `v` lines and copies of the text between them (a shape set writes the same
/// 2.5 MB head eighty times).
#[derive(Clone, Debug)]
pub struct ObjVertexLines<'a> {
    text: &'a str,
    /// The `v` statements in order, each with the text before it since the previous one.
    vertices: Vec<VertexLine<'a>>,
    /// Where the text after the last `v` statement starts.
    tail: usize,
    layout: ObjLayout,
}

/// One `v` statement, split into what a rewrite keeps and what it replaces.
#[derive(Clone, Debug)]
struct VertexLine<'a> {
    /// The text from the end of the previous `v` statement to the start of this one.
    before: std::ops::Range<usize>,
    /// The statement as written (kept when the vertex does not move).
    statement: &'a str,
    /// The coordinates as read (`None` where a token is not a number).
    at: [Option<f32>; 3],
    /// A BOM or indentation before the keyword.
    lead: &'a str,
    /// Tokens after `v x y z` (`w`, or `r g b`), continuations joined, each with a leading
    /// space, then the trailing comment.
    rest: String,
    /// `\r\n`, `\n` or nothing.
    ending: &'static str,
}

impl<'a> ObjVertexLines<'a> {
    /// Cuts `text` at its `v` statements.
    pub fn parse(text: &'a str) -> Self {
        let mut vertices = Vec::new();
        let mut layout = ObjLayout::default();
        let mut offset = 0usize;
        let mut kept_from = 0usize;
        for s in statements(text) {
            let start = offset;
            offset += s.len();
            match keyword(s) {
                "v" => layout.vertices += 1,
                "f" => {
                    layout.faces += 1;
                    continue;
                }
                _ => continue,
            }
            vertices.push(VertexLine::parse(s, kept_from..start));
            kept_from = offset;
        }
        Self {
            text,
            vertices,
            tail: kept_from,
            layout,
        }
    }

    /// How many `v` and `f` statements the text has.
    pub fn layout(&self) -> ObjLayout {
        self.layout
    }

    /// The text with its `k`-th `v` statement moved to `positions[k]` (module docs); `None`
    /// when the text has not exactly `positions.len()` `v` statements.
    pub fn with_positions(&self, positions: &[Vec3]) -> Option<String> {
        if positions.len() != self.vertices.len() {
            return None;
        }
        let mut out = String::with_capacity(self.text.len() + self.text.len() / 8);
        for (line, p) in self.vertices.iter().zip(positions) {
            out.push_str(&self.text[line.before.clone()]);
            line.write(*p, &mut out);
        }
        out.push_str(&self.text[self.tail..]);
        Some(out)
    }
}

impl<'a> VertexLine<'a> {
    fn parse(s: &'a str, before: std::ops::Range<usize>) -> Self {
        let mut coords = s
            .split_whitespace()
            .filter(|t| *t != "\\")
            .skip(1)
            .take(3)
            .map(|t| t.trim_end_matches('\\').parse::<f32>().ok());
        let at = [
            coords.next().flatten(),
            coords.next().flatten(),
            coords.next().flatten(),
        ];
        let ending = if s.ends_with("\r\n") {
            "\r\n"
        } else if s.ends_with('\n') {
            "\n"
        } else {
            ""
        };
        let body = s.trim_end_matches(['\n', '\r']);
        let lead_len = body.len() - body.trim_start_matches(['\u{feff}', ' ', '\t']).len();
        let (data, comment) = match body.find('#') {
            Some(i) => (&body[..i], Some(&body[i..])),
            None => (body, None),
        };
        let mut rest = String::new();
        for t in data[lead_len..]
            .split_whitespace()
            .filter(|t| *t != "\\")
            .skip(4)
        {
            rest.push(' ');
            rest.push_str(t.trim_end_matches('\\'));
        }
        if let Some(c) = comment {
            rest.push(' ');
            rest.push_str(c.trim_end());
        }
        Self {
            before,
            statement: s,
            at,
            lead: &body[..lead_len],
            rest,
            ending,
        }
    }

    fn write(&self, p: Vec3, out: &mut String) {
        use std::fmt::Write;
        // A vertex already where it should be keeps its line, spelling and all.
        if self.at == [Some(p.x), Some(p.y), Some(p.z)] {
            out.push_str(self.statement);
            return;
        }
        out.push_str(self.lead);
        // Writing into a String cannot fail.
        let _ = write!(out, "v {} {} {}", p.x, p.y, p.z);
        out.push_str(&self.rest);
        out.push_str(self.ending);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const TEXT: &str = "\u{feff}# head\r\nmtllib head.mtl\r\no Head\r\nv 0 0 0 # first\r\n\
v 1 0 0 0.5 0.25 1\r\nvt 0 0\r\nvn 0 0 1\r\n  v 0 \\\r\n 1 0\r\ng skin\r\nusemtl Skin\r\n\
f 1/1/1 2/1/1 3/1/1\r\nv 9 9 9";

    #[test]
    fn only_v_lines_change() {
        assert_eq!(
            obj_layout(TEXT),
            ObjLayout {
                vertices: 4,
                faces: 1
            }
        );
        let pts = [
            Vec3::new(0.5, 0.0, -1.0),
            Vec3::new(1.25, 2.0, 3.0),
            Vec3::new(0.1, 0.2, 0.3),
            Vec3::new(-7.0, 8.5, 1e-7),
        ];
        let out = patch_vertex_lines(TEXT, &pts).unwrap();
        let want = "\u{feff}# head\r\nmtllib head.mtl\r\no Head\r\nv 0.5 0 -1 # first\r\n\
v 1.25 2 3 0.5 0.25 1\r\nvt 0 0\r\nvn 0 0 1\r\n  v 0.1 0.2 0.3\r\ng skin\r\nusemtl Skin\r\n\
f 1/1/1 2/1/1 3/1/1\r\nv -7 8.5 0.0000001";
        assert_eq!(out, want);
        // The same positions give the same text back.
        let again = patch_vertex_lines(&out, &pts).unwrap();
        assert_eq!(again, out);
        let unmoved = [Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::splat(9.0)];
        assert_eq!(patch_vertex_lines(TEXT, &unmoved).unwrap(), TEXT);
        assert!(patch_vertex_lines(TEXT, &pts[..3]).is_none());
        assert_eq!(patch_vertex_lines("", &[]).as_deref(), Some(""));
    }

    #[test]
    fn one_cut_writes_many_poses() {
        let lines = ObjVertexLines::parse(TEXT);
        assert_eq!(lines.layout(), obj_layout(TEXT));
        let unmoved = [Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::splat(9.0)];
        for k in 0..4 {
            let mut pts = unmoved;
            pts[k] += Vec3::new(0.5, -0.25, 2.0);
            let text = lines.with_positions(&pts).unwrap();
            // Only statement k changes (the continued one, k = 2, becomes one line).
            let changed: Vec<_> = text
                .split('\n')
                .zip(TEXT.split('\n'))
                .filter(|(a, b)| a != b)
                .collect();
            if k != 2 {
                assert_eq!(changed.len(), 1, "pose {k}: {changed:?}");
            }
            assert_eq!(text, patch_vertex_lines(TEXT, &pts).unwrap());
            assert_eq!(
                ObjVertexLines::parse(&text).with_positions(&pts).unwrap(),
                text
            );
        }
        assert_eq!(lines.with_positions(&unmoved).unwrap(), TEXT);
        assert!(lines.with_positions(&unmoved[..2]).is_none());
    }

    #[test]
    fn reads_back_to_the_positions() {
        let text = "v 1 2 3\nv 4 5 6\nvt 0.5 0.5\nf 1/1 2/1 1/1\n";
        let pts = [Vec3::new(0.1, -0.2, 0.3), Vec3::new(1e-3, 2e3, -3.5)];
        let out = patch_vertex_lines(text, &pts).unwrap();
        let (scene, _) = super::super::obj::parse_obj(&out, std::path::Path::new("t.obj")).unwrap();
        assert_eq!(scene.mesh.positions, pts);
        assert!(out.ends_with("vt 0.5 0.5\nf 1/1 2/1 1/1\n"));
    }
}
