//! Transforms and meshes the face has and its own scene lacks (cloning adds a `head` root or
//! a part transform, and cuts eyes and teeth out of a one-mesh head): a new DEF'd `Transform`
//! is put where its content sits in the scene and that content (shapes, child transforms) is
//! moved into it; a new mesh's `Shape` goes right after the shape of a mesh under the same
//! transform (else into that transform's `children`, else after the face's first shape). Every
//! other node of the file stays where it was.

use std::collections::HashMap;

use super::write::set_field;
use crate::face::FaceModel;
use crate::vrml::{FieldValue, Node, NodeId, NodeRef, Scene, Statement, UntypedItem};

/// Where a node is defined (its one non-`USE` reference).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Slot {
    /// Root statement `k`.
    Root(usize),
    /// Item `item` of field `field` of `node`.
    Field {
        node: NodeId,
        field: usize,
        item: usize,
    },
}

/// The defining slot of every node reachable from the scene's statements.
fn slots(scene: &Scene) -> HashMap<NodeId, Slot> {
    let mut out = HashMap::new();
    for (k, s) in scene.statements.iter().enumerate() {
        if let Statement::Node(r) = s {
            if !r.is_use {
                out.insert(r.id, Slot::Root(k));
            }
        }
    }
    for (n, node) in scene.nodes.iter().enumerate() {
        for (f, (_, value)) in node.fields.iter().enumerate() {
            for (item, r) in refs_with_items(value) {
                if !r.is_use {
                    out.entry(r.id).or_insert(Slot::Field {
                        node: NodeId(n),
                        field: f,
                        item,
                    });
                }
            }
        }
    }
    out
}

/// The node references of a value with their item positions.
fn refs_with_items(value: &FieldValue) -> Vec<(usize, NodeRef)> {
    match value {
        FieldValue::SFNode(Some(r)) => vec![(0, *r)],
        FieldValue::MFNode(v) => v.iter().copied().enumerate().collect(),
        FieldValue::Untyped { items, .. } => items
            .iter()
            .enumerate()
            .filter_map(|(i, it)| match it {
                UntypedItem::Node(r) => Some((i, *r)),
                _ => None,
            })
            .collect(),
        _ => Vec::new(),
    }
}

/// The `Transform` node nearest above `slot` (`None` at the top level).
fn enclosing_transform(scene: &Scene, all: &HashMap<NodeId, Slot>, slot: Slot) -> Option<NodeId> {
    let mut at = slot;
    // Bounded: a cyclic graph cannot loop here.
    for _ in 0..=scene.nodes.len() {
        let Slot::Field { node, .. } = at else {
            return None;
        };
        if scene.node(node).type_name == "Transform" {
            return Some(node);
        }
        at = *all.get(&node)?;
    }
    None
}

/// Puts `new` in place of the reference at `slot`.
fn replace_at(scene: &mut Scene, slot: Slot, new: NodeRef) {
    match slot {
        Slot::Root(k) => scene.statements[k] = Statement::Node(new),
        Slot::Field { node, field, item } => match &mut scene.nodes[node.0].fields[field].1 {
            FieldValue::SFNode(r) => *r = Some(new),
            FieldValue::MFNode(v) => v[item] = new,
            FieldValue::Untyped { items, .. } => items[item] = UntypedItem::Node(new),
            _ => {}
        },
    }
}

/// Removes the reference at `slot`.
fn remove_at(scene: &mut Scene, slot: Slot) {
    match slot {
        Slot::Root(k) => {
            scene.statements.remove(k);
        }
        Slot::Field { node, field, item } => match &mut scene.nodes[node.0].fields[field].1 {
            FieldValue::SFNode(r) => *r = None,
            FieldValue::MFNode(v) => {
                v.remove(item);
            }
            FieldValue::Untyped { items, bracketed } => {
                items.remove(item);
                // An empty unbracketed value would not parse back.
                *bracketed = true;
            }
            _ => {}
        },
    }
}

/// Appends `child` to the `children` of grouping node `parent`.
fn append_child(scene: &mut Scene, parent: NodeId, child: NodeRef) {
    let mut kids = scene
        .node(parent)
        .field("children")
        .map(|v| v.node_refs())
        .unwrap_or_default();
    kids.push(child);
    set_field(
        &mut scene.nodes[parent.0],
        "children",
        FieldValue::MFNode(kids),
    );
}

/// Inserts a new item right after the reference at `slot` (or appends at the top level).
fn insert_after(scene: &mut Scene, slot: Slot, new: NodeRef) -> bool {
    match slot {
        Slot::Root(k) => {
            scene.statements.insert(k + 1, Statement::Node(new));
            true
        }
        Slot::Field { node, field, item } => match &mut scene.nodes[node.0].fields[field].1 {
            FieldValue::MFNode(v) => {
                v.insert(item + 1, new);
                true
            }
            FieldValue::Untyped { items, bracketed } => {
                items.insert(item + 1, UntypedItem::Node(new));
                *bracketed = true;
                true
            }
            _ => false,
        },
    }
}

/// The `Shape` holding `ifs` as its geometry, and that shape's slot.
fn shape_of(scene: &Scene, all: &HashMap<NodeId, Slot>, ifs: NodeId) -> Option<(NodeId, Slot)> {
    match all.get(&ifs)? {
        Slot::Field { node, .. } if scene.node(*node).type_name == "Shape" => {
            Some((*node, *all.get(node)?))
        }
        _ => None,
    }
}

/// Places the `Shape` of each mesh `mesh_nodes` lacks (`make` builds it and returns the shape
/// and its `IndexedFaceSet`), as the module docs say, filling `mesh_nodes`. Transforms must be
/// placed afterwards ([`insert_transforms`] moves the new shapes with the rest).
pub(super) fn insert_meshes(
    scene: &mut Scene,
    face: &FaceModel,
    mesh_nodes: &mut [Option<NodeId>],
    transform_nodes: &[Option<NodeId>],
    mut make: impl FnMut(&mut Scene, usize) -> (NodeRef, NodeId),
) {
    for m in 0..face.meshes.len() {
        if mesh_nodes[m].is_some() {
            continue;
        }
        let all = slots(scene);
        let tf = face.meshes[m].transform;
        // A shape of an existing mesh under the same transform, else of any existing mesh.
        let sibling = |same: bool| {
            (0..face.meshes.len())
                .filter(|&o| !same || face.meshes[o].transform == tf)
                .filter_map(|o| mesh_nodes[o])
                .find_map(|ifs| shape_of(scene, &all, ifs))
        };
        let (same_slot, any_slot) = (sibling(true).map(|x| x.1), sibling(false).map(|x| x.1));
        // New nodes are appended to the scene: the slots found above stay valid.
        let (shape, ifs) = make(scene, m);
        let placed = match same_slot {
            Some(slot) => insert_after(scene, slot, shape),
            None => false,
        } || match tf.and_then(|t| transform_nodes.get(t).copied().flatten()) {
            Some(p) => {
                append_child(scene, p, shape);
                true
            }
            None => false,
        } || match any_slot {
            Some(slot) => insert_after(scene, slot, shape),
            None => false,
        };
        if !placed {
            scene.statements.push(Statement::Node(shape));
        }
        mesh_nodes[m] = Some(ifs);
    }
}

/// Adds a DEF'd `Transform` node for each of the face's transforms `transform_nodes` lacks
/// (fields are written by the caller), moving the shapes of its meshes and the nodes of its
/// child transforms into it. It takes the place of its first content that sits directly in
/// the parent transform; when none does, it is appended to the parent's `children`.
pub(super) fn insert_transforms(
    scene: &mut Scene,
    face: &FaceModel,
    transform_nodes: &mut [Option<NodeId>],
    mesh_nodes: &[NodeId],
) {
    let depth = |mut t: usize| {
        let mut d = 0;
        while let Some(p) = face.transforms[t].parent {
            if d > face.transforms.len() {
                break;
            }
            d += 1;
            t = p;
        }
        d
    };
    // Deepest first: a new transform's new children exist when it is placed.
    let mut missing: Vec<usize> = (0..face.transforms.len())
        .filter(|&t| transform_nodes[t].is_none())
        .collect();
    missing.sort_by_key(|&t| std::cmp::Reverse(depth(t)));
    for t in missing {
        let all = slots(scene);
        // The content: shapes of the transform's meshes, nodes of its child transforms.
        let mut content: Vec<NodeId> = Vec::new();
        for (m, mesh) in face.meshes.iter().enumerate() {
            if mesh.transform != Some(t) {
                continue;
            }
            if let Some(Slot::Field { node, .. }) = all.get(&mesh_nodes[m]) {
                if scene.node(*node).type_name == "Shape" {
                    content.push(*node);
                }
            }
        }
        for (c, tr) in face.transforms.iter().enumerate() {
            if tr.parent == Some(t) {
                content.extend(transform_nodes[c]);
            }
        }
        let parent_node = face.transforms[t].parent.and_then(|p| transform_nodes[p]);
        let mut node = Node::new("Transform");
        node.def_name = Some(face.transforms[t].name.clone());
        let id = scene.add_node(node);
        let new_ref = NodeRef { id, is_use: false };
        let anchor = content.iter().position(|c| {
            all.get(c)
                .is_some_and(|&s| enclosing_transform(scene, &all, s) == parent_node)
        });
        match anchor {
            Some(k) => replace_at(scene, all[&content[k]], new_ref),
            None => match parent_node {
                Some(p) => append_child(scene, p, new_ref),
                None => scene.statements.push(Statement::Node(new_ref)),
            },
        }
        // Take the rest out of their places (slots move as items go, so look each up again).
        for (k, &c) in content.iter().enumerate() {
            if Some(k) == anchor {
                continue;
            }
            if let Some(&s) = slots(scene).get(&c) {
                remove_at(scene, s);
            }
        }
        let children = content
            .iter()
            .map(|&c| NodeRef {
                id: c,
                is_use: false,
            })
            .collect();
        set_field(
            &mut scene.nodes[id.0],
            "children",
            FieldValue::MFNode(children),
        );
        transform_nodes[t] = Some(id);
    }
}
