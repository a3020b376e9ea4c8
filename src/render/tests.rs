use glam::Vec3;

use super::*;
use crate::mesh::Aabb;

const BG: [u8; 4] = [0, 0, 0, 255];

/// Orthographic front camera where world (x, y) in [−1, 1] fills an `n × n` image and the
/// pixel grid is aligned with integer world coordinates ×(n/2).
fn ortho_front() -> Camera {
    Camera::look_at(
        Vec3::new(0.0, 0.0, 10.0),
        Vec3::ZERO,
        Vec3::Y,
        Projection::Orthographic { extent: 2.0 },
    )
}

fn opts(n: u32) -> RenderOptions {
    RenderOptions {
        width: n,
        height: n,
        background: BG,
        supersample: 1,
        ..RenderOptions::default()
    }
}

fn covered(img: &Image) -> Vec<bool> {
    img.rgba.chunks(4).map(|p| p != BG).collect()
}

#[test]
fn triangle_covers_the_pixels_whose_centres_are_inside() {
    // Right triangle with legs along the left and top edges of an 8×8 image: world
    // (−1, 1), (1, 1), (−1, −1) → pixels (0, 0), (8, 0), (0, 8).
    let p = [
        Vec3::new(-1.0, 1.0, 0.0),
        Vec3::new(-1.0, -1.0, 0.0),
        Vec3::new(1.0, 1.0, 0.0),
    ];
    let tris = [[0, 1, 2]];
    let img = render(
        &[RenderMesh::new(&p, &tris, [1.0; 3])],
        &ortho_front(),
        &opts(8),
    );
    let cov = covered(&img);
    for y in 0..8 {
        for x in 0..8 {
            // Centre (x + .5, y + .5) is inside iff x + y + 1 < 8; on the hypotenuse
            // (x + y + 1 = 8) it belongs to the bottom-right edge, so it is excluded.
            assert_eq!(cov[y * 8 + x], x + y + 1 < 8, "pixel {x},{y}");
        }
    }
}

#[test]
fn quad_split_in_two_covers_every_pixel_exactly_once() {
    // A quad whose diagonal passes exactly through pixel centres, at several offsets.
    for shift in [0.0f32, 0.25, 0.5, 1.0 / 3.0] {
        let s = shift * 2.0 / 8.0;
        let p = [
            Vec3::new(-0.75 + s, -0.75, 0.0),
            Vec3::new(0.75 + s, -0.75, 0.0),
            Vec3::new(0.75 + s, 0.75, 0.0),
            Vec3::new(-0.75 + s, 0.75, 0.0),
        ];
        let t1 = [[0u32, 1, 2]];
        let t2 = [[0u32, 2, 3]];
        let both = [[0u32, 1, 2], [0, 2, 3]];
        let o = opts(8);
        let cam = ortho_front();
        let c1 = covered(&render(&[RenderMesh::new(&p, &t1, [1.0; 3])], &cam, &o));
        let c2 = covered(&render(&[RenderMesh::new(&p, &t2, [1.0; 3])], &cam, &o));
        let cb = covered(&render(&[RenderMesh::new(&p, &both, [1.0; 3])], &cam, &o));
        let mut total = 0;
        for i in 0..64 {
            assert!(!(c1[i] && c2[i]), "pixel {i} covered twice (shift {shift})");
            assert_eq!(c1[i] || c2[i], cb[i]);
            total += cb[i] as usize;
        }
        // 1.5 world units = 6 pixels per side.
        assert_eq!(total, 36, "shift {shift}");
        assert!(c1.iter().any(|&c| c) && c2.iter().any(|&c| c));
    }
}

#[test]
fn depth_test_keeps_the_nearer_triangle_in_either_order() {
    let near = [
        Vec3::new(-1.0, -1.0, 1.0),
        Vec3::new(1.0, -1.0, 1.0),
        Vec3::new(0.0, 1.0, 1.0),
    ];
    let far = near.map(|p| p - Vec3::Z * 2.0);
    let tris = [[0u32, 1, 2]];
    let red = RenderMesh::new(&near, &tris, [1.0, 0.0, 0.0]);
    let blue = RenderMesh::new(&far, &tris, [0.0, 0.0, 1.0]);
    for cam in [
        ortho_front(),
        Camera::look_at(
            Vec3::new(0.0, 0.0, 6.0),
            Vec3::ZERO,
            Vec3::Y,
            Projection::Perspective { fov: 1.0 },
        ),
    ] {
        for scene in [[red, blue], [blue, red]] {
            let img = render(&scene, &cam, &opts(16));
            let p = img.pixel(8, 8).unwrap();
            assert!(p[0] > p[2] + 150, "{p:?}");
        }
    }
}

#[test]
fn back_faces_are_culled_only_when_asked() {
    // Clockwise seen from +z: a back face.
    let p = [
        Vec3::new(-1.0, -1.0, 0.0),
        Vec3::new(0.0, 1.0, 0.0),
        Vec3::new(1.0, -1.0, 0.0),
    ];
    let tris = [[0u32, 1, 2]];
    let mesh = [RenderMesh::new(&p, &tris, [1.0; 3])];
    let mut o = opts(16);
    let drawn = render(&mesh, &ortho_front(), &o);
    assert!(drawn.stats(BG).coverage > 0.2);
    o.cull_back_faces = true;
    let culled = render(&mesh, &ortho_front(), &o);
    assert_eq!(culled.stats(BG).coverage, 0.0);
    // Front faces stay.
    let front = [[0u32, 2, 1]];
    let img = render(&[RenderMesh::new(&p, &front, [1.0; 3])], &ortho_front(), &o);
    assert!(img.stats(BG).coverage > 0.2);
    // And the back face is darker than the same triangle seen from the front.
    assert!(drawn.pixel(8, 10).unwrap()[0] < img.pixel(8, 10).unwrap()[0]);
}

/// A low-poly sphere (UV grid), counter-clockwise from outside.
fn sphere(n: u32) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let mut p = Vec::new();
    for i in 0..=n {
        let th = std::f32::consts::PI * i as f32 / n as f32;
        for j in 0..2 * n {
            let ph = std::f32::consts::PI * j as f32 / n as f32;
            p.push(Vec3::new(
                th.sin() * ph.sin(),
                th.cos(),
                th.sin() * ph.cos(),
            ));
        }
    }
    let mut polys = Vec::new();
    for i in 0..n {
        for j in 0..2 * n {
            let a = i * 2 * n + j;
            let b = i * 2 * n + (j + 1) % (2 * n);
            polys.push(vec![a, a + 2 * n, b + 2 * n, b]);
        }
    }
    (p, fan_triangulate(&polys))
}

#[test]
fn flat_and_smooth_shading_differ_and_smooth_is_smoother() {
    let (p, t) = sphere(8);
    let mesh = [RenderMesh::new(&p, &t, [0.8, 0.8, 0.8])];
    let cam = Camera::framing(&bounds(&mesh).unwrap(), 0.0, 0.0);
    let mut o = opts(64);
    o.shading = Shading::Flat;
    let flat = render(&mesh, &cam, &o);
    o.shading = Shading::Smooth;
    let smooth = render(&mesh, &cam, &o);
    assert_ne!(flat, smooth);
    assert_eq!(flat.stats(BG).bbox, smooth.stats(BG).bbox);
    // Flat shading has fewer distinct grey levels across the middle row.
    let distinct = |img: &Image| {
        let mut v: Vec<u8> = (0..64)
            .filter_map(|x| img.pixel(x, 32))
            .map(|p| p[0])
            .collect();
        v.sort();
        v.dedup();
        v.len()
    };
    assert!(distinct(&flat) < distinct(&smooth));
}

#[test]
fn framing_centres_the_bounds() {
    let b = Aabb {
        min: Vec3::new(10.0, -30.0, 5.0),
        max: Vec3::new(50.0, 40.0, 25.0),
    };
    for (yaw, pitch) in [(0.0, 0.0), (0.7, 0.0), (-1.2, 0.3), (3.0, -0.4)] {
        for cam in [
            Camera::framing(&b, yaw, pitch),
            Camera::framing_orthographic(&b, yaw, pitch),
        ] {
            let (x, y) = cam.project(b.center(), 200, 100).unwrap();
            assert!((x - 100.0).abs() < 1e-3 && (y - 50.0).abs() < 1e-3);
            // Every corner is inside the image.
            for i in 0..8 {
                let c = Vec3::new(
                    if i & 1 == 0 { b.min.x } else { b.max.x },
                    if i & 2 == 0 { b.min.y } else { b.max.y },
                    if i & 4 == 0 { b.min.z } else { b.max.z },
                );
                let (x, y) = cam.project(c, 200, 100).unwrap();
                assert!((0.0..=200.0).contains(&x) && (0.0..=100.0).contains(&y));
            }
        }
    }
    // Front view looks from +z.
    let cam = Camera::framing(&b, 0.0, 0.0);
    assert!(cam.eye.z > b.max.z && (cam.eye.x - 30.0).abs() < 1e-4);
}

#[test]
fn rendered_box_is_centred() {
    let (p, t) = sphere(12);
    let p: Vec<Vec3> = p
        .iter()
        .map(|v| *v * 20.0 + Vec3::new(5.0, -7.0, 3.0))
        .collect();
    let mesh = [RenderMesh::new(&p, &t, [0.8, 0.5, 0.3])];
    let cam = Camera::framing(&bounds(&mesh).unwrap(), 0.0, 0.0);
    let img = render(&mesh, &cam, &opts(100));
    let (cx, cy) = img.stats(BG).bbox.unwrap().center();
    assert!(
        (cx - 50.0).abs() <= 1.0 && (cy - 50.0).abs() <= 1.0,
        "{cx} {cy}"
    );
}

#[test]
fn supersampling_smooths_edges_and_keeps_interior() {
    let (p, t) = sphere(12);
    let mesh = [RenderMesh::new(&p, &t, [0.8, 0.8, 0.8])];
    let cam = Camera::framing(&bounds(&mesh).unwrap(), 0.0, 0.0);
    let mut o = opts(48);
    let one = render(&mesh, &cam, &o);
    o.supersample = 2;
    let two = render(&mesh, &cam, &o);
    let grey_levels = |img: &Image| {
        let mut v: Vec<u8> = img.rgba.chunks(4).map(|p| p[1]).collect();
        v.sort();
        v.dedup();
        v.len()
    };
    assert!(grey_levels(&two) > grey_levels(&one));
    let (s1, s2) = (one.stats(BG), two.stats(BG));
    assert!((s1.coverage - s2.coverage).abs() < 0.05);
}

#[test]
fn hostile_meshes_do_not_panic() {
    let p = [
        Vec3::new(0.0, 0.0, 0.0),
        Vec3::new(f32::NAN, 0.0, 0.0),
        Vec3::new(1e30, 1e30, 0.0),
        Vec3::new(0.0, 1.0, 0.0),
    ];
    let tris = [[0u32, 1, 3], [0, 2, 3], [0, 3, 99], [0, 0, 0]];
    let normals = [Vec3::ZERO; 2]; // wrong length: recomputed
    let mesh = RenderMesh {
        normals: Some(&normals),
        ..RenderMesh::new(&p, &tris, [2.0, -1.0, f32::NAN])
    };
    let cams = [
        ortho_front(),
        Camera::look_at(
            Vec3::ZERO,
            Vec3::ZERO,
            Vec3::ZERO,
            Projection::Perspective { fov: 1.0 },
        ),
    ];
    for cam in cams {
        let img = render(
            &[mesh],
            &cam,
            &RenderOptions {
                width: 0,
                height: 3,
                ..opts(8)
            },
        );
        assert_eq!((img.width, img.height), (1, 3));
    }
}

#[test]
fn fan_triangulation() {
    let t = fan_triangulate(&[vec![0, 1, 2, 3], vec![4, 5], vec![6, 7, 8]]);
    assert_eq!(t, vec![[0, 1, 2], [0, 2, 3], [6, 7, 8]]);
}

#[test]
fn downscale_blit_and_text() {
    let mut img = Image::new(4, 4, [0, 0, 0, 255]);
    img.fill_rect(0, 0, 2, 2, [255, 255, 255, 255]);
    let small = img.downscale(2);
    assert_eq!((small.width, small.height), (2, 2));
    assert_eq!(small.pixel(0, 0), Some([255, 255, 255, 255]));
    assert_eq!(small.pixel(1, 1), Some([0, 0, 0, 255]));
    // Half white, half black averages in linear light: 0.5 linear ≈ sRGB 188.
    let mut half = Image::new(2, 1, [0, 0, 0, 255]);
    half.set_pixel(0, 0, [255, 255, 255, 255]);
    assert_eq!(half.downscale(2).pixel(0, 0), Some([188, 188, 188, 255]));

    let mut canvas = Image::new(5, 5, [0; 4]);
    canvas.blit(&small, 4, -1); // clipped to one pixel: small(0, 1)
    assert_eq!(canvas.pixel(4, 0), Some([0, 0, 0, 255]));
    canvas.blit(&small, -1, -1);
    assert_eq!(canvas.pixel(0, 0), Some([0, 0, 0, 255]));
    canvas.blit(&small, 3, 3);
    assert_eq!(canvas.pixel(3, 3), Some([255, 255, 255, 255]));
    canvas.blit(&small, 100, -100);

    let mut t = Image::new(12, 7, [0; 4]);
    t.draw_text(0, 0, "T!", [9, 9, 9, 255], 1);
    // 'T' has a full top row, '!' a single centre column.
    for x in 0..5 {
        assert_eq!(t.pixel(x, 0), Some([9, 9, 9, 255]));
    }
    assert_eq!(t.pixel(8, 0), Some([9, 9, 9, 255]));
    assert_eq!(t.pixel(8, 5), Some([0; 4]));
    assert_eq!(t.pixel(7, 0), Some([0; 4]));
}

#[test]
fn contact_sheet_and_grid_layout() {
    let red = Image::new(10, 8, [255, 0, 0, 255]);
    let blue = Image::new(6, 6, [0, 0, 255, 255]);
    let sheet = contact_sheet(&[red.clone(), blue.clone(), red.clone()], 2, 3, None);
    assert_eq!((sheet.width, sheet.height), (2 * 10 + 3 * 3, 2 * 8 + 3 * 3));
    assert_eq!(sheet.pixel(3, 3), Some([255, 0, 0, 255]));
    assert_eq!(sheet.pixel(3 + 10 + 3 + 2, 3 + 1), Some([0, 0, 255, 255]));
    let labelled = contact_sheet(&[red.clone(), blue.clone()], 5, 2, Some(&["joy", "x"]));
    assert_eq!(labelled.width, 2 * 10 + 3 * 2);
    assert!(labelled.height > 8 + 2 * 2 + 7);
    let captions = labelled.stats(SHEET_BG);
    assert!(captions.bbox.unwrap().y1 > 8 + 2);
    assert!(contact_sheet(&[], 3, 2, None).width >= 1);

    let g = grid(
        &[vec![red.clone(), blue.clone()], vec![blue.clone()]],
        &["alma", "bruno"],
        &["alma→bruno", "b"],
    );
    assert!(g.width > 2 * 10 && g.height > 2 * 8 + 7);
    let s = g.stats(SHEET_BG);
    assert!(s.coverage > 0.08);
    assert!(grid(&[], &[], &[]).width >= 1);
}

const SHEET_BG: [u8; 4] = [24, 24, 28, 255];

#[test]
fn stats_of_a_known_image() {
    let mut img = Image::new(32, 32, [0, 0, 0, 255]);
    img.fill_rect(8, 4, 16, 8, [255, 255, 255, 255]);
    let s = img.stats([0, 0, 0, 255]);
    assert_eq!(s.coverage, 128.0 / 1024.0);
    assert_eq!(
        s.bbox,
        Some(PixelRect {
            x0: 8,
            y0: 4,
            x1: 23,
            y1: 11
        })
    );
    assert_eq!(s.mean_colour, [255.0; 3]);
    assert_eq!(s.thumbnail.len(), 16);
    assert_eq!(s.thumbnail[2], "    ########    ");
    assert_eq!(s.thumbnail[0], " ".repeat(16));
    let mut other = img.clone();
    other.fill_rect(0, 0, 2, 2, [255; 4]);
    assert_ne!(other.stats([0, 0, 0, 255]).checksum, s.checksum);
}
