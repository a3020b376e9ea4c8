//! RGBA images: PNG output, downscaling, blitting, captions, layout of contact sheets and
//! cloning grids, and stable statistics for tests.

use std::path::Path;

use serde::Serialize;

use super::colour::{linear_to_srgb8, srgb8_to_linear};
use super::font;
use crate::error::Result;

/// Largest width or height of an image made by this module; larger requests are clamped so a
/// bad argument cannot allocate without bound.
pub const MAX_IMAGE_SIDE: u32 = 16_384;

/// An 8-bit sRGB image with straight (not premultiplied) alpha, rows top to bottom.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Image {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// `width × height` pixels of `[r, g, b, a]`, row-major.
    pub rgba: Vec<u8>,
}

/// Inclusive pixel rectangle.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct PixelRect {
    /// Leftmost column.
    pub x0: u32,
    /// Top row.
    pub y0: u32,
    /// Rightmost column.
    pub x1: u32,
    /// Bottom row.
    pub y1: u32,
}

impl PixelRect {
    /// Centre of the rectangle in pixel coordinates (pixel centres at +0.5).
    pub fn center(&self) -> (f32, f32) {
        (
            (self.x0 + self.x1 + 1) as f32 / 2.0,
            (self.y0 + self.y1 + 1) as f32 / 2.0,
        )
    }
}

/// Side of the greyscale thumbnail behind [`ImageStats::thumbnail`] and
/// [`ImageStats::checksum`].
pub const THUMBNAIL_SIDE: u32 = 16;

/// Characters for the four grey levels of the thumbnail, dark to light.
const LEVELS: [char; 4] = [' ', '.', 'o', '#'];

/// Summary of an image that is stable enough to pin in snapshot tests.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ImageStats {
    /// Fraction of pixels that differ from the background.
    pub coverage: f64,
    /// Bounding box of the pixels that differ from the background (`None` if none do).
    pub bbox: Option<PixelRect>,
    /// Mean sRGB colour of the non-background pixels (zero if there are none).
    pub mean_colour: [f64; 3],
    /// The image box-filtered to 16×16 grey and quantised to four levels, one string per row
    /// (`' '`, `'.'`, `'o'`, `'#'` from dark to light).
    pub thumbnail: Vec<String>,
    /// FNV-1a hash of the thumbnail levels.
    pub checksum: u64,
}

impl Image {
    /// An image of `width × height` pixels (each clamped to `1..=MAX_IMAGE_SIDE`) filled with
    /// `fill`.
    pub fn new(width: u32, height: u32, fill: [u8; 4]) -> Image {
        let (width, height) = (
            width.clamp(1, MAX_IMAGE_SIDE),
            height.clamp(1, MAX_IMAGE_SIDE),
        );
        Image {
            width,
            height,
            rgba: fill.repeat(width as usize * height as usize),
        }
    }

    /// The pixel at `(x, y)`, or `None` outside the image.
    pub fn pixel(&self, x: u32, y: u32) -> Option<[u8; 4]> {
        if x >= self.width || y >= self.height {
            return None;
        }
        let i = (y as usize * self.width as usize + x as usize) * 4;
        self.rgba.get(i..i + 4).map(|p| [p[0], p[1], p[2], p[3]])
    }

    /// Sets the pixel at `(x, y)`; outside the image nothing happens.
    pub fn set_pixel(&mut self, x: i64, y: i64, value: [u8; 4]) {
        if x < 0 || y < 0 || x >= self.width as i64 || y >= self.height as i64 {
            return;
        }
        let i = (y as usize * self.width as usize + x as usize) * 4;
        self.rgba[i..i + 4].copy_from_slice(&value);
    }

    /// Fills the rectangle at `(x, y)` of `w × h` pixels (clipped) with `value`.
    pub fn fill_rect(&mut self, x: i64, y: i64, w: u32, h: u32, value: [u8; 4]) {
        for yy in y.max(0)..(y + h as i64).min(self.height as i64) {
            for xx in x.max(0)..(x + w as i64).min(self.width as i64) {
                self.set_pixel(xx, yy, value);
            }
        }
    }

    /// Encodes the image as an 8-bit RGBA PNG.
    pub fn encode_png(&self, out: &mut dyn std::io::Write) -> std::io::Result<()> {
        let mut encoder = png::Encoder::new(out, self.width, self.height);
        encoder.set_color(png::ColorType::Rgba);
        encoder.set_depth(png::BitDepth::Eight);
        encoder.set_source_srgb(png::SrgbRenderingIntent::Perceptual);
        let mut writer = encoder.write_header().map_err(std::io::Error::other)?;
        writer
            .write_image_data(&self.rgba)
            .map_err(std::io::Error::other)?;
        writer.finish().map_err(std::io::Error::other)
    }

    /// Writes the image as a PNG file, atomically (the target is replaced only on success).
    pub fn write_png(&self, path: &Path) -> Result<()> {
        if self.rgba.len() != self.width as usize * self.height as usize * 4 {
            return Err(super::RenderError::PixelCount {
                width: self.width,
                height: self.height,
                bytes: self.rgba.len(),
            }
            .into());
        }
        crate::io::write_atomic_with(path, |w| self.encode_png(w))
    }

    /// Shrinks the image by an integer `factor` (0 is taken as 1), averaging each
    /// `factor × factor` block in linear light, weighted by alpha. Leftover columns and rows
    /// at the right and bottom edges are dropped.
    pub fn downscale(&self, factor: u32) -> Image {
        let f = factor.max(1);
        let (w, h) = ((self.width / f).max(1), (self.height / f).max(1));
        let mut out = Image::new(w, h, [0; 4]);
        for oy in 0..h {
            for ox in 0..w {
                let mut acc = [0.0f32; 4];
                let mut n = 0.0f32;
                for y in oy * f..((oy + 1) * f).min(self.height) {
                    for x in ox * f..((ox + 1) * f).min(self.width) {
                        let p = self.pixel(x, y).unwrap_or([0; 4]);
                        let a = p[3] as f32 / 255.0;
                        for c in 0..3 {
                            acc[c] += srgb8_to_linear(p[c]) * a;
                        }
                        acc[3] += a;
                        n += 1.0;
                    }
                }
                let a = acc[3];
                let px = if a > 0.0 {
                    [
                        linear_to_srgb8(acc[0] / a),
                        linear_to_srgb8(acc[1] / a),
                        linear_to_srgb8(acc[2] / a),
                        (a / n.max(1.0) * 255.0).round() as u8,
                    ]
                } else {
                    [0; 4]
                };
                out.set_pixel(ox as i64, oy as i64, px);
            }
        }
        out
    }

    /// Copies `src` into this image with its top-left corner at `(x, y)`, clipped to this
    /// image. Pixels are replaced, not blended.
    pub fn blit(&mut self, src: &Image, x: i64, y: i64) {
        let x0 = x.max(0);
        let x1 = (x + src.width as i64).min(self.width as i64);
        if x0 >= x1 {
            return;
        }
        for sy in 0..src.height as i64 {
            let dy = y + sy;
            if dy < 0 || dy >= self.height as i64 {
                continue;
            }
            let s = ((sy * src.width as i64 + (x0 - x)) * 4) as usize;
            let d = ((dy * self.width as i64 + x0) * 4) as usize;
            let n = ((x1 - x0) * 4) as usize;
            self.rgba[d..d + n].copy_from_slice(&src.rgba[s..s + n]);
        }
    }

    /// Draws `text` with the built-in 5×7 font, each font pixel a `scale × scale` square
    /// (scale 0 is taken as 1), top-left corner at `(x, y)`, clipped.
    pub fn draw_text(&mut self, x: i64, y: i64, text: &str, colour: [u8; 4], scale: u32) {
        let s = scale.max(1) as i64;
        for (i, c) in text.chars().enumerate() {
            let gx = x + i as i64 * font::ADVANCE as i64 * s;
            if gx >= self.width as i64 {
                break;
            }
            for (row, bits) in font::glyph(c).iter().enumerate() {
                for col in 0..font::GLYPH_WIDTH {
                    if bits & (0x10 >> col) != 0 {
                        self.fill_rect(
                            gx + col as i64 * s,
                            y + row as i64 * s,
                            s as u32,
                            s as u32,
                            colour,
                        );
                    }
                }
            }
        }
    }

    /// Statistics relative to `background`: pixels exactly equal to it count as empty.
    pub fn stats(&self, background: [u8; 4]) -> ImageStats {
        let (w, h) = (self.width, self.height);
        let mut covered = 0u64;
        let mut sum = [0u64; 3];
        let mut bbox: Option<PixelRect> = None;
        for y in 0..h {
            for x in 0..w {
                let p = self.pixel(x, y).unwrap_or(background);
                if p == background {
                    continue;
                }
                covered += 1;
                for c in 0..3 {
                    sum[c] += p[c] as u64;
                }
                bbox = Some(match bbox {
                    None => PixelRect {
                        x0: x,
                        y0: y,
                        x1: x,
                        y1: y,
                    },
                    Some(b) => PixelRect {
                        x0: b.x0.min(x),
                        y0: b.y0.min(y),
                        x1: b.x1.max(x),
                        y1: b.y1.max(y),
                    },
                });
            }
        }
        let mean_colour = if covered == 0 {
            [0.0; 3]
        } else {
            sum.map(|s| s as f64 / covered as f64)
        };

        // Thumbnail: box-average grey (Rec. 709 luma of the sRGB values, alpha over black)
        // over the cells of a 16×16 partition of the image.
        let t = THUMBNAIL_SIDE;
        let mut thumbnail = Vec::with_capacity(t as usize);
        let mut checksum: u64 = 0xcbf2_9ce4_8422_2325;
        for ty in 0..t {
            let mut row = String::with_capacity(t as usize);
            let (ya, yb) = (ty * h / t, ((ty + 1) * h / t).max(ty * h / t + 1).min(h));
            for tx in 0..t {
                let (xa, xb) = (tx * w / t, ((tx + 1) * w / t).max(tx * w / t + 1).min(w));
                let (mut acc, mut n) = (0.0f64, 0u64);
                for y in ya..yb {
                    for x in xa..xb {
                        let p = self.pixel(x, y).unwrap_or([0; 4]);
                        let a = p[3] as f64 / 255.0;
                        acc += (0.2126 * p[0] as f64 + 0.7152 * p[1] as f64 + 0.0722 * p[2] as f64)
                            * a;
                        n += 1;
                    }
                }
                let grey = if n == 0 { 0.0 } else { acc / n as f64 };
                let level = ((grey / 256.0 * LEVELS.len() as f64) as usize).min(LEVELS.len() - 1);
                row.push(LEVELS[level]);
                checksum = (checksum ^ level as u64).wrapping_mul(0x0100_0000_01b3);
            }
            thumbnail.push(row);
        }
        ImageStats {
            coverage: covered as f64 / (w as u64 * h as u64) as f64,
            bbox,
            mean_colour,
            thumbnail,
            checksum,
        }
    }
}

/// Background of sheets and grids.
const SHEET_BACKGROUND: [u8; 4] = [24, 24, 28, 255];
/// Caption colour.
const CAPTION: [u8; 4] = [235, 235, 235, 255];

/// Font scale for captions under cells `cell_width` pixels wide: 1 up to 255 px, then 2, ….
fn caption_scale(cell_width: u32) -> u32 {
    (cell_width / 256 + 1).min(4)
}

/// Largest width and height over `images` (at least 1×1).
fn max_size<'a>(images: impl Iterator<Item = &'a Image>) -> (u32, u32) {
    images.fold((1, 1), |(w, h), i| (w.max(i.width), h.max(i.height)))
}

/// Drops characters from the end of `text` until it fits in `width` pixels at `scale`.
fn fit_text(text: &str, width: u32, scale: u32) -> String {
    let max_chars = (width / scale.max(1) + 1) / font::ADVANCE;
    text.chars().take(max_chars as usize).collect()
}

/// Lays `images` out in rows of `columns` cells (0 is taken as 1) separated by `padding`
/// pixels on a dark background, each cell as large as the largest image, images centred in
/// their cells. With `labels`, each cell gets the matching caption (missing labels leave
/// the cell uncaptioned) centred in a strip below it; captions too wide are truncated.
pub fn contact_sheet(
    images: &[Image],
    columns: u32,
    padding: u32,
    labels: Option<&[&str]>,
) -> Image {
    let columns = columns.clamp(1, images.len().max(1) as u32);
    let rows = (images.len() as u32).div_ceil(columns).max(1);
    let (cw, ch) = max_size(images.iter());
    let scale = caption_scale(cw);
    let strip = if labels.is_some() {
        font::GLYPH_HEIGHT * scale + padding.max(2 * scale)
    } else {
        0
    };
    let width = columns * cw + (columns + 1) * padding;
    let height = rows * (ch + strip) + (rows + 1) * padding;
    let mut sheet = Image::new(width, height, SHEET_BACKGROUND);
    for (i, img) in images.iter().enumerate() {
        let (col, row) = (i as u32 % columns, i as u32 / columns);
        let x = (padding + col * (cw + padding)) as i64;
        let y = (padding + row * (ch + strip + padding)) as i64;
        sheet.blit(
            img,
            x + (cw - img.width) as i64 / 2,
            y + (ch - img.height) as i64 / 2,
        );
        if let Some(text) = labels.and_then(|l| l.get(i)) {
            let text = fit_text(text, cw, scale);
            let tw = font::text_width(&text) * scale;
            let ty = y + ch as i64 + (strip - font::GLYPH_HEIGHT * scale) as i64 / 2;
            sheet.draw_text(x + (cw - tw) as i64 / 2, ty, &text, CAPTION, scale);
        }
    }
    sheet
}

/// The cloning grid: `cells[r][c]` is drawn at row `r`, column `c` (rows may be ragged),
/// with `col_labels` above the columns and `row_labels` left of the rows, on a dark
/// background. Cells are as large as the largest image, images centred.
pub fn grid(cells: &[Vec<Image>], row_labels: &[&str], col_labels: &[&str]) -> Image {
    let rows = cells.len().max(row_labels.len()).max(1) as u32;
    let cols = cells
        .iter()
        .map(Vec::len)
        .max()
        .unwrap_or(0)
        .max(col_labels.len())
        .max(1) as u32;
    let (cw, ch) = max_size(cells.iter().flatten());
    let scale = caption_scale(cw);
    let pad = 4 * scale;
    let label_w = row_labels
        .iter()
        .map(|l| font::text_width(l) * scale)
        .max()
        .unwrap_or(0)
        .min(cw.max(64 * scale));
    let header_h = if col_labels.is_empty() {
        0
    } else {
        font::GLYPH_HEIGHT * scale + pad
    };
    let left = if row_labels.is_empty() {
        0
    } else {
        label_w + pad
    };
    let width = left + cols * cw + (cols + 1) * pad;
    let height = header_h + rows * ch + (rows + 1) * pad;
    let mut out = Image::new(width, height, SHEET_BACKGROUND);
    let cell_x = |c: u32| (left + pad + c * (cw + pad)) as i64;
    let cell_y = |r: u32| (header_h + pad + r * (ch + pad)) as i64;
    for (c, text) in col_labels.iter().enumerate() {
        let text = fit_text(text, cw, scale);
        let tw = font::text_width(&text) * scale;
        out.draw_text(
            cell_x(c as u32) + (cw - tw) as i64 / 2,
            pad as i64,
            &text,
            CAPTION,
            scale,
        );
    }
    for (r, text) in row_labels.iter().enumerate() {
        let text = fit_text(text, label_w, scale);
        let y = cell_y(r as u32) + (ch as i64 - (font::GLYPH_HEIGHT * scale) as i64) / 2;
        out.draw_text(pad as i64, y, &text, CAPTION, scale);
    }
    for (r, row) in cells.iter().enumerate() {
        for (c, img) in row.iter().enumerate() {
            out.blit(
                img,
                cell_x(c as u32) + (cw - img.width) as i64 / 2,
                cell_y(r as u32) + (ch - img.height) as i64 / 2,
            );
        }
    }
    out
}
