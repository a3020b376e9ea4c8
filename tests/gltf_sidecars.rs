//! A `.gltf` with its buffer and images in files of their own, written back by `clone`,
//! `play` and `face export` (issue 19, "your face back"): the output's own `.bin` beside it,
//! the images carried over with their URIs rewritten wherever the output goes (also from a
//! Sketchfab-style `../textures/` folder, a space in the name), a user's own file of the same
//! name neither used nor overwritten, a `.bin` that would replace an input file refused, and
//! the cleanup of a rewritten document held back by an extension fbakit cannot renumber.
//! Outputs are checked by the Khronos validator (external files read beside the document),
//! three.js (`tests/support/gltf-loaders-check.mjs`) and Blender (`tests/support/blender.rs`).
//!
//! One layout per test binary (a shared fixture), made by the real `fbakit` binary.

mod support;

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use serde_json::Value;
use support::avatar;
use support::cli::{clone_alma_to, face_export, run_ok, text};
use support::loader_outputs::{assert_clean, json_of, load_in_three_js};

/// The image's name in the user's texture folder (a space, so URIs are escaped).
const IMAGE: &str = "skin base.png";

/// The files the fixture made, under `dir`.
struct Layout {
    dir: PathBuf,
    /// `models/avatar.gltf` + `models/avatar.bin`, its image `../textures/skin%20base.png`.
    input: PathBuf,
    /// The texture's bytes.
    png: Vec<u8>,
    /// `clone alma models/avatar.gltf -o results/cloned/clone.gltf` (another folder, one
    /// deeper).
    cloned: PathBuf,
    /// `clone alma models/avatar.gltf -o models/clone.gltf` (the input's folder).
    cloned_here: PathBuf,
    /// `play models/clone.gltf lowlevel.fap -o results/out/play.gltf`.
    played: PathBuf,
    /// `face export models/clone.gltf -o results/out/export.gltf` (the image already there,
    /// same bytes).
    exported: PathBuf,
    /// `face export models/clone.gltf -o results/foreign/face.gltf`, a foreign
    /// `skin base.png` in `results/foreign/`.
    foreign: PathBuf,
    /// `clone alma models/avatar.gltf -o results/glb/clone.glb`: one self-contained file.
    glb: PathBuf,
    /// The stderr of each run, by output.
    stderr: Vec<(PathBuf, String)>,
}

fn layout() -> &'static Layout {
    static L: OnceLock<Layout> = OnceLock::new();
    L.get_or_init(|| {
        let dir = tempfile::tempdir().unwrap().keep();
        let input = avatar::build().write_gltf(&dir.join("models"), "avatar");
        // The texture moves to a sibling folder, as Sketchfab's downloads lay it out.
        std::fs::create_dir_all(dir.join("textures")).unwrap();
        std::fs::rename(
            dir.join("models/textures/skin.png"),
            dir.join("textures").join(IMAGE),
        )
        .unwrap();
        std::fs::remove_dir(dir.join("models/textures")).unwrap();
        let mut json = json_of(&input);
        json["images"][0]["uri"] = "../textures/skin%20base.png".into();
        std::fs::write(&input, serde_json::to_vec_pretty(&json).unwrap()).unwrap();
        let png = std::fs::read(dir.join("textures").join(IMAGE)).unwrap();

        let alma = fbakit::face::read("alma").unwrap();
        let fp = avatar::fp_csv(&alma, &dir, "");
        let mut stderr = Vec::new();
        // Outputs one folder deeper than the input, so that an image URI carried over
        // unchanged (`../textures/…`) would name a file that is not there.
        let res = dir.join("results");
        let cloned = res.join("cloned/clone.gltf");
        std::fs::create_dir_all(res.join("cloned")).unwrap();
        stderr.push((cloned.clone(), clone_alma_to(&input, &fp, &cloned)));
        let cloned_here = dir.join("models/clone.gltf");
        stderr.push((
            cloned_here.clone(),
            clone_alma_to(&input, &fp, &cloned_here),
        ));

        std::fs::create_dir_all(res.join("out")).unwrap();
        let played = res.join("out/play.gltf");
        let lowlevel = Path::new(env!("CARGO_MANIFEST_DIR")).join("samples/lowlevel.fap");
        stderr.push((
            played.clone(),
            run_ok(&[
                "play".as_ref(),
                cloned_here.as_os_str(),
                lowlevel.as_os_str(),
                "--jaw-node".as_ref(),
                "Jaw".as_ref(),
                "-o".as_ref(),
                played.as_os_str(),
            ]),
        ));
        let exported = res.join("out/export.gltf");
        let o = face_export(&cloned_here, &exported);
        assert!(o.status.success(), "{}", text(&o.stderr));
        stderr.push((exported.clone(), text(&o.stderr)));

        std::fs::create_dir_all(res.join("foreign")).unwrap();
        std::fs::write(res.join("foreign").join(IMAGE), b"the user's own file").unwrap();
        let foreign = res.join("foreign/face.gltf");
        let o = face_export(&cloned_here, &foreign);
        assert!(o.status.success(), "{}", text(&o.stderr));
        stderr.push((foreign.clone(), text(&o.stderr)));
        std::fs::create_dir_all(res.join("glb")).unwrap();
        let glb = res.join("glb/clone.glb");
        stderr.push((glb.clone(), clone_alma_to(&input, &fp, &glb)));
        Layout {
            dir,
            input,
            png,
            glb,
            cloned,
            cloned_here,
            played,
            exported,
            foreign,
            stderr,
        }
    })
}

/// `%XX` decoding of a relative URI.
fn unescape(uri: &str) -> String {
    let b = uri.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    while i < b.len() {
        if b[i] == b'%' && i + 3 <= b.len() {
            let hex = std::str::from_utf8(&b[i + 1..i + 3]).unwrap_or("");
            if let Ok(v) = u8::from_str_radix(hex, 16) {
                out.push(v);
                i += 3;
                continue;
            }
        }
        out.push(b[i]);
        i += 1;
    }
    String::from_utf8(out).unwrap()
}

/// The file a document's relative URI names.
fn resolve(doc: &Path, uri: &str) -> PathBuf {
    doc.parent().unwrap().join(unescape(uri))
}

/// Each output: one buffer `<stem>.bin` beside it holding `byteLength` bytes, its image URI
/// as expected and resolving to the texture's bytes; and what fbakit printed names no
/// missing image.
#[test]
fn outputs_get_their_own_bin_and_images_that_resolve() {
    let l = layout();
    for (doc, uri) in [
        (&l.cloned, "skin%20base.png"),
        // The input's folder: nothing copied, the URI kept.
        (&l.cloned_here, "../textures/skin%20base.png"),
        (&l.played, "skin%20base.png"),
        // The same bytes already there (play's copy): used, not copied again.
        (&l.exported, "skin%20base.png"),
        // A foreign file of that name: another name, the file untouched.
        (&l.foreign, "skin%20base_2.png"),
    ] {
        let json = json_of(doc);
        let stem = doc.file_stem().unwrap().to_str().unwrap();
        let buffers = json["buffers"].as_array().unwrap();
        assert_eq!(buffers.len(), 1, "{}", doc.display());
        assert_eq!(
            buffers[0]["uri"],
            format!("{stem}.bin"),
            "{}",
            doc.display()
        );
        let bin = std::fs::read(resolve(doc, buffers[0]["uri"].as_str().unwrap())).unwrap();
        assert_eq!(Some(bin.len() as u64), buffers[0]["byteLength"].as_u64());
        assert_eq!(json["images"][0]["uri"], uri, "{}", doc.display());
        let image = resolve(doc, uri);
        assert_eq!(
            std::fs::read(&image).unwrap(),
            l.png,
            "{}: {}",
            doc.display(),
            image.display()
        );
    }
    assert!(!l.dir.join("models").join(IMAGE).exists());
    assert_eq!(
        std::fs::read(l.foreign.with_file_name(IMAGE)).unwrap(),
        b"the user's own file"
    );
    // The input is untouched by the clone written beside it.
    assert_eq!(
        json_of(&l.input)["images"][0]["uri"],
        "../textures/skin%20base.png"
    );
    for (doc, stderr) in &l.stderr {
        assert!(
            !stderr.contains("does not exist"),
            "{}: {stderr}",
            doc.display()
        );
    }
}

/// A `.glb` written from the `.gltf` is one file: the texture embedded in its binary chunk
/// (was: copied beside it under the old URI scheme), nothing else written beside it.
#[test]
fn a_glb_output_embeds_the_texture() {
    let l = layout();
    let bytes = std::fs::read(&l.glb).unwrap();
    let chunks = fbakit::gltf::parse_glb(&bytes).unwrap();
    let json: Value = serde_json::from_slice(chunks.json).unwrap();
    let bin = chunks.bin.unwrap();
    let buffers = json["buffers"].as_array().unwrap();
    assert_eq!(buffers.len(), 1);
    assert!(buffers[0].get("uri").is_none(), "{}", buffers[0]);
    // The chunk is padded to 4 bytes; the buffer is what the views use.
    let length = buffers[0]["byteLength"].as_u64().unwrap() as usize;
    assert!(
        length <= bin.len() && bin.len() - length < 4,
        "{length} of {}",
        bin.len()
    );
    let image = &json["images"][0];
    assert!(image.get("uri").is_none(), "{image}");
    assert_eq!(image["mimeType"], "image/png");
    let view = &json["bufferViews"][image["bufferView"].as_u64().unwrap() as usize];
    let at = view["byteOffset"].as_u64().unwrap_or(0) as usize;
    let len = view["byteLength"].as_u64().unwrap() as usize;
    assert_eq!(bin[at..at + len], l.png[..]);
    let beside: Vec<_> = std::fs::read_dir(l.glb.parent().unwrap())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(beside, [std::ffi::OsString::from("clone.glb")]);
    // Read back, it is the clone written as `.gltf`.
    let a = fbakit::face::read(&l.glb).unwrap();
    let b = fbakit::face::read(&l.cloned).unwrap();
    assert_eq!(a.meshes.len(), b.meshes.len());
    for (x, y) in a.meshes.iter().zip(&b.meshes) {
        assert_eq!(x.mesh.positions, y.mesh.positions, "{}", x.name);
    }
    assert_eq!(a.fat.tables.len(), b.fat.tables.len());
}

/// The Khronos validator, reading each document's `.bin` and images beside it, finds no error
/// or warning in an output that the input did not have (an unresolved image or buffer is an
/// `IO_ERROR`).
#[test]
fn validator_finds_no_new_issue_with_the_files_beside() {
    let l = layout();
    let files = [
        l.input.clone(),
        l.cloned.clone(),
        l.cloned_here.clone(),
        l.played.clone(),
        l.exported.clone(),
        l.foreign.clone(),
        l.glb.clone(),
    ];
    let Some(reports) = support::validator::validate(&files) else {
        return;
    };
    let base = support::validator::issue_codes(&reports[0]);
    eprintln!(
        "validator on the input: {base:?} ({} infos)",
        reports[0]["infos"]
    );
    assert!(
        !base.iter().any(|c| c == "IO_ERROR"),
        "{}",
        reports[0]["messages"]
    );
    for (file, r) in files.iter().zip(&reports).skip(1) {
        let got = support::validator::issue_codes(r);
        eprintln!(
            "validator on {}: {got:?} ({} infos)",
            file.display(),
            r["infos"]
        );
        let new: Vec<&String> = got.iter().filter(|c| !base.contains(c)).collect();
        assert!(
            new.is_empty(),
            "{}: new {new:?}: {}",
            file.display(),
            r["messages"]
        );
    }
}

/// three.js's `GLTFLoader` (headless Chromium, files served beside each document) loads each
/// output without an error or a failed request, and the skin's texture is the 4×4 image.
#[test]
fn outputs_load_in_three_js_with_their_texture() {
    let l = layout();
    // The input's folder's clone climbs to `../textures/`, above what the check serves.
    let files = [&l.cloned, &l.played, &l.exported, &l.foreign, &l.glb];
    let Some(reports) = load_in_three_js(&files) else {
        return;
    };
    for r in &reports {
        let file = &r["file"];
        assert_clean(r);
        let textured: Vec<&Value> = r["meshes"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|m| !m["textureImage"].is_null())
            .collect();
        assert!(!textured.is_empty(), "{file}: no mesh with a texture");
        for m in textured {
            assert_eq!(
                m["textureImage"],
                serde_json::json!([4, 4]),
                "{file}: {}",
                m["name"]
            );
        }
        let morphs = r["meshes"]
            .as_array()
            .unwrap()
            .iter()
            .flat_map(|m| m["names"].as_array().unwrap())
            .filter(|n| n.as_str().is_some_and(|n| n.starts_with("open_jaw")))
            .count();
        assert!(morphs > 0, "{file}: no open_jaw morph target");
        eprintln!(
            "three.js: {file}: {} meshes, {} open_jaw targets",
            r["meshes"].as_array().unwrap().len(),
            morphs
        );
    }
}

/// Blender's importer reads each output, the input's folder's clone too (its `../textures/`
/// image): the image found (4×4, not Blender's 0×0 of a missing file), fbakit's shape keys on
/// the face mesh.
#[test]
fn outputs_import_in_blender_with_their_texture() {
    let l = layout();
    let files = [
        &l.cloned,
        &l.cloned_here,
        &l.played,
        &l.exported,
        &l.foreign,
        &l.glb,
    ];
    let Some(reports) = support::blender::import_in_blender(&files) else {
        return;
    };
    for r in &reports {
        let file = &r["file"];
        let images = r["images"].as_array().unwrap();
        assert!(!images.is_empty(), "{file}: no image");
        for i in images {
            assert_eq!(i["size"], serde_json::json!([4, 4]), "{file}: {i}");
        }
        let keys: Vec<&str> = r["objects"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|o| o["type"] == "MESH")
            .flat_map(|o| o["shapeKeys"].as_array().unwrap())
            .filter_map(Value::as_str)
            .collect();
        assert!(
            keys.iter().any(|k| k.starts_with("open_jaw")),
            "{file}: no open_jaw shape key in {keys:?}"
        );
    }
}

/// Every file in `dir` (recursively) with its bytes.
fn snapshot(dir: &Path) -> Vec<(PathBuf, Vec<u8>)> {
    let mut out = Vec::new();
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            out.extend(snapshot(&p));
        } else {
            out.push((p.clone(), std::fs::read(&p).unwrap()));
        }
    }
    out.sort();
    out
}

/// An output whose `.bin` would replace one of the input's files fails with exit code 2 and
/// one line naming the file and what to do, and writes nothing: `face export other.gltf -o
/// clone.gltf` where `other.gltf`'s buffer is `clone.bin`. Writing over the input itself is
/// refused by the CLI; through the library, a document may replace itself only when its
/// buffer is not the `<stem>.bin` the write makes.
#[test]
fn a_bin_that_would_replace_an_input_file_is_refused() {
    let l = layout();
    let dir = l.dir.join("collide");
    std::fs::create_dir_all(&dir).unwrap();
    for f in ["clone.gltf", "clone.bin"] {
        std::fs::copy(l.cloned.with_file_name(f), dir.join(f)).unwrap();
    }
    std::fs::write(dir.join(IMAGE), &l.png).unwrap();
    // `other.gltf` is the clone under another name, its buffer still `clone.bin`.
    std::fs::copy(dir.join("clone.gltf"), dir.join("other.gltf")).unwrap();
    let before = snapshot(&dir);
    let o = face_export(&dir.join("other.gltf"), &dir.join("clone.gltf"));
    let stderr = text(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{stderr}");
    assert_eq!(stderr.trim().lines().count(), 1, "{stderr}");
    assert!(
        stderr.contains("clone.bin")
            && stderr.contains("other.gltf")
            && stderr.contains("choose another output name"),
        "{stderr}"
    );
    assert!(before == snapshot(&dir), "files changed");

    // Writing over the input document itself: refused by the CLI.
    let o = face_export(&dir.join("clone.gltf"), &dir.join("clone.gltf"));
    assert_eq!(o.status.code(), Some(2), "{}", text(&o.stderr));
    assert!(before == snapshot(&dir), "files changed");

    // Through the library: `clone.gltf` over itself would replace its `clone.bin` (refused,
    // nothing written); `other.gltf` over itself writes `other.bin` and leaves `clone.bin`.
    let face = fbakit::face::read(dir.join("clone.gltf")).unwrap();
    let e = fbakit::export::write_face(dir.join("clone.gltf"), &face).unwrap_err();
    assert!(e.is_input_error(), "{e}");
    assert!(e.to_string().contains("clone.bin"), "{e}");
    assert!(before == snapshot(&dir), "files changed");
    let other = dir.join("other.gltf");
    let face = fbakit::face::read(&other).unwrap();
    fbakit::export::write_face(&other, &face).unwrap();
    assert_eq!(json_of(&other)["buffers"][0]["uri"], "other.bin");
    assert_eq!(
        std::fs::read(dir.join("clone.bin")).unwrap(),
        std::fs::read(l.cloned.with_file_name("clone.bin")).unwrap()
    );
    let back = fbakit::face::read(&other).unwrap();
    assert_eq!(back.meshes.len(), face.meshes.len());
}

/// Rewriting a document fbakit patched before drops the replaced targets' old accessors,
/// unless the document uses an extension whose references fbakit cannot renumber: then all
/// are kept and the warning (on stderr) names the extension.
#[test]
fn an_unknown_extension_keeps_every_accessor_and_says_so() {
    let l = layout();
    let dir = l.dir.join("unknown");
    std::fs::create_dir_all(&dir).unwrap();
    let mut json = json_of(&l.cloned);
    json["buffers"][0]["uri"] = "../results/cloned/clone.bin".into();
    json["images"][0]["uri"] = "../results/cloned/skin%20base.png".into();
    let plain = dir.join("plain.gltf");
    std::fs::write(&plain, serde_json::to_vec(&json).unwrap()).unwrap();
    json["extensionsUsed"] = serde_json::json!(["EXT_fbakit_test"]);
    json["nodes"][0]["extensions"] = serde_json::json!({"EXT_fbakit_test": {"accessor": 0}});
    let ext = dir.join("ext.gltf");
    std::fs::write(&ext, serde_json::to_vec(&json).unwrap()).unwrap();
    let accessors = |p: &Path| json_of(p)["accessors"].as_array().unwrap().len();

    let o = face_export(&plain, &dir.join("plain-out.gltf"));
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert!(
        !text(&o.stderr).contains("unused accessors"),
        "{}",
        text(&o.stderr)
    );
    let o = face_export(&ext, &dir.join("ext-out.gltf"));
    let stderr = text(&o.stderr);
    assert!(o.status.success(), "{stderr}");
    let (n_in, n_plain, n_ext) = (
        accessors(&plain),
        accessors(&dir.join("plain-out.gltf")),
        accessors(&dir.join("ext-out.gltf")),
    );
    eprintln!("accessors: input {n_in}, rewritten {n_plain}, with EXT_fbakit_test {n_ext}");
    assert!(n_plain < n_ext, "{n_plain} vs {n_ext}");
    let kept = n_ext - n_plain;
    assert!(
        stderr.contains(&format!("kept {kept} unused accessors"))
            && stderr.contains("EXT_fbakit_test")
            && stderr.contains("cannot renumber"),
        "{stderr}"
    );
    // The extension's object came through as it was.
    assert_eq!(
        json_of(&dir.join("ext-out.gltf"))["nodes"][0]["extensions"],
        json["nodes"][0]["extensions"]
    );
}

/// An image whose file is missing: the output keeps its URI and `face export` warns, naming
/// the file it looked for.
#[test]
fn a_missing_image_is_named_and_its_uri_kept() {
    let l = layout();
    let dir = l.dir.join("missing");
    std::fs::create_dir_all(&dir).unwrap();
    let mut json = json_of(&l.cloned);
    json["buffers"][0]["uri"] = "../results/cloned/clone.bin".into();
    json["images"][0]["uri"] = "gone%20away.png".into();
    let input = dir.join("face.gltf");
    std::fs::write(&input, serde_json::to_vec(&json).unwrap()).unwrap();
    let out = l.dir.join("results/missing-out.gltf");
    let o = face_export(&input, &out);
    let stderr = text(&o.stderr);
    assert!(o.status.success(), "{stderr}");
    let named = dir.join("gone away.png");
    assert!(
        stderr.contains(&named.display().to_string()) && stderr.contains("does not exist"),
        "{stderr}"
    );
    assert_eq!(json_of(&out)["images"][0]["uri"], "gone%20away.png");
}
