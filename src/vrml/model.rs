//! The scene graph: an arena of nodes with DEF/USE sharing preserved.

use std::path::PathBuf;

use crate::error::Location;

/// Index of a node in [`Scene::nodes`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct NodeId(pub usize);

/// A reference from a field to a node: either the node's definition (written in place) or a
/// `USE` of a node defined earlier (written as `USE name`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct NodeRef {
    /// The referenced node.
    pub id: NodeId,
    /// True when the file said `USE name` here.
    pub is_use: bool,
}

/// An SFImage: `width height components` then `width x height` packed pixels.
#[derive(Clone, Debug, PartialEq, Eq, Default)]
pub struct SfImage {
    /// Pixels per row.
    pub width: u32,
    /// Rows.
    pub height: u32,
    /// Components per pixel, 0..=4 (intensity, +alpha, RGB, RGBA).
    pub components: u8,
    /// One packed value per pixel, row by row from the bottom.
    pub pixels: Vec<u32>,
}

/// One item of a field of an unknown node type, kept without interpretation.
#[derive(Clone, Debug, PartialEq)]
pub enum UntypedItem {
    /// A number exactly as written (`0x1F`, `1.50`), so it is written back unchanged.
    Number(String),
    /// A string (unescaped).
    String(String),
    /// `TRUE` or `FALSE`.
    Bool(bool),
    /// `NULL`.
    Null,
    /// A node (definition or USE).
    Node(NodeRef),
}

/// A field value, typed by the node type's field table ([`super::fields`]).
#[derive(Clone, Debug, PartialEq)]
#[allow(missing_docs)] // Variants are the standard's field types.
pub enum FieldValue {
    SFBool(bool),
    SFInt32(i32),
    SFFloat(f32),
    SFTime(f64),
    SFString(String),
    SFVec2f([f32; 2]),
    SFVec3f([f32; 3]),
    SFColor([f32; 3]),
    /// Axis x y z, then angle in radians.
    SFRotation([f32; 4]),
    SFImage(SfImage),
    /// `None` is `NULL`.
    SFNode(Option<NodeRef>),
    MFInt32(Vec<i32>),
    MFFloat(Vec<f32>),
    MFTime(Vec<f64>),
    MFString(Vec<String>),
    MFVec2f(Vec<[f32; 2]>),
    MFVec3f(Vec<[f32; 3]>),
    MFColor(Vec<[f32; 3]>),
    MFRotation(Vec<[f32; 4]>),
    MFNode(Vec<NodeRef>),
    /// A field of a node type without a field table. `bracketed` records `[ ... ]`.
    Untyped {
        /// Whether the value was written in brackets.
        bracketed: bool,
        /// The items in order.
        items: Vec<UntypedItem>,
    },
}

impl FieldValue {
    /// The nodes this value references, in order.
    pub fn node_refs(&self) -> Vec<NodeRef> {
        match self {
            FieldValue::SFNode(Some(r)) => vec![*r],
            FieldValue::MFNode(v) => v.clone(),
            FieldValue::Untyped { items, .. } => items
                .iter()
                .filter_map(|i| match i {
                    UntypedItem::Node(r) => Some(*r),
                    _ => None,
                })
                .collect(),
            _ => Vec::new(),
        }
    }
}

/// One node: its type, optional DEF name, the fields given in the file (defaults are not
/// filled in) and where it starts.
#[derive(Clone, Debug)]
pub struct Node {
    /// Node type name, e.g. `IndexedFaceSet`.
    pub type_name: String,
    /// The `DEF` name, if any.
    pub def_name: Option<String>,
    /// Fields in file order; each name at most once.
    pub fields: Vec<(String, FieldValue)>,
    /// Where the node (its `DEF` or type name) starts; ignored by equality.
    pub location: Location,
}

impl PartialEq for Node {
    /// Equal content; the location is where it came from, not what it is.
    fn eq(&self, other: &Self) -> bool {
        self.type_name == other.type_name
            && self.def_name == other.def_name
            && self.fields == other.fields
    }
}

impl Node {
    /// A node without fields, located nowhere (for scenes built in code).
    pub fn new(type_name: impl Into<String>) -> Node {
        Node {
            type_name: type_name.into(),
            def_name: None,
            fields: Vec::new(),
            location: Location {
                file: PathBuf::from("<generated>"),
                line: 0,
                column: 0,
            },
        }
    }

    /// The value of field `name`, if given.
    pub fn field(&self, name: &str) -> Option<&FieldValue> {
        self.fields.iter().find(|(n, _)| n == name).map(|(_, v)| v)
    }
}

/// `ROUTE from_node.from_field TO to_node.to_field`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Route {
    /// DEF name of the source node.
    pub from_node: String,
    /// Its eventOut.
    pub from_field: String,
    /// DEF name of the target node.
    pub to_node: String,
    /// Its eventIn.
    pub to_field: String,
}

/// A top-level statement, in file order (PROTOs must precede their use, ROUTEs follow DEFs).
#[derive(Clone, Debug, PartialEq)]
pub enum Statement {
    /// A root node.
    Node(NodeRef),
    /// A `PROTO` declaration, kept verbatim (from `PROTO` to its closing `}`).
    Proto {
        /// The prototype's name.
        name: String,
        /// The source text, written back unchanged.
        text: String,
    },
    /// An `EXTERNPROTO` declaration, kept verbatim (through its URL list).
    ExternProto {
        /// The prototype's name.
        name: String,
        /// The source text, written back unchanged.
        text: String,
    },
    /// A `ROUTE`.
    Route(Route),
}

/// A parsed VRML97 file.
#[derive(Clone, Debug, Default)]
pub struct Scene {
    /// The file it was read from (`<input>` for text).
    pub file: PathBuf,
    /// Every node, in file order of their definitions (parents before children).
    pub nodes: Vec<Node>,
    /// Top-level statements in file order.
    pub statements: Vec<Statement>,
}

impl PartialEq for Scene {
    /// Equal graphs and statements, wherever they came from.
    fn eq(&self, other: &Self) -> bool {
        self.nodes == other.nodes && self.statements == other.statements
    }
}

/// One step of [`Scene::depth_first`].
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Visit {
    /// The node reached.
    pub id: NodeId,
    /// Nodes from the root down to and including `id`.
    pub path: Vec<NodeId>,
    /// True when reached through `USE` (its children are then not visited again).
    pub via_use: bool,
}

impl Scene {
    /// An empty scene (for building in code).
    pub fn new() -> Scene {
        Scene::default()
    }

    /// Appends a node to the arena and returns its id.
    pub fn add_node(&mut self, node: Node) -> NodeId {
        self.nodes.push(node);
        NodeId(self.nodes.len() - 1)
    }

    /// Appends a root node statement.
    pub fn push_root(&mut self, id: NodeId) {
        self.statements
            .push(Statement::Node(NodeRef { id, is_use: false }));
    }

    /// The root nodes in file order.
    pub fn roots(&self) -> impl Iterator<Item = NodeId> + '_ {
        self.statements.iter().filter_map(|s| match s {
            Statement::Node(r) => Some(r.id),
            _ => None,
        })
    }

    /// The ROUTEs in file order.
    pub fn routes(&self) -> impl Iterator<Item = &Route> + '_ {
        self.statements.iter().filter_map(|s| match s {
            Statement::Route(r) => Some(r),
            _ => None,
        })
    }

    /// The node `id`. Panics on an id not from this scene.
    pub fn node(&self, id: NodeId) -> &Node {
        &self.nodes[id.0]
    }

    /// The node last defined with `DEF name` (VRML: a later DEF rebinds the name).
    pub fn find_def(&self, name: &str) -> Option<NodeId> {
        self.nodes
            .iter()
            .rposition(|n| n.def_name.as_deref() == Some(name))
            .map(NodeId)
    }

    /// All nodes of type `type_name`, in file order.
    pub fn nodes_of_type<'a>(&'a self, type_name: &'a str) -> impl Iterator<Item = NodeId> + 'a {
        self.nodes
            .iter()
            .enumerate()
            .filter(move |(_, n)| n.type_name == type_name)
            .map(|(i, _)| NodeId(i))
    }

    /// Field `name` of node `id`, if given in the file.
    pub fn field(&self, id: NodeId, name: &str) -> Option<&FieldValue> {
        self.nodes.get(id.0)?.field(name)
    }

    /// SFBool field.
    pub fn get_sfbool(&self, id: NodeId, name: &str) -> Option<bool> {
        match self.field(id, name)? {
            FieldValue::SFBool(v) => Some(*v),
            _ => None,
        }
    }

    /// SFInt32 field.
    pub fn get_sfint32(&self, id: NodeId, name: &str) -> Option<i32> {
        match self.field(id, name)? {
            FieldValue::SFInt32(v) => Some(*v),
            _ => None,
        }
    }

    /// SFFloat field.
    pub fn get_sffloat(&self, id: NodeId, name: &str) -> Option<f32> {
        match self.field(id, name)? {
            FieldValue::SFFloat(v) => Some(*v),
            _ => None,
        }
    }

    /// SFString field.
    pub fn get_sfstring(&self, id: NodeId, name: &str) -> Option<&str> {
        match self.field(id, name)? {
            FieldValue::SFString(v) => Some(v),
            _ => None,
        }
    }

    /// SFVec3f or SFColor field.
    pub fn get_sfvec3f(&self, id: NodeId, name: &str) -> Option<[f32; 3]> {
        match self.field(id, name)? {
            FieldValue::SFVec3f(v) | FieldValue::SFColor(v) => Some(*v),
            _ => None,
        }
    }

    /// SFRotation field (axis, angle).
    pub fn get_sfrotation(&self, id: NodeId, name: &str) -> Option<[f32; 4]> {
        match self.field(id, name)? {
            FieldValue::SFRotation(v) => Some(*v),
            _ => None,
        }
    }

    /// SFNode field; `None` when absent, NULL or not an SFNode.
    pub fn get_sfnode(&self, id: NodeId, name: &str) -> Option<NodeId> {
        match self.field(id, name)? {
            FieldValue::SFNode(Some(r)) => Some(r.id),
            _ => None,
        }
    }

    /// MFNode field's nodes (empty when absent).
    pub fn get_mfnode(&self, id: NodeId, name: &str) -> Vec<NodeId> {
        match self.field(id, name) {
            Some(FieldValue::MFNode(v)) => v.iter().map(|r| r.id).collect(),
            _ => Vec::new(),
        }
    }

    /// MFInt32 field.
    pub fn get_mfint32(&self, id: NodeId, name: &str) -> Option<&[i32]> {
        match self.field(id, name)? {
            FieldValue::MFInt32(v) => Some(v),
            _ => None,
        }
    }

    /// MFFloat field.
    pub fn get_mffloat(&self, id: NodeId, name: &str) -> Option<&[f32]> {
        match self.field(id, name)? {
            FieldValue::MFFloat(v) => Some(v),
            _ => None,
        }
    }

    /// MFString field.
    pub fn get_mfstring(&self, id: NodeId, name: &str) -> Option<&[String]> {
        match self.field(id, name)? {
            FieldValue::MFString(v) => Some(v),
            _ => None,
        }
    }

    /// MFVec2f field.
    pub fn get_mfvec2f(&self, id: NodeId, name: &str) -> Option<&[[f32; 2]]> {
        match self.field(id, name)? {
            FieldValue::MFVec2f(v) => Some(v),
            _ => None,
        }
    }

    /// MFVec3f or MFColor field.
    pub fn get_mfvec3f(&self, id: NodeId, name: &str) -> Option<&[[f32; 3]]> {
        match self.field(id, name)? {
            FieldValue::MFVec3f(v) | FieldValue::MFColor(v) => Some(v),
            _ => None,
        }
    }

    /// The child nodes of `id` in field order.
    pub fn children(&self, id: NodeId) -> Vec<NodeRef> {
        self.node(id)
            .fields
            .iter()
            .flat_map(|(_, v)| v.node_refs())
            .collect()
    }

    /// Every node reachable from the roots, depth first in file order, with its path from
    /// the root. A node reached through `USE` is visited (with `via_use`) but not descended
    /// into again, so shared subgraphs cost nothing extra. Iterative: no recursion.
    pub fn depth_first(&self) -> Vec<Visit> {
        let mut out = Vec::new();
        // Stack of (ref, parent path).
        let mut stack: Vec<(NodeRef, Vec<NodeId>)> = self
            .statements
            .iter()
            .rev()
            .filter_map(|s| match s {
                Statement::Node(r) => Some((*r, Vec::new())),
                _ => None,
            })
            .collect();
        while let Some((r, mut path)) = stack.pop() {
            if r.id.0 >= self.nodes.len() {
                continue;
            }
            path.push(r.id);
            if !r.is_use {
                for child in self.children(r.id).into_iter().rev() {
                    stack.push((child, path.clone()));
                }
            }
            out.push(Visit {
                id: r.id,
                path,
                via_use: r.is_use,
            });
        }
        out
    }

    /// A human-readable path for messages: `Transform(DEF Head) > Shape > IndexedFaceSet`.
    pub fn path_string(&self, path: &[NodeId]) -> String {
        path.iter()
            .map(|&id| {
                let n = self.node(id);
                match &n.def_name {
                    Some(d) => format!("{}(DEF {d})", n.type_name),
                    None => n.type_name.clone(),
                }
            })
            .collect::<Vec<_>>()
            .join(" > ")
    }
}
