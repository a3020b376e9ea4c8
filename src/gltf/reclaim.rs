//! Dropping the storage of fbakit's own morph targets that a new write replaced.
//!
//! Patching a document fbakit wrote before (`play` or `face export` on a clone's output)
//! rewrites fbakit's targets in their slots. Their old accessors, the buffer views only they
//! used and those views' bytes would otherwise stay in the file: unused objects for the
//! validator, and a file that grows with every write. Only accessors the patch released and
//! nothing references any more are dropped; references are renumbered where glTF (and the
//! extensions that point at accessors or views) keeps them.
//!
//! An extension fbakit does not know may hold accessor or view indices it cannot renumber:
//! when the document uses one, nothing is dropped (the file keeps the unused data, and a
//! warning names the extensions), since a wrong index would break the user's file.

use std::collections::BTreeSet;

use serde_json::Value;

use crate::error::Diagnostic;

/// Extensions whose accessor and buffer view indices the walks below renumber.
const WALKED: &[&str] = &["EXT_mesh_gpu_instancing", "KHR_draco_mesh_compression"];

/// Extensions whose JSON holds no accessor or buffer view index (only factors, texture,
/// image, node, mesh or material indices, morph target slots, which dropping accessors does
/// not move), so they never stop the cleanup.
const HOLD_NO_ACCESSORS: &[&str] = &[
    "KHR_animation_pointer",
    "KHR_lights_punctual",
    "KHR_materials_anisotropy",
    "KHR_materials_clearcoat",
    "KHR_materials_diffuse_transmission",
    "KHR_materials_dispersion",
    "KHR_materials_emissive_strength",
    "KHR_materials_ior",
    "KHR_materials_iridescence",
    "KHR_materials_pbrSpecularGlossiness",
    "KHR_materials_sheen",
    "KHR_materials_specular",
    "KHR_materials_transmission",
    "KHR_materials_unlit",
    "KHR_materials_variants",
    "KHR_materials_volume",
    "KHR_mesh_quantization",
    "KHR_texture_basisu",
    "KHR_texture_transform",
    "KHR_xmp_json_ld",
    "EXT_texture_avif",
    "EXT_texture_webp",
    "VRM",
    "VRMC_materials_mtoon",
    "VRMC_node_constraint",
    "VRMC_springBone",
    "VRMC_vrm",
];

/// The extensions `json` uses that fbakit cannot renumber references in: named in
/// `extensionsUsed` or as a key of an `extensions` object anywhere (extras, the user's own
/// data, are not looked into).
fn unknown_extensions(json: &Value) -> BTreeSet<String> {
    fn walk(v: &Value, out: &mut BTreeSet<String>) {
        match v {
            Value::Object(o) => {
                for (k, child) in o {
                    match k.as_str() {
                        "extras" => {}
                        "extensions" => {
                            if let Some(e) = child.as_object() {
                                out.extend(e.keys().cloned());
                            }
                            walk(child, out);
                        }
                        _ => walk(child, out),
                    }
                }
            }
            Value::Array(a) => a.iter().for_each(|c| walk(c, out)),
            _ => {}
        }
    }
    let mut names: BTreeSet<String> = json["extensionsUsed"]
        .as_array()
        .into_iter()
        .flatten()
        .filter_map(|n| n.as_str().map(str::to_string))
        .collect();
    walk(json, &mut names);
    names.retain(|n| !WALKED.contains(&n.as_str()) && !HOLD_NO_ACCESSORS.contains(&n.as_str()));
    names
}

/// A walk over one kind of reference (accessor or buffer view indices) of a document.
type Visit = fn(&mut Value, &mut dyn FnMut(&mut Value));

/// Calls `f` on every accessor reference of `json`.
fn for_each_accessor_ref(json: &mut Value, f: &mut impl FnMut(&mut Value)) {
    let on_map = |m: &mut Value, f: &mut dyn FnMut(&mut Value)| {
        if let Some(o) = m.as_object_mut() {
            o.values_mut().for_each(f);
        }
    };
    if let Some(meshes) = json.get_mut("meshes").and_then(Value::as_array_mut) {
        for prim in meshes
            .iter_mut()
            .filter_map(|m| m.get_mut("primitives").and_then(Value::as_array_mut))
            .flatten()
        {
            if let Some(a) = prim.get_mut("attributes") {
                on_map(a, f);
            }
            if let Some(i) = prim.get_mut("indices") {
                f(i);
            }
            if let Some(ts) = prim.get_mut("targets").and_then(Value::as_array_mut) {
                ts.iter_mut().for_each(|t| on_map(t, f));
            }
        }
    }
    if let Some(skins) = json.get_mut("skins").and_then(Value::as_array_mut) {
        for s in skins {
            if let Some(i) = s.get_mut("inverseBindMatrices") {
                f(i);
            }
        }
    }
    if let Some(anims) = json.get_mut("animations").and_then(Value::as_array_mut) {
        for s in anims
            .iter_mut()
            .filter_map(|a| a.get_mut("samplers").and_then(Value::as_array_mut))
            .flatten()
        {
            for k in ["input", "output"] {
                if let Some(i) = s.get_mut(k) {
                    f(i);
                }
            }
        }
    }
    if let Some(nodes) = json.get_mut("nodes").and_then(Value::as_array_mut) {
        for n in nodes {
            if let Some(a) = n.pointer_mut("/extensions/EXT_mesh_gpu_instancing/attributes") {
                on_map(a, f);
            }
        }
    }
}

/// Calls `f` on every buffer view reference of `json`.
fn for_each_view_ref(json: &mut Value, f: &mut impl FnMut(&mut Value)) {
    if let Some(accs) = json.get_mut("accessors").and_then(Value::as_array_mut) {
        for a in accs {
            for p in [
                "/bufferView",
                "/sparse/indices/bufferView",
                "/sparse/values/bufferView",
            ] {
                if let Some(v) = a.pointer_mut(p) {
                    f(v);
                }
            }
        }
    }
    if let Some(images) = json.get_mut("images").and_then(Value::as_array_mut) {
        for i in images {
            if let Some(v) = i.get_mut("bufferView") {
                f(v);
            }
        }
    }
    if let Some(meshes) = json.get_mut("meshes").and_then(Value::as_array_mut) {
        for prim in meshes
            .iter_mut()
            .filter_map(|m| m.get_mut("primitives").and_then(Value::as_array_mut))
            .flatten()
        {
            if let Some(v) = prim.pointer_mut("/extensions/KHR_draco_mesh_compression/bufferView") {
                f(v);
            }
        }
    }
}

/// How often each of `n` objects is referenced through `visit`.
fn counts(json: &mut Value, n: usize, visit: Visit) -> Vec<usize> {
    let mut c = vec![0; n];
    visit(json, &mut |v: &mut Value| {
        if let Some(i) = v.as_u64().map(|i| i as usize).filter(|&i| i < n) {
            c[i] += 1;
        }
    });
    c
}

/// Removes the entries `drop` of the array `key` and renumbers the references `visit` finds.
fn remove_and_renumber(json: &mut Value, key: &str, drop: &[bool], visit: Visit) {
    let mut next = 0;
    let map: Vec<Option<usize>> = drop
        .iter()
        .map(|&d| {
            (!d).then(|| {
                next += 1;
                next - 1
            })
        })
        .collect();
    if let Some(list) = json.get_mut(key).and_then(Value::as_array_mut) {
        let mut k = 0;
        list.retain(|_| {
            k += 1;
            !drop[k - 1]
        });
    }
    visit(json, &mut |v: &mut Value| {
        if let Some(Some(n)) = v.as_u64().and_then(|i| map.get(i as usize)) {
            *v = Value::from(*n);
        }
    });
}

fn accessor_refs(json: &mut Value, f: &mut dyn FnMut(&mut Value)) {
    for_each_accessor_ref(json, &mut |v: &mut Value| f(v));
}

fn view_refs(json: &mut Value, f: &mut dyn FnMut(&mut Value)) {
    for_each_view_ref(json, &mut |v: &mut Value| f(v));
}

/// Drops the accessors `released` that nothing references any more, then the buffer views
/// only they used, then those views' bytes in `bin` (buffer 0; the views after them move down,
/// keeping their 4-byte alignment). In a document using an extension fbakit cannot renumber,
/// keeps them all and says so in `warnings` (`file` names the document).
pub(super) fn drop_released(
    json: &mut Value,
    bin: &mut Vec<u8>,
    released: &[usize],
    file: &str,
    warnings: &mut Vec<Diagnostic>,
) {
    let n_acc = json["accessors"].as_array().map_or(0, Vec::len);
    let refs = counts(json, n_acc, accessor_refs);
    let mut drop_acc = vec![false; n_acc];
    for &a in released.iter().filter(|&&a| a < n_acc && refs[a] == 0) {
        drop_acc[a] = true;
    }
    let unused = drop_acc.iter().filter(|&&d| d).count();
    if unused == 0 {
        return;
    }
    let unknown = unknown_extensions(json);
    if !unknown.is_empty() {
        let names: Vec<&str> = unknown.iter().map(String::as_str).collect();
        warnings.push(Diagnostic::warning(format!(
            "{file}: kept {unused} unused accessors (fbakit's replaced morph targets) because \
             the document uses {}, whose references fbakit cannot renumber; the file is \
             larger than it needs to be",
            names.join(", ")
        )));
        return;
    }
    // The views the dropped accessors used.
    let mut freed_views = Vec::new();
    for (a, acc) in json["accessors"]
        .as_array()
        .into_iter()
        .flatten()
        .enumerate()
    {
        if drop_acc[a] {
            for p in [
                "/bufferView",
                "/sparse/indices/bufferView",
                "/sparse/values/bufferView",
            ] {
                freed_views.extend(acc.pointer(p).and_then(Value::as_u64).map(|v| v as usize));
            }
        }
    }
    remove_and_renumber(json, "accessors", &drop_acc, accessor_refs);
    let n_views = json["bufferViews"].as_array().map_or(0, Vec::len);
    let refs = counts(json, n_views, view_refs);
    let mut drop_view = vec![false; n_views];
    for &v in freed_views.iter().filter(|&&v| v < n_views && refs[v] == 0) {
        drop_view[v] = true;
    }
    // Byte ranges of the dropped views, padded to 4 bytes (views fbakit writes start aligned).
    let views = json["bufferViews"].as_array().cloned().unwrap_or_default();
    let range = |v: &Value| {
        let o = v["byteOffset"].as_u64().unwrap_or(0) as usize;
        (o, o + v["byteLength"].as_u64().unwrap_or(0) as usize)
    };
    let mut gaps: Vec<(usize, usize)> = views
        .iter()
        .enumerate()
        .filter(|&(k, v)| drop_view[k] && v["buffer"].as_u64().unwrap_or(0) == 0)
        .map(|(_, v)| range(v))
        .filter(|&(s, e)| s % 4 == 0 && e <= bin.len())
        .map(|(s, e)| (s, e.next_multiple_of(4).min(bin.len())))
        .collect();
    remove_and_renumber(json, "bufferViews", &drop_view, view_refs);
    // A gap any kept view still touches stays.
    let kept: Vec<(usize, usize)> = json["bufferViews"]
        .as_array()
        .into_iter()
        .flatten()
        .map(range)
        .collect();
    gaps.retain(|&(s, e)| kept.iter().all(|&(ks, ke)| ke <= s || ks >= e));
    gaps.sort_unstable();
    gaps.dedup();
    if gaps.is_empty() {
        return;
    }
    let removed_before = |offset: usize| -> usize {
        gaps.iter()
            .filter(|&&(_, e)| e <= offset)
            .map(|&(s, e)| e - s)
            .sum()
    };
    if let Some(list) = json.get_mut("bufferViews").and_then(Value::as_array_mut) {
        for v in list {
            let o = v["byteOffset"].as_u64().unwrap_or(0) as usize;
            let shift = removed_before(o);
            if shift > 0 {
                v["byteOffset"] = Value::from(o - shift);
            }
        }
    }
    let mut out = Vec::with_capacity(bin.len());
    let mut at = 0;
    for &(s, e) in &gaps {
        if s >= at {
            out.extend_from_slice(&bin[at..s]);
            at = e;
        }
    }
    out.extend_from_slice(&bin[at..]);
    *bin = out;
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn a_released_accessor_goes_with_its_views_and_bytes_and_the_rest_is_renumbered() {
        let mut json = json!({
            "meshes": [{"primitives": [{"attributes": {"POSITION": 2}, "targets": [{"POSITION": 0}]}]}],
            "accessors": [
                {"count": 1, "sparse": {"indices": {"bufferView": 2}, "values": {"bufferView": 3}}},
                {"count": 1, "bufferView": 0},
                {"count": 1, "bufferView": 1}
            ],
            "bufferViews": [
                {"buffer": 0, "byteOffset": 0, "byteLength": 4},
                {"buffer": 0, "byteOffset": 16, "byteLength": 4},
                {"buffer": 0, "byteOffset": 4, "byteLength": 4},
                {"buffer": 0, "byteOffset": 8, "byteLength": 6}
            ],
            "images": [{"bufferView": 1}]
        });
        let mut bin: Vec<u8> = (0..20).collect();
        // Accessor 1 (released, referenced by nothing) goes; 0 and 2 are used and stay.
        drop_released(&mut json, &mut bin, &[1], "d.gltf", &mut Vec::new());
        assert_eq!(json["accessors"].as_array().unwrap().len(), 2);
        assert_eq!(
            json["meshes"][0]["primitives"][0]["attributes"]["POSITION"],
            1
        );
        assert_eq!(
            json["meshes"][0]["primitives"][0]["targets"][0]["POSITION"],
            0
        );
        // View 0 (bytes 0..4) went; the others moved down 4 bytes and were renumbered.
        let views = json["bufferViews"].as_array().unwrap();
        assert_eq!(views.len(), 3);
        assert_eq!(json["images"][0]["bufferView"], 0);
        assert_eq!(views[0]["byteOffset"], 12);
        assert_eq!(json["accessors"][1]["bufferView"], 0);
        assert_eq!(json["accessors"][0]["sparse"]["indices"]["bufferView"], 1);
        assert_eq!(views[1]["byteOffset"], 0);
        assert_eq!(bin.len(), 16);
        assert_eq!(bin[12], 16);
    }

    #[test]
    fn an_unknown_extension_keeps_everything_and_says_so() {
        let doc = |ext: Value| {
            json!({
                "extensionsUsed": ["KHR_materials_specular"],
                "meshes": [{"primitives": [{"attributes": {"POSITION": 1}, "extensions": ext}]}],
                "accessors": [{"count": 1, "bufferView": 0}, {"count": 1, "bufferView": 1}],
                "bufferViews": [
                    {"buffer": 0, "byteOffset": 0, "byteLength": 4},
                    {"buffer": 0, "byteOffset": 4, "byteLength": 4}
                ],
                "materials": [{"extensions": {"KHR_materials_specular": {"specularFactor": 0.5}}}],
                "extras": {"extensions": {"MY_NOTE": {}}}
            })
        };
        // Known ones (and an `extensions` key inside extras) do not stop the cleanup.
        let mut json = doc(json!({}));
        let mut bin = vec![0u8; 8];
        let mut warnings = Vec::new();
        drop_released(&mut json, &mut bin, &[0], "d.gltf", &mut warnings);
        assert!(warnings.is_empty(), "{warnings:?}");
        assert_eq!(json["accessors"].as_array().unwrap().len(), 1);
        assert_eq!(bin.len(), 4);
        // An unknown one on a primitive, or only listed as used: nothing dropped, a warning.
        for mut json in [doc(json!({"EXT_foo": {"accessor": 0}})), {
            let mut j = doc(json!({}));
            j["extensionsUsed"] = json!(["EXT_foo"]);
            j
        }] {
            let before = json.clone();
            let mut bin = vec![0u8; 8];
            let mut warnings = Vec::new();
            drop_released(&mut json, &mut bin, &[0], "d.gltf", &mut warnings);
            assert_eq!(json, before);
            assert_eq!(bin.len(), 8);
            assert_eq!(warnings.len(), 1);
            let w = &warnings[0].message;
            assert!(
                w.contains("d.gltf: kept 1 unused accessors") && w.contains("EXT_foo"),
                "{w}"
            );
            assert!(!w.contains("KHR_materials_specular"), "{w}");
        }
    }

    #[test]
    fn a_released_accessor_still_referenced_stays() {
        let mut json = json!({
            "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "targets": [{"POSITION": 0}]}]}],
            "accessors": [{"count": 1, "bufferView": 0}],
            "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 4}]
        });
        let before = json.clone();
        let mut bin = vec![0u8; 4];
        drop_released(&mut json, &mut bin, &[0], "d.gltf", &mut Vec::new());
        assert_eq!(json, before);
        assert_eq!(bin.len(), 4);
    }
}
