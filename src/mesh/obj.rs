//! Wavefront OBJ reading and writing (polygonal subset).
//!
//! **One [`Mesh`] per file.** OBJ indices are global to the file, so objects (`o`) and groups
//! (`g`) are kept as [`FaceGroup`] spans over one mesh instead of being split apart; the writer
//! re-emits them at the same faces. The mesh is named after the file stem.
//!
//! Read: `v x y z [w]` (a `w` is dropped, with a warning unless it is 1) and `v x y z r g b`
//! (colours kept, see [`Mesh::colors`]), `vt u [v [w]]` (`w` dropped), `vn x y z`, `f` with
//! `v`, `v/vt`, `v//vn`, `v/vt/vn` corners (the same form for every corner of one face), relative
//! (negative) indices, any arity ≥ 3, `o`, `g`, `s`, `usemtl`, `mtllib`, `#` comments (also after
//! a statement), `\` line continuations, LF or CRLF, a leading UTF-8 BOM. Other statements (`l`,
//! `p`, curves, ...) are skipped with a warning. Positive indices must refer to elements defined
//! earlier in the file (as the format specifies). When only some faces carry uvs (or normals, or
//! only some vertices colours), that attribute is dropped for the whole mesh with a warning,
//! because [`Mesh`] stores attributes for all faces or none. Comments are not kept.
//!
//! Write: canonical OBJ — `mtllib`s, then all `v`, `vt`, `vn` in order, then the faces with
//! `o`/`g`/`s`/`usemtl` lines where the spans change. Numbers are printed in Rust's shortest
//! round-trip form, so read → write → read gives an equal [`ObjScene`].

use std::fmt::Write as _;
use std::path::Path;

use glam::{Vec2, Vec3};

use super::text::{fail, integer, newline_or_eof, real, rest_of_line, unsigned, PErr, Res};
use super::{FaceGroup, Mesh, MeshError, Polygons};
use crate::error::{Diagnostic, Error, Location, ParseError, Result, Severity};

/// Warnings kept per file; the rest are counted in one last warning.
const MAX_WARNINGS: usize = 1000;

/// The content of one OBJ file.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ObjScene {
    /// All geometry of the file (objects and groups as spans, see the module docs).
    pub mesh: Mesh,
    /// Arguments of the `mtllib` statements, verbatim, in order.
    pub material_libraries: Vec<String>,
}

/// One corner of an `f` statement as written: 1-based or negative indices.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct FaceCorner {
    pub v: i64,
    pub vt: Option<i64>,
    pub vn: Option<i64>,
}

/// One OBJ statement (the keyword already consumed; parsed up to the end of its line).
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum Statement<'a> {
    Vertex {
        position: Vec3,
        w: Option<f32>,
        color: Option<Vec3>,
    },
    TexCoord(Vec2),
    Normal(Vec3),
    /// Corners with the input at each corner (for located index errors).
    Face(Vec<(&'a str, FaceCorner)>),
    Object(&'a str),
    Group(Vec<&'a str>),
    Smoothing(Option<u32>),
    UseMaterial(&'a str),
    MaterialLibrary(&'a str),
}

/// Spaces, tabs and `\`-newline continuations (possibly none).
pub(crate) fn blank(mut i: &str) -> Res<'_, ()> {
    loop {
        let t = i.trim_start_matches([' ', '\t']);
        if let Some(r) = t.strip_prefix("\\\n").or_else(|| t.strip_prefix("\\\r\n")) {
            i = r;
        } else {
            return Ok((t, ()));
        }
    }
}

/// At least one separator ([`blank`]) before the next token.
fn separator(i: &str) -> Res<'_, ()> {
    let (r, ()) = blank(i)?;
    if r.len() == i.len() {
        fail(i, "a space")
    } else {
        Ok((r, ()))
    }
}

/// End of a statement: blanks, an optional `# comment`, then a line ending or end of input.
pub(crate) fn statement_end(i: &str) -> Res<'_, ()> {
    let (r, ()) = blank(i)?;
    let r = if r.starts_with('#') {
        &r[rest_of_line(r).0.len()..]
    } else {
        r
    };
    newline_or_eof(r)
}

/// Up to `max` numbers, each after a separator, stopping at the end of the statement.
fn numbers(mut i: &str, max: usize) -> Res<'_, Vec<f32>> {
    let mut out = Vec::new();
    loop {
        if statement_end(i).is_ok() {
            return Ok((i, out));
        }
        if out.len() == max {
            return fail(i, "end of line (too many numbers)");
        }
        let (r, ()) = separator(i)?;
        if statement_end(r).is_ok() {
            return Ok((r, out));
        }
        let (r, v) = real(r)?;
        out.push(v);
        i = r;
    }
}

/// `v x y z [w]` or `v x y z r g b`, after the keyword.
pub(crate) fn vertex_statement(i: &str) -> Res<'_, Statement<'_>> {
    let (r, n) = numbers(i, 6)?;
    let stmt = match n[..] {
        [x, y, z] => Statement::Vertex {
            position: Vec3::new(x, y, z),
            w: None,
            color: None,
        },
        [x, y, z, w] => Statement::Vertex {
            position: Vec3::new(x, y, z),
            w: Some(w),
            color: None,
        },
        [x, y, z, cr, cg, cb] => Statement::Vertex {
            position: Vec3::new(x, y, z),
            w: None,
            color: Some(Vec3::new(cr, cg, cb)),
        },
        _ => {
            return fail(
                r,
                "3 (x y z), 4 (x y z w) or 6 (x y z r g b) numbers after `v`",
            )
        }
    };
    Ok((statement_end(r)?.0, stmt))
}

/// `vt u [v [w]]`, after the keyword.
pub(crate) fn texcoord_statement(i: &str) -> Res<'_, Statement<'_>> {
    let (r, n) = numbers(i, 3)?;
    let uv = match n[..] {
        [u] => Vec2::new(u, 0.0),
        [u, v] | [u, v, _] => Vec2::new(u, v),
        _ => return fail(r, "1 to 3 numbers (u [v [w]]) after `vt`"),
    };
    Ok((statement_end(r)?.0, Statement::TexCoord(uv)))
}

/// `vn x y z`, after the keyword.
pub(crate) fn normal_statement(i: &str) -> Res<'_, Statement<'_>> {
    let (r, n) = numbers(i, 3)?;
    match n[..] {
        [x, y, z] => Ok((statement_end(r)?.0, Statement::Normal(Vec3::new(x, y, z)))),
        _ => fail(r, "3 numbers (x y z) after `vn`"),
    }
}

/// One face corner: `v`, `v/vt`, `v//vn` or `v/vt/vn`.
pub(crate) fn face_corner(i: &str) -> Res<'_, FaceCorner> {
    let (r, v) = integer(i).map_err(|_| {
        nom::Err::Error(PErr {
            at: i,
            expected: "a vertex index",
        })
    })?;
    let Some(r) = r.strip_prefix('/') else {
        return Ok((
            r,
            FaceCorner {
                v,
                vt: None,
                vn: None,
            },
        ));
    };
    if let Some(r) = r.strip_prefix('/') {
        let (r, vn) = integer(r).map_err(|_| {
            nom::Err::Error(PErr {
                at: r,
                expected: "a normal index after `//`",
            })
        })?;
        return Ok((
            r,
            FaceCorner {
                v,
                vt: None,
                vn: Some(vn),
            },
        ));
    }
    let (r, vt) = integer(r).map_err(|_| {
        nom::Err::Error(PErr {
            at: r,
            expected: "a texture-coordinate index after `/`",
        })
    })?;
    let Some(r) = r.strip_prefix('/') else {
        return Ok((
            r,
            FaceCorner {
                v,
                vt: Some(vt),
                vn: None,
            },
        ));
    };
    let (r, vn) = integer(r).map_err(|_| {
        nom::Err::Error(PErr {
            at: r,
            expected: "a normal index after `/`",
        })
    })?;
    Ok((
        r,
        FaceCorner {
            v,
            vt: Some(vt),
            vn: Some(vn),
        },
    ))
}

/// `f c1 c2 c3 ...` (at least three corners, one index form), after the keyword.
pub(crate) fn face_statement(i: &str) -> Res<'_, Statement<'_>> {
    let mut corners: Vec<(&str, FaceCorner)> = Vec::new();
    let mut r = i;
    loop {
        if statement_end(r).is_ok() {
            break;
        }
        let (after_sep, ()) = separator(r)?;
        if statement_end(after_sep).is_ok() {
            r = after_sep;
            break;
        }
        let (rest, c) = face_corner(after_sep)?;
        if let Some((_, first)) = corners.first() {
            if first.vt.is_some() != c.vt.is_some() || first.vn.is_some() != c.vn.is_some() {
                return fail(
                    after_sep,
                    "the same index form (v, v/vt, v//vn or v/vt/vn) on every corner of a face",
                );
            }
        }
        corners.push((after_sep, c));
        r = rest;
    }
    if corners.len() < 3 {
        return fail(r, "at least 3 corners after `f`");
    }
    Ok((statement_end(r)?.0, Statement::Face(corners)))
}

/// The rest of the statement as one trimmed argument (names may contain spaces).
fn argument(i: &str) -> Res<'_, &str> {
    let (r, ()) = blank(i)?;
    let end = r.find(['\n', '#']).unwrap_or(r.len());
    let arg = r[..end].trim_end_matches(['\r', ' ', '\t']);
    let (rest, ()) = statement_end(&r[arg.len()..])?;
    Ok((rest, arg))
}

/// `o [name]`, after the keyword.
pub(crate) fn object_statement(i: &str) -> Res<'_, Statement<'_>> {
    let (r, name) = argument(i)?;
    Ok((r, Statement::Object(name)))
}

/// `usemtl [name]`, after the keyword.
pub(crate) fn usemtl_statement(i: &str) -> Res<'_, Statement<'_>> {
    let (r, name) = argument(i)?;
    Ok((r, Statement::UseMaterial(name)))
}

/// `mtllib file...`, after the keyword (kept verbatim).
pub(crate) fn mtllib_statement(i: &str) -> Res<'_, Statement<'_>> {
    let (r, arg) = argument(i)?;
    Ok((r, Statement::MaterialLibrary(arg)))
}

/// `g [name...]`, after the keyword.
pub(crate) fn group_statement(i: &str) -> Res<'_, Statement<'_>> {
    let (r, arg) = argument(i)?;
    Ok((r, Statement::Group(arg.split_whitespace().collect())))
}

/// `s off`, `s 0` or `s n`, after the keyword.
pub(crate) fn smoothing_statement(i: &str) -> Res<'_, Statement<'_>> {
    let (r, ()) = separator(i)?;
    if let Some(rest) = r.strip_prefix("off") {
        return Ok((statement_end(rest)?.0, Statement::Smoothing(None)));
    }
    let (rest, n) = unsigned(r).map_err(|_| {
        nom::Err::Error(PErr {
            at: r,
            expected: "`off` or a smoothing group number",
        })
    })?;
    let n = u32::try_from(n).map_err(|_| {
        nom::Err::Error(PErr {
            at: r,
            expected: "a smoothing group number below 2^32",
        })
    })?;
    Ok((
        statement_end(rest)?.0,
        Statement::Smoothing((n != 0).then_some(n)),
    ))
}

/// The statement keyword: the first run of non-blank characters.
pub(crate) fn keyword(i: &str) -> Res<'_, &str> {
    let n = i
        .find([' ', '\t', '\r', '\n', '\\', '#'])
        .unwrap_or(i.len());
    if n == 0 {
        fail(i, "a statement keyword")
    } else {
        Ok((&i[n..], &i[..n]))
    }
}

/// Skips to the end of a logical line (following `\` continuations).
fn skip_logical_line(mut i: &str) -> &str {
    loop {
        let (line, rest) = rest_of_line(i);
        if line.ends_with('\\') && !rest.is_empty() {
            i = rest;
        } else {
            return rest;
        }
    }
}

/// Converts a 1-based or negative OBJ index into a 0-based one among `count` defined elements.
fn resolve(raw: i64, count: usize) -> Option<u32> {
    let idx = if raw > 0 {
        usize::try_from(raw - 1).ok()?
    } else if raw < 0 {
        count.checked_sub(usize::try_from(raw.unsigned_abs()).ok()?)?
    } else {
        return None;
    };
    if idx < count {
        u32::try_from(idx).ok()
    } else {
        None
    }
}

/// Reader state while walking the statements.
struct Builder {
    mesh: Mesh,
    libs: Vec<String>,
    colored: usize,
    uv_polys: Polygons,
    uv_faces: usize,
    normal_polys: Polygons,
    normal_faces: usize,
}

impl Builder {
    /// Changes the grouping state; a new span starts unless no face was read since the last one.
    fn set_state(&mut self, f: impl FnOnce(&mut FaceGroup)) {
        let faces = self.mesh.polygons.len() as u32;
        match self.mesh.groups.last_mut() {
            Some(g) if g.first_face == faces => f(g),
            last => {
                let mut g = last.map(|g| g.clone()).unwrap_or_default();
                g.first_face = faces;
                f(&mut g);
                self.mesh.groups.push(g);
            }
        }
    }
}

/// Reads OBJ text. `file` names the source in errors and diagnostics and gives the mesh name.
pub fn parse_obj(text: &str, file: &Path) -> Result<(ObjScene, Vec<Diagnostic>)> {
    let mut warnings: Vec<Diagnostic> = Vec::new();
    let mut suppressed = 0usize;
    let mut warn = |at: &str, message: String, warnings: &mut Vec<Diagnostic>| {
        if warnings.len() < MAX_WARNINGS {
            warnings.push(Diagnostic {
                severity: Severity::Warning,
                location: Some(Location::from_rest(file, text, at)),
                message,
            });
        } else {
            suppressed += 1;
        }
    };
    let name = file
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let mut b = Builder {
        mesh: Mesh {
            name,
            ..Mesh::default()
        },
        libs: Vec::new(),
        colored: 0,
        uv_polys: Polygons::new(),
        uv_faces: 0,
        normal_polys: Polygons::new(),
        normal_faces: 0,
    };
    let mut i = text.strip_prefix('\u{feff}').unwrap_or(text);
    let mut corners: Vec<u32> = Vec::new();
    loop {
        let (r, ()) = blank(i).expect("blank never fails");
        i = r;
        if i.is_empty() {
            break;
        }
        if let Ok((r, ())) = newline_or_eof(i) {
            i = r;
            continue;
        }
        if i.starts_with('#') {
            i = rest_of_line(i).1;
            continue;
        }
        let (after_kw, kw) = keyword(i).map_err(|e| to_error(e, file, text, "a statement"))?;
        let parsed = match kw {
            "v" => vertex_statement(after_kw),
            "vt" => texcoord_statement(after_kw),
            "vn" => normal_statement(after_kw),
            "f" => face_statement(after_kw),
            "o" => object_statement(after_kw),
            "g" => group_statement(after_kw),
            "s" => smoothing_statement(after_kw),
            "usemtl" => usemtl_statement(after_kw),
            "mtllib" => mtllib_statement(after_kw),
            _ => {
                warn(
                    i,
                    format!(
                        "unsupported statement `{}` skipped",
                        kw.chars().take(40).collect::<String>()
                    ),
                    &mut warnings,
                );
                i = skip_logical_line(i);
                continue;
            }
        };
        let (rest, stmt) = parsed.map_err(|e| to_error(e, file, text, "a valid statement"))?;
        let stmt_at = i;
        i = rest;
        match stmt {
            Statement::Vertex { position, w, color } => {
                if let Some(w) = w.filter(|&w| w != 1.0) {
                    warn(
                        stmt_at,
                        format!("vertex weight w = {w} dropped"),
                        &mut warnings,
                    );
                }
                if let Some(c) = color {
                    b.colored += 1;
                    b.mesh.colors.push(c);
                } else {
                    b.mesh.colors.push(Vec3::ZERO);
                }
                b.mesh.positions.push(position);
            }
            Statement::TexCoord(uv) => b.mesh.uvs.push(uv),
            Statement::Normal(n) => b.mesh.normals.push(n),
            Statement::Face(cs) => {
                let located = |at: &str, what: String| -> Error {
                    ParseError::at_rest(file, text, at, what).into()
                };
                corners.clear();
                for (at, c) in &cs {
                    let np = b.mesh.positions.len();
                    let v = resolve(c.v, np).ok_or_else(|| {
                        located(at, format!("a vertex index in 1..={np} or -{np}..=-1 (vertices defined so far)"))
                    })?;
                    corners.push(v);
                }
                b.mesh.polygons.push(&corners);
                if cs[0].1.vt.is_some() {
                    corners.clear();
                    for (at, c) in &cs {
                        let n = b.mesh.uvs.len();
                        let raw = c.vt.unwrap_or(0);
                        let t = resolve(raw, n).ok_or_else(|| {
                            located(at, format!("a texture-coordinate index in 1..={n} or -{n}..=-1 (defined so far)"))
                        })?;
                        corners.push(t);
                    }
                    b.uv_polys.push(&corners);
                    b.uv_faces += 1;
                }
                if cs[0].1.vn.is_some() {
                    corners.clear();
                    for (at, c) in &cs {
                        let n = b.mesh.normals.len();
                        let raw = c.vn.unwrap_or(0);
                        let t = resolve(raw, n).ok_or_else(|| {
                            located(
                                at,
                                format!("a normal index in 1..={n} or -{n}..=-1 (defined so far)"),
                            )
                        })?;
                        corners.push(t);
                    }
                    b.normal_polys.push(&corners);
                    b.normal_faces += 1;
                }
            }
            Statement::Object(name) => {
                b.set_state(|g| g.object = (!name.is_empty()).then(|| name.to_string()))
            }
            Statement::Group(names) => {
                b.set_state(|g| g.groups = names.iter().map(|s| s.to_string()).collect())
            }
            Statement::Smoothing(s) => b.set_state(|g| g.smoothing = s),
            Statement::UseMaterial(name) => {
                b.set_state(|g| g.material = (!name.is_empty()).then(|| name.to_string()))
            }
            Statement::MaterialLibrary(arg) => b.libs.push(arg.to_string()),
        }
    }
    let faces = b.mesh.polygons.len();
    let n = b.mesh.positions.len();
    let whole_file = |message: String, warnings: &mut Vec<Diagnostic>| {
        warnings.push(Diagnostic {
            severity: Severity::Warning,
            location: None,
            message,
        })
    };
    if b.colored == n {
        // all vertices coloured (or none and no vertices)
    } else {
        if b.colored > 0 {
            whole_file(
                format!(
                    "only {} of {n} vertices have colours; colours dropped",
                    b.colored
                ),
                &mut warnings,
            );
        }
        b.mesh.colors.clear();
    }
    if n == 0 {
        b.mesh.colors.clear();
    }
    if b.uv_faces == faces && faces > 0 {
        b.mesh.uv_polygons = Some(b.uv_polys);
    } else if b.uv_faces > 0 {
        whole_file(
            format!(
                "only {} of {faces} faces have texture coordinates; face uvs dropped",
                b.uv_faces
            ),
            &mut warnings,
        );
    }
    if b.normal_faces == faces && faces > 0 {
        b.mesh.normal_polygons = Some(b.normal_polys);
    } else if b.normal_faces > 0 {
        whole_file(
            format!(
                "only {} of {faces} faces have normals; face normals dropped",
                b.normal_faces
            ),
            &mut warnings,
        );
    }
    if suppressed > 0 {
        whole_file(
            format!("{suppressed} more warnings not shown"),
            &mut warnings,
        );
    }
    Ok((
        ObjScene {
            mesh: b.mesh,
            material_libraries: b.libs,
        },
        warnings,
    ))
}

fn to_error(e: nom::Err<PErr<'_>>, file: &Path, text: &str, default: &str) -> Error {
    match e {
        nom::Err::Error(p) | nom::Err::Failure(p) => p.located(file, text, default).into(),
        nom::Err::Incomplete(_) => ParseError::at_offset(file, text, text.len(), default).into(),
    }
}

/// Reads an OBJ file (UTF-8, size-bounded by [`crate::io::read_text`]).
pub fn read_obj_file(path: &Path) -> Result<(ObjScene, Vec<Diagnostic>)> {
    let text = crate::io::read_text(path)?;
    parse_obj(&text, path)
}

/// Reads OBJ from `reader` (UTF-8, bounded by [`crate::io::DEFAULT_MAX_INPUT_BYTES`]);
/// `source` names it in locations and warnings.
pub fn read_obj_from<R: std::io::BufRead>(
    reader: R,
    source: &Path,
) -> Result<(ObjScene, Vec<Diagnostic>)> {
    let text = crate::io::read_text_from(reader, source, crate::io::DEFAULT_MAX_INPUT_BYTES)?;
    parse_obj(&text, source)
}

/// Vertex positions (`v` statements) of OBJ text, in order; everything else is skipped.
///
/// For files known to share another file's faces (blend-shape OBJs): several times faster
/// than [`parse_obj`] because faces are not parsed. The same numbers are accepted (3, 4 or
/// 6 finite numbers after `v`); errors name file, line and column. Text with `\` line
/// continuations goes through [`parse_obj`].
pub fn parse_obj_positions(text: &str, file: &Path) -> Result<Vec<Vec3>> {
    if text.contains("\\\n") || text.contains("\\\r\n") {
        return parse_obj(text, file).map(|(s, _)| s.mesh.positions);
    }
    let body = text.strip_prefix('\u{feff}').unwrap_or(text);
    let base = text.len() - body.len();
    let mut out = Vec::new();
    let mut offset = base;
    for line in body.split_inclusive('\n') {
        let start = offset;
        offset += line.len();
        let Some(rest) = line.strip_prefix('v') else {
            continue;
        };
        if !rest.starts_with([' ', '\t']) {
            continue;
        }
        let content = rest.split('#').next().unwrap_or("");
        let mut numbers = [0f32; 6];
        let mut count = 0;
        for token in content.split_ascii_whitespace() {
            let at = start + 1 + (token.as_ptr() as usize - rest.as_ptr() as usize);
            let v = token
                .parse::<f32>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| {
                    Error::from(ParseError::at_offset(
                        file,
                        text,
                        at,
                        "a finite number (within ±3.4e38)",
                    ))
                })?;
            if count == numbers.len() {
                return Err(ParseError::at_offset(
                    file,
                    text,
                    at,
                    "end of line (too many numbers)",
                )
                .into());
            }
            numbers[count] = v;
            count += 1;
        }
        if !matches!(count, 3 | 4 | 6) {
            return Err(ParseError::at_offset(
                file,
                text,
                start,
                "3 (x y z), 4 (x y z w) or 6 (x y z r g b) numbers after `v`",
            )
            .into());
        }
        out.push(Vec3::new(numbers[0], numbers[1], numbers[2]));
    }
    Ok(out)
}

/// [`parse_obj_positions`] on a file (UTF-8, size-bounded by [`crate::io::read_text`]).
pub fn read_obj_positions_file(path: &Path) -> Result<Vec<Vec3>> {
    let text = crate::io::read_text(path)?;
    parse_obj_positions(&text, path)
}

/// Writes `scene` as canonical OBJ text (see the module docs).
///
/// Fails with a [`MeshError`] if the mesh is structurally invalid ([`Mesh::validate`]),
/// holds non-finite numbers, or a name contains a line break — such a file could not be read
/// back.
pub fn write_obj_string(scene: &ObjScene) -> Result<String> {
    let m = &scene.mesh;
    check_writable(scene)?;
    let mut s = String::with_capacity(m.positions.len() * 32 + m.polygons.corner_count() * 8);
    // Infallible: fmt::Write on String.
    let _ = write_body(&mut s, scene);
    Ok(s)
}

fn check_writable(scene: &ObjScene) -> Result<()> {
    let m = &scene.mesh;
    let v = m.validate();
    if !v.is_valid() {
        return Err(MeshError::InvalidMesh {
            details: format!("{v:?}"),
        }
        .into());
    }
    if m.polygons.iter().any(|p| p.len() < 3) {
        return Err(MeshError::DegenerateFace.into());
    }
    let finite2 = m.uvs.iter().all(|v| v.is_finite());
    let finite3 = m.normals.iter().chain(&m.colors).all(|v| v.is_finite());
    if !finite2 || !finite3 {
        return Err(MeshError::NonFiniteAttributes.into());
    }
    // A trailing `\` would read back as a line continuation.
    let bad_name = |s: &str| s.contains(['\n', '\r', '#']) || s.trim() != s || s.ends_with('\\');
    let names = m.groups.iter().flat_map(|g| {
        g.object
            .iter()
            .chain(&g.material)
            .map(String::as_str)
            .chain(g.groups.iter().map(String::as_str))
    });
    for n in names.chain(scene.material_libraries.iter().map(String::as_str)) {
        if bad_name(n) {
            return Err(MeshError::UnwritableName {
                name: n.escape_debug().to_string(),
            }
            .into());
        }
    }
    if m.groups
        .iter()
        .flat_map(|g| &g.groups)
        .any(|g| g.is_empty() || g.contains([' ', '\t']))
    {
        return Err(MeshError::BadGroupName.into());
    }
    Ok(())
}

fn write_body(s: &mut String, scene: &ObjScene) -> std::fmt::Result {
    let m = &scene.mesh;
    for lib in &scene.material_libraries {
        writeln!(s, "mtllib {lib}")?;
    }
    for (i, p) in m.positions.iter().enumerate() {
        match m.colors.get(i) {
            Some(c) => writeln!(s, "v {} {} {} {} {} {}", p.x, p.y, p.z, c.x, c.y, c.z)?,
            None => writeln!(s, "v {} {} {}", p.x, p.y, p.z)?,
        }
    }
    for t in &m.uvs {
        writeln!(s, "vt {} {}", t.x, t.y)?;
    }
    for n in &m.normals {
        writeln!(s, "vn {} {} {}", n.x, n.y, n.z)?;
    }
    let mut state = FaceGroup::default();
    let mut groups = m.groups.iter().peekable();
    let uv = m.uv_polygons.as_ref();
    let nr = m.normal_polygons.as_ref();
    let faces = m.polygons.len();
    for f in 0..=faces {
        while let Some(g) = groups.next_if(|g| g.first_face as usize == f) {
            write_group_change(s, &state, g)?;
            state = g.clone();
        }
        if f == faces {
            break;
        }
        let poly = m.polygons.get(f).unwrap_or_default();
        let uvp = uv.and_then(|u| u.get(f));
        let nrp = nr.and_then(|n| n.get(f));
        s.push('f');
        for (k, v) in poly.iter().enumerate() {
            match (uvp, nrp) {
                (None, None) => write!(s, " {}", v + 1)?,
                (Some(t), None) => write!(s, " {}/{}", v + 1, t[k] + 1)?,
                (None, Some(n)) => write!(s, " {}//{}", v + 1, n[k] + 1)?,
                (Some(t), Some(n)) => write!(s, " {}/{}/{}", v + 1, t[k] + 1, n[k] + 1)?,
            }
        }
        s.push('\n');
    }
    Ok(())
}

/// Emits the statements that turn grouping state `from` into `to`; at least one, so the reader
/// starts a new span here.
fn write_group_change(s: &mut String, from: &FaceGroup, to: &FaceGroup) -> std::fmt::Result {
    let mut wrote = false;
    if from.object != to.object {
        writeln!(s, "o {}", to.object.as_deref().unwrap_or(""))?;
        wrote = true;
    }
    if from.groups != to.groups {
        writeln!(s, "g {}", to.groups.join(" "))?;
        wrote = true;
    }
    if from.smoothing != to.smoothing {
        match to.smoothing {
            Some(n) => writeln!(s, "s {n}")?,
            None => writeln!(s, "s off")?,
        }
        wrote = true;
    }
    if from.material != to.material {
        writeln!(s, "usemtl {}", to.material.as_deref().unwrap_or(""))?;
        wrote = true;
    }
    if !wrote {
        writeln!(s, "g {}", to.groups.join(" "))?;
    }
    Ok(())
}

/// Writes `scene` to `path` atomically (see [`write_obj_string`]).
pub fn write_obj_file(scene: &ObjScene, path: &Path) -> Result<()> {
    let text = write_obj_string(scene)?;
    crate::io::write_atomic(path, text.as_bytes())
}

#[cfg(test)]
mod tests;
