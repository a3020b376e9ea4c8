//! Rendering the procedural faces: silhouettes, framing, animation visible in the mouth,
//! pinned image statistics, determinism across thread counts, PNG round trip.
//!
//! `RENDER_PREVIEW_DIR=/tmp cargo test --test render_faces` also writes the PNGs for a look.

#[path = "../examples/render_faces.rs"]
mod example;

use std::sync::OnceLock;

use example::{joy_open_jaw, pose, PosedFace};
use fbakit::render::{bounds, render, turntable, Camera, Image, ImageStats, RenderOptions};
use fbakit::synth::{self, SynthFace};

const SIZE: u32 = 256;

fn alma() -> &'static SynthFace {
    static F: OnceLock<SynthFace> = OnceLock::new();
    F.get_or_init(synth::alma)
}

/// (neutral, joy + open jaw) poses of alma.
fn poses() -> &'static (PosedFace, PosedFace) {
    static P: OnceLock<(PosedFace, PosedFace)> = OnceLock::new();
    P.get_or_init(|| (pose(alma(), &[]), pose(alma(), &joy_open_jaw(400.0))))
}

fn opts() -> RenderOptions {
    RenderOptions::sized(SIZE, SIZE)
}

/// Front camera framed on the neutral face (shared by both poses).
fn camera() -> Camera {
    Camera::framing(&bounds(&poses().0.meshes()).unwrap(), 0.0, 0.0)
}

fn frames() -> &'static (Image, Image) {
    static I: OnceLock<(Image, Image)> = OnceLock::new();
    I.get_or_init(|| {
        let (n, j) = poses();
        let (a, b) = (
            render(&n.meshes(), &camera(), &opts()),
            render(&j.meshes(), &camera(), &opts()),
        );
        if let Ok(dir) = std::env::var("RENDER_PREVIEW_DIR") {
            let dir = std::path::Path::new(&dir);
            a.write_png(&dir.join("render_alma_neutral.png")).unwrap();
            b.write_png(&dir.join("render_alma_joy.png")).unwrap();
        }
        (a, b)
    })
}

fn bg() -> [u8; 4] {
    opts().background
}

#[test]
fn face_silhouette_is_framed_and_centred() {
    for img in [&frames().0, &frames().1] {
        let s = img.stats(bg());
        // A head seen from the front: an oval filling a good part of the square.
        assert!(
            (0.25..0.45).contains(&s.coverage),
            "coverage {}",
            s.coverage
        );
        let b = s.bbox.unwrap();
        let (cx, cy) = b.center();
        assert!(
            (cx - 128.0).abs() < 6.0 && (cy - 128.0).abs() < 12.0,
            "{b:?}"
        );
        // Taller than wide, and inside the frame with a margin.
        assert!(b.y1 - b.y0 > b.x1 - b.x0);
        assert!(b.x0 > 5 && b.y0 > 5 && b.x1 < SIZE - 5 && b.y1 < SIZE - 5);
        // Skin dominates the colour: warm, red above blue.
        assert!(
            s.mean_colour[0] > s.mean_colour[2] + 30.0,
            "{:?}",
            s.mean_colour
        );
    }
}

/// Pixels differing between the two images inside `[x0, x1) × [y0, y1)`.
fn differing(a: &Image, b: &Image, x0: u32, y0: u32, x1: u32, y1: u32) -> usize {
    let mut n = 0;
    for y in y0..y1 {
        for x in x0..x1 {
            n += (a.pixel(x, y) != b.pixel(x, y)) as usize;
        }
    }
    n
}

#[test]
fn joy_and_open_jaw_change_the_mouth_not_the_forehead() {
    let (neutral, joy) = frames();
    let face = alma();
    let cam = camera();
    let at = |label: &str| {
        let p = face.feature_point(label.parse().unwrap()).unwrap().position;
        let (x, y) = cam.project(p, SIZE, SIZE).unwrap();
        (x as u32, y as u32)
    };
    // Mouth box: between the mouth corners (8.4 right, 8.3 left), from the nose bottom
    // (9.15) down to the chin (2.1).
    let ((xr, _), (xl, _)) = (at("8.4"), at("8.3"));
    let ((_, ynose), (_, ychin)) = (at("9.15"), at("2.1"));
    assert!(xr < xl && ynose < ychin);
    let area = ((xl - xr) * (ychin - ynose)) as usize;
    let mouth = differing(neutral, joy, xr, ynose, xl, ychin);
    assert!(mouth > area / 3, "{mouth} of {area} mouth pixels changed");
    // The mouth interior shows (dark inside, red tongue): a pixel below the slit is redder
    // and darker than the closed lips were.
    let (_, yslit) = at("2.2");
    let (xm, _) = at("2.2");
    let (n, j) = (
        neutral.pixel(xm, yslit + 6).unwrap(),
        joy.pixel(xm, yslit + 6).unwrap(),
    );
    assert_ne!(n, j);
    // Forehead: between the eyebrow tops and the hairline, nothing moves much.
    let (_, yhair) = at("11.1");
    let (_, ybrow) = at("4.1");
    let forehead = differing(neutral, joy, xr, yhair + 2, xl, ybrow.saturating_sub(8));
    assert!(forehead < mouth / 10, "forehead {forehead}, mouth {mouth}");
}

/// The statistics pinned by the snapshot, rounded so the snapshot reads well.
fn summary(s: &ImageStats) -> serde_json::Value {
    serde_json::json!({
        "coverage": (s.coverage * 1000.0).round() / 1000.0,
        "bbox": s.bbox,
        "mean_colour": s.mean_colour.map(|c| c.round()),
        "thumbnail": s.thumbnail,
        "checksum": format!("{:016x}", s.checksum),
    })
}

#[test]
fn image_stats_snapshot() {
    let (neutral, joy) = frames();
    insta::assert_json_snapshot!(serde_json::json!({
        "alma_neutral": summary(&neutral.stats(bg())),
        "alma_joy_open_jaw": summary(&joy.stats(bg())),
    }));
}

#[test]
fn rendering_is_deterministic_across_thread_counts() {
    let (_, joy) = poses();
    let once = &frames().1;
    let again = render(&joy.meshes(), &camera(), &opts());
    assert_eq!(once.rgba, again.rgba);
    let single = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap()
        .install(|| render(&joy.meshes(), &camera(), &opts()));
    assert_eq!(once.rgba, single.rgba);
}

#[test]
fn png_round_trip() {
    let img = &frames().1;
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("alma.png");
    img.write_png(&path).unwrap();
    let file = std::io::BufReader::new(std::fs::File::open(&path).unwrap());
    let mut reader = png::Decoder::new(file).read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut buf).unwrap();
    assert_eq!((info.width, info.height), (img.width, img.height));
    assert_eq!(info.color_type, png::ColorType::Rgba);
    assert_eq!(info.bit_depth, png::BitDepth::Eight);
    assert_eq!(&buf[..info.buffer_size()], &img.rgba[..]);
}

#[test]
fn turntable_keeps_the_head_centred_and_the_same_size() {
    let (neutral, _) = poses();
    let b = bounds(&neutral.meshes()).unwrap();
    let angles = [0.0f32, 1.0, 2.0, 3.0];
    let small = RenderOptions::sized(96, 96);
    let frames = turntable(&neutral.meshes(), &b, &angles, &small);
    assert_eq!(frames.len(), 4);
    let heights: Vec<u32> = frames
        .iter()
        .map(|f| {
            let r = f.stats(small.background).bbox.unwrap();
            let (cx, _) = r.center();
            assert!((cx - 48.0).abs() < 8.0, "{r:?}");
            r.y1 - r.y0
        })
        .collect();
    // Turning about the vertical axis hardly changes the head's height on screen.
    let (lo, hi) = (heights.iter().min().unwrap(), heights.iter().max().unwrap());
    assert!(hi - lo <= 4, "{heights:?}");
    // The front and back views differ (face vs back of the head).
    assert_ne!(frames[0], frames[3]);
}
