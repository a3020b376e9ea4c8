//! `fbakit face from-rig RIG [--map arkit|FILE.csv] [--fp FP] -o FACE`: a face with a
//! FAP-compliant FAT built from a blendshape rig.

use std::path::PathBuf;

use clap::Args;
use fbakit::error::Result;
use fbakit::rig::fap_map::{read_fap_map, FapMap};
use fbakit::rig::fat_build::{face_from_rig, RigFatReport};
use fbakit::rig::read_rig;
use serde::Serialize;

use super::{print_json, EXIT_OK};

/// Arguments of `face from-rig`.
#[derive(Debug, Args)]
pub struct FromRigArgs {
    /// The rig: .glb, .gltf, a folder of OBJs (neutral + one OBJ per shape) or a neutral .obj.
    pub rig: PathBuf,
    /// Mapping table: `arkit` (built in, specs/arkit-fap-map.csv) or a CSV file with the
    /// columns fap,positive,negative,reasoning.
    #[arg(long, value_name = "arkit|FILE", default_value = "arkit")]
    pub map: String,
    /// Feature points of the neutral (.xml, .fdp, .csv); needed to calibrate low-level FAPs.
    #[arg(long, value_name = "FILE")]
    pub fp: Option<PathBuf>,
    /// Output face: .wrl, .wrl.gz (VRML with the FAT) or .glb/.gltf (FAT as morph targets).
    #[arg(short, long, value_name = "FACE")]
    pub output: PathBuf,
    /// Print the report as JSON.
    #[arg(long)]
    pub json: bool,
}

#[derive(Serialize)]
struct Output<'a> {
    rig: String,
    output: String,
    tables: usize,
    #[serde(flatten)]
    report: &'a RigFatReport,
    warnings: &'a [fbakit::error::Diagnostic],
}

/// The mapping table `--map` names: `arkit` (built in) or a CSV file checked against `rig`.
pub fn load_map(map: &str, rig: &fbakit::rig::Rig) -> Result<FapMap> {
    if map.eq_ignore_ascii_case("arkit") {
        return Ok(FapMap::arkit());
    }
    let path = PathBuf::from(map);
    let m = read_fap_map(&path)?;
    m.check_against(rig, &path)?;
    Ok(m)
}

/// Runs `face from-rig`.
pub fn run(a: FromRigArgs) -> Result<u8> {
    fbakit::format::OutputFormat::resolve(
        &a.output,
        fbakit::format::OutputFormat::FACES,
        "`face from-rig` output",
    )?;
    fbakit::format::refuse_overwriting_input(&a.output, &[&a.rig])?;
    let rig = read_rig(&a.rig)?;
    let map = load_map(&a.map, &rig)?;
    let fp = match &a.fp {
        Some(p) => Some(fbakit::fdp::read_feature_points(p)?.points),
        None => None,
    };
    let (face, report) = face_from_rig(&rig, fp, &map)?;
    super::print_warnings(&fbakit::export::write_face(&a.output, &face)?);
    super::print_warnings(&rig.warnings);
    if a.json {
        print_json(&Output {
            rig: a.rig.display().to_string(),
            output: a.output.display().to_string(),
            tables: face.fat.tables.len(),
            report: &report,
            warnings: &rig.warnings,
        })?;
        return Ok(EXIT_OK);
    }
    println!(
        "wrote {} ({} FAT tables from rig `{}`, map {})",
        a.output.display(),
        face.fat.tables.len(),
        rig.name,
        report.map
    );
    println!("calibrated ({} FAP sides):", report.calibrated.len());
    for c in &report.calibrated {
        println!(
            "  {:<24} {}  {:<40} fp {:<5} {:>9.1} {} at weight 1",
            c.fap,
            c.sign,
            c.shapes.join("+"),
            c.feature_point,
            c.value,
            c.unit
        );
    }
    println!("visemes and expressions:");
    for h in &report.high_level {
        println!("  {:<24} {}", h.key, h.source);
    }
    println!("not realised ({}):", report.unmapped.len());
    for u in &report.unmapped {
        println!("  {:<28} {}", u.key, u.reason);
    }
    println!(
        "unused shapes ({}): {}",
        report.unused_shapes.len(),
        report.unused_shapes.join(", ")
    );
    Ok(EXIT_OK)
}
