//! Cloning onto one-mesh heads: the bundled `ict` holds its eyes, teeth and gums as separate
//! connected pieces of one mesh; cloning cuts them into parts so lids never move an eyeball
//! and the lower teeth follow the jaw.

use std::collections::HashSet;
use std::sync::OnceLock;

use fbakit::clone::face::{clone_face, CloneOptions, CloneOutcome, Method, Part};
use fbakit::export::picture::strip_fat;
use fbakit::face::FaceModel;
use fbakit::fat::eval::Activation;
use fbakit::fat::TableKey;
use fbakit::spec::{FapId, FeaturePointId};
use glam::Vec3;

/// ICT is in metres; the figures below were set in its original centimetres.
const CM: f32 = 0.01;

fn ict() -> &'static FaceModel {
    static F: OnceLock<FaceModel> = OnceLock::new();
    F.get_or_init(|| strip_fat(&fbakit::face::read("ict").unwrap()))
}

fn alma_to_ict(method: Method) -> &'static CloneOutcome {
    static F: OnceLock<[CloneOutcome; 2]> = OnceLock::new();
    let all = F.get_or_init(|| {
        let alma = fbakit::face::read("alma").unwrap();
        [Method::Fmc, Method::Rbf].map(|m| {
            let opts = CloneOptions {
                method: m,
                ..CloneOptions::default()
            };
            clone_face(&alma, ict(), &opts).unwrap()
        })
    });
    &all[(method == Method::Rbf) as usize]
}

fn fp(s: &str) -> Vec3 {
    ict()
        .feature_points
        .position(s.parse::<FeaturePointId>().unwrap())
        .unwrap()
}

/// The pieces of ict's one mesh, found here independently of the library: union-find over
/// polygon edges, coincident positions joined.
fn pieces() -> Vec<Vec<Vec3>> {
    let m = &ict().meshes[0].mesh;
    let n = m.positions.len();
    let key = |p: Vec3| ((p * 1e7).round().as_ivec3()).to_array();
    let mut first = std::collections::HashMap::new();
    let mut parent: Vec<usize> = (0..n)
        .map(|i| *first.entry(key(m.positions[i])).or_insert(i))
        .collect();
    fn root(p: &mut [usize], mut x: usize) -> usize {
        while p[x] != x {
            p[x] = p[p[x]];
            x = p[x];
        }
        x
    }
    for poly in m.polygons.iter() {
        for w in poly.windows(2) {
            let (a, b) = (
                root(&mut parent, w[0] as usize),
                root(&mut parent, w[1] as usize),
            );
            parent[a] = b;
        }
    }
    let mut by_root: std::collections::BTreeMap<usize, Vec<Vec3>> = Default::default();
    for i in 0..n {
        let r = root(&mut parent, i);
        by_root.entry(r).or_default().push(m.positions[i]);
    }
    by_root.into_values().collect()
}

fn qkey(p: Vec3) -> [i32; 3] {
    (p * 1e6).round().as_ivec3().to_array()
}

/// Displacement of every cloned vertex at `fap` = `value`, with its neutral position.
fn motion(face: &FaceModel, fap: u8, value: f64) -> Vec<(Vec3, Vec3)> {
    let neutral = face.pose(&[]).unwrap();
    let posed = face
        .pose(&[Activation {
            key: TableKey::LowLevel(FapId::new(fap).unwrap()),
            value,
        }])
        .unwrap();
    neutral
        .iter()
        .flatten()
        .zip(posed.iter().flatten())
        .map(|(&a, &b)| (a, b - a))
        .collect()
}

/// Mean displacement length of the cloned vertices at the given neutral positions.
fn mean_motion(m: &[(Vec3, Vec3)], at: &HashSet<[i32; 3]>) -> f32 {
    let sel: Vec<f32> = m
        .iter()
        .filter(|(p, _)| at.contains(&qkey(*p)))
        .map(|(_, d)| d.length())
        .collect();
    assert!(!sel.is_empty());
    sel.iter().sum::<f32>() / sel.len() as f32
}

#[test]
fn ict_is_cut_into_eyes_and_jaws() {
    let r = &alma_to_ict(Method::Fmc).report;
    let parts: HashSet<Part> = r.split_parts.iter().map(|s| s.part).collect();
    for p in [
        Part::LeftEye,
        Part::RightEye,
        Part::UpperTeeth,
        Part::LowerTeeth,
    ] {
        assert!(parts.contains(&p), "{:?}", r.split_parts);
    }
    let eyes: usize = r
        .split_parts
        .iter()
        .filter(|s| matches!(s.part, Part::LeftEye | Part::RightEye))
        .map(|s| s.vertices)
        .sum();
    // ICT's eyeballs: sclera + iris, 1 570 vertices each.
    assert_eq!(eyes, 3140, "{:?}", r.split_parts);
}

#[test]
fn eyelids_never_move_an_eyeball() {
    let pieces = pieces();
    let eyeball = |pupil: Vec3| {
        let near = pieces
            .iter()
            .flatten()
            .min_by(|a, b| a.distance(pupil).total_cmp(&b.distance(pupil)))
            .copied()
            .unwrap();
        // Every piece whose centroid is within the eyeball's reach of that vertex (sclera and
        // iris are separate pieces).
        pieces
            .iter()
            .filter(|p| {
                let c = p.iter().copied().sum::<Vec3>() / p.len() as f32;
                c.distance(near) < 2.0 * CM && p.len() < 5000
            })
            .flatten()
            .map(|&p| qkey(p))
            .collect::<HashSet<_>>()
    };
    let mut eyes = eyeball(fp("3.5"));
    eyes.extend(eyeball(fp("3.6")));
    assert!(eyes.len() > 2000);
    for method in [Method::Fmc, Method::Rbf] {
        let face = &alma_to_ict(method).face;
        // close_t_l_eyelid (19), close_t_r_eyelid (20), raise_l_i_eyebrow (31).
        for fap in [19, 20, 31, 33] {
            let m = motion(face, fap, 1024.0);
            let peak = m.iter().map(|x| x.1.length()).fold(0.0, f32::max);
            let eye_peak = m
                .iter()
                .filter(|(p, _)| eyes.contains(&qkey(*p)))
                .map(|x| x.1.length())
                .fold(0.0, f32::max);
            eprintln!("{method:?} FAP {fap}: peak {peak:.6}, eyeball peak {eye_peak:.8}");
            assert!(peak > 0.05 * CM, "FAP {fap} does not move ({method:?})");
            assert!(
                eye_peak < 1e-5 * CM,
                "FAP {fap} moves an eyeball by {eye_peak}"
            );
        }
    }
}

#[test]
fn lower_teeth_follow_the_jaw_upper_teeth_stay() {
    let lip_y = (fp("2.2").y + fp("2.3").y) / 2.0;
    let lip_z = fp("2.2").z.min(fp("2.3").z);
    let mns = ict().fapu().unwrap().distances.mns0 as f32;
    let (mut upper, mut lower) = (HashSet::new(), HashSet::new());
    for p in pieces() {
        let c = p.iter().copied().sum::<Vec3>() / p.len() as f32;
        let small = p.len() < 500; // single teeth, not the gums
        if !small || c.z > lip_z || (c.y - lip_y).abs() > 1.5 * mns || c.x.abs() > 4.0 * CM {
            continue;
        }
        let set = if c.y > lip_y { &mut upper } else { &mut lower };
        set.extend(p.iter().map(|&q| qkey(q)));
    }
    assert!(!upper.is_empty() && !lower.is_empty());
    let chin = qkey(
        ict().meshes[0]
            .mesh
            .positions
            .iter()
            .copied()
            .min_by(|a, b| a.distance(fp("2.1")).total_cmp(&b.distance(fp("2.1"))))
            .unwrap(),
    );
    for method in [Method::Fmc, Method::Rbf] {
        let face = &alma_to_ict(method).face;
        let m = motion(face, 3, 1024.0); // open_jaw
        let c = mean_motion(&m, &[chin].into());
        let lo = mean_motion(&m, &lower);
        let up = mean_motion(&m, &upper);
        eprintln!("{method:?} open_jaw: chin {c:.6}, lower teeth {lo:.6}, upper teeth {up:.7}");
        assert!(c > 0.1 * CM);
        assert!(lo >= 0.5 * c, "lower teeth {lo} vs chin {c}");
        assert!(up < 0.05 * c, "upper teeth {up} vs chin {c}");
    }
}

/// A target (bruno: not alma's mesh, whose welding a clone from alma would reuse) whose
/// feature point 2.3 (the bottom inner-lip midpoint) has been rebound to a vertex at the
/// back of the head: the lips are split wrongly and inner-lip FAPs leave their
/// feature points still, so they fail the guard (repaired or dropped). Without --strict the clone is written and the failure reported; with it,
/// exit 1 and nothing written.
#[test]
fn strict_refuses_failed_faps() {
    let dir = tempfile::tempdir().unwrap();
    let mut target = strip_fat(&fbakit::face::read("bruno").unwrap());
    let id = FeaturePointId::FP_2_3;
    let skin = target.mesh_index("skin").expect("alma has a skin mesh");
    let back = target.meshes[skin]
        .mesh
        .positions
        .iter()
        .enumerate()
        .min_by(|a, b| a.1.z.total_cmp(&b.1.z))
        .map(|(v, _)| v as u32)
        .unwrap();
    let fp = target.feature_points.get_mut(id).unwrap();
    fp.binding = Some(fbakit::fdp::VertexBinding {
        mesh: Some("skin".into()),
        vertices: vec![back],
    });
    target.resolve_feature_points().unwrap();
    let target_path = dir.path().join("target.wrl");
    fbakit::face::vrml::write_face_file(&target_path, &target).unwrap();
    let run = |out: &std::path::Path, strict: bool| {
        let mut args = vec!["clone", "alma", target_path.to_str().unwrap()];
        args.extend(["--method", "fmc", "--json", "-o", out.to_str().unwrap()]);
        if strict {
            args.push("--strict");
        }
        std::process::Command::new(env!("CARGO_BIN_EXE_fbakit"))
            .args(&args)
            .output()
            .unwrap()
    };
    let loose = dir.path().join("loose.glb");
    let o = run(&loose, false);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let failed = v["report"]["failed_faps"].as_array().unwrap();
    assert!(!failed.is_empty());
    assert!(v["report"]["warnings"]
        .to_string()
        .contains(failed[0]["fap"].as_str().unwrap()));
    assert!(loose.exists());
    let strict = dir.path().join("strict.glb");
    let o = run(&strict, true);
    assert_eq!(o.status.code(), Some(1));
    assert!(!strict.exists());
    assert!(String::from_utf8_lossy(&o.stderr).contains("--strict"));
}

/// The target's layout is sacred: the cut into eyes and jaws is an internal view, and the
/// clone hands back ict's one mesh with every vertex, polygon and attribute where it was.
#[test]
fn ict_comes_back_in_its_own_layout() {
    let ict = ict();
    for method in [Method::Fmc, Method::Rbf] {
        let out = alma_to_ict(method);
        let face = &out.face;
        assert_eq!(face.meshes.len(), 1, "{method:?}");
        let (a, b) = (&face.meshes[0], &ict.meshes[0]);
        assert_eq!(a.name, b.name);
        assert_eq!(a.mesh.positions, b.mesh.positions);
        assert_eq!(a.mesh.polygons, b.mesh.polygons);
        assert_eq!(a.mesh.uvs, b.mesh.uvs);
        assert_eq!(a.mesh.uv_polygons, b.mesh.uv_polygons);
        assert_eq!(a.mesh.normals, b.mesh.normals);
        assert_eq!(a.mesh.normal_polygons, b.mesh.normal_polygons);
        assert_eq!(
            face.neutral_world_positions(),
            ict.neutral_world_positions()
        );
        // alma's eyes turn by transforms; ict's eyeballs are vertices: that motion is baked.
        let baked = &out.report.rigid.baked_transforms;
        assert!(!baked.is_empty(), "{:?}", out.report.rigid);
        for t in baked {
            assert!(face.transform_index(t).is_none(), "{t} left in the face");
            assert!(!out.report.rigid.created_transforms.contains(t));
        }
        face.evaluator().unwrap();
        assert!(fbakit::fat::validate::validate_fat(
            &face.fat,
            &face.mesh_sizes(),
            &face.transform_names()
        )
        .is_empty());
    }
}

/// Vertices of the original mesh in the cut parts `parts`.
fn part_vertices(out: &CloneOutcome, parts: &[Part]) -> HashSet<usize> {
    out.report
        .split_parts
        .iter()
        .filter(|s| parts.contains(&s.part))
        .flat_map(|s| s.source_vertices.iter().map(|&v| v as usize))
        .collect()
}

/// Per vertex of mesh 0, its displacement at `fap` = `value`.
fn displacements(face: &FaceModel, fap: u8, value: f64) -> Vec<Vec3> {
    motion(face, fap, value).into_iter().map(|m| m.1).collect()
}

/// Eyeball FAPs move their eyeball only, rigidly: every distance between two of its vertices
/// is kept within 1 % of its size (the baking's tolerance) at every value the table covers
/// (alma's eyeball tables show 20 000 AU; the FAPs are bidirectional).
#[test]
fn eyeball_faps_turn_only_their_eyeball() {
    for method in [Method::Fmc, Method::Rbf] {
        let out = alma_to_ict(method);
        let face = &out.face;
        let neutral = &face.neutral_world_positions()[0];
        for (fap, part) in [
            (23, Part::LeftEye),
            (24, Part::RightEye),
            (25, Part::LeftEye),
            (26, Part::RightEye),
        ] {
            let eye = part_vertices(out, &[part]);
            assert!(eye.len() > 1000, "{part:?}: {}", eye.len());
            let mut sample: Vec<usize> = eye.iter().copied().collect();
            sample.sort_unstable();
            let sample: Vec<usize> = sample.iter().step_by(sample.len() / 150).copied().collect();
            let pts: Vec<Vec3> = eye.iter().map(|&v| neutral[v]).collect();
            let lo = pts.iter().copied().fold(Vec3::INFINITY, Vec3::min);
            let hi = pts.iter().copied().fold(Vec3::NEG_INFINITY, Vec3::max);
            let size = (hi - lo).length();
            for value in [-20_000.0, -7_000.0, 5_000.0, 12_345.0, 20_000.0] {
                let d = displacements(face, fap, value);
                let outside = d
                    .iter()
                    .enumerate()
                    .filter(|(v, _)| !eye.contains(v))
                    .map(|(_, d)| d.length())
                    .fold(0.0, f32::max);
                assert!(
                    outside < 1e-6,
                    "FAP {fap} at {value} moves non-eye vertices by {outside}"
                );
                let peak = eye.iter().map(|&v| d[v].length()).fold(0.0, f32::max);
                assert!(
                    peak > 0.01 * size,
                    "FAP {fap} at {value} barely moves the eye ({peak})"
                );
                let mut worst: f32 = 0.0;
                for &a in &sample {
                    for &b in &sample {
                        let before = neutral[a].distance(neutral[b]);
                        let after = (neutral[a] + d[a]).distance(neutral[b] + d[b]);
                        worst = worst.max((before - after).abs());
                    }
                }
                assert!(
                    worst < 0.01 * size,
                    "FAP {fap} at {value}: deformed by {worst} of {size}"
                );
            }
        }
    }
}

/// The bundled ICT glb (one primitive) comes back with its vertex count and order.
#[test]
fn glb_head_keeps_its_layout() {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/samples/faces/ict-head");
    let fp = format!("{dir}/ict-head-fp.csv");
    let opts = fbakit::face::FaceReadOptions::with_feature_points(Some(std::path::Path::new(&fp)));
    let glb = format!("{dir}/ict-head.glb");
    let (head, _) = fbakit::face::read_with(std::path::Path::new(&glb), &opts).unwrap();
    let head = strip_fat(&head);
    let alma = fbakit::face::read("alma").unwrap();
    let out = clone_face(&alma, &head, &CloneOptions::default()).unwrap();
    assert!(
        !out.report.split_parts.is_empty(),
        "the glb head is cut inside"
    );
    assert_eq!(out.face.mesh_sizes(), head.mesh_sizes());
    assert_eq!(
        out.face.neutral_world_positions(),
        head.neutral_world_positions()
    );
}

/// ict with a UV-style seam down the midline: every vertex shared by polygons on both sides
/// gets a twin (same position) used by the polygons right of the midline. Returns the face and
/// the (original, twin) pairs.
fn with_midline_seam(face: &FaceModel) -> (FaceModel, Vec<(usize, usize)>) {
    let mut out = face.clone();
    let m = &mut out.meshes[0].mesh;
    let n = m.positions.len();
    let right: Vec<bool> = m
        .polygons
        .iter()
        .map(|p| p.iter().map(|&v| m.positions[v as usize].x).sum::<f32>() > 0.0)
        .collect();
    let (mut on_left, mut on_right) = (vec![false; n], vec![false; n]);
    for (p, &r) in m.polygons.iter().zip(&right) {
        for &v in p {
            if r {
                on_right[v as usize] = true;
            } else {
                on_left[v as usize] = true;
            }
        }
    }
    let mut twin = vec![None; n];
    let mut pairs = Vec::new();
    for v in 0..n {
        if on_left[v] && on_right[v] {
            let t = m.positions.len();
            m.positions.push(m.positions[v]);
            if m.uv_polygons.is_none() && m.uvs.len() == n {
                m.uvs.push(m.uvs[v]);
            }
            if m.normal_polygons.is_none() && m.normals.len() == n {
                m.normals.push(m.normals[v]);
            }
            if m.colors.len() == n {
                m.colors.push(m.colors[v]);
            }
            twin[v] = Some(t as u32);
            pairs.push((v, t));
        }
    }
    let mut polys = fbakit::mesh::Polygons::new();
    for (p, &r) in m.polygons.iter().zip(&right) {
        let q: Vec<u32> = p
            .iter()
            .map(|&v| if r { twin[v as usize].unwrap_or(v) } else { v })
            .collect();
        polys.push(&q);
    }
    m.polygons = polys;
    (out, pairs)
}

/// Seam duplicates (same position, joined across the seam by the surface) move exactly like
/// their twins: no cracks, also where the seam crosses the closed mouth's lips (each lip's
/// twins are welded, the lips stay apart).
#[test]
fn seam_duplicates_move_like_their_twins() {
    let (head, pairs) = with_midline_seam(ict());
    assert!(pairs.len() > 50, "{} seam vertices", pairs.len());
    let alma = fbakit::face::read("alma").unwrap();
    let lip_y = (fp("2.2").y + fp("2.3").y) / 2.0;
    let mns = ict().fapu().unwrap().distances.mns0 as f32;
    for method in [Method::Fmc, Method::Fit] {
        let opts = CloneOptions {
            method,
            ..CloneOptions::default()
        };
        let out = clone_face(&alma, &head, &opts).unwrap();
        let face = &out.face;
        assert_eq!(face.mesh_sizes(), head.mesh_sizes());
        let p = &head.meshes[0].mesh.positions;
        let (mut checked, mut in_mouth) = (0, 0);
        for fap in [3, 5, 15, 19, 31, 48] {
            let d: Vec<Vec3> = motion(face, fap, 512.0).into_iter().map(|m| m.1).collect();
            let peak = d.iter().map(|x| x.length()).fold(0.0, f32::max);
            assert!(peak > 0.0, "FAP {fap} moves nothing");
            for &(a, b) in &pairs {
                let gap = d[a].distance(d[b]);
                checked += 1;
                in_mouth += usize::from((p[a].y - lip_y).abs() < 0.35 * mns);
                assert!(
                    gap <= 1e-5 * peak,
                    "{method:?} FAP {fap}: twins {a} and {b} at {} move {gap} apart (peak {peak})",
                    p[a]
                );
            }
        }
        // open_jaw (3) parts the lips: the midline points of the closed lip line go apart.
        let d: Vec<Vec3> = motion(face, 3, 512.0).into_iter().map(|m| m.1).collect();
        let at_slit: Vec<usize> = pairs
            .iter()
            .map(|&(a, _)| a)
            .filter(|&a| (p[a].y - lip_y).abs() < 0.05 * mns && p[a].z > fp("2.2").z - 0.5 * mns)
            .collect();
        let spread = at_slit
            .iter()
            .flat_map(|&a| at_slit.iter().map(move |&b| (a, b)))
            .filter(|&(a, b)| p[a].distance(p[b]) < 1e-5)
            .map(|(a, b)| d[a].distance(d[b]))
            .fold(0.0, f32::max);
        eprintln!(
            "{method:?}: {checked} twin motions equal ({in_mouth} in the mouth box); \
             {} midline slit points, coincident ones apart by up to {spread}",
            at_slit.len()
        );
        assert!(checked > 200);
    }
}
