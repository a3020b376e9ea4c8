//! Output budgets: a played stream's output is estimated before any frame is computed, so a
//! tiny hostile stream (frames 0 and 9 999 999) is refused at once instead of filling memory
//! or the disk.
//!
//! Limits: [`MAX_OUTPUT_BYTES`] for the estimated output and [`MAX_PLAYED_FRAMES`] frames.
//! Estimates are upper-end figures per frame; a refused run writes nothing.

use std::ops::Range;
use std::path::Path;

use crate::error::Result;
use crate::face::FaceModel;

/// Largest estimated output of one played stream: 2 GiB.
pub const MAX_OUTPUT_BYTES: u64 = 2 << 30;

/// Most frames one output holds (a glTF clip is built in memory whole): 1 000 000 (11 hours
/// at 25 fps).
pub const MAX_PLAYED_FRAMES: usize = 1_000_000;

/// Bytes per frame of a glTF clip, in the file and in memory while it is built: a time key,
/// one weight per table (morph target) and rotation + translation + scale keys per animated
/// transform, plus the per-frame bookkeeping of [`crate::player::AnimationFrame`].
pub fn clip_bytes_per_frame(face: &FaceModel) -> u64 {
    let weights = face.fat.tables.len() as u64;
    let transforms = face.transform_names().len() as u64;
    let bookkeeping = std::mem::size_of::<crate::player::AnimationFrame>() as u64;
    4 + 4 * weights + 40 * transforms + bookkeeping + 16 * weights
}

/// Largest estimated memory of a glTF clip (or viewer page), which is built whole before it
/// is written: 256 MiB.
pub const MAX_CLIP_MEMORY_BYTES: u64 = 256 << 20;

/// Memory per frame while a clip is built: [`clip_bytes_per_frame`] twice over (sampled
/// frames, keys, accessors and the GLB buffer live at once; a 1 000 000-frame alma clip
/// peaked at 3.0 GB, 1.6 times its estimate, for a 641 MB file).
pub fn clip_memory_per_frame(face: &FaceModel) -> u64 {
    2 * clip_bytes_per_frame(face)
}

/// [`check`] for a glTF clip, which must also fit [`MAX_CLIP_MEMORY_BYTES`] while it is built.
pub fn check_clip(output: &Path, frames: &Range<usize>, face: &FaceModel) -> Result<()> {
    check(output, frames, clip_bytes_per_frame(face))?;
    let n = frames.len();
    let estimate = (n as u64).saturating_mul(clip_memory_per_frame(face));
    if estimate <= MAX_CLIP_MEMORY_BYTES {
        return Ok(());
    }
    Err(over_budget(
        output,
        frames,
        format!(
            "about {} MB of memory while the clip is built, more than the {} MB a clip may take",
            estimate >> 20,
            MAX_CLIP_MEMORY_BYTES >> 20
        ),
    ))
}

/// The refusal of `frames` written to `output`, `over` saying which limit is passed.
fn over_budget(output: &Path, frames: &Range<usize>, over: String) -> crate::error::Error {
    super::ExportError::OverBudget {
        output: output.to_path_buf(),
        start: frames.start,
        end: frames.end,
        frames: frames.len(),
        over,
        advice: String::new(),
    }
    .into()
}

/// Bytes per OBJ frame file: positions written as text (about 36 bytes a vertex) and the
/// faces (about 24 bytes each).
pub fn obj_bytes_per_frame(face: &FaceModel) -> u64 {
    let (vertices, faces) = face.meshes.iter().fold((0u64, 0u64), |(v, f), m| {
        (
            v + m.mesh.positions.len() as u64,
            f + m.mesh.polygons.len() as u64,
        )
    });
    36 * vertices + 24 * faces + 64
}

/// Bytes per rendered image frame of `width` × `height` (a PNG of a face on a plain
/// background compresses to well under one byte a pixel; one is the safe figure).
pub fn image_bytes_per_frame(width: u32, height: u32) -> u64 {
    u64::from(width) * u64::from(height)
}

/// Refuses to play `frames` into `output` when the estimate (`frames × bytes_per_frame`) is
/// over [`MAX_OUTPUT_BYTES`] or the frame count over [`MAX_PLAYED_FRAMES`]. The message names
/// the output, the frame span and the estimate.
pub fn check(output: &Path, frames: &Range<usize>, bytes_per_frame: u64) -> Result<()> {
    let n = frames.len();
    let estimate = (n as u64).saturating_mul(bytes_per_frame);
    let over = if n > MAX_PLAYED_FRAMES {
        format!("more than the {MAX_PLAYED_FRAMES} frames an output holds")
    } else if estimate > MAX_OUTPUT_BYTES {
        format!(
            "about {} MB, more than the {} MB output limit",
            estimate >> 20,
            MAX_OUTPUT_BYTES >> 20
        )
    } else {
        return Ok(());
    };
    Err(over_budget(output, frames, over))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn long_spans_are_refused_and_short_ones_pass() {
        let out = Path::new("x.glb");
        assert!(check(out, &(0..1000), 1000).is_ok());
        let e = check(out, &(0..10_000_000), 10).unwrap_err().to_string();
        assert!(e.contains("x.glb") && e.contains("0..10000000"), "{e}");
        let e = check(out, &(0..1000), 1 << 30).unwrap_err().to_string();
        assert!(e.contains("MB output limit"), "{e}");
        // No overflow on absurd figures.
        assert!(check(out, &(0..usize::MAX), u64::MAX).is_err());
    }
}
