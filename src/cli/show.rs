//! `fbakit grid` (the cloning grid) and `fbakit demo` (the end-to-end demo).

use std::path::{Path, PathBuf};

use clap::Args;
use fbakit::clone::face::Method;
use fbakit::demo::{run_demo, DemoOptions};
use fbakit::error::{Error, Result};
use fbakit::export::picture::cloning_grid;
use fbakit::face::FaceModel;
use fbakit::fat::TableKey;
use fbakit::format::OutputFormat;

use super::{print_json, MethodArg, EXIT_OK};

/// Arguments of `grid`.
#[derive(Debug, Args)]
pub struct GridArgs {
    /// Faces: VRML face files (.wrl, .wrl.gz) or `alma` / `bruno`; each is a source (row)
    /// and a target (column).
    #[arg(required = true, num_args = 1..)]
    pub faces: Vec<PathBuf>,
    /// What to show: a FAP name (`open_jaw`), `viseme_N` or an expression (`joy`).
    #[arg(long, default_value = "joy", value_parser = parse_key)]
    pub key: TableKey,
    /// Its value (expressions 0..63, FAPs in FAP units).
    #[arg(long, default_value_t = 63.0)]
    pub value: f64,
    /// Cloning method.
    #[arg(long, value_enum, default_value_t)]
    pub method: MethodArg,
    /// Cell side in pixels.
    #[arg(long, default_value_t = 256, value_parser = clap::value_parser!(u32).range(16..=2048))]
    pub cell: u32,
    /// Output PNG.
    #[arg(short, long, value_name = "OUT.png")]
    pub output: PathBuf,
    /// Print the report as JSON.
    #[arg(long)]
    pub json: bool,
}

fn parse_key(s: &str) -> std::result::Result<TableKey, String> {
    TableKey::from_name(s).ok_or_else(|| {
        format!("`{s}` is not a FAP name, viseme_N (1..14) or expression (joy, sadness, ...)")
    })
}

/// Short display name of a face argument (`bruno` for `faces/bruno.wrl.gz`).
fn short_name(spec: &Path) -> String {
    let name = spec.file_name().map_or_else(
        || spec.display().to_string(),
        |n| n.to_string_lossy().into(),
    );
    name.split('.').next().unwrap_or(&name).to_string()
}

/// Runs `grid`.
pub fn grid(a: GridArgs) -> Result<u8> {
    OutputFormat::resolve(&a.output, &[OutputFormat::Png], "the cloning grid")?;
    if !a.value.is_finite() {
        return Err(Error::Unsupported("--value must be a finite number".into()));
    }
    let faces: Vec<FaceModel> = a
        .faces
        .iter()
        .map(fbakit::face::read)
        .collect::<Result<_>>()?;
    let names: Vec<String> = a.faces.iter().map(|p| short_name(p)).collect();
    let pairs: Vec<(&str, &FaceModel)> = names.iter().map(String::as_str).zip(&faces).collect();
    let image = cloning_grid(&pairs, a.key, a.value, a.method.into(), a.cell)?;
    image.write_png(&a.output)?;
    if a.json {
        print_json(&serde_json::json!({
            "output": a.output.display().to_string(),
            "faces": names,
            "key": a.key.name(),
            "value": a.value,
            "method": Method::from(a.method),
            "width": image.width,
            "height": image.height,
        }))?;
        return Ok(EXIT_OK);
    }
    println!(
        "wrote {}: {}×{} cloning grid of {} ({} at {}, {})",
        a.output.display(),
        names.len(),
        names.len(),
        names.join(", "),
        a.key.name(),
        a.value,
        Method::from(a.method).name()
    );
    Ok(EXIT_OK)
}

/// Arguments of `demo`.
#[derive(Debug, Args)]
pub struct DemoArgs {
    /// Output directory (created).
    #[arg(long, default_value = "fbakit-demo", value_name = "DIR")]
    pub out: PathBuf,
    /// Cloning method for the outputs (the other methods are measured too unless --single).
    #[arg(long, value_enum, default_value_t)]
    pub method: MethodArg,
    /// Only run the chosen method (skip the comparison with the other methods).
    #[arg(long)]
    pub single: bool,
    /// Print the report as JSON.
    #[arg(long)]
    pub json: bool,
    /// Print the time of each step (always in --json).
    #[arg(short, long)]
    pub verbose: bool,
}

/// Runs `demo`.
pub fn demo(a: DemoArgs) -> Result<u8> {
    let opts = DemoOptions {
        method: a.method.into(),
        compare_methods: !a.single,
        ..DemoOptions::default()
    };
    let report = run_demo(&a.out, &opts)?;
    if a.json {
        print_json(&report)?;
    } else {
        print!("{report}");
        if a.verbose {
            print!("{}", report.timings_text());
            super::print_warnings(&report.warnings);
        } else {
            // One line per kind of warning: a newcomer sees what kinds there are, not 40 lines.
            let kinds = fbakit::demo::group_warnings(&report.warnings);
            for k in &kinds {
                let more = if k.count > 1 {
                    format!(" (+{} more like it)", k.count - 1)
                } else {
                    String::new()
                };
                eprintln!(
                    "warning: {}{more}",
                    fbakit::error::escape_control(&shorten(&k.first, 110))
                );
            }
            if kinds
                .iter()
                .any(|k| k.count > 1 || k.first.chars().count() > 110)
            {
                eprintln!("note: `fbakit demo --verbose` prints every warning in full");
            }
        }
    }
    Ok(EXIT_OK)
}

/// `text` cut to at most `max` characters, with `…` when cut.
fn shorten(text: &str, max: usize) -> String {
    if text.chars().count() <= max {
        return text.to_string();
    }
    let mut out: String = text.chars().take(max.saturating_sub(1)).collect();
    out.push('…');
    out
}
