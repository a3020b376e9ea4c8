//! `fbakit fapu FILE`: the six FAP units of a face from its feature-point file.

use std::path::PathBuf;

use fbakit::error::{Result, ResultExt};
use fbakit::fdp::{read_feature_points, Fapu, FapuSource};
use fbakit::spec::{FapuKind, FAPU_DIVISOR};
use serde::Serialize;

use super::{print_json, EXIT_OK};

#[derive(Debug, clap::Args)]
pub struct FapuArgs {
    /// Feature-point file: fbakit `.xml`, Xface `.fdp` or `.csv` (fp,vertices,combine,description).
    pub file: PathBuf,
    /// Neutral mesh (.obj, .wrl, .wrl.gz) whose vertices the feature points are bound to; the
    /// points are placed on it and the FAPUs measured there.
    #[arg(long, value_name = "PATH")]
    pub mesh: Option<PathBuf>,
    /// Print JSON instead of a text table.
    #[arg(long)]
    pub json: bool,
}

#[derive(Serialize)]
struct Row {
    fapu: FapuKind,
    /// Neutral distance X0 (`None` for AU).
    distance: Option<f64>,
    /// X0/1024, or radians for AU.
    unit: f64,
}

#[derive(Serialize)]
struct Report {
    file: String,
    source: FapuSource,
    units: Vec<Row>,
    notes: Vec<fbakit::error::Diagnostic>,
}

pub fn run(args: FapuArgs) -> Result<u8> {
    let (source, measured) = match &args.mesh {
        // With a mesh, the points are placed on its vertices and the FAPUs measured there,
        // even when the file also states FAPU distances.
        Some(mesh) => {
            let (face, _) = fbakit::face::read_with(
                mesh,
                &fbakit::face::FaceReadOptions::with_feature_points(Some(&args.file)),
            )?;
            (
                FapuSource::FeaturePoints,
                Fapu::measure(&face.feature_points).with_context(|| {
                    format!(
                        "measuring the FAPUs of {} on {}",
                        args.file.display(),
                        mesh.display()
                    )
                })?,
            )
        }
        None => {
            let file = read_feature_points(&args.file)?;
            if file.fapu.is_none() && file.points.needs_mesh() {
                return Err(fbakit::fdp::FdpError::NeedsMesh {
                    file: args.file.clone(),
                }
                .into());
            }
            file.fapu()
                .with_context(|| format!("measuring the FAPUs of {}", args.file.display()))?
        }
    };
    let units = FapuKind::ALL
        .into_iter()
        .map(|k| Row {
            fapu: k,
            distance: measured.fapu.distance(k),
            unit: measured.fapu.unit(k),
        })
        .collect();
    let report = Report {
        file: args.file.display().to_string(),
        source,
        units,
        notes: measured.notes,
    };
    if args.json {
        print_json(&report)?;
    } else {
        super::print_text(&text(&report));
    }
    Ok(EXIT_OK)
}

fn text(r: &Report) -> String {
    use std::fmt::Write as _;
    let source = match r.source {
        FapuSource::File => "from file",
        FapuSource::FeaturePoints => "from feature points",
    };
    let mut s = format!("FAPU of {} ({source})\n", r.file);
    let _ = writeln!(s, "{:<6} {:<14} unit", "FAPU", "distance X0");
    for row in &r.units {
        let (d, u) = match row.distance {
            Some(d) => (d.to_string(), format!("{} (X0/{FAPU_DIVISOR})", row.unit)),
            None => ("-".to_string(), format!("{} rad", row.unit)),
        };
        let _ = writeln!(s, "{:<6} {:<14} {u}", row.fapu.abbreviation(), d);
    }
    for n in &r.notes {
        let _ = writeln!(s, "note: {}", n.located_message());
    }
    s
}
