//! File input and output with the guarantees every command relies on: inputs are read with a
//! size bound (a hostile file cannot make us allocate without limit) and outputs are written
//! atomically (a temporary file in the same directory, renamed into place), so a failed run
//! never leaves a half-written file behind.

use std::io::{Read, Write};

use flate2::read::MultiGzDecoder;
use flate2::write::GzEncoder;
use flate2::Compression;
use std::path::{Path, PathBuf};

use crate::error::{Error, Result};

/// Largest input file read by default: 1 GiB. Readers take text in memory; this keeps one
/// hostile file from exhausting the machine.
pub const DEFAULT_MAX_INPUT_BYTES: u64 = 1 << 30;

/// Reads a whole file, refusing files larger than `max_bytes`.
///
/// The size is checked from the file's metadata before anything is read, so refusing a huge
/// (or sparse) file costs nothing; the read itself is still bounded, for files that grow or
/// report no size (pipes, `/proc`).
pub fn read_bounded(path: &Path, max_bytes: u64) -> Result<Vec<u8>> {
    let file = std::fs::File::open(path).map_err(|e| Error::io(path, e))?;
    let meta = file.metadata().map_err(|e| Error::io(path, e))?;
    if meta.is_dir() {
        return Err(Error::io(
            path,
            std::io::Error::new(
                std::io::ErrorKind::IsADirectory,
                "is a directory, not a file",
            ),
        ));
    }
    if meta.is_file() && meta.len() > max_bytes {
        return Err(too_large(path, Some(meta.len()), max_bytes));
    }
    // Never reserve more than the file claims: a hostile size cannot cost memory up front.
    let mut buf = Vec::with_capacity(meta.len().min(max_bytes) as usize);
    // Read one byte past the limit to detect an oversized file without trusting metadata.
    file.take(max_bytes.saturating_add(1))
        .read_to_end(&mut buf)
        .map_err(|e| Error::io(path, e))?;
    if buf.len() as u64 > max_bytes {
        return Err(too_large(path, None, max_bytes));
    }
    Ok(buf)
}

/// Like [`read_bounded`], for text formats: refuses the file at its first NUL byte (no text
/// format fbakit reads has one), so a file of a billion zeros costs one 64 KiB chunk, not a
/// billion bytes of memory and half a minute. Gzip data (magic `1F 8B`) is read whole, for
/// readers that decompress it.
pub fn read_bounded_text(path: &Path, max_bytes: u64) -> Result<Vec<u8>> {
    let file = std::fs::File::open(path).map_err(|e| Error::io(path, e))?;
    let meta = file.metadata().map_err(|e| Error::io(path, e))?;
    if meta.is_dir() {
        return read_bounded(path, max_bytes);
    }
    if meta.is_file() && meta.len() > max_bytes {
        return Err(too_large(path, Some(meta.len()), max_bytes));
    }
    let mut buf = Vec::new();
    let mut chunk = vec![0u8; 1 << 16];
    let mut is_gzip = None;
    let mut reader = file.take(max_bytes.saturating_add(1));
    loop {
        let n = match reader.read(&mut chunk) {
            Ok(0) => break,
            Ok(n) => n,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
            Err(e) => return Err(Error::io(path, e)),
        };
        // Decided by the first read (a whole 64 KiB chunk from a file).
        let gzip = *is_gzip.get_or_insert_with(|| chunk[..n].starts_with(&[0x1F, 0x8B]));
        if !gzip {
            if let Some(i) = chunk[..n].iter().position(|&b| b == 0) {
                let at = buf.len() + i;
                buf.extend_from_slice(&chunk[..i]);
                let valid = match std::str::from_utf8(&buf) {
                    Ok(t) => t,
                    Err(e) => std::str::from_utf8(&buf[..e.valid_up_to()]).unwrap_or_default(),
                };
                return Err(Error::Parse(crate::error::ParseError {
                    location: crate::error::Location::from_offset(path, valid, at),
                    expected: "text".to_string(),
                    found: Some("a NUL byte (binary data, not text)".to_string()),
                }));
            }
        }
        buf.extend_from_slice(&chunk[..n]);
        if buf.len() as u64 > max_bytes {
            return Err(too_large(path, None, max_bytes));
        }
    }
    Ok(buf)
}

fn too_large(path: &Path, size: Option<u64>, max_bytes: u64) -> Error {
    let what = match size {
        Some(n) => format!("the file has {n} bytes, more than the {max_bytes}-byte input limit"),
        None => format!("file is larger than the {max_bytes}-byte input limit"),
    };
    Error::io(
        path,
        std::io::Error::new(std::io::ErrorKind::FileTooLarge, what),
    )
}

/// Reads a whole UTF-8 text file (bounded by [`DEFAULT_MAX_INPUT_BYTES`]).
///
/// Invalid UTF-8 is an error that names the byte offset of the first bad sequence.
pub fn read_text(path: &Path) -> Result<String> {
    let bytes = read_bounded_text(path, DEFAULT_MAX_INPUT_BYTES)?;
    text_from_bytes(bytes, path)
}

/// Reads all of `reader` as UTF-8 text, refusing more than `max_bytes` (like
/// [`read_bounded`]); `source` names the input in errors. The `read_*_from` readers of every
/// format use it with [`DEFAULT_MAX_INPUT_BYTES`].
pub fn read_text_from<R: std::io::BufRead>(
    reader: R,
    source: &Path,
    max_bytes: u64,
) -> Result<String> {
    let mut bytes = Vec::new();
    // One byte past the limit tells an oversized input from one exactly at it.
    reader
        .take(max_bytes.saturating_add(1))
        .read_to_end(&mut bytes)
        .map_err(|e| Error::io(source, e))?;
    if bytes.len() as u64 > max_bytes {
        return Err(too_large(source, None, max_bytes));
    }
    text_from_bytes(bytes, source)
}

/// `bytes` as UTF-8 text; gzip data and invalid UTF-8 are located errors in `path`.
fn text_from_bytes(bytes: Vec<u8>, path: &Path) -> Result<String> {
    // A compressed file where text was expected deserves a hint, not a byte value.
    if bytes.starts_with(&[0x1F, 0x8B]) {
        return Err(Error::Parse(crate::error::ParseError {
            location: crate::error::Location::from_offset(path, "", 0),
            expected: "UTF-8 text".to_string(),
            found: Some("gzip-compressed data (decompress it first, e.g. `gunzip -k`)".to_string()),
        }));
    }
    String::from_utf8(bytes).map_err(|e| {
        let at = e.utf8_error().valid_up_to();
        let valid = std::str::from_utf8(&e.as_bytes()[..at]).unwrap_or_default();
        Error::Parse(crate::error::ParseError {
            location: crate::error::Location::from_offset(path, valid, at),
            expected: "UTF-8 text".to_string(),
            found: Some(format!("byte 0x{:02X}", e.as_bytes()[at])),
        })
    })
}

/// Writes `bytes` to `path` atomically: into a temporary file beside it, flushed, then renamed.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    write_atomic_with(path, |w| w.write_all(bytes))
}

/// Writes to `path` atomically through a writer callback; if the callback fails, the target
/// is left untouched and the temporary file is removed.
pub fn write_atomic_with(
    path: &Path,
    fill: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> Result<()> {
    let mut out = AtomicFile::create(path, ".tmp")?;
    {
        let mut w = std::io::BufWriter::new(out.file());
        fill(&mut w).map_err(|e| Error::output(path, e))?;
        w.flush().map_err(|e| Error::output(path, e))?;
    }
    out.commit()
}

/// The OS error alone: `tempfile` appends the temporary file's name, which means nothing to
/// the user (errors name the output they asked for).
fn without_temp_path(e: std::io::Error) -> std::io::Error {
    match e.raw_os_error() {
        Some(code) => std::io::Error::from_raw_os_error(code),
        None => std::io::Error::from(e.kind()),
    }
}

/// The directory a new output at `path` is created in (`.` for a bare file name).
fn parent_dir(path: &Path) -> &Path {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    }
}

/// An output file written over time (a video fed frame by frame, or by another program):
/// a temporary file beside `path` that [`AtomicFile::commit`] renames into place. Dropped
/// without a commit (an error, a panic), the temporary file is removed and `path` is left
/// as it was.
#[derive(Debug)]
pub struct AtomicFile {
    tmp: tempfile::NamedTempFile,
    path: PathBuf,
}

impl AtomicFile {
    /// Creates the temporary file beside `path`; its name ends in `suffix` (programs such as
    /// `ffmpeg` pick a container from the extension).
    pub fn create(path: &Path, suffix: &str) -> Result<AtomicFile> {
        let dir = parent_dir(path);
        let tmp = tempfile::Builder::new()
            .prefix(".fbakit-")
            .suffix(suffix)
            .tempfile_in(dir)
            .map_err(|e| Error::output(path, without_temp_path(e)))?;
        Ok(AtomicFile {
            tmp,
            path: path.to_path_buf(),
        })
    }

    /// Where the content is being written (hand this to a program that writes the file).
    pub fn temp_path(&self) -> &Path {
        self.tmp.path()
    }

    /// The final path.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The open temporary file.
    pub fn file(&mut self) -> &mut std::fs::File {
        self.tmp.as_file_mut()
    }

    /// Flushes the content to disk, gives it the permissions of a plain new file and renames
    /// it to the final path.
    pub fn commit(self) -> Result<()> {
        let AtomicFile { tmp, path } = self;
        tmp.as_file()
            .sync_all()
            .map_err(|e| Error::output(&path, e))?;
        set_default_permissions(tmp.as_file()).map_err(|e| Error::output(&path, e))?;
        tmp.persist(&path)
            .map_err(|e| Error::output(&path, without_temp_path(e.error)))?;
        Ok(())
    }
}

/// An output directory filled over time (one file per frame): a temporary directory beside
/// `path` that [`AtomicDir::commit`] renames into place, replacing an existing directory
/// there. Dropped without a commit, the temporary directory and its files are removed.
#[derive(Debug)]
pub struct AtomicDir {
    tmp: tempfile::TempDir,
    path: PathBuf,
}

impl AtomicDir {
    /// Creates the temporary directory beside `path` (the parent must exist).
    pub fn create(path: &Path) -> Result<AtomicDir> {
        let dir = parent_dir(path);
        let tmp = tempfile::Builder::new()
            .prefix(".fbakit-")
            .suffix(".tmp")
            .tempdir_in(dir)
            .map_err(|e| Error::output(path, without_temp_path(e)))?;
        Ok(AtomicDir {
            tmp,
            path: path.to_path_buf(),
        })
    }

    /// Where the files are being written.
    pub fn temp_path(&self) -> &Path {
        self.tmp.path()
    }

    /// The final path.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Writes the file `name` in the folder with `write` (given its temporary path); an error
    /// names the file at its final place, never the temporary folder.
    pub fn write_file(&self, name: &str, write: impl FnOnce(&Path) -> Result<()>) -> Result<()> {
        write(&self.tmp.path().join(name)).map_err(|e| {
            let path = self.path.join(name);
            match e {
                Error::Output { source, .. } => Error::output(path, source),
                Error::Io { source, .. } => Error::output(path, source),
                other => other,
            }
        })
    }

    /// Renames the directory into place. An existing directory at the final path is first
    /// moved aside and removed only after the rename succeeded.
    pub fn commit(self) -> Result<()> {
        let AtomicDir { tmp, path } = self;
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            // Temporary directories are private (0700); a plain new directory is 0777 less
            // the umask, which for the common 022 is 0755.
            let _ = std::fs::set_permissions(tmp.path(), std::fs::Permissions::from_mode(0o755));
        }
        let old = if path.exists() {
            let aside = tempfile::Builder::new()
                .prefix(".fbakit-old-")
                .tempdir_in(parent_dir(&path))
                .map_err(|e| Error::output(&path, without_temp_path(e)))?;
            let aside_path = aside.path().join("old");
            std::fs::rename(&path, &aside_path)
                .map_err(|e| Error::output(&path, without_temp_path(e)))?;
            Some((aside, aside_path))
        } else {
            None
        };
        let kept = tmp.keep();
        if let Err(e) = std::fs::rename(&kept, &path) {
            // Put the old directory back; the new one is dropped.
            if let Some((_, aside_path)) = &old {
                let _ = std::fs::rename(aside_path, &path);
            }
            let _ = std::fs::remove_dir_all(&kept);
            return Err(Error::output(&path, e));
        }
        // `old`'s TempDir removes the previous content when dropped here.
        drop(old);
        Ok(())
    }
}

/// Opens a folder of frame files for writing as an [`AtomicDir`]: `path` may be new (its
/// missing parents are created) or an existing directory that holds only files `is_ours`
/// recognises (frames of an earlier run, which the commit replaces). Anything else in it is
/// refused, so a mistyped `-o ~/` can never replace a directory of other files.
pub fn open_frame_dir(path: &Path, is_ours: impl Fn(&str) -> bool) -> Result<AtomicDir> {
    if path.exists() {
        if !path.is_dir() {
            return Err(crate::format::OutputPathError::NotADirectory {
                path: path.to_path_buf(),
            }
            .into());
        }
        let entries = std::fs::read_dir(path).map_err(|e| Error::output(path, e))?;
        for entry in entries {
            let entry = entry.map_err(|e| Error::output(path, e))?;
            let name = entry.file_name();
            let name = name.to_string_lossy();
            let is_file = entry.file_type().is_ok_and(|t| t.is_file());
            if !(is_file && is_ours(&name)) {
                return Err(crate::format::OutputPathError::ForeignEntry {
                    path: path.to_path_buf(),
                    entry: name.into_owned(),
                }
                .into());
            }
        }
    }
    // A trailing slash names the same directory; the temporary sibling needs its parent.
    let clean: PathBuf = path.components().collect();
    let parent = parent_dir(&clean);
    if parent.exists() && !parent.is_dir() {
        // `create_dir_all` would say "File exists", which reads as the wrong problem.
        return Err(Error::output(
            path,
            std::io::Error::new(
                std::io::ErrorKind::NotADirectory,
                format!("{} is not a directory", parent.display()),
            ),
        ));
    }
    std::fs::create_dir_all(parent).map_err(|e| Error::output(path, e))?;
    AtomicDir::create(&clean)
}

/// Whether `name` is `PREFIX` + digits + `SUFFIX` (frame files such as `frame_00012.png`).
pub fn is_numbered_file(name: &str, prefix: &str, suffix: &str) -> bool {
    name.strip_prefix(prefix)
        .and_then(|r| r.strip_suffix(suffix))
        .is_some_and(|d| !d.is_empty() && d.bytes().all(|b| b.is_ascii_digit()))
}

/// Temporary files are created private (0600); an output should get the permissions a plain
/// `File::create` would give it: 0666 less the process umask. The mask is read from
/// `/proc/self/status` (setting it to read it would race with other threads); where that is
/// unavailable the common default 022 is assumed.
#[cfg(unix)]
fn set_default_permissions(file: &std::fs::File) -> std::io::Result<()> {
    use std::os::unix::fs::PermissionsExt;
    let mask = std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines()
                .find_map(|l| l.strip_prefix("Umask:"))
                .and_then(|v| u32::from_str_radix(v.trim(), 8).ok())
        })
        .unwrap_or(0o022);
    file.set_permissions(std::fs::Permissions::from_mode(0o666 & !mask))
}

#[cfg(not(unix))]
fn set_default_permissions(_file: &std::fs::File) -> std::io::Result<()> {
    Ok(())
}

/// Largest ratio of decompressed to compressed size accepted once the output passes
/// [`GZIP_RATIO_FLOOR`] bytes. Text faces compress 3 to 10 times; a gzip bomb (zeros)
/// about 1000 times, so a bomb is refused after a few MB instead of at the full limit.
pub const MAX_GZIP_RATIO: u64 = 64;

/// Output size below which the [`MAX_GZIP_RATIO`] is not applied (small, very regular files
/// are legitimate).
pub const GZIP_RATIO_FLOOR: u64 = 8 << 20;

/// Decompresses gzip data, refusing output larger than `max_bytes` or larger than
/// [`MAX_GZIP_RATIO`] times the compressed size (beyond [`GZIP_RATIO_FLOOR`]).
///
/// The output is decompressed in a stream and grows as it arrives: a refused input costs at
/// most the bytes decompressed before the limit, never the limit allocated up front.
pub fn gunzip_bounded(data: &[u8], max_bytes: u64) -> std::io::Result<Vec<u8>> {
    let by_ratio = (data.len() as u64)
        .saturating_mul(MAX_GZIP_RATIO)
        .max(GZIP_RATIO_FLOOR);
    let limit = max_bytes.min(by_ratio);
    let mut out = Vec::new();
    MultiGzDecoder::new(data)
        .take(limit.saturating_add(1))
        .read_to_end(&mut out)
        .map_err(|e| std::io::Error::new(std::io::ErrorKind::InvalidData, e))?;
    if out.len() as u64 > limit {
        let why = if limit < max_bytes {
            format!(
                "decompresses to more than {MAX_GZIP_RATIO} times its compressed size \
                 ({limit} bytes; a gzip bomb?)"
            )
        } else {
            format!("decompresses to more than the {max_bytes}-byte input limit")
        };
        return Err(std::io::Error::new(std::io::ErrorKind::FileTooLarge, why));
    }
    Ok(out)
}

/// Gzip-compresses `data` (best level, zero timestamp: equal input gives equal bytes).
pub fn gzip(data: &[u8], w: &mut dyn Write) -> std::io::Result<()> {
    let mut enc = GzEncoder::new(w, Compression::best());
    enc.write_all(data)?;
    enc.finish()?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn read_text_from_is_bounded_and_located() {
        let src = Path::new("pipe.fap");
        assert_eq!(read_text_from(&b"abc"[..], src, 3).unwrap(), "abc");
        let e = read_text_from(&b"abcd"[..], src, 3).unwrap_err();
        assert!(
            matches!(&e, Error::Io { source, .. } if source.kind() == std::io::ErrorKind::FileTooLarge)
        );
        assert!(e.to_string().starts_with("pipe.fap: "), "{e}");
        let e = read_text_from(&b"ok\n\xff"[..], src, 100).unwrap_err();
        assert!(
            e.to_string()
                .starts_with("pipe.fap:2:1: expected UTF-8 text"),
            "{e}"
        );
    }

    #[test]
    fn atomic_write_replaces_and_failed_write_leaves_nothing() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("out.txt");
        write_atomic(&p, b"first").unwrap();
        assert_eq!(std::fs::read(&p).unwrap(), b"first");
        let err = write_atomic_with(&p, |w| {
            w.write_all(b"partial")?;
            Err(std::io::Error::other("boom"))
        });
        assert!(err.is_err());
        assert_eq!(std::fs::read(&p).unwrap(), b"first", "target untouched");
        let leftovers: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
        assert_eq!(leftovers.len(), 1, "temporary file removed");
    }

    #[cfg(unix)]
    #[test]
    fn outputs_are_readable_like_plain_files() {
        use std::os::unix::fs::PermissionsExt;
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("out.txt");
        write_atomic(&p, b"x").unwrap();
        let mode = std::fs::metadata(&p).unwrap().permissions().mode() & 0o777;
        let plain = dir.path().join("plain.txt");
        std::fs::write(&plain, b"x").unwrap();
        let expected = std::fs::metadata(&plain).unwrap().permissions().mode() & 0o777;
        assert_eq!(
            mode, expected,
            "atomic output {mode:o} vs plain file {expected:o}"
        );
    }

    #[test]
    fn atomic_file_appears_on_commit_only() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("v.mp4");
        let mut f = AtomicFile::create(&p, ".mp4").unwrap();
        assert!(f.temp_path().to_string_lossy().ends_with(".mp4"));
        f.file().write_all(b"data").unwrap();
        assert!(!p.exists());
        f.commit().unwrap();
        assert_eq!(std::fs::read(&p).unwrap(), b"data");
        let dropped = AtomicFile::create(&dir.path().join("w.mp4"), ".mp4").unwrap();
        drop(dropped);
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }

    #[test]
    fn atomic_dir_replaces_the_old_directory_whole() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("frames");
        std::fs::create_dir(&p).unwrap();
        std::fs::write(p.join("old.png"), b"old").unwrap();
        let d = AtomicDir::create(&p).unwrap();
        std::fs::write(d.temp_path().join("new.png"), b"new").unwrap();
        assert!(p.join("old.png").exists(), "old content until commit");
        d.commit().unwrap();
        assert!(!p.join("old.png").exists());
        assert_eq!(std::fs::read(p.join("new.png")).unwrap(), b"new");
        let dropped = AtomicDir::create(&dir.path().join("other")).unwrap();
        drop(dropped);
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }

    #[test]
    fn bounded_read_refuses_large_files() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("big");
        std::fs::write(&p, vec![b'x'; 100]).unwrap();
        assert!(read_bounded(&p, 100).is_ok());
        let e = read_bounded(&p, 99).unwrap_err();
        assert!(e.to_string().contains("input limit"), "{e}");
        assert!(e.is_input_error());
    }

    #[test]
    fn text_reads_stop_at_the_first_nul() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("zeros.fap");
        // 1e9 zeros as a sparse file: refused from the first chunk, not read whole.
        std::fs::File::create(&p)
            .unwrap()
            .set_len(1_000_000_000)
            .unwrap();
        let t = std::time::Instant::now();
        let e = read_text(&p).unwrap_err();
        assert!(t.elapsed().as_millis() < 500, "{:?}", t.elapsed());
        let m = e.to_string();
        assert!(
            m.contains("zeros.fap:1:1: expected text") && m.contains("NUL"),
            "{m}"
        );
        assert!(e.is_input_error());
        let p = dir.path().join("late.wrl");
        std::fs::write(&p, b"#VRML V2.0 utf8\nGroup {\0}").unwrap();
        let m = read_text(&p).unwrap_err().to_string();
        assert!(m.contains("late.wrl:2:8"), "{m}");
        // Gzip data may hold zeros: it is read whole (its reader decompresses it).
        let mut z = Vec::new();
        gzip(&[0u8; 100], &mut z).unwrap();
        std::fs::write(&p, &z).unwrap();
        assert_eq!(read_bounded_text(&p, 1 << 20).unwrap(), z);
    }

    #[test]
    fn non_utf8_is_a_located_error() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("bad.fap");
        std::fs::write(&p, b"2.1 x\n\xff\xfe").unwrap();
        let e = read_text(&p).unwrap_err().to_string();
        assert!(
            e.contains("bad.fap:2:1: expected UTF-8 text, found `byte 0xFF`"),
            "{e}"
        );
    }

    #[test]
    fn gzip_round_trip_and_bomb_refused() {
        let mut z = Vec::new();
        gzip(b"hello hello hello", &mut z).unwrap();
        assert_eq!(gunzip_bounded(&z, 100).unwrap(), b"hello hello hello");
        // Deterministic output.
        let mut z2 = Vec::new();
        gzip(b"hello hello hello", &mut z2).unwrap();
        assert_eq!(z, z2);
        // 1 MB of zeros compresses to ~1 kB; a 64 kB limit refuses it.
        let mut bomb = Vec::new();
        gzip(&vec![0u8; 1 << 20], &mut bomb).unwrap();
        assert!(bomb.len() < 4096);
        let e = gunzip_bounded(&bomb, 1 << 16).unwrap_err();
        assert_eq!(e.kind(), std::io::ErrorKind::FileTooLarge);
        // Garbage is an error, not a panic.
        assert!(gunzip_bounded(b"\x1f\x8b\x08garbage", 100).is_err());
        assert!(gunzip_bounded(&bomb[..bomb.len() / 2], 1 << 30).is_err());
        // A bomb under the size limit is still refused by its ratio, early.
        let mut big = Vec::new();
        gzip(&vec![0u8; 40 << 20], &mut big).unwrap();
        let e = gunzip_bounded(&big, 1 << 30).unwrap_err();
        assert!(e.to_string().contains("gzip bomb"), "{e}");
    }

    #[test]
    fn size_is_checked_before_reading() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("sparse.wrl");
        std::fs::File::create(&p).unwrap().set_len(1 << 31).unwrap();
        let t = std::time::Instant::now();
        let e = read_bounded(&p, DEFAULT_MAX_INPUT_BYTES).unwrap_err();
        assert!(t.elapsed().as_millis() < 500, "refused without reading");
        let m = e.to_string();
        assert!(
            m.contains("sparse.wrl") && m.contains("2147483648") && m.contains("1073741824"),
            "{m}"
        );
        assert!(e.is_input_error());
        let e = read_bounded(dir.path(), 100).unwrap_err();
        assert!(e.is_input_error(), "{e}");
    }
}
