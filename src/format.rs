//! Output file formats, resolved once from the path a user gives.
//!
//! Every command that writes a file asks [`OutputFormat::resolve`] which format the path
//! names and whether the command can write it, so `.wrl.gz` means the same thing to every
//! command and an unknown extension is one clear error instead of a silent guess.
//! [`refuse_overwriting_input`] keeps a command from replacing the file it is reading.

use std::fmt;
use std::path::{Path, PathBuf};

use serde::Serialize;

use crate::error::Result;

/// An output path a command cannot use. All variants are input errors (exit code 2).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum OutputPathError {
    /// The path's extension names no format the command writes.
    #[error("{}: {what} must be {accepted}; found {found}", path.display())]
    WrongFormat {
        /// The output path.
        path: PathBuf,
        /// What is being written, e.g. "`fap convert` output".
        what: String,
        /// The accepted formats, comma-separated.
        accepted: String,
        /// What the path names instead.
        found: String,
    },
    /// The output is one of the command's inputs.
    #[error("{}: refusing to write over the input file; choose another output path", path.display())]
    WouldOverwriteInput {
        /// The output path.
        path: PathBuf,
    },
    /// A folder output exists as a file.
    #[error("{}: exists and is not a directory", path.display())]
    NotADirectory {
        /// The output path.
        path: PathBuf,
    },
    /// A folder output holds something that is not a frame of an earlier run.
    #[error("{}: exists and holds `{entry}`, which is not a frame of an earlier run; choose an empty or new directory", path.display())]
    ForeignEntry {
        /// The output folder.
        path: PathBuf,
        /// The entry that is not ours.
        entry: String,
    },
}

impl OutputPathError {
    /// Always true: a bad output path is bad usage.
    pub fn is_input_error(&self) -> bool {
        true
    }
}

/// A kind of file fbakit writes, named by its extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum OutputFormat {
    /// VRML97 face file (`.wrl`, `.vrml`).
    Vrml,
    /// Gzip-compressed VRML97 (`.wrl.gz`, `.vrml.gz`, `.wrz`).
    VrmlGz,
    /// Wavefront OBJ (`.obj`).
    Obj,
    /// Binary glTF 2.0 (`.glb`; `.vrm`, a VRM avatar, is one too: see [`is_vrm_path`]).
    Glb,
    /// Text glTF 2.0 with embedded buffers (`.gltf`).
    Gltf,
    /// ASCII FAP stream (`.fap`).
    Fap,
    /// JSON (`.json`): a FAP stream's JSON view or a report.
    Json,
    /// PNG picture (`.png`).
    Png,
    /// Comma-separated values (`.csv`).
    Csv,
    /// XML (`.xml`): fbakit feature-point files.
    Xml,
    /// Xface feature-point definition (`.fdp`).
    Fdp,
    /// A self-contained HTML page (`.html`, `.htm`).
    Html,
    /// MP4 video (`.mp4`).
    Mp4,
    /// Animated GIF (`.gif`).
    Gif,
    /// WAV audio (`.wav`).
    Wav,
    /// A directory of files (a path ending in `/`, or an existing directory).
    Directory,
}

/// Extensions, longest first so `.wrl.gz` wins over `.gz`.
const EXTENSIONS: &[(&str, OutputFormat)] = &[
    (".vrml.gz", OutputFormat::VrmlGz),
    (".wrl.gz", OutputFormat::VrmlGz),
    (".vrml", OutputFormat::Vrml),
    (".gltf", OutputFormat::Gltf),
    (".html", OutputFormat::Html),
    (".json", OutputFormat::Json),
    (".wrz", OutputFormat::VrmlGz),
    (".wrl", OutputFormat::Vrml),
    (".obj", OutputFormat::Obj),
    (".glb", OutputFormat::Glb),
    (".vrm", OutputFormat::Glb),
    (".fap", OutputFormat::Fap),
    (".png", OutputFormat::Png),
    (".csv", OutputFormat::Csv),
    (".xml", OutputFormat::Xml),
    (".fdp", OutputFormat::Fdp),
    (".htm", OutputFormat::Html),
    (".mp4", OutputFormat::Mp4),
    (".gif", OutputFormat::Gif),
    (".wav", OutputFormat::Wav),
];

impl OutputFormat {
    /// The format a path names: by extension (case-insensitive), or [`OutputFormat::Directory`]
    /// for a path ending in a separator or naming an existing directory. `None` when neither.
    pub fn of_path(path: &Path) -> Option<OutputFormat> {
        let text = path.to_string_lossy();
        if text.ends_with('/') || text.ends_with(std::path::MAIN_SEPARATOR) || path.is_dir() {
            return Some(OutputFormat::Directory);
        }
        let name = path.file_name()?.to_string_lossy().to_ascii_lowercase();
        EXTENSIONS
            .iter()
            .find(|(ext, _)| name.len() > ext.len() && name.ends_with(ext))
            .map(|&(_, f)| f)
    }

    /// The format of `path` if it is one of `accepted`; otherwise an input error that names
    /// the path, what `what` (e.g. "`fap convert` output") accepts, and what it found.
    pub fn resolve(path: &Path, accepted: &[OutputFormat], what: &str) -> Result<OutputFormat> {
        match OutputFormat::of_path(path) {
            Some(f) if accepted.contains(&f) => Ok(f),
            found => {
                let list: Vec<String> = accepted.iter().map(|f| f.to_string()).collect();
                let found = match found {
                    Some(f) => format!("{f}"),
                    None => match path.extension() {
                        Some(e) => format!("unknown extension `.{}`", e.to_string_lossy()),
                        None => "no extension".to_string(),
                    },
                };
                Err(OutputPathError::WrongFormat {
                    path: path.to_path_buf(),
                    what: what.to_string(),
                    accepted: list.join(", "),
                    found,
                }
                .into())
            }
        }
    }

    /// The main extension of the format (`.wrl.gz`, `.glb`, `/` for a directory).
    pub fn extension(self) -> &'static str {
        match self {
            OutputFormat::Vrml => ".wrl",
            OutputFormat::VrmlGz => ".wrl.gz",
            OutputFormat::Obj => ".obj",
            OutputFormat::Glb => ".glb",
            OutputFormat::Gltf => ".gltf",
            OutputFormat::Fap => ".fap",
            OutputFormat::Json => ".json",
            OutputFormat::Png => ".png",
            OutputFormat::Csv => ".csv",
            OutputFormat::Xml => ".xml",
            OutputFormat::Fdp => ".fdp",
            OutputFormat::Html => ".html",
            OutputFormat::Mp4 => ".mp4",
            OutputFormat::Gif => ".gif",
            OutputFormat::Wav => ".wav",
            OutputFormat::Directory => "/",
        }
    }

    /// The face file formats (what `face convert` and `clone` write).
    pub const FACES: &'static [OutputFormat] = &[
        OutputFormat::Vrml,
        OutputFormat::VrmlGz,
        OutputFormat::Obj,
        OutputFormat::Glb,
        OutputFormat::Gltf,
    ];
}

impl fmt::Display for OutputFormat {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            OutputFormat::Directory => f.write_str("a directory"),
            OutputFormat::Vrml => f.write_str(".wrl/.vrml"),
            OutputFormat::VrmlGz => f.write_str(".wrl.gz/.vrml.gz/.wrz"),
            OutputFormat::Html => f.write_str(".html"),
            other => f.write_str(other.extension()),
        }
    }
}

/// Whether `path` names a VRM avatar (`.vrm`): a binary glTF whose document carries the VRM
/// extension (`VRM` for VRM 0.x, `VRMC_vrm` for 1.0). fbakit writes one only by patching a
/// VRM avatar it read ([`crate::gltf::check_vrm_output`]).
pub fn is_vrm_path(path: &Path) -> bool {
    path.extension()
        .is_some_and(|e| e.to_string_lossy().eq_ignore_ascii_case("vrm"))
}

/// Refuses an `output` that is one of the `inputs` (same file after resolving links), so a
/// command never replaces what it is reading. Paths that do not exist yet cannot collide.
pub fn refuse_overwriting_input(output: &Path, inputs: &[&Path]) -> Result<()> {
    let Ok(out) = std::fs::canonicalize(output) else {
        return Ok(());
    };
    for input in inputs {
        if std::fs::canonicalize(input).is_ok_and(|i| i == out) {
            return Err(OutputPathError::WouldOverwriteInput {
                path: output.to_path_buf(),
            }
            .into());
        }
    }
    Ok(())
}

/// `path` with its file name replaced by `name` (for sibling outputs such as temporary
/// directories).
pub fn sibling(path: &Path, name: &str) -> PathBuf {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.join(name),
        _ => PathBuf::from(name),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn extensions_resolve_once_for_everyone() {
        let f = |p: &str| OutputFormat::of_path(Path::new(p));
        assert_eq!(f("a.wrl"), Some(OutputFormat::Vrml));
        assert_eq!(f("a.VRML.GZ"), Some(OutputFormat::VrmlGz));
        assert_eq!(f("a.vrml.gz"), Some(OutputFormat::VrmlGz));
        assert_eq!(f("a.wrz"), Some(OutputFormat::VrmlGz));
        assert_eq!(f("x/a.glb"), Some(OutputFormat::Glb));
        // A VRM avatar is a binary glTF.
        assert_eq!(f("x/a.VRM"), Some(OutputFormat::Glb));
        assert!(is_vrm_path(Path::new("x/a.VRM")) && !is_vrm_path(Path::new("a.glb")));
        assert_eq!(f("frames/"), Some(OutputFormat::Directory));
        assert_eq!(f("a.html"), Some(OutputFormat::Html));
        assert_eq!(f("A.HTM"), Some(OutputFormat::Html));
        assert_eq!(f("page"), None);
        assert_eq!(f("a.xyz"), None);
        assert_eq!(f(".glb"), None, "a bare extension is not a file name");
    }

    #[test]
    fn resolve_names_what_is_accepted() {
        let p = Path::new("out.xyz");
        let e = OutputFormat::resolve(
            p,
            &[OutputFormat::Fap, OutputFormat::Json],
            "`fap convert` output",
        )
        .unwrap_err()
        .to_string();
        assert_eq!(
            e,
            "out.xyz: `fap convert` output must be .fap, .json; found unknown extension `.xyz`"
        );
        let e = OutputFormat::resolve(Path::new("a.png"), OutputFormat::FACES, "a face")
            .unwrap_err()
            .to_string();
        assert!(e.contains("found .png"), "{e}");
        assert_eq!(
            OutputFormat::resolve(Path::new("a.wrl.gz"), OutputFormat::FACES, "a face").unwrap(),
            OutputFormat::VrmlGz
        );
    }

    #[test]
    fn writing_onto_an_input_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        let a = dir.path().join("a.fap");
        std::fs::write(&a, "x").unwrap();
        let b = dir.path().join("b.fap");
        assert!(refuse_overwriting_input(&b, &[&a]).is_ok());
        let via_dot = dir.path().join(".").join("a.fap");
        let e = refuse_overwriting_input(&via_dot, &[&a]).unwrap_err();
        assert!(e.to_string().contains("refusing to write over the input"));
        assert!(e.is_input_error());
    }
}
