//! The VRML97 grammar: statements, nodes, fields and typed values, built on [`super::lexer`].
//!
//! Each grammar rule is one method taking the unparsed rest of the text and returning the
//! rest after it; errors are located [`ParseError`]s. Node nesting is bounded by
//! [`MAX_DEPTH`] (recursion happens only through nodes), so hostile input cannot overflow the
//! stack.

use std::collections::{HashMap, HashSet};
use std::path::Path;

use nom::sequence::preceded;
use nom::{IResult, Parser as _};

use super::fields::{node_fields, FieldDecl, FieldType};
use super::lexer::{
    boolean, float32, float64, float_text, header, identifier, int32, int_text, keyword, name,
    opens_body, string, ws,
};
use super::model::{
    FieldValue, Node, NodeId, NodeRef, Route, Scene, SfImage, Statement, UntypedItem,
};
use crate::error::{Location, ParseError};

/// Deepest node nesting accepted (a root node is at depth 1).
pub const MAX_DEPTH: usize = 256;

/// The header every file must start with.
pub const HEADER: &str = "#VRML V2.0 utf8";

type Res<'a, T> = Result<(&'a str, T), Box<ParseError>>;

/// Parses VRML97 text; `file` names it in error messages.
pub fn parse_vrml(text: &str, file: &Path) -> Result<Scene, ParseError> {
    let mut p = Parser {
        file,
        text,
        scene: Scene {
            file: file.to_path_buf(),
            ..Scene::default()
        },
        defs: HashMap::new(),
        open: Vec::new(),
        protos: HashSet::new(),
        lines: LineTracker::default(),
    };
    p.scene_text(text).map_err(|e| *e)?;
    Ok(p.scene)
}

/// Turns a failed token combinator into "expected ..." at the failure point.
fn at_failure<'a>(e: nom::Err<nom::error::Error<&'a str>>, fallback: &'a str) -> &'a str {
    match e {
        nom::Err::Error(e) | nom::Err::Failure(e) => e.input,
        nom::Err::Incomplete(_) => fallback,
    }
}

/// Incremental line/column computation: nodes are located in increasing offset order, so
/// scanning from the previous node keeps locating linear in the file size.
#[derive(Default)]
struct LineTracker {
    offset: usize,
    line: usize,
    column: usize,
}

impl LineTracker {
    fn locate(&mut self, file: &Path, text: &str, offset: usize) -> Location {
        if offset < self.offset || self.line == 0 {
            *self = LineTracker {
                offset: 0,
                line: 1,
                column: 1,
            };
        }
        let span = &text[self.offset..offset];
        match span.rfind('\n') {
            Some(last) => {
                self.line += span.bytes().filter(|&b| b == b'\n').count();
                self.column = span[last + 1..].chars().count() + 1;
            }
            None => self.column += span.chars().count(),
        }
        self.offset = offset;
        Location {
            file: file.to_path_buf(),
            line: self.line,
            column: self.column,
        }
    }
}

struct Parser<'a> {
    file: &'a Path,
    text: &'a str,
    scene: Scene,
    /// DEF name → latest node defined with it.
    defs: HashMap<String, NodeId>,
    /// Nodes whose bodies are being parsed (a USE of one of them would be a cycle).
    open: Vec<NodeId>,
    /// PROTO/EXTERNPROTO names: their instances are read generically even if the name
    /// shadows a built-in node type.
    protos: HashSet<String>,
    lines: LineTracker,
}

impl<'a> Parser<'a> {
    fn error(&self, at: &str, expected: impl Into<String>) -> Box<ParseError> {
        Box::new(ParseError::at_rest(self.file, self.text, at, expected))
    }

    fn offset(&self, rest: &str) -> usize {
        self.text.len() - rest.len()
    }

    /// Runs a token combinator after separators, mapping failure to a located error.
    fn token<T>(
        &self,
        rest: &'a str,
        mut f: impl FnMut(&'a str) -> IResult<&'a str, T>,
        expected: &str,
    ) -> Res<'a, T> {
        let (rest, _) = ws(rest).expect("ws never fails");
        f(rest).map_err(|e| self.error(at_failure(e, rest), expected))
    }

    /// `vrmlScene ::= header statement*`
    fn scene_text(&mut self, text: &'a str) -> Result<(), Box<ParseError>> {
        let (mut rest, _) = header(text).map_err(|_| {
            self.error(
                text,
                format!("the header `{HEADER}` on the first line (VRML97 text)"),
            )
        })?;
        loop {
            let (r, _) = ws(rest).expect("ws never fails");
            if r.is_empty() {
                return Ok(());
            }
            let (r, statement) = self.statement(r)?;
            self.scene.statements.push(statement);
            rest = r;
        }
    }

    /// `statement ::= nodeStatement | protoStatement | routeStatement`
    fn statement(&mut self, rest: &'a str) -> Res<'a, Statement> {
        match identifier(rest) {
            Ok((_, "PROTO")) => self.proto(rest),
            Ok((_, "EXTERNPROTO")) => self.extern_proto(rest),
            Ok((_, "ROUTE")) => self.route(rest),
            _ => {
                let (r, node) =
                    self.node_statement(rest, 1, "a node, PROTO, EXTERNPROTO or ROUTE")?;
                Ok((r, Statement::Node(node)))
            }
        }
    }

    /// `nodeStatement ::= node | DEF name node | USE name` at nesting `depth`.
    fn node_statement(&mut self, rest: &'a str, depth: usize, expected: &str) -> Res<'a, NodeRef> {
        let (rest, _) = ws(rest).expect("ws never fails");
        let start = rest;
        match identifier(rest) {
            Ok((r, "DEF")) => {
                let (r, def) = self.token(r, name, "a DEF name")?;
                let (r, id) = self.node(r, start, Some(def), depth)?;
                Ok((r, NodeRef { id, is_use: false }))
            }
            Ok((r, "USE")) => {
                let (after, used) = self.token(r, name, "a DEF name after USE")?;
                let name_at = &r[r.len() - after.len() - used.len()..];
                let Some(&id) = self.defs.get(used) else {
                    return Err(self.error(name_at, "a name defined earlier with DEF"));
                };
                if self.open.contains(&id) {
                    return Err(self.error(
                        name_at,
                        format!("a USE outside the definition of `{used}` (a node cannot contain itself)"),
                    ));
                }
                Ok((after, NodeRef { id, is_use: true }))
            }
            Ok((_, t)) if !super::lexer::KEYWORDS.contains(&t) => {
                let (r, id) = self.node(rest, start, None, depth)?;
                Ok((r, NodeRef { id, is_use: false }))
            }
            _ => Err(self.error(rest, expected)),
        }
    }

    /// `node ::= nodeTypeId { nodeBody }`; `start` is where its statement (DEF) began.
    fn node(
        &mut self,
        rest: &'a str,
        start: &'a str,
        def: Option<&'a str>,
        depth: usize,
    ) -> Res<'a, NodeId> {
        let (rest, _) = ws(rest).expect("ws never fails");
        if depth > MAX_DEPTH {
            return Err(self.error(rest, format!("at most {MAX_DEPTH} levels of nested nodes")));
        }
        let (after_type, type_name) = self.token(rest, name, "a node type name")?;
        if type_name == "Script" {
            return Err(self.error(
                rest,
                "a node type other than Script (Script nodes are not supported)",
            ));
        }
        let (body, _) = self.token(
            after_type,
            |i| nom::character::complete::char('{').parse(i),
            &format!("`{{` to open the body of {type_name}"),
        )?;
        let location = self.lines.locate(self.file, self.text, self.offset(start));
        let id = self.scene.add_node(Node {
            type_name: type_name.to_string(),
            def_name: def.map(str::to_string),
            fields: Vec::new(),
            location,
        });
        // VRML binds the name at its DEF; a later DEF of the same name rebinds it.
        if let Some(def) = def {
            self.defs.insert(def.to_string(), id);
        }
        let table = if self.protos.contains(type_name) {
            None
        } else {
            node_fields(type_name)
        };
        self.open.push(id);
        let result = self.node_body(body, type_name, table, depth);
        self.open.pop();
        let (rest, fields) = result?;
        self.scene.nodes[id.0].fields = fields;
        Ok((rest, id))
    }

    /// `nodeBody ::= (fieldId fieldValue)* }`
    fn node_body(
        &mut self,
        mut rest: &'a str,
        type_name: &str,
        table: Option<&'static [FieldDecl]>,
        depth: usize,
    ) -> Res<'a, Vec<(String, FieldValue)>> {
        let mut fields: Vec<(String, FieldValue)> = Vec::new();
        let expected_field = || match table {
            Some(t) => format!(
                "a field name of {type_name} ({}) or `}}`",
                t.iter().map(|d| d.name).collect::<Vec<_>>().join(", ")
            ),
            None => format!("a field name of {type_name} or `}}`"),
        };
        loop {
            let (r, _) = ws(rest).expect("ws never fails");
            if let Some(r) = r.strip_prefix('}') {
                return Ok((r, fields));
            }
            let field_at = r;
            let (r, field) = match identifier(r) {
                Ok((_, k @ ("ROUTE" | "PROTO" | "EXTERNPROTO"))) => {
                    return Err(self.error(
                        field_at,
                        format!("a field name or `}}` ({k} inside a node body is not supported; move it to the top level)"),
                    ))
                }
                Ok((r, f)) if !super::lexer::KEYWORDS.contains(&f) => (r, f),
                _ => return Err(self.error(field_at, expected_field())),
            };
            if fields.iter().any(|(n, _)| n == field) {
                return Err(self.error(
                    field_at,
                    format!("each field of {type_name} at most once (`{field}` is already set)"),
                ));
            }
            let (r, value) = match table {
                Some(t) => match t.iter().find(|d| d.name == field) {
                    Some(decl) => self.field_value(r, decl.ty, depth)?,
                    None => return Err(self.error(field_at, expected_field())),
                },
                None => self.untyped_value(r, depth)?,
            };
            fields.push((field.to_string(), value));
            rest = r;
        }
    }

    /// A value of field type `ty`.
    fn field_value(&mut self, rest: &'a str, ty: FieldType, depth: usize) -> Res<'a, FieldValue> {
        use FieldType as T;
        use FieldValue as V;
        let sf = |f: &str| format!("an {ty} value ({f})");
        Ok(match ty {
            T::SFBool => {
                let (r, v) = self.token(rest, boolean, &sf("TRUE or FALSE"))?;
                (r, V::SFBool(v))
            }
            T::SFInt32 => {
                let (r, v) = self.token(rest, int32, &sf("a 32-bit integer"))?;
                (r, V::SFInt32(v))
            }
            T::SFFloat => {
                let (r, v) = self.token(rest, float32, &sf("a finite number"))?;
                (r, V::SFFloat(v))
            }
            T::SFTime => {
                let (r, v) = self.token(rest, float64, &sf("a finite number"))?;
                (r, V::SFTime(v))
            }
            T::SFString => {
                let (r, v) = self.token(rest, string, &sf("a quoted string"))?;
                (r, V::SFString(v))
            }
            T::SFVec2f => {
                let (r, v) = self.token(rest, vec2f, &sf("2 finite numbers"))?;
                (r, V::SFVec2f(v))
            }
            T::SFVec3f => {
                let (r, v) = self.token(rest, vec3f, &sf("3 finite numbers"))?;
                (r, V::SFVec3f(v))
            }
            T::SFColor => {
                let (r, v) = self.token(rest, vec3f, &sf("3 finite numbers"))?;
                (r, V::SFColor(v))
            }
            T::SFRotation => {
                let (r, v) = self.token(rest, rotation, &sf("4 finite numbers: axis and angle"))?;
                (r, V::SFRotation(v))
            }
            T::SFImage => {
                let (r, v) = self.sf_image(rest)?;
                (r, V::SFImage(v))
            }
            T::SFNode => {
                let (r, v) = self.sf_node(rest, depth)?;
                (r, V::SFNode(v))
            }
            T::MFInt32 => {
                let (r, v) = self.mf(rest, int32, "an SFInt32 value (a 32-bit integer)")?;
                (r, V::MFInt32(v))
            }
            T::MFFloat => {
                let (r, v) = self.mf(rest, float32, "an SFFloat value (a finite number)")?;
                (r, V::MFFloat(v))
            }
            T::MFTime => {
                let (r, v) = self.mf(rest, float64, "an SFTime value (a finite number)")?;
                (r, V::MFTime(v))
            }
            T::MFString => {
                let (r, v) = self.mf(rest, string, "an SFString value (a quoted string)")?;
                (r, V::MFString(v))
            }
            T::MFVec2f => {
                let (r, v) = self.mf(rest, vec2f, "an SFVec2f value (2 finite numbers)")?;
                (r, V::MFVec2f(v))
            }
            T::MFVec3f => {
                let (r, v) = self.mf(rest, vec3f, "an SFVec3f value (3 finite numbers)")?;
                (r, V::MFVec3f(v))
            }
            T::MFColor => {
                let (r, v) = self.mf(rest, vec3f, "an SFColor value (3 finite numbers)")?;
                (r, V::MFColor(v))
            }
            T::MFRotation => {
                let (r, v) = self.mf(rest, rotation, "an SFRotation value (4 finite numbers)")?;
                (r, V::MFRotation(v))
            }
            T::MFNode => {
                let (r, v) = self.mf_node(rest, depth)?;
                (r, V::MFNode(v))
            }
        })
    }

    /// `mfValue ::= sfValue | [ sfValue* ]` for non-node types. Linear: one pass, no
    /// per-token allocation for numbers.
    fn mf<T>(
        &self,
        rest: &'a str,
        mut item: impl FnMut(&'a str) -> IResult<&'a str, T>,
        expected_item: &str,
    ) -> Res<'a, Vec<T>> {
        let (rest, _) = ws(rest).expect("ws never fails");
        let Some(mut rest) = rest.strip_prefix('[') else {
            let (r, v) = self.token(rest, item, &format!("{expected_item} or `[`"))?;
            return Ok((r, vec![v]));
        };
        let mut out = Vec::new();
        loop {
            let (r, _) = ws(rest).expect("ws never fails");
            if let Some(r) = r.strip_prefix(']') {
                return Ok((r, out));
            }
            match item(r) {
                Ok((r, v)) => {
                    out.push(v);
                    rest = r;
                }
                Err(e) => {
                    return Err(self.error(at_failure(e, r), format!("{expected_item} or `]`")))
                }
            }
        }
    }

    /// `sfNodeValue ::= nodeStatement | NULL`
    fn sf_node(&mut self, rest: &'a str, depth: usize) -> Res<'a, Option<NodeRef>> {
        let (rest, _) = ws(rest).expect("ws never fails");
        if let Ok((r, _)) = keyword("NULL").parse(rest) {
            return Ok((r, None));
        }
        let (r, n) = self.node_statement(
            rest,
            depth + 1,
            "an SFNode value (a node, USE name or NULL)",
        )?;
        Ok((r, Some(n)))
    }

    /// `mfNodeValue ::= nodeStatement | [ nodeStatement* ]`
    fn mf_node(&mut self, rest: &'a str, depth: usize) -> Res<'a, Vec<NodeRef>> {
        let (rest, _) = ws(rest).expect("ws never fails");
        let Some(mut rest) = rest.strip_prefix('[') else {
            let (r, n) =
                self.node_statement(rest, depth + 1, "an MFNode value (a node, USE name or `[`)")?;
            return Ok((r, vec![n]));
        };
        let mut out = Vec::new();
        loop {
            let (r, _) = ws(rest).expect("ws never fails");
            if let Some(r) = r.strip_prefix(']') {
                return Ok((r, out));
            }
            let (r, n) = self.node_statement(r, depth + 1, "a node, USE name or `]`")?;
            out.push(n);
            rest = r;
        }
    }

    /// `sfImageValue ::= width height components pixel*` with exactly width x height pixels.
    fn sf_image(&self, rest: &'a str) -> Res<'a, SfImage> {
        let (r, w) = self.token(rest, int32, "an SFImage width (an integer >= 0)")?;
        let (r, h) = self.token(r, int32, "an SFImage height (an integer >= 0)")?;
        let (after, c) = self.token(r, int32, "an SFImage component count (0..=4)")?;
        if w < 0 || h < 0 {
            return Err(self.error(ws(rest).expect("ws").0, "an SFImage width and height >= 0"));
        }
        if !(0..=4).contains(&c) {
            let c_at = ws(r).expect("ws").0;
            return Err(self.error(c_at, "an SFImage component count in 0..=4"));
        }
        // The count is declared by the file: never allocate from it, only from pixels read.
        let count = w as u64 * h as u64;
        let mut pixels = Vec::new();
        let mut r = after;
        for _ in 0..count {
            let (next, p) = self.token(r, int32, &format!("{count} SFImage pixel values"))?;
            pixels.push(p as u32);
            r = next;
        }
        Ok((
            r,
            SfImage {
                width: w as u32,
                height: h as u32,
                components: c as u8,
                pixels,
            },
        ))
    }

    /// A field of a node type without a table: `[ item* ]`, one node, or a run of scalars
    /// (numbers, strings, booleans, NULL) up to the next field name or `}`.
    fn untyped_value(&mut self, rest: &'a str, depth: usize) -> Res<'a, FieldValue> {
        let (rest, _) = ws(rest).expect("ws never fails");
        if let Some(mut r) = rest.strip_prefix('[') {
            let mut items = Vec::new();
            loop {
                let (next, _) = ws(r).expect("ws never fails");
                if let Some(next) = next.strip_prefix(']') {
                    return Ok((
                        next,
                        FieldValue::Untyped {
                            bracketed: true,
                            items,
                        },
                    ));
                }
                let (next, item) = self.untyped_item(next, depth, "a value, node or `]`")?;
                items.push(item);
                r = next;
            }
        }
        let (mut r, first) = self.untyped_item(rest, depth, "a field value")?;
        let is_node = matches!(first, UntypedItem::Node(_));
        let mut items = vec![first];
        if !is_node {
            loop {
                let (next, _) = ws(r).expect("ws never fails");
                match untyped_scalar(next) {
                    Ok((next, Some(item))) => {
                        items.push(item);
                        r = next;
                    }
                    Ok((_, None)) => break,
                    Err(e) => return Err(self.error(at_failure(e, next), "a finite number")),
                }
            }
        }
        Ok((
            r,
            FieldValue::Untyped {
                bracketed: false,
                items,
            },
        ))
    }

    /// One untyped scalar or node.
    fn untyped_item(
        &mut self,
        rest: &'a str,
        depth: usize,
        expected: &str,
    ) -> Res<'a, UntypedItem> {
        match untyped_scalar(rest) {
            Ok((r, Some(item))) => return Ok((r, item)),
            Ok((_, None)) => {}
            Err(e) => return Err(self.error(at_failure(e, rest), "a finite number")),
        }
        let is_node = match identifier(rest) {
            Ok((_, "DEF" | "USE")) => true,
            Ok((r, _)) => opens_body(r),
            Err(_) => false,
        };
        if !is_node {
            return Err(self.error(rest, expected));
        }
        let (r, n) = self.node_statement(rest, depth + 1, expected)?;
        Ok((r, UntypedItem::Node(n)))
    }

    /// `PROTO name [ interface ] { body }`, kept verbatim.
    fn proto(&mut self, rest: &'a str) -> Res<'a, Statement> {
        let (r, _) = keyword("PROTO")
            .parse(rest)
            .map_err(|_| self.error(rest, "PROTO"))?;
        let (r, proto_name) = self.token(r, name, "a PROTO name")?;
        let (r, _) = ws(r).expect("ws never fails");
        let r = self.balanced(r, b'[', b']', "`[` to open the PROTO interface")?;
        let (r, _) = ws(r).expect("ws never fails");
        let r = self.balanced(r, b'{', b'}', "`{` to open the PROTO body")?;
        self.protos.insert(proto_name.to_string());
        Ok((
            r,
            Statement::Proto {
                name: proto_name.to_string(),
                text: rest[..rest.len() - r.len()].to_string(),
            },
        ))
    }

    /// `EXTERNPROTO name [ interface ] urls`, kept verbatim.
    fn extern_proto(&mut self, rest: &'a str) -> Res<'a, Statement> {
        let (r, _) = keyword("EXTERNPROTO")
            .parse(rest)
            .map_err(|_| self.error(rest, "EXTERNPROTO"))?;
        let (r, proto_name) = self.token(r, name, "an EXTERNPROTO name")?;
        let (r, _) = ws(r).expect("ws never fails");
        let r = self.balanced(r, b'[', b']', "`[` to open the EXTERNPROTO interface")?;
        let (r, _urls) = self.mf(r, string, "an EXTERNPROTO URL (a quoted string)")?;
        self.protos.insert(proto_name.to_string());
        Ok((
            r,
            Statement::ExternProto {
                name: proto_name.to_string(),
                text: rest[..rest.len() - r.len()].to_string(),
            },
        ))
    }

    /// Skips from `open` to its matching `close`, ignoring strings and comments. Iterative.
    fn balanced(
        &self,
        rest: &'a str,
        open: u8,
        close: u8,
        expected: &str,
    ) -> Result<&'a str, Box<ParseError>> {
        let b = rest.as_bytes();
        if b.first() != Some(&open) {
            return Err(self.error(rest, expected));
        }
        let mut depth = 0usize;
        let mut i = 0;
        while i < b.len() {
            match b[i] {
                b'"' => match string(&rest[i..]) {
                    Ok((r, _)) => {
                        i = rest.len() - r.len();
                        continue;
                    }
                    Err(_) => return Err(self.error(&rest[i..], "a string closed by `\"`")),
                },
                b'#' => {
                    while i < b.len() && b[i] != b'\n' {
                        i += 1;
                    }
                    continue;
                }
                c if c == open => depth += 1,
                c if c == close => {
                    depth -= 1;
                    if depth == 0 {
                        return Ok(&rest[i + 1..]);
                    }
                }
                _ => {}
            }
            i += 1;
        }
        Err(self.error(
            rest,
            format!("a matching `{}` for this `{}`", close as char, open as char),
        ))
    }

    /// `ROUTE node.eventOut TO node.eventIn`; both nodes must be DEFined before.
    fn route(&mut self, rest: &'a str) -> Res<'a, Statement> {
        let (r, _) = keyword("ROUTE")
            .parse(rest)
            .map_err(|_| self.error(rest, "ROUTE"))?;
        let (r, (from_node, from_field)) = self.route_end(r)?;
        let (r, _) = self.token(r, |i| keyword("TO").parse(i), "`TO`")?;
        let (r, (to_node, to_field)) = self.route_end(r)?;
        Ok((
            r,
            Statement::Route(Route {
                from_node: from_node.to_string(),
                from_field: from_field.to_string(),
                to_node: to_node.to_string(),
                to_field: to_field.to_string(),
            }),
        ))
    }

    /// `name . field` of a ROUTE.
    fn route_end(&self, rest: &'a str) -> Res<'a, (&'a str, &'a str)> {
        let (after, node) = self.token(rest, name, "a DEF name")?;
        if !self.defs.contains_key(node) {
            let at = &rest[rest.len() - after.len() - node.len()..];
            return Err(self.error(at, "a DEF name defined before this ROUTE"));
        }
        let (r, _) = self.token(
            after,
            |i| nom::character::complete::char('.').parse(i),
            "`.` between node and field",
        )?;
        let (r, field) = self.token(r, name, "a field or event name")?;
        Ok((r, (node, field)))
    }
}

/// `x y` as an SFVec2f.
pub fn vec2f(input: &str) -> IResult<&str, [f32; 2]> {
    (float32, preceded(ws, float32))
        .map(|(x, y)| [x, y])
        .parse(input)
}

/// `x y z` as an SFVec3f or SFColor.
pub fn vec3f(input: &str) -> IResult<&str, [f32; 3]> {
    (float32, preceded(ws, float32), preceded(ws, float32))
        .map(|(x, y, z)| [x, y, z])
        .parse(input)
}

/// `x y z angle` as an SFRotation.
pub fn rotation(input: &str) -> IResult<&str, [f32; 4]> {
    (
        float32,
        preceded(ws, float32),
        preceded(ws, float32),
        preceded(ws, float32),
    )
        .map(|(x, y, z, a)| [x, y, z, a])
        .parse(input)
}

/// One scalar of an untyped value: `Ok(None)` when the input does not start with one
/// (e.g. the next field name); an error for a number that is not finite.
pub fn untyped_scalar(input: &str) -> IResult<&str, Option<UntypedItem>> {
    let first = input.as_bytes().first().copied();
    match first {
        Some(b'"') => {
            let (r, s) = string(input)?;
            Ok((r, Some(UntypedItem::String(s))))
        }
        Some(b'0'..=b'9' | b'+' | b'-' | b'.') => {
            // Hexadecimal first: `0x1F` would otherwise read as `0` then a name.
            let (r, text) = match int_text(input) {
                Ok((r, t)) if t.starts_with("0x") || t.starts_with("0X") => (r, t),
                _ => float_text(input)?,
            };
            let finite = if text.starts_with("0x") || text.starts_with("0X") {
                true
            } else {
                text.parse::<f64>().is_ok_and(f64::is_finite)
            };
            if !finite {
                return Err(nom::Err::Error(nom::error::Error::new(
                    input,
                    nom::error::ErrorKind::Float,
                )));
            }
            Ok((r, Some(UntypedItem::Number(text.to_string()))))
        }
        _ => match identifier(input) {
            Ok((r, "TRUE")) => Ok((r, Some(UntypedItem::Bool(true)))),
            Ok((r, "FALSE")) => Ok((r, Some(UntypedItem::Bool(false)))),
            Ok((r, "NULL")) => Ok((r, Some(UntypedItem::Null))),
            _ => Ok((input, None)),
        },
    }
}
