use super::*;

fn p() -> &'static Path {
    Path::new("t.wfm")
}

const SMALL: &str = "\
# Tiny test model
# second header line

# VERTEX LIST:
4
0.0 0.0 0.0
1.0 0.0 0.0
0.0   1.0  0.0
0.0 0.0 1.0

# FACE LIST:
2
0 1 2
0  2 3

# ANIMATION UNITS LIST:
2

# AUV0   Upper lip raiser (AU10)
1
3    0.000000    0.086957    0.021739

# FAP 3 open_jaw
# MNS
2
1 0 -1 0
2 0 -1 0

# FAPs not implemented:
# FAP43 shift_tongue_tip

# SHAPE UNITS LIST:
1

# Eyes, width
1
0  0.1 0 0

# ANIMATION PARAMETERS:
1
1 0.5

# SHAPE PARAMETERS:
0

# TEXTURE:
0

# GLOBAL MOTION:
0.00000  0.00000  0.00000
1.00000  1.00000  1.00000
0.00000  0.00000  0.00000

# END OF FILE";

#[test]
fn line_combinators() {
    assert_eq!(
        comment_line("  #  FAP 3 open_jaw \nx"),
        Ok(("x", "FAP 3 open_jaw"))
    );
    assert!(comment_line("3\n").is_err());
    assert_eq!(blank_line("  \r\nx"), Ok(("x", ())));
    assert!(blank_line("").is_err());
    assert_eq!(
        vec3_line("0.1   -2  3\n"),
        Ok(("", Vec3::new(0.1, -2.0, 3.0)))
    );
    assert!(vec3_line("0.1 -2\n").is_err());
    assert!(vec3_line("0.1 -2 3 4\n").is_err());
    assert_eq!(triangle_line("0   11  1\n"), Ok(("", [0, 11, 1])));
    assert!(triangle_line("0 -1 1\n").is_err());
    assert_eq!(
        displacement_line("10 0 -1 0\n"),
        Ok(("", (10, Vec3::new(0.0, -1.0, 0.0))))
    );
    assert_eq!(param_line("3 0.25"), Ok(("", (3, 0.25))));
    assert_eq!(count_line("\n3\nxxxxxxxxxx", 1), Ok(("xxxxxxxxxx", 3usize)));
    assert!(count_line("1000000000000\n0 0 0\n", 6).is_err());
    assert_eq!(
        next_section("\n# note\n# FACE LIST:\n2\n"),
        Ok(("2\n", Some("FACE LIST")))
    );
    assert_eq!(next_section("\n\n"), Ok(("", None)));
    assert!(next_section("7\n").is_err());
    let (_, (comments, disp)) = unit_block("\n# FAP 3 open_jaw\n# MNS\n1\n10 0 -1 0\n").unwrap();
    assert_eq!(comments, ["FAP 3 open_jaw", "MNS"]);
    assert_eq!(disp.len(), 1);
    assert!(unit_block("1\n10 0 -1 0\n").is_err());
    assert_eq!(
        fap_label("FAP10 raise_b_lip_lm"),
        Some((10, "raise_b_lip_lm"))
    );
    assert_eq!(fap_label("FAP 3 open_jaw"), Some((3, "open_jaw")));
    assert_eq!(fap_label("FAPs not implemented:"), None);
}

#[test]
fn reads_every_section() {
    let m = parse_wfm(SMALL, p()).unwrap();
    assert_eq!(m.header, ["Tiny test model", "second header line"]);
    assert_eq!(m.vertices.len(), 4);
    assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 3]]);
    assert_eq!(m.animation_units.len(), 2);
    let auv = &m.animation_units[0];
    assert_eq!(
        (auv.name.as_str(), auv.fap, auv.fapu),
        ("AUV0 Upper lip raiser (AU10)", None, None)
    );
    let jaw = &m.animation_units[1];
    assert_eq!(jaw.name, "open_jaw");
    assert_eq!(jaw.fap, Some(FapId::OPEN_JAW));
    assert_eq!(jaw.fapu, Some(FapuKind::Mns));
    assert_eq!(jaw.displacements, vec![(1, -Vec3::Y), (2, -Vec3::Y)]);
    assert_eq!(m.shape_units.len(), 1);
    assert_eq!(m.shape_units[0].name, "Eyes, width");
    assert_eq!(m.animation_params, vec![(1, 0.5)]);
    assert!(m.shape_params.is_empty() && m.texture.is_empty());
    assert_eq!(m.global_motion.unwrap().scale, Vec3::ONE);
    let shaped = m.with_shape(&[("eyes, width", 2.0)]).unwrap();
    assert_eq!(shaped.vertices[0], Vec3::new(0.2, 0.0, 0.0));
    let e = m
        .with_shape(&[("Mouth width", 1.0)])
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("unknown shape unit `Mouth width`; valid names: Eyes, width"),
        "{e}"
    );
    assert!(m.with_shape(&[("Eyes, width", f32::NAN)]).is_err());
}

#[test]
fn trailing_sections_are_optional() {
    let cut = SMALL.find("# ANIMATION UNITS LIST:").unwrap();
    let m = parse_wfm(&SMALL[..cut], p()).unwrap();
    assert_eq!((m.vertices.len(), m.triangles.len()), (4, 2));
    assert!(m.animation_units.is_empty() && m.global_motion.is_none());
    assert_eq!(m.to_mesh().face_count(), 2);
    // The last line may lack its line ending; counts still fit.
    let m = parse_wfm("# h\n# VERTEX LIST:\n1\n0 0 0\n# FACE LIST:\n1\n0 0 0", p()).unwrap();
    assert_eq!(m.vertices, vec![Vec3::ZERO]);
    assert_eq!(m.triangles, vec![[0, 0, 0]]);
}

fn err(text: &str) -> String {
    parse_wfm(text, p()).unwrap_err().to_string()
}

#[test]
fn hostile_and_broken_inputs_are_located_errors() {
    let huge = SMALL.replace("# VERTEX LIST:\n4\n", "# VERTEX LIST:\n1000000000000\n");
    assert_eq!(
        err(&huge),
        "t.wfm:5:1: expected a count the rest of the file can hold, found `1000000000000`"
    );
    let huge = SMALL.replace(
        "ANIMATION UNITS LIST:\n2\n",
        "ANIMATION UNITS LIST:\n99999999999999999999\n",
    );
    assert!(err(&huge).contains("expected a non-negative integer of at most 19 digits"));
    // Truncated inside the vertex list.
    let cut = SMALL.find("0.0 0.0 1.0").unwrap();
    assert!(
        err(&SMALL[..cut]).starts_with("t.wfm:9:1: expected a number, found end of input"),
        "{}",
        err(&SMALL[..cut])
    );
    // Truncated inside a unit.
    let cut = SMALL.find("2 0 -1 0").unwrap();
    assert_eq!(
        err(&SMALL[..cut]),
        "t.wfm:25:1: expected a count the rest of the file can hold, found `2`"
    );
    let cut = SMALL.find("0\n\n# FAPs").unwrap();
    assert!(
        err(&SMALL[..cut]).starts_with("t.wfm:27:8: expected a number"),
        "{}",
        err(&SMALL[..cut])
    );
    // Out-of-range vertex in a face and in a unit.
    assert_eq!(
        err(&SMALL.replace("0  2 3", "0 2 9")),
        "t.wfm:14:1: expected vertex indices below 4 (found 9), found `0 2 9`"
    );
    assert!(err(&SMALL.replace("1 0 -1 0", "7 0 -1 0"))
        .starts_with("t.wfm:26:1: expected a vertex index below 4"));
    assert!(err(&SMALL.replace("0.0   1.0  0.0", "0.0 nan 0.0"))
        .starts_with("t.wfm:8:5: expected a number"));
    assert!(err(&SMALL.replace("# FAP 3 open_jaw", "# FAP 99 x"))
        .starts_with("t.wfm:23:1: expected a FAP number"));
    assert!(err(&SMALL.replace("1\n1 0.5", "1\n5 0.5")).contains("expected a unit index below 2"));
    assert!(err("").starts_with("t.wfm:1:1: expected a `#` header comment or `# VERTEX LIST:`"));
    assert!(err("# VERTEX LIST:\n0\n# SHAPE UNITS LIST:\n0\n").contains("expected `# FACE LIST:`"));
    let swapped = SMALL
        .replace("# SHAPE PARAMETERS:\n0\n", "")
        .replace("# TEXTURE:", "# TEXTURE:\n0\n# SHAPE PARAMETERS:");
    assert!(
        err(&swapped).contains("sections in file order"),
        "{}",
        err(&swapped)
    );
}

#[test]
fn reference_candide3_file() {
    let path = Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../shared/data/candide3/candide3.wfm"
    ));
    if !path.exists() {
        eprintln!("note: {} missing, test skipped", path.display());
        return;
    }
    let m = read_wfm_file(path).unwrap();
    assert_eq!(m.header[0], "Candide-3.1.6");
    assert_eq!(m.vertices.len(), 113);
    assert_eq!(m.triangles.len(), 184);
    assert_eq!(m.animation_units.len(), 65);
    let faps: Vec<u8> = m
        .animation_units
        .iter()
        .filter_map(|u| u.fap)
        .map(FapId::number)
        .collect();
    let expected: Vec<u8> = (3..=42).chain(51..=64).collect();
    assert_eq!(faps, expected, "54 FAP units: FAPs 3-42 and 51-64");
    let auvs: Vec<&str> = m
        .animation_units
        .iter()
        .filter(|u| u.fap.is_none())
        .map(|u| u.name.split(' ').next().unwrap())
        .collect();
    assert_eq!(
        auvs,
        [
            "AUV0", "AUV11", "AUV2", "AUV3", "AUV14", "AUV5", "AUV6", "AUV7", "AUV8", "AUV9",
            "AUV10"
        ]
    );
    assert_eq!(m.shape_units.len(), 14);
    assert_eq!(m.shape_units[0].name, "Head height");
    assert_eq!(m.shape_units[13].name, "Chin width");
    assert!(m.animation_params.is_empty() && m.shape_params.is_empty() && m.texture.is_empty());
    assert_eq!(m.global_motion.unwrap().scale, Vec3::ONE);

    // FAP 3 open_jaw (MNS) moves vertex 10 = FP 2.1 straight down.
    let jaw = m.fap_unit(FapId::OPEN_JAW).unwrap();
    assert_eq!(jaw.name, "open_jaw");
    assert_eq!(jaw.fapu, Some(FapuKind::Mns));
    assert!(jaw.displacements.contains(&(10, Vec3::new(0.0, -1.0, 0.0))));
    // README cross-checks: FAP 8 → 81, FAP 55 → 79, FAP 19 → 21; eyeball units carry no FAPU.
    let moves = |fap: u8, v: u32| {
        m.fap_unit(FapId::new(fap).unwrap())
            .unwrap()
            .displacements
            .iter()
            .any(|d| d.0 == v)
    };
    assert!(moves(8, 81) && moves(55, 79) && moves(19, 21));
    assert_eq!(
        m.fap_unit(FapId::new(19).unwrap()).unwrap().fapu,
        Some(FapuKind::Irisd)
    );
    assert!((23..=30).all(|f| m.fap_unit(FapId::new(f).unwrap()).unwrap().fapu.is_none()));
    // The FAP names in the file are the standard's (except the file's typos in 61/62).
    for u in m
        .animation_units
        .iter()
        .filter(|u| u.fap.is_some_and(|f| !matches!(f.number(), 61 | 62)))
    {
        assert_eq!(u.fap.unwrap().name(), u.name, "{}", u.label);
    }
    // Vertex 31 (left lip corner, FP 8.3) at x = +0.246; README MW = x(31) - x(64) = 0.492.
    assert!((m.vertices[31].x - 0.246).abs() < 1e-6);
    assert!((m.vertices[31].x - m.vertices[64].x - 0.492).abs() < 1e-5);

    let mesh = m.to_mesh();
    assert!(mesh.validate().is_valid());
    assert_eq!(mesh.triangles().len(), 184);
    // Shape units: "Mouth width" moves the lip corners apart symmetrically.
    let shaped = m
        .with_shape(&super::super::parse_shape_spec("Mouth width=1").unwrap())
        .unwrap();
    let d31 = shaped.vertices[31] - m.vertices[31];
    let d64 = shaped.vertices[64] - m.vertices[64];
    assert!(d31.x > 0.0 && (d31.x + d64.x).abs() < 1e-6, "{d31} {d64}");
}
