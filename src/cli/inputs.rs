//! Reading the inputs commands share: a face (through the one front door, with an optional
//! feature-point file) and a FAP stream (strict or lenient), so every command reads them the
//! same way.

use std::path::Path;

use fbakit::error::Result;
use fbakit::error::{Diagnostic, Severity};
use fbakit::face::{FaceModel, FaceReadOptions, FaceReadReport};
use fbakit::fap::{read_stream_file, FapStream, ReadOptions};

/// Reads a face file, rig or bundled face; `fp` replaces its feature points (an OBJ needs
/// them; a rig's shapes become a FAT with them).
pub fn read_face(path: &Path, fp: Option<&Path>) -> Result<FaceModel> {
    let (face, report) =
        match fbakit::face::read_with(path, &FaceReadOptions::with_feature_points(fp)) {
            Ok(read) => read,
            // Some layers cannot know the file (FAPUs of a degenerate feature-point set):
            // name the files unless the message already does.
            Err(e) => {
                let message = e.to_string();
                let named = |p: &Path| message.contains(&p.display().to_string());
                if named(path) || fp.is_some_and(named) {
                    return Err(e);
                }
                return Err(match fp {
                    Some(fp) => e.context(format!(
                        "reading {} with feature points {}",
                        path.display(),
                        fp.display()
                    )),
                    None => e.context(format!("reading {}", path.display())),
                });
            }
        };
    print_reader_warnings(&report);
    if let Some(fp) = fp {
        // Points given by position were snapped to vertices: name the far snaps.
        super::print_warnings(&fbakit::face::attach::snap_warnings(
            &face,
            &report.fp_matches,
            fp,
        ));
    }
    Ok(face)
}

/// Prints the warnings a face reader noticed (a compressed glTF decoded, a file without a
/// scene, a rig read without its feature points), so every command says them, not only
/// `face info`.
fn print_reader_warnings(report: &FaceReadReport) {
    let warnings: Vec<Diagnostic> = report
        .diagnostics
        .iter()
        .filter(|d| d.severity == Severity::Warning)
        .cloned()
        .collect();
    super::print_warnings(&warnings);
}

/// Reads a FAP stream, strictly or leniently, with its reader warnings.
pub fn read_stream(path: &Path, strict: bool) -> Result<(FapStream, Vec<Diagnostic>)> {
    let opts = if strict {
        ReadOptions::strict()
    } else {
        ReadOptions::lenient()
    };
    read_stream_file(path, &opts)
}
