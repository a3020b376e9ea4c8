//! `fbakit render FACE STREAM -o out.mp4|out.gif|frames/`: a video of a FAP stream played on
//! a face, optionally with a soundtrack.

use std::path::PathBuf;

use clap::Args;
use fbakit::error::{Error, Result, ResultExt};
use fbakit::export::movie::{movie_fps, render_movie, MovieOptions};
use fbakit::export::video::{open_sink, VideoFormat, VideoSettings};

use fbakit::face::FaceModel;
use fbakit::fap::FapStream;
use serde::Serialize;

use super::play::{parse_size, progress};
use super::{parse_fps, print_json, EXIT_OK};

/// Arguments of `render`.
#[derive(Debug, Args)]
pub struct RenderArgs {
    /// Face: a face file or rig, or a bundled face (`alma`, `bruno`, `ict`).
    pub face: PathBuf,
    /// Feature points of the face (an OBJ needs them; with them a rig's shapes become its
    /// FAT).
    #[arg(long, value_name = "FILE")]
    pub fp: Option<PathBuf>,
    /// FAP stream (`.fap` or `.json`).
    pub stream: PathBuf,
    /// Output: `.mp4` (needs the ffmpeg program), `.gif`, or a directory for one PNG per
    /// frame.
    #[arg(short, long, value_name = "OUT")]
    pub output: PathBuf,
    /// Frame size in pixels, `WxH`.
    #[arg(long, value_name = "WxH", default_value = "512x512", value_parser = parse_size)]
    pub size: (u32, u32),
    /// Video frame rate (the stream is resampled); default: the stream's.
    #[arg(long, value_name = "N", allow_negative_numbers = true, value_parser = parse_fps)]
    pub fps: Option<f64>,
    /// Sound file muxed into the mp4 (e.g. the WAV from `fbakit speak`). The video sets the
    /// length: longer audio is cut, shorter audio ends in silence.
    #[arg(long, value_name = "FILE")]
    pub audio: Option<PathBuf>,
    /// Read the stream strictly.
    #[arg(long)]
    pub strict: bool,
    /// Print the report as JSON.
    #[arg(long)]
    pub json: bool,
}

/// What a rendered video holds.
#[derive(Debug, Serialize)]
pub struct RenderReport {
    face: String,
    stream: String,
    output: String,
    format: VideoFormat,
    frames: usize,
    fps: f64,
    duration_seconds: f64,
    width: u32,
    height: u32,
    audio: Option<String>,
    bytes: u64,
    framed_on_feature_points: bool,
    missing_tables: Vec<(String, usize)>,
    warnings: Vec<fbakit::error::Diagnostic>,
}

/// `main` restores the default SIGPIPE action (die) for `fbakit ... | head`; `render` feeds
/// frames into ffmpeg through a pipe, and when ffmpeg stops early that write must fail with
/// an error we can report (and clean up after), not kill the process.
fn ignore_sigpipe() {
    #[cfg(unix)]
    // SAFETY: SIG_IGN is a valid disposition; no handler code runs.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_IGN);
    }
}

/// Runs `render`.
pub fn run(a: RenderArgs) -> Result<u8> {
    let format = VideoFormat::from_path(&a.output)?;
    if a.audio.is_some() && format != VideoFormat::Mp4 {
        return Err(Error::Unsupported(
            "--audio needs an .mp4 output (GIF and PNG frames have no sound)".into(),
        ));
    }
    let mut inputs: Vec<&std::path::Path> = vec![&a.face, &a.stream];
    inputs.extend(a.fp.as_deref());
    inputs.extend(a.audio.as_deref());
    fbakit::format::refuse_overwriting_input(&a.output, &inputs)?;
    let face = super::inputs::read_face(&a.face, a.fp.as_deref())?;
    let (stream, warnings) = super::inputs::read_stream(&a.stream, a.strict)?;
    let job = VideoJob {
        output: &a.output,
        format,
        size: a.size,
        fps: a.fps,
        audio: a.audio.as_deref(),
    };
    let out = write_video(
        &face,
        &stream,
        &a.stream.display().to_string(),
        &job,
        warnings,
    )?;
    if a.json {
        print_json(&out)?;
    } else {
        print_report(&out);
    }
    Ok(EXIT_OK)
}

/// What to render and where (shared by `render` and `speak`).
pub struct VideoJob<'a> {
    /// The output path.
    pub output: &'a std::path::Path,
    /// Its format.
    pub format: VideoFormat,
    /// Frame size.
    pub size: (u32, u32),
    /// Frame rate; default the stream's.
    pub fps: Option<f64>,
    /// Sound muxed into an mp4.
    pub audio: Option<&'a std::path::Path>,
}

/// Plays `stream` on `face` into the video `job` describes, with a progress bar on a
/// terminal.
pub fn write_video(
    face: &FaceModel,
    stream: &FapStream,
    stream_name: &str,
    job: &VideoJob<'_>,
    warnings: Vec<fbakit::error::Diagnostic>,
) -> Result<RenderReport> {
    ignore_sigpipe();
    // Refuse an absurd span (a stream numbered up to frame 9 999 999) before any output.
    let span = fbakit::player::Player::new(
        face,
        stream,
        &fbakit::player::PlayOptions {
            fps: job.fps,
            frames: None,
        },
    )
    .with_context(|| format!("playing stream {stream_name}"))?
    .frame_range();
    let image = fbakit::export::budget::image_bytes_per_frame(job.size.0, job.size.1);
    let per_frame = match job.format {
        // H.264 keeps a talking face far under a byte a pixel.
        VideoFormat::Mp4 => image / 16,
        _ => image,
    };
    fbakit::export::budget::check(job.output, &span, per_frame).map_err(|mut e| {
        if let Error::Export(fbakit::export::ExportError::OverBudget { advice, .. }) = &mut e {
            *advice = "; render fewer with a lower --fps or a shorter stream \
                       (`fbakit play --frames` cuts one)"
                .into();
        }
        e
    })?;
    let settings = VideoSettings {
        width: job.size.0,
        height: job.size.1,
        fps: movie_fps(stream, job.fps),
        audio: job.audio.map(std::path::Path::to_path_buf),
    };
    let mut sink = open_sink(job.output, job.format, &settings)?;
    let movie = MovieOptions {
        width: job.size.0,
        height: job.size.1,
        fps: job.fps,
    };
    let bar = progress(0, "rendering");
    let report = render_movie(face, stream, &movie, sink.as_mut(), &mut |n, total| {
        bar.set_length(total as u64);
        bar.set_position(n as u64);
    });
    let report = match report {
        Ok(r) => r,
        Err(e) => {
            bar.finish_and_clear();
            return Err(e);
        }
    };
    let written = sink.finish()?;
    bar.finish_and_clear();
    Ok(RenderReport {
        face: face.name.clone(),
        stream: stream_name.to_string(),
        output: written.path.display().to_string(),
        format: job.format,
        frames: report.frames,
        fps: report.fps,
        duration_seconds: report.duration_seconds,
        width: job.size.0,
        height: job.size.1,
        audio: job.audio.map(|p| p.display().to_string()),
        bytes: written.bytes,
        framed_on_feature_points: report.framed_on_feature_points,
        missing_tables: report.missing_tables,
        warnings,
    })
}

/// The text report of a written video, warnings on stderr.
pub fn print_report(out: &RenderReport) {
    super::print_warnings(&out.warnings);
    let what = match out.format {
        VideoFormat::Mp4 if out.audio.is_some() => "H.264 MP4 with AAC audio",
        VideoFormat::Mp4 => "H.264 MP4",
        VideoFormat::Gif => "animated GIF",
        VideoFormat::PngFolder => "PNG frames",
    };
    println!(
        "wrote {}: {what}, {} frames {}x{} at {} fps ({:.3} s, {} bytes)",
        out.output, out.frames, out.width, out.height, out.fps, out.duration_seconds, out.bytes
    );
    if !out.missing_tables.is_empty() {
        let keys: Vec<String> = out
            .missing_tables
            .iter()
            .map(|(k, n)| format!("{k} ({n} frames)"))
            .collect();
        super::print_warnings(&[format!(
            "the face has no table for {} (those did not move it)",
            keys.join(", ")
        )]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frame_rates() {
        assert_eq!(parse_fps("30"), Ok(30.0));
        assert_eq!(parse_fps("12.5"), Ok(12.5));
        for bad in ["0", "-1", "nan", "inf", "1000", "x"] {
            assert!(parse_fps(bad).is_err(), "{bad}");
        }
    }
}
