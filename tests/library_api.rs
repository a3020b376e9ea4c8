//! The library as a Rust user meets it: the README's read → clone → write → play example,
//! uniform signatures (paths as `impl AsRef<Path>`, options by reference), `Display` on what
//! users print, and whole-pose world positions in one call.

use fbakit::prelude::*;

#[test]
fn read_clone_write_play_as_the_readme_shows() -> fbakit::error::Result<()> {
    let dir = tempfile::tempdir().unwrap();
    let source = face::read("alma")?;
    let target = FaceModel {
        fat: Fat::default(),
        ..face::read("bruno")?
    };
    let cloned = clone_face(&source, &target, &CloneOptions::default())?;
    let summary = cloned.report.to_string();
    assert!(summary.starts_with("cloned "), "{summary}");
    assert!(summary.contains(" with fit "), "{summary}");
    let out = dir.path().join("bruno-cloned.wrl");
    let written = export::write(&out, &cloned.face, &ExportOptions::default())?;
    assert_eq!(written.kind, export::ExportKind::Vrml, "{written}");
    assert!(written.warnings.is_empty(), "{:?}", written.warnings);
    let back = face::read(&out)?;
    assert_eq!(back.fat.tables.len(), cloned.face.fat.tables.len());
    // The same front door writes the OBJ shape set the README's example asks for.
    let set = export::write(
        dir.path().join("bruno-cloned/"),
        &cloned.face,
        &ExportOptions::default(),
    )?;
    assert_eq!(set.kind, export::ExportKind::ObjShapes, "{set}");
    assert_eq!(set.shapes.as_ref().unwrap().shapes.len(), set.morph_targets);

    let stream = fap::read("samples/speech.fap")?;
    let mut player = Player::new(&back, &stream, &PlayOptions::default())?;
    let neutral = player.frame(0).world_positions();
    let busiest = (0..player.frame_count())
        .map(|i| {
            let w = player.frame(i).world_positions();
            w.iter()
                .flatten()
                .zip(neutral.iter().flatten())
                .map(|(a, b)| a.distance(*b))
                .fold(0.0f32, f32::max)
        })
        .fold(0.0f32, f32::max);
    assert_eq!(neutral.len(), back.meshes.len());
    assert!(busiest > 0.0, "speech moves the cloned face");
    Ok(())
}

#[test]
fn reports_users_print_have_display() -> fbakit::error::Result<()> {
    assert_eq!(Method::Fit.to_string(), "fit");
    assert_eq!(Method::Fmc.to_string(), "fmc");
    let alma = face::read("alma")?;
    let fapu = Fapu::measure(&alma.feature_points)?.fapu;
    let text = fapu.to_string();
    assert_eq!(text.lines().count(), 6, "{text}");
    assert!(text.lines().next().unwrap().starts_with("IRISD "), "{text}");
    assert!(text.contains("MNS0 "), "{text}");
    Ok(())
}

#[test]
fn paths_are_taken_as_str_path_or_pathbuf() -> fbakit::error::Result<()> {
    let p = std::path::PathBuf::from("samples/speech.fap");
    let a = fap::read("samples/speech.fap")?;
    let b = fap::read(&p)?;
    let (c, _) = fap::read_with(p.as_path(), &ReadOptions::strict())?;
    assert_eq!(a, b);
    assert_eq!(a, c);
    let v: Vec3 = glam::Vec3::ONE; // glam is re-exported
    assert_eq!(v.x, 1.0);
    Ok(())
}
