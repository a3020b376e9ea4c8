//! Reader for Ahlberg's `.wfm` wireframe format (CANDIDE-3 report, Appendix D), as found in
//! `candide3.wfm` 3.1.6.
//!
//! Layout: header comment lines; then sections, each introduced by a `# TITLE:` line, in this
//! order: `VERTEX LIST` (count, then `x y z` lines), `FACE LIST` (count, then `a b c` vertex
//! triples), `ANIMATION UNITS LIST` (count, then per unit: one or more `#` comment lines — name
//! first, e.g. `# FAP 3 open_jaw`, optionally a FAPU such as `# MNS` — then a displacement count
//! and `vertex dx dy dz` lines), `SHAPE UNITS LIST` (same unit layout), `ANIMATION PARAMETERS` and
//! `SHAPE PARAMETERS` (count, then `unit value` lines), `TEXTURE` (count; following lines kept
//! verbatim) and `GLOBAL MOTION` (three `x y z` lines: rotation, scale, translation); an
//! optional `# END OF FILE` ends the file. The sections after `FACE LIST` may be absent at the
//! end of the file. Blank lines and comment lines that are not section titles may appear
//! between sections (the reference file lists unimplemented FAPs there).
//!
//! Hostile input: every count is checked against the bytes left (an item needs at least a few
//! bytes), nothing is pre-allocated from a count, every index is range-checked, non-finite
//! numbers are rejected, and errors carry file:line:column.

use std::path::Path;

use glam::Vec3;

use super::{AnimationUnit, CandideModel, GlobalMotion, ShapeUnit};
use crate::error::{ParseError, Result};
use crate::mesh::text::{fail, newline_or_eof, real, rest_of_line, spaces, unsigned, PErr, Res};
use crate::spec::{FapId, FapuKind};

/// The section titles, in file order.
const SECTIONS: [&str; 8] = [
    "VERTEX LIST",
    "FACE LIST",
    "ANIMATION UNITS LIST",
    "SHAPE UNITS LIST",
    "ANIMATION PARAMETERS",
    "SHAPE PARAMETERS",
    "TEXTURE",
    "GLOBAL MOTION",
];

/// The text of a comment line (after `#`, trimmed) and the input after the line.
pub(crate) fn comment_line(i: &str) -> Res<'_, &str> {
    let (r, _) = spaces(i)?;
    let Some(r) = r.strip_prefix('#') else {
        return fail(i, "a `#` comment line");
    };
    let (line, rest) = rest_of_line(r);
    Ok((rest, line.trim()))
}

/// A line holding only blanks (not the end of input).
pub(crate) fn blank_line(i: &str) -> Res<'_, ()> {
    let (r, _) = spaces(i)?;
    if r.is_empty() {
        return fail(i, "a blank line");
    }
    newline_or_eof(r)
}

/// The section title of a comment line (`# VERTEX LIST:` → `VERTEX LIST`), if it is one.
fn section_title(comment: &str) -> Option<&'static str> {
    let t = comment.strip_suffix(':')?.trim();
    SECTIONS
        .iter()
        .copied()
        .chain(["END OF FILE"])
        .find(|s| s.eq_ignore_ascii_case(t))
}

/// Skips blank lines and comments that are not section titles; returns the next section title
/// (consuming its line), `None` at end of input.
pub(crate) fn next_section(mut i: &str) -> Res<'_, Option<&'static str>> {
    loop {
        if i.is_empty() {
            return Ok((i, None));
        }
        if let Ok((r, ())) = blank_line(i) {
            i = r;
            continue;
        }
        let (r, text) = comment_line(i).map_err(|_| {
            nom::Err::Error(PErr {
                at: i,
                expected: "a `# SECTION:` title line or a comment",
            })
        })?;
        if let Some(t) = section_title(text) {
            return Ok((r, Some(t)));
        }
        i = r;
    }
}

/// Blank lines (possibly none).
fn skip_blank_lines(mut i: &str) -> &str {
    while let Ok((r, ())) = blank_line(i) {
        i = r;
    }
    i
}

/// Blanks then the end of the line.
fn line_end(i: &str) -> Res<'_, ()> {
    let (r, _) = spaces(i)?;
    newline_or_eof(r)
}

/// At least one blank, then a number.
fn spaced_real(i: &str) -> Res<'_, f32> {
    let (r, s) = spaces(i)?;
    if s.is_empty() {
        return fail(i, "a space");
    }
    real(r)
}

/// A count line, checked against the input left: each item needs at least `min_item_bytes`.
pub(crate) fn count_line(i: &str, min_item_bytes: usize) -> Res<'_, usize> {
    let i = skip_blank_lines(i);
    let (r, _) = spaces(i)?;
    let (r2, n) = unsigned(r)?;
    let (rest, ()) = line_end(r2)?;
    match usize::try_from(n) {
        // The last item may lack its line ending, hence `+ 1`.
        Ok(n) if n <= (rest.len() + 1) / min_item_bytes.max(1) => Ok((rest, n)),
        _ => fail(r, "a count the rest of the file can hold"),
    }
}

/// `x y z`.
pub(crate) fn vec3_line(i: &str) -> Res<'_, Vec3> {
    let (r, _) = spaces(i)?;
    let (r, x) = real(r)?;
    let (r, y) = spaced_real(r)?;
    let (r, z) = spaced_real(r)?;
    let (r, ()) = line_end(r)?;
    Ok((r, Vec3::new(x, y, z)))
}

/// A vertex index (range-checked by the caller).
fn index(i: &str) -> Res<'_, u32> {
    let (r, n) = unsigned(i).map_err(|_| {
        nom::Err::Error(PErr {
            at: i,
            expected: "a vertex index",
        })
    })?;
    match u32::try_from(n) {
        Ok(n) => Ok((r, n)),
        Err(_) => fail(i, "a vertex index below 2^32"),
    }
}

/// At least one blank, then an index.
fn spaced_index(i: &str) -> Res<'_, u32> {
    let (r, s) = spaces(i)?;
    if s.is_empty() {
        return fail(i, "a space");
    }
    index(r)
}

/// `a b c` — a triangle.
pub(crate) fn triangle_line(i: &str) -> Res<'_, [u32; 3]> {
    let (r, _) = spaces(i)?;
    let (r, a) = index(r)?;
    let (r, b) = spaced_index(r)?;
    let (r, c) = spaced_index(r)?;
    let (r, ()) = line_end(r)?;
    Ok((r, [a, b, c]))
}

/// `vertex dx dy dz` — one displacement of a unit.
pub(crate) fn displacement_line(i: &str) -> Res<'_, (u32, Vec3)> {
    let (r, _) = spaces(i)?;
    let (r, v) = index(r)?;
    let (r, x) = spaced_real(r)?;
    let (r, y) = spaced_real(r)?;
    let (r, z) = spaced_real(r)?;
    let (r, ()) = line_end(r)?;
    Ok((r, (v, Vec3::new(x, y, z))))
}

/// `unit value` — one stored parameter.
pub(crate) fn param_line(i: &str) -> Res<'_, (u32, f32)> {
    let (r, _) = spaces(i)?;
    let (r, u) = index(r)?;
    let (r, v) = spaced_real(r)?;
    let (r, ()) = line_end(r)?;
    Ok((r, (u, v)))
}

/// A unit: comment lines (at least one: the name), a count, displacement lines. Returns the
/// comments, the displacements and, for each displacement, the input at its line.
#[allow(clippy::type_complexity)]
pub(crate) fn unit_block(i: &str) -> Res<'_, (Vec<&str>, Vec<(&str, u32, Vec3)>)> {
    let mut r = skip_blank_lines(i);
    let mut comments = Vec::new();
    while let Ok((rest, text)) = comment_line(r) {
        comments.push(text);
        r = rest;
    }
    if comments.is_empty() {
        return fail(r, "a `#` comment line naming the unit");
    }
    let (mut r, n) = count_line(r, 8)?;
    let mut displacements = Vec::new();
    for _ in 0..n {
        let (rest, (v, d)) = displacement_line(r)?;
        displacements.push((r, v, d));
        r = rest;
    }
    Ok((r, (comments, displacements)))
}

/// `FAP 3 open_jaw` / `FAP10 raise_b_lip_lm` → (3, "open_jaw"); `None` for other names.
fn fap_label(label: &str) -> Option<(u64, &str)> {
    let rest = label.strip_prefix("FAP")?.trim_start();
    let digits = rest.bytes().take_while(u8::is_ascii_digit).count();
    if digits == 0 {
        return None;
    }
    let n = rest[..digits].parse().ok()?;
    Some((n, rest[digits..].trim()))
}

fn collapse_blanks(s: &str) -> String {
    s.split_whitespace().collect::<Vec<_>>().join(" ")
}

/// Reads `.wfm` text; `file` names the source in errors.
pub fn parse_wfm(text: &str, file: &Path) -> Result<CandideModel> {
    let err = |e: nom::Err<PErr<'_>>, default: &str| -> crate::error::Error {
        match e {
            nom::Err::Error(p) | nom::Err::Failure(p) => p.located(file, text, default).into(),
            nom::Err::Incomplete(_) => {
                ParseError::at_offset(file, text, text.len(), default).into()
            }
        }
    };
    let located = |at: &str, what: String| -> crate::error::Error {
        ParseError::at_rest(file, text, at, what).into()
    };
    let mut i = text.strip_prefix('\u{feff}').unwrap_or(text);

    // Header: comments up to the first section title.
    let mut header = Vec::new();
    loop {
        i = skip_blank_lines(i);
        let (r, c) = comment_line(i)
            .map_err(|_| located(i, "a `#` header comment or `# VERTEX LIST:`".into()))?;
        if section_title(c) == Some("VERTEX LIST") {
            i = r;
            break;
        }
        if section_title(c).is_some() {
            return Err(located(i, "`# VERTEX LIST:` as the first section".into()));
        }
        header.push(c.to_string());
        i = r;
    }

    let (mut r, n) = count_line(i, 6).map_err(|e| err(e, "a vertex count"))?;
    let mut vertices = Vec::new();
    for _ in 0..n {
        let (rest, v) = vec3_line(r).map_err(|e| err(e, "a vertex line `x y z`"))?;
        vertices.push(v);
        r = rest;
    }
    let nv = vertices.len();

    let (r2, s) = next_section(r).map_err(|e| err(e, "`# FACE LIST:`"))?;
    if s != Some("FACE LIST") {
        return Err(located(r, "`# FACE LIST:`".into()));
    }
    let (mut r, n) = count_line(r2, 6).map_err(|e| err(e, "a face count"))?;
    let mut triangles = Vec::new();
    for _ in 0..n {
        let (rest, t) = triangle_line(r).map_err(|e| err(e, "a face line `a b c`"))?;
        if let Some(&bad) = t.iter().find(|&&v| v as usize >= nv) {
            return Err(located(
                r,
                format!("vertex indices below {nv} (found {bad})"),
            ));
        }
        triangles.push(t);
        r = rest;
    }

    let mut model = CandideModel {
        header,
        vertices,
        triangles,
        animation_units: Vec::new(),
        shape_units: Vec::new(),
        animation_params: Vec::new(),
        shape_params: Vec::new(),
        texture: Vec::new(),
        global_motion: None,
    };
    let check_vertices = |disp: &[(&str, u32, Vec3)]| -> Result<Vec<(u32, Vec3)>> {
        disp.iter()
            .map(|&(at, v, d)| {
                if (v as usize) < nv {
                    Ok((v, d))
                } else {
                    Err(located(at, format!("a vertex index below {nv}")))
                }
            })
            .collect()
    };

    // Optional sections, in order, until the end of the file.
    let mut expected_next = 2;
    loop {
        let before = r;
        let (rest, title) = next_section(r).map_err(|e| err(e, "a section title"))?;
        let Some(title) = title else { break };
        if title == "END OF FILE" {
            break;
        }
        let pos = SECTIONS.iter().position(|&s| s == title).unwrap_or(0);
        if pos < expected_next {
            return Err(located(
                before,
                format!(
                    "a section after `{}` (sections in file order)",
                    SECTIONS[expected_next - 1]
                ),
            ));
        }
        expected_next = pos + 1;
        r = rest;
        match title {
            "ANIMATION UNITS LIST" | "SHAPE UNITS LIST" => {
                let (mut rr, n) = count_line(r, 4).map_err(|e| err(e, "a unit count"))?;
                for _ in 0..n {
                    let unit_at = skip_blank_lines(rr);
                    let (rest, (comments, disp)) = unit_block(rr).map_err(|e| err(e, "a unit"))?;
                    let displacements = check_vertices(&disp)?;
                    let label = comments[0];
                    let extra: Vec<&str> = comments[1..].to_vec();
                    if title == "SHAPE UNITS LIST" {
                        model.shape_units.push(ShapeUnit {
                            name: collapse_blanks(label),
                            comments: extra.iter().map(|s| s.to_string()).collect(),
                            displacements,
                        });
                    } else {
                        let (fap, name) = match fap_label(label) {
                            Some((n, name)) => {
                                let id =
                                    u8::try_from(n).ok().and_then(FapId::new).ok_or_else(|| {
                                        located(unit_at, "a FAP number from 1 to 68".into())
                                    })?;
                                (Some(id), name.to_string())
                            }
                            None => (None, collapse_blanks(label)),
                        };
                        let mut fapu = None;
                        let mut rest_comments = Vec::new();
                        for c in extra {
                            match c.parse::<FapuKind>() {
                                Ok(k) if fapu.is_none() => fapu = Some(k),
                                _ => rest_comments.push(c.to_string()),
                            }
                        }
                        model.animation_units.push(AnimationUnit {
                            name,
                            label: label.to_string(),
                            fap,
                            fapu,
                            comments: rest_comments,
                            displacements,
                        });
                    }
                    rr = rest;
                }
                r = rr;
            }
            "ANIMATION PARAMETERS" | "SHAPE PARAMETERS" => {
                let units = if title == "SHAPE PARAMETERS" {
                    model.shape_units.len()
                } else {
                    model.animation_units.len()
                };
                let (mut rr, n) = count_line(r, 4).map_err(|e| err(e, "a parameter count"))?;
                let mut params = Vec::new();
                for _ in 0..n {
                    let (rest, (u, v)) =
                        param_line(rr).map_err(|e| err(e, "a parameter line `unit value`"))?;
                    if u as usize >= units {
                        return Err(located(rr, format!("a unit index below {units}")));
                    }
                    params.push((u, v));
                    rr = rest;
                }
                if title == "SHAPE PARAMETERS" {
                    model.shape_params = params;
                } else {
                    model.animation_params = params;
                }
                r = rr;
            }
            "TEXTURE" => {
                let (mut rr, _n) = count_line(r, 1).map_err(|e| err(e, "a texture count"))?;
                // Verbatim lines up to the next blank line or section title.
                while !rr.is_empty() {
                    let (line, rest) = rest_of_line(rr);
                    let t = line.trim();
                    if t.is_empty()
                        || t.strip_prefix('#')
                            .and_then(|c| section_title(c.trim()))
                            .is_some()
                    {
                        break;
                    }
                    model.texture.push(t.to_string());
                    rr = rest;
                }
                r = rr;
            }
            _ => {
                // GLOBAL MOTION
                let mut rr = skip_blank_lines(r);
                let mut v = [Vec3::ZERO; 3];
                for slot in &mut v {
                    let (rest, x) = vec3_line(rr).map_err(|e| err(e, "a line `x y z`"))?;
                    *slot = x;
                    rr = rest;
                }
                model.global_motion = Some(GlobalMotion {
                    rotation: v[0],
                    scale: v[1],
                    translation: v[2],
                });
                r = rr;
            }
        }
    }
    Ok(model)
}

/// Reads a `.wfm` file (UTF-8, size-bounded by [`crate::io::read_text`]).
pub fn read_wfm_file(path: &Path) -> Result<CandideModel> {
    let text = crate::io::read_text(path)?;
    parse_wfm(&text, path)
}

/// Reads a CANDIDE-3 model from `reader` (UTF-8, bounded by
/// [`crate::io::DEFAULT_MAX_INPUT_BYTES`]); `source` names it in locations.
pub fn read_wfm_from<R: std::io::BufRead>(reader: R, source: &Path) -> Result<CandideModel> {
    let text = crate::io::read_text_from(reader, source, crate::io::DEFAULT_MAX_INPUT_BYTES)?;
    parse_wfm(&text, source)
}

#[cfg(test)]
mod tests;
