//! Video outputs fed one rendered frame at a time: an H.264 MP4 through the `ffmpeg`
//! program, an animated GIF and a folder of PNG frames, behind the one [`FrameSink`] trait.
//!
//! Every sink streams: a frame is encoded (or piped to `ffmpeg`) as soon as it is pushed, so
//! memory does not grow with the number of frames. Every sink is atomic: it writes into a
//! temporary file or directory beside the output ([`crate::io::AtomicFile`],
//! [`crate::io::AtomicDir`]) and only [`FrameSink::finish`] moves it into place; a sink
//! dropped before that (an error mid-way) leaves nothing behind.
//!
//! ## MP4
//! Raw RGB frames go into `ffmpeg`'s standard input (`-f rawvideo -pix_fmt rgb24`) and are
//! encoded as H.264 in `yuv420p` (what browsers play), `-crf 20`, with `+faststart` so the
//! file plays while it downloads. Odd image sides are padded by one pixel (4:2:0 chroma
//! needs even sides). With an audio file it is encoded as AAC and **the video sets the
//! length**: the audio is padded with silence (`-af apad`) and cut where the video ends
//! (`-shortest`), so a soundtrack longer than the animation is cut and a shorter one ends
//! in silence (`-shortest` ends at the first packet boundary after the video's end, so
//! the container can be up to one AAC frame, 1024 samples, longer). Without `ffmpeg` on the
//! `PATH` the sink fails with [`Error::MissingTool`] naming the package to install. When
//! `ffmpeg` stops early, the next write gets a broken pipe, which becomes an error with
//! `ffmpeg`'s last message — if the process ignores SIGPIPE (Rust's default; `fbakit
//! render` keeps it so).
//!
//! ## GIF
//! Encoded with the `gif` crate, one locally quantised palette per frame, looping forever.
//! GIF delays are whole hundredths of a second, so each frame's delay is the rounded end
//! time minus the rounded start time: at 30 fps the delays go 3, 3, 4, … and the total
//! stays within 10 ms of `frames / fps`.
//!
//! ## PNG folder
//! `frame_00000.png`, `frame_00001.png`, … in a temporary sibling directory renamed into
//! place at the end. An existing output directory is replaced only when it is empty or
//! holds nothing but `frame_*.png` files (an earlier render); anything else is refused
//! before the first frame is rendered.

use std::io::{Read, Write};
use std::path::{Path, PathBuf};
use std::process::{Child, ChildStdin, Command, Stdio};
use std::thread::JoinHandle;

use serde::Serialize;

use super::ExportError;
use crate::error::{Error, Result};
use crate::format::OutputFormat;
use crate::io::{AtomicDir, AtomicFile};
use crate::render::Image;

/// The program the MP4 sink runs.
pub const FFMPEG: &str = "ffmpeg";
/// Largest number of bytes of `ffmpeg`'s error output kept for the error message.
const FFMPEG_STDERR_KEEP: usize = 4096;

/// A video container fed frame by frame.
pub trait FrameSink {
    /// Appends one frame. Every frame must have the size the sink was opened with.
    fn push(&mut self, frame: &Image) -> Result<()>;
    /// Completes the output and moves it into place.
    fn finish(self: Box<Self>) -> Result<VideoOutput>;
}

/// The kind of video output.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum VideoFormat {
    /// H.264 MP4 through `ffmpeg` (optionally with AAC audio).
    Mp4,
    /// Animated GIF.
    Gif,
    /// A directory of PNG frames.
    PngFolder,
}

impl VideoFormat {
    /// The format an output path asks for: `.mp4`, `.gif`, or a directory (an existing
    /// directory, a path ending in `/`, or a path without extension).
    pub fn from_path(path: &Path) -> Result<VideoFormat> {
        if path.extension().is_none() {
            return Ok(VideoFormat::PngFolder);
        }
        match OutputFormat::resolve(
            path,
            &[
                OutputFormat::Mp4,
                OutputFormat::Gif,
                OutputFormat::Directory,
            ],
            "a video",
        )? {
            OutputFormat::Mp4 => Ok(VideoFormat::Mp4),
            OutputFormat::Gif => Ok(VideoFormat::Gif),
            _ => Ok(VideoFormat::PngFolder),
        }
    }
}

/// Size, rate and soundtrack of a video.
#[derive(Clone, Debug, PartialEq)]
pub struct VideoSettings {
    /// Frame width in pixels.
    pub width: u32,
    /// Frame height in pixels.
    pub height: u32,
    /// Frames per second (finite, > 0).
    pub fps: f64,
    /// A sound file muxed into the MP4 (any format `ffmpeg` reads, e.g. WAV).
    pub audio: Option<PathBuf>,
}

/// What a finished sink wrote.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct VideoOutput {
    /// The output path.
    pub path: PathBuf,
    /// Its format.
    pub format: VideoFormat,
    /// Frames written.
    pub frames: usize,
    /// Bytes written (all files for a PNG folder).
    pub bytes: u64,
}

/// Opens the sink for `format` at `path`. Checks everything that can be checked before
/// rendering starts: the settings, the audio file (MP4 only; an error for the other
/// formats, which have no sound), the output directory, and that `ffmpeg` runs.
pub fn open_sink(
    path: &Path,
    format: VideoFormat,
    settings: &VideoSettings,
) -> Result<Box<dyn FrameSink>> {
    if !(settings.fps.is_finite() && settings.fps > 0.0) {
        return Err(ExportError::BadFrameRate { fps: settings.fps }.into());
    }
    if settings.width == 0 || settings.height == 0 {
        return Err(ExportError::ZeroSize.into());
    }
    if settings.audio.is_some() && format != VideoFormat::Mp4 {
        return Err(Error::Unsupported(
            "only .mp4 output carries audio; drop --audio or write an .mp4".into(),
        ));
    }
    Ok(match format {
        VideoFormat::Mp4 => Box::new(Mp4Sink::open(path, settings)?),
        VideoFormat::Gif => Box::new(GifSink::open(path, settings)?),
        VideoFormat::PngFolder => Box::new(PngFolderSink::open(path, settings)?),
    })
}

/// Refuses a frame whose size differs from the sink's.
fn check_size(frame: &Image, settings: &VideoSettings) -> Result<()> {
    if (frame.width, frame.height) != (settings.width, settings.height) {
        return Err(ExportError::FrameSize {
            width: frame.width,
            height: frame.height,
            video_width: settings.width,
            video_height: settings.height,
        }
        .into());
    }
    Ok(())
}

// ---------------------------------------------------------------------------------------------
// MP4 through ffmpeg
// ---------------------------------------------------------------------------------------------

/// Whether the `ffmpeg` program can be started.
pub fn ffmpeg_available() -> bool {
    Command::new(FFMPEG)
        .arg("-version")
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
        .is_ok_and(|s| s.success())
}

/// The message when `ffmpeg` is absent.
fn ffmpeg_missing() -> Error {
    Error::MissingTool(
        "ffmpeg is not installed: .mp4 output runs the ffmpeg program (Debian/Ubuntu: \
         apt-get install ffmpeg); .gif and PNG-frame folders work without it"
            .into(),
    )
}

/// The `ffmpeg` arguments that encode raw RGB frames of `settings` from standard input into
/// the MP4 file `out` (see the module docs).
pub fn ffmpeg_arguments(settings: &VideoSettings, out: &Path) -> Vec<std::ffi::OsString> {
    let audio = settings.audio.as_deref();
    let size = format!("{}x{}", settings.width, settings.height);
    let rate = format!("{}", settings.fps);
    let mut a: Vec<std::ffi::OsString> = Vec::new();
    let mut push = |items: &[&std::ffi::OsStr]| a.extend(items.iter().map(|s| s.to_os_string()));
    let s = |t: &'static str| std::ffi::OsStr::new(t);
    push(&[s("-hide_banner"), s("-loglevel"), s("error"), s("-y")]);
    push(&[s("-f"), s("rawvideo"), s("-pix_fmt"), s("rgb24")]);
    push(&[
        s("-video_size"),
        size.as_ref(),
        s("-framerate"),
        rate.as_ref(),
    ]);
    push(&[s("-i"), s("pipe:0")]);
    if let Some(audio) = audio {
        push(&[s("-i"), audio.as_os_str()]);
    }
    push(&[s("-map"), s("0:v:0")]);
    if audio.is_some() {
        push(&[s("-map"), s("1:a:0")]);
    }
    push(&[s("-vf"), s("pad=ceil(iw/2)*2:ceil(ih/2)*2")]);
    push(&[
        s("-c:v"),
        s("libx264"),
        s("-preset"),
        s("medium"),
        s("-crf"),
        s("20"),
    ]);
    push(&[s("-pix_fmt"), s("yuv420p"), s("-movflags"), s("+faststart")]);
    if audio.is_some() {
        push(&[s("-c:a"), s("aac"), s("-b:a"), s("128k")]);
        push(&[s("-af"), s("apad"), s("-shortest")]);
    }
    push(&[s("-f"), s("mp4"), out.as_os_str()]);
    a
}

/// H.264 MP4 written by an `ffmpeg` child process fed raw frames on its standard input.
pub struct Mp4Sink {
    settings: VideoSettings,
    out: Option<AtomicFile>,
    child: Option<Child>,
    stdin: Option<ChildStdin>,
    stderr: Option<JoinHandle<Vec<u8>>>,
    rgb: Vec<u8>,
    frames: usize,
}

impl Mp4Sink {
    /// Starts `ffmpeg` writing into a temporary file beside `path`.
    pub fn open(path: &Path, settings: &VideoSettings) -> Result<Mp4Sink> {
        if let Some(audio) = &settings.audio {
            // A missing or unreadable soundtrack is bad input, found before any rendering.
            std::fs::File::open(audio).map_err(|e| Error::io(audio, e))?;
            if audio.is_dir() {
                return Err(ExportError::AudioIsDirectory {
                    path: audio.clone(),
                }
                .into());
            }
        }
        let out = AtomicFile::create(path, ".mp4")?;
        let mut child = Command::new(FFMPEG)
            .args(ffmpeg_arguments(settings, out.temp_path()))
            .stdin(Stdio::piped())
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .map_err(|e| {
                if e.kind() == std::io::ErrorKind::NotFound {
                    ffmpeg_missing()
                } else {
                    Error::MissingTool(format!("cannot start {FFMPEG}: {e}"))
                }
            })?;
        let stdin = child.stdin.take();
        // Drained on a thread so a chatty ffmpeg never blocks on a full pipe while we write.
        let stderr = child.stderr.take().map(|mut s| {
            std::thread::spawn(move || {
                let mut kept = Vec::new();
                let mut buf = [0u8; 1024];
                while let Ok(n) = s.read(&mut buf) {
                    if n == 0 {
                        break;
                    }
                    kept.extend_from_slice(&buf[..n]);
                    if kept.len() > FFMPEG_STDERR_KEEP {
                        kept.drain(..kept.len() - FFMPEG_STDERR_KEEP);
                    }
                }
                kept
            })
        });
        Ok(Mp4Sink {
            settings: settings.clone(),
            out: Some(out),
            child: Some(child),
            stdin,
            stderr,
            rgb: Vec::with_capacity(settings.width as usize * settings.height as usize * 3),
            frames: 0,
        })
    }

    /// Waits for `ffmpeg` and turns a failure into an error with its last message line.
    fn wait(&mut self) -> Result<()> {
        self.stdin = None;
        let status = match self.child.take() {
            Some(mut c) => c.wait().map_err(|e| Error::io(FFMPEG, e))?,
            None => return Ok(()),
        };
        let stderr = self
            .stderr
            .take()
            .and_then(|h| h.join().ok())
            .unwrap_or_default();
        if status.success() {
            return Ok(());
        }
        let text = String::from_utf8_lossy(&stderr);
        let last = text
            .lines()
            .rev()
            .find(|l| !l.trim().is_empty())
            .unwrap_or("no message");
        // An operation failure (exit 1): ffmpeg's message says whether the input was bad.
        Err(Error::io(
            FFMPEG,
            std::io::Error::other(format!("failed ({status}): {}", last.trim())),
        ))
    }
}

impl FrameSink for Mp4Sink {
    fn push(&mut self, frame: &Image) -> Result<()> {
        check_size(frame, &self.settings)?;
        self.rgb.clear();
        for px in frame.rgba.chunks_exact(4) {
            self.rgb.extend_from_slice(&px[..3]);
        }
        let Some(stdin) = self.stdin.as_mut() else {
            return Err(ExportError::FfmpegNotRunning.into());
        };
        if let Err(e) = stdin.write_all(&self.rgb) {
            // A broken pipe means ffmpeg stopped; its own message says why.
            self.wait()?;
            return Err(Error::io(FFMPEG, e));
        }
        self.frames += 1;
        Ok(())
    }

    fn finish(mut self: Box<Self>) -> Result<VideoOutput> {
        if let Some(mut stdin) = self.stdin.take() {
            stdin.flush().map_err(|e| Error::io(FFMPEG, e))?;
        }
        self.wait()?;
        let out = self
            .out
            .take()
            .ok_or(ExportError::SinkFinished { sink: "MP4" })?;
        let path = out.path().to_path_buf();
        out.commit()?;
        let bytes = file_size(&path)?;
        Ok(VideoOutput {
            path,
            format: VideoFormat::Mp4,
            frames: self.frames,
            bytes,
        })
    }
}

impl Drop for Mp4Sink {
    /// An unfinished sink stops `ffmpeg`; the temporary file goes with `out`.
    fn drop(&mut self) {
        self.stdin = None;
        if let Some(mut c) = self.child.take() {
            let _ = c.kill();
            let _ = c.wait();
        }
    }
}

fn file_size(path: &Path) -> Result<u64> {
    Ok(std::fs::metadata(path)
        .map_err(|e| Error::io(path, e))?
        .len())
}

// ---------------------------------------------------------------------------------------------
// GIF
// ---------------------------------------------------------------------------------------------

/// Largest GIF side (the format stores sides as 16-bit numbers).
const GIF_MAX_SIDE: u32 = u16::MAX as u32;
/// NeuQuant sampling factor: 1 best, 30 fastest; 10 is the crate's recommended balance.
const GIF_QUANTISER_SPEED: i32 = 10;

/// Delay of frame `k` in hundredths of a second at `fps`: rounded end time minus rounded
/// start time, so the sum over frames tracks `frames / fps`.
pub fn gif_delay(k: usize, fps: f64) -> u16 {
    let at = |n: usize| (n as f64 * 100.0 / fps).round();
    (at(k + 1) - at(k)).clamp(1.0, f64::from(u16::MAX)) as u16
}

/// Animated GIF, encoded frame by frame into a temporary file.
pub struct GifSink {
    settings: VideoSettings,
    encoder: Option<gif::Encoder<std::io::BufWriter<std::fs::File>>>,
    out: Option<AtomicFile>,
    rgba: Vec<u8>,
    frames: usize,
}

impl GifSink {
    /// Creates the temporary file and writes the GIF header.
    pub fn open(path: &Path, settings: &VideoSettings) -> Result<GifSink> {
        if settings.width > GIF_MAX_SIDE || settings.height > GIF_MAX_SIDE {
            return Err(ExportError::GifTooLarge {
                limit: GIF_MAX_SIDE,
            }
            .into());
        }
        let mut out = AtomicFile::create(path, ".gif")?;
        let file = out.file().try_clone().map_err(|e| Error::output(path, e))?;
        let gif_err = |e: gif::EncodingError| Error::output(path, std::io::Error::other(e));
        let mut encoder = gif::Encoder::new(
            std::io::BufWriter::new(file),
            settings.width as u16,
            settings.height as u16,
            &[],
        )
        .map_err(gif_err)?;
        encoder.set_repeat(gif::Repeat::Infinite).map_err(gif_err)?;
        Ok(GifSink {
            settings: settings.clone(),
            encoder: Some(encoder),
            out: Some(out),
            rgba: Vec::new(),
            frames: 0,
        })
    }
}

impl FrameSink for GifSink {
    fn push(&mut self, frame: &Image) -> Result<()> {
        check_size(frame, &self.settings)?;
        let path = self.out.as_ref().map(|o| o.path().to_path_buf());
        let path = path.unwrap_or_default();
        let encoder = self
            .encoder
            .as_mut()
            .ok_or(ExportError::SinkFinished { sink: "GIF" })?;
        self.rgba.clear();
        self.rgba.extend_from_slice(&frame.rgba);
        let mut f = gif::Frame::from_rgba_speed(
            frame.width as u16,
            frame.height as u16,
            &mut self.rgba,
            GIF_QUANTISER_SPEED,
        );
        f.delay = gif_delay(self.frames, self.settings.fps);
        encoder
            .write_frame(&f)
            .map_err(|e| Error::output(&path, std::io::Error::other(e)))?;
        self.frames += 1;
        Ok(())
    }

    fn finish(mut self: Box<Self>) -> Result<VideoOutput> {
        let out = self
            .out
            .take()
            .ok_or(ExportError::SinkFinished { sink: "GIF" })?;
        let path = out.path().to_path_buf();
        if let Some(encoder) = self.encoder.take() {
            // `into_inner` writes the trailer; the buffered writer is then flushed.
            let mut w = encoder
                .into_inner()
                .map_err(|e| Error::output(&path, std::io::Error::other(e)))?;
            w.flush().map_err(|e| Error::output(&path, e))?;
        }
        out.commit()?;
        Ok(VideoOutput {
            bytes: file_size(&path)?,
            path,
            format: VideoFormat::Gif,
            frames: self.frames,
        })
    }
}

// ---------------------------------------------------------------------------------------------
// PNG folder
// ---------------------------------------------------------------------------------------------

/// The file name of frame `k` in a PNG folder.
pub fn png_frame_name(k: usize) -> String {
    format!("frame_{k:05}.png")
}

/// Whether `name` is a frame file an earlier render wrote.
fn is_frame_file(name: &str) -> bool {
    crate::io::is_numbered_file(name, "frame_", ".png")
}

/// One PNG per frame in a directory that appears whole at the end.
pub struct PngFolderSink {
    settings: VideoSettings,
    dir: Option<AtomicDir>,
    frames: usize,
    bytes: u64,
}

impl PngFolderSink {
    /// Checks the output path and creates the temporary sibling directory.
    pub fn open(path: &Path, settings: &VideoSettings) -> Result<PngFolderSink> {
        let dir = crate::io::open_frame_dir(path, is_frame_file)?;
        Ok(PngFolderSink {
            settings: settings.clone(),
            dir: Some(dir),
            frames: 0,
            bytes: 0,
        })
    }
}

impl FrameSink for PngFolderSink {
    fn push(&mut self, frame: &Image) -> Result<()> {
        check_size(frame, &self.settings)?;
        let dir = self
            .dir
            .as_ref()
            .ok_or(ExportError::SinkFinished { sink: "PNG" })?;
        let path = dir.temp_path().join(png_frame_name(self.frames));
        // Errors name the frame as it will be called, never the temporary directory.
        let named = || dir.path().join(png_frame_name(self.frames));
        let file = std::fs::File::create(&path).map_err(|e| Error::output(named(), e))?;
        let mut w = std::io::BufWriter::new(file);
        frame
            .encode_png(&mut w)
            .and_then(|()| w.flush())
            .map_err(|e| Error::output(named(), e))?;
        self.bytes += file_size(&path)?;
        self.frames += 1;
        Ok(())
    }

    fn finish(mut self: Box<Self>) -> Result<VideoOutput> {
        let dir = self
            .dir
            .take()
            .ok_or(ExportError::SinkFinished { sink: "PNG" })?;
        let path = dir.path().to_path_buf();
        dir.commit()?;
        Ok(VideoOutput {
            path,
            format: VideoFormat::PngFolder,
            frames: self.frames,
            bytes: self.bytes,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn settings(fps: f64) -> VideoSettings {
        VideoSettings {
            width: 16,
            height: 8,
            fps,
            audio: None,
        }
    }

    #[test]
    fn formats_from_paths() {
        let f = |p: &str| VideoFormat::from_path(Path::new(p));
        assert_eq!(f("a.mp4").unwrap(), VideoFormat::Mp4);
        assert_eq!(f("a.GIF").unwrap(), VideoFormat::Gif);
        assert_eq!(f("frames/").unwrap(), VideoFormat::PngFolder);
        assert_eq!(f("frames").unwrap(), VideoFormat::PngFolder);
        let e = f("a.avi").unwrap_err().to_string();
        assert!(e.contains("`.avi`"), "{e}");
    }

    #[test]
    fn gif_delays_track_the_frame_rate() {
        assert!((0..25).all(|k| gif_delay(k, 25.0) == 4));
        let total: u32 = (0..30).map(|k| u32::from(gif_delay(k, 30.0))).sum();
        assert_eq!(total, 100);
        let d: Vec<u16> = (0..3).map(|k| gif_delay(k, 30.0)).collect();
        assert_eq!(d, vec![3, 4, 3]);
        // Faster than 100 fps still shows every frame.
        assert_eq!(gif_delay(0, 500.0), 1);
    }

    #[test]
    fn frame_names() {
        assert_eq!(png_frame_name(7), "frame_00007.png");
        assert!(is_frame_file("frame_00007.png"));
        assert!(!is_frame_file("frame_.png"));
        assert!(!is_frame_file("notes.txt"));
    }

    #[test]
    fn ffmpeg_arguments_with_audio_pad_and_cut() {
        let mut s = settings(25.0);
        s.audio = Some(PathBuf::from("speech.wav"));
        let a: Vec<String> = ffmpeg_arguments(&s, Path::new("out.mp4"))
            .into_iter()
            .map(|a| a.to_string_lossy().into_owned())
            .collect();
        let text = a.join(" ");
        assert!(text.contains("-video_size 16x8 -framerate 25 -i pipe:0 -i speech.wav"));
        assert!(text.contains("-pix_fmt yuv420p"));
        assert!(text.contains("-c:a aac -b:a 128k -af apad -shortest"));
        assert!(text.ends_with("-f mp4 out.mp4"));
        let silent = ffmpeg_arguments(&settings(25.0), Path::new("o.mp4"));
        assert!(!silent.iter().any(|a| a == "-shortest"));
    }

    #[test]
    fn png_folder_appears_whole_and_refuses_foreign_directories() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("frames");
        let mut sink = open_sink(&out, VideoFormat::PngFolder, &settings(25.0)).unwrap();
        let img = Image::new(16, 8, [10, 20, 30, 255]);
        sink.push(&img).unwrap();
        sink.push(&img).unwrap();
        assert!(!out.exists(), "nothing in place before finish");
        assert!(sink.push(&Image::new(8, 8, [0; 4])).is_err());
        let done = sink.finish().unwrap();
        assert_eq!(done.frames, 2);
        let mut names: Vec<String> = std::fs::read_dir(&out)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        names.sort();
        assert_eq!(names, vec!["frame_00000.png", "frame_00001.png"]);
        // A second render replaces the frames of the first.
        let mut sink = open_sink(&out, VideoFormat::PngFolder, &settings(25.0)).unwrap();
        sink.push(&img).unwrap();
        sink.finish().unwrap();
        assert_eq!(std::fs::read_dir(&out).unwrap().count(), 1);
        // A directory with other files is refused.
        std::fs::write(out.join("notes.txt"), "mine").unwrap();
        assert!(open_sink(&out, VideoFormat::PngFolder, &settings(25.0)).is_err());
        // Only the output directory is left beside it: no temporary leftovers.
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }

    #[test]
    fn dropped_sinks_leave_nothing() {
        let dir = tempfile::tempdir().unwrap();
        let img = Image::new(16, 8, [200, 20, 30, 255]);
        for name in ["a.gif", "frames"] {
            let out = dir.path().join(name);
            let format = VideoFormat::from_path(&out).unwrap();
            let mut sink = open_sink(&out, format, &settings(25.0)).unwrap();
            sink.push(&img).unwrap();
            drop(sink);
            assert!(!out.exists(), "{name}");
        }
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
    }

    #[test]
    fn audio_only_goes_into_mp4() {
        let mut s = settings(25.0);
        s.audio = Some(PathBuf::from("x.wav"));
        let e = open_sink(Path::new("x.gif"), VideoFormat::Gif, &s)
            .err()
            .unwrap();
        assert!(e.to_string().contains("--audio"), "{e}");
        assert!(open_sink(Path::new("x.gif"), VideoFormat::Gif, &settings(0.0)).is_err());
    }
}
