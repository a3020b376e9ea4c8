//! VRML97 (ISO/IEC 14772, UTF-8 text syntax): lexer, parser, scene graph and canonical writer.
//!
//! This is the syntax layer under MPEG-4 face files: it turns text into a [`Scene`] (an arena
//! of [`Node`]s with DEF/USE sharing preserved) and back. Meaning (meshes, FATs) is built on
//! top by other modules.
//!
//! # What is read, and how
//! - The file must start with `#VRML V2.0 utf8` (text after it on that line is ignored).
//! - Nodes whose type is in [`fields::KNOWN_NODE_TYPES`] (common VRML97 nodes and every MPEG-4
//!   face node: `Face`, `FAP`, `Viseme`, `Expression`, `FDP`, `FIT`, `FaceDefTables`,
//!   `FaceDefMesh`, `FaceDefTransform`) get typed [`FieldValue`]s; a field the type does not
//!   declare is an error listing the valid ones. Other node types are kept generically
//!   ([`FieldValue::Untyped`]) and written back unchanged in meaning.
//! - `DEF`/`USE`: a USE must name an earlier DEF; a USE inside the node it names (a cycle) is
//!   an error; a repeated DEF rebinds the name for later USEs, as VRML specifies.
//! - Decisions: `PROTO` and `EXTERNPROTO` declarations at the top level are kept verbatim (raw
//!   source text, written back unchanged) and their instances are read generically; `ROUTE`s at
//!   the top level are kept as [`Route`]s (their nodes must be DEFined before). `ROUTE`/`PROTO`
//!   inside a node body and `Script` nodes are rejected with a located "not supported" error.
//! - Each field may appear once per node. Default values are not filled in.
//! - Limits: nodes nest at most [`MAX_DEPTH`] deep; numbers must be finite; an SFImage's
//!   declared size never drives allocation. All errors are located [`ParseError`]s.
//!
//! # Example
//! ```
//! use std::path::Path;
//! use fbakit::vrml::{parse_vrml, write_vrml_string};
//! let text = "#VRML V2.0 utf8\nDEF C Coordinate { point [ 0 0 0, 1 0 0 ] }";
//! let scene = parse_vrml(text, Path::new("<input>")).unwrap();
//! let c = scene.find_def("C").unwrap();
//! assert_eq!(scene.get_mfvec3f(c, "point").unwrap().len(), 2);
//! assert_eq!(parse_vrml(&write_vrml_string(&scene), Path::new("<input>")).unwrap(), scene);
//! ```

pub mod fields;
pub mod lexer;
pub mod model;
mod parser;
#[cfg(test)]
mod tests;
pub mod writer;

use std::path::Path;

pub use fields::{field_type, node_fields, FieldDecl, FieldType};
pub use model::{
    FieldValue, Node, NodeId, NodeRef, Route, Scene, SfImage, Statement, UntypedItem, Visit,
};
pub use parser::{parse_vrml, rotation, untyped_scalar, vec2f, vec3f, HEADER, MAX_DEPTH};
pub use writer::{write_vrml_file, write_vrml_string};

use crate::error::{ParseError, Result};

/// Reads and parses a VRML97 file (bounded read, UTF-8 checked with a located error).
pub fn read_vrml_file(path: &Path) -> Result<Scene> {
    let text = crate::io::read_text(path)?;
    Ok(parse_vrml(&text, path)?)
}

/// Reads a VRML97 scene from `reader` (UTF-8, bounded by
/// [`crate::io::DEFAULT_MAX_INPUT_BYTES`]); `source` names it in locations.
pub fn read_vrml_from<R: std::io::BufRead>(reader: R, source: &Path) -> Result<Scene> {
    let text = crate::io::read_text_from(reader, source, crate::io::DEFAULT_MAX_INPUT_BYTES)?;
    Ok(parse_vrml(&text, source)?)
}

/// [`parse_vrml`] for text without a file, named `<input>` in errors.
pub fn parse_vrml_str(text: &str) -> Result<Scene, ParseError> {
    parse_vrml(text, Path::new("<input>"))
}
