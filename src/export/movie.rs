//! A FAP stream played on a face and rendered frame by frame into a video
//! ([`super::video::FrameSink`]): the player evaluates one frame, the CPU renderer draws it,
//! the sink encodes it, and the next frame reuses the same buffers, so memory stays flat
//! however long the stream is.
//!
//! The camera looks at the face from the front and is framed once, on the neutral face's
//! *facial* feature points — chin and inner lips (group 2), eyes (3), brows (4), cheeks
//! (5), outer lips (8), nose (9) and the hairline (11.1–11.3); not the ears, the top and
//! back of the head or the spine, which would frame the whole head small — widened by
//! [`FEATURE_POINT_MARGIN`] so a dropped jaw stays in the picture: a talking-head close-up.
//! A face with fewer than [`MIN_FRAMING_POINTS`] such points is framed on its whole neutral
//! mesh instead.

use glam::Vec3;
use serde::Serialize;

use super::video::FrameSink;
use crate::error::Result;
use crate::export::picture::FaceView;
use crate::face::FaceModel;
use crate::fap::FapStream;
use crate::mesh::Aabb;
use crate::player::{PlayOptions, Player};
use crate::render::{Camera, RenderOptions};

/// Fraction of the feature points' box added on every side of the framed box.
pub const FEATURE_POINT_MARGIN: f32 = 0.15;
/// Fewest positioned feature points to frame on (fewer: frame the whole neutral face).
pub const MIN_FRAMING_POINTS: usize = 4;

/// How to render a stream into a video.
#[derive(Clone, Debug, PartialEq)]
pub struct MovieOptions {
    /// Frame width in pixels.
    pub width: u32,
    /// Frame height in pixels.
    pub height: u32,
    /// Output frame rate; `None` uses the stream's.
    pub fps: Option<f64>,
}

/// What [`render_movie`] did.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct MovieReport {
    /// Frames rendered.
    pub frames: usize,
    /// Frame rate of the video.
    pub fps: f64,
    /// Seconds of video (`frames / fps`).
    pub duration_seconds: f64,
    /// Whether the camera was framed on the feature points (else on the whole face).
    pub framed_on_feature_points: bool,
    /// Keys the stream uses that the face has no table for, with their frame counts.
    pub missing_tables: Vec<(String, usize)>,
}

/// Whether a feature point belongs to the face region a video frames (see the module docs).
fn frames_the_face(id: crate::spec::FeaturePointId) -> bool {
    matches!(id.group(), 2 | 3 | 4 | 5 | 8 | 9) || (id.group() == 11 && id.index() <= 3)
}

/// The box around the face's positioned facial feature points widened by
/// [`FEATURE_POINT_MARGIN`], or `None` with fewer than [`MIN_FRAMING_POINTS`] of them.
pub fn feature_point_box(face: &FaceModel) -> Option<Aabb> {
    let points: Vec<Vec3> = face
        .feature_points
        .iter()
        .filter(|p| frames_the_face(p.id))
        .filter_map(|p| p.position)
        .filter(|p| p.is_finite())
        .collect();
    if points.len() < MIN_FRAMING_POINTS {
        return None;
    }
    let b = Aabb::of_points(&points)?;
    let size = b.size();
    // A flat or degenerate set (all points in a plane) still gets depth from its width.
    let pad =
        Vec3::splat(size.max_element() * FEATURE_POINT_MARGIN).max(size * FEATURE_POINT_MARGIN);
    Some(Aabb {
        min: b.min - pad,
        max: b.max + pad,
    })
}

/// The front camera for a video of `view`'s face: framed on its feature points, or on its
/// neutral bounds when it has too few (second value false).
pub fn movie_camera(view: &FaceView) -> (Camera, bool) {
    // The view's own box: a face turned in its file is framed stood up, as it is drawn.
    (view.face_camera(), view.framed_on_feature_points())
}

/// Plays `stream` on `face` and pushes every rendered frame into `sink` (which the caller
/// then finishes); `on_frame(done, total)` is called after each frame (for a progress bar). The sink must
/// have been opened with `opts`' size and [`Player::fps`] of the same stream and options.
pub fn render_movie(
    face: &FaceModel,
    stream: &FapStream,
    opts: &MovieOptions,
    sink: &mut dyn FrameSink,
    on_frame: &mut dyn FnMut(usize, usize),
) -> Result<MovieReport> {
    let mut player = Player::new(
        face,
        stream,
        &PlayOptions {
            fps: opts.fps,
            frames: None,
        },
    )?;
    let view = FaceView::new(face)?;
    let (camera, framed) = movie_camera(&view);
    let render_opts = RenderOptions::sized(opts.width, opts.height);
    let mut frame = player.new_frame();
    let mut positions = Vec::new();
    let total = player.frame_count();
    let mut n = 0;
    while player.next_frame(&mut frame) {
        frame.pose.world_positions_into(&mut positions);
        let image = view.render(&positions, &camera, &render_opts);
        sink.push(&image)?;
        n += 1;
        on_frame(n, total);
    }
    Ok(MovieReport {
        frames: n,
        fps: player.fps(),
        duration_seconds: player.duration(),
        framed_on_feature_points: framed,
        missing_tables: player
            .missing_tables()
            .into_iter()
            .map(|(k, f)| (k.to_string(), f))
            .collect(),
    })
}

/// The frame rate a movie of `stream` will have with `fps` (the override or the stream's).
pub fn movie_fps(stream: &FapStream, fps: Option<f64>) -> f64 {
    fps.unwrap_or(stream.frame_rate)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::export::video::{open_sink, VideoFormat, VideoSettings};

    #[test]
    fn feature_points_frame_the_face_inside_the_head() {
        let face = crate::synth::alma().to_face_model();
        let b = feature_point_box(&face).unwrap();
        let view = FaceView::new(&face).unwrap();
        let head = view.neutral_bounds();
        // The landmark box is a real box, shallower than the head (no back of the head), and
        // the camera on it is closer than the whole-head camera: a close-up of the face.
        assert!(b.size().min_element() > 0.0);
        assert!(b.size().z < 0.8 * head.size().z, "{b:?} in {head:?}");
        assert!(b.size().y > 0.5 * head.size().y);
        let (cam, framed) = movie_camera(&view);
        assert!(framed);
        let whole = view.front_camera();
        assert!(cam.eye.distance(cam.target) < 0.9 * whole.eye.distance(whole.target));
        let mut bare = face.clone();
        bare.feature_points = Default::default();
        assert!(feature_point_box(&bare).is_none());
        assert!(!movie_camera(&FaceView::new(&bare).unwrap()).1);
    }

    /// A face modelled facing −z is drawn from its own front, framed as the upright face:
    /// the same picture.
    #[test]
    fn a_face_turned_round_is_drawn_from_its_front() {
        let face = crate::synth::alma().to_face_model();
        let half = glam::Mat3::from_cols(-Vec3::X, Vec3::Y, -Vec3::Z);
        let turned = crate::clone::face::upright::upright_copy(&face, half);
        let opts = RenderOptions {
            width: 96,
            height: 96,
            ..RenderOptions::default()
        };
        let picture = |f: &FaceModel| {
            let view = FaceView::new(f).unwrap();
            let (camera, framed) = movie_camera(&view);
            assert!(framed);
            view.render(&f.neutral_world_positions(), &camera, &opts)
        };
        let (a, b) = (picture(&face), picture(&turned));
        let covered = a.stats(opts.background).coverage;
        assert!(covered > 0.2, "{covered}");
        assert!(a.rgba == b.rgba, "the turned face is drawn otherwise");
    }

    #[test]
    fn renders_every_frame_into_the_sink() {
        let face = crate::synth::alma().to_face_model();
        let text = std::fs::read_to_string(
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("samples/speech.fap"),
        )
        .unwrap();
        let (mut stream, _) = crate::fap::parse_fap(
            &text,
            std::path::Path::new("speech.fap"),
            &crate::fap::ReadOptions::lenient(),
        )
        .unwrap();
        stream.frames.retain(|f| f.number < 6);
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("f");
        let opts = MovieOptions {
            width: 48,
            height: 40,
            fps: None,
        };
        let settings = VideoSettings {
            width: 48,
            height: 40,
            fps: movie_fps(&stream, None),
            audio: None,
        };
        let mut sink = open_sink(&out, VideoFormat::PngFolder, &settings).unwrap();
        let mut calls = 0;
        let report =
            render_movie(&face, &stream, &opts, sink.as_mut(), &mut |_, _| calls += 1).unwrap();
        let written = sink.finish().unwrap();
        assert_eq!(report.frames, 6);
        assert_eq!(calls, 6);
        assert_eq!(written.frames, 6);
        assert!((report.duration_seconds - 6.0 / 25.0).abs() < 1e-9);
    }
}
