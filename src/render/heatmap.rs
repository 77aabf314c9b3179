//! Heat maps: a per-pixel error map in [0, 1] colour-mapped with magma (the map FLIP's own
//! tool uses), above a legend: a gradient strip from 0 to 1, tick marks at the quarters and
//! the labels 0, 0.5 and 1 in a 3×5 pixel font, so no font file is needed.

use std::path::Path;

use crate::io::OutputError;
use crate::io::write_atomic;

/// Rows of background between the image and the gradient strip.
const GAP: u32 = 3;
/// Height of the gradient strip.
const BAR: u32 = 10;
/// Length of the tick marks below the strip.
const TICK: u32 = 4;
/// Rows between the ticks and the labels.
const LABEL_GAP: u32 = 2;
/// Glyph size of the label font.
const GLYPH_W: u32 = 3;
const GLYPH_H: u32 = 5;
/// Rows of background below the labels.
const BOTTOM: u32 = 2;
/// Rows the legend adds below the image.
pub const LEGEND_HEIGHT: u32 = GAP + BAR + TICK + LABEL_GAP + GLYPH_H + BOTTOM;
/// Narrowest image whose legend has room for the labels "0", "0.5" and "1" apart.
const MIN_LABEL_WIDTH: u32 = 32;

const BACKGROUND: [u8; 3] = [24, 24, 24];
const INK: [u8; 3] = [255, 255, 255];

/// A heat map: `width × (height + LEGEND_HEIGHT)` RGB8 pixels.
pub struct HeatMap {
    pub width: u32,
    pub height: u32,
    pub rgb: Vec<u8>,
}

/// Colour-maps `values` (row-major, `width * height`, clamped to [0, 1]) with magma and
/// adds the legend below.
pub fn heat_map(values: &[f32], width: u32, height: u32) -> HeatMap {
    let lut = nv_flip::magma_lut().to_vec();
    let colour = |v: f32| {
        let i = (v.clamp(0.0, 1.0) * 255.0).round() as usize * 3;
        [lut[i], lut[i + 1], lut[i + 2]]
    };
    let total_height = height + LEGEND_HEIGHT;
    let mut rgb = Vec::with_capacity(width as usize * total_height as usize * 3);
    for &v in values {
        rgb.extend_from_slice(&colour(v));
    }
    let mut legend = Canvas {
        width,
        rgb: BACKGROUND.repeat(width as usize * LEGEND_HEIGHT as usize),
    };
    let last = width.saturating_sub(1).max(1);
    for x in 0..width {
        let c = colour(x as f32 / last as f32);
        for y in GAP..GAP + BAR {
            legend.set(x, y, c);
        }
    }
    for q in 0..=4 {
        let x = (q * width.saturating_sub(1)) / 4;
        for y in GAP + BAR..GAP + BAR + TICK {
            legend.set(x, y, INK);
        }
    }
    if width >= MIN_LABEL_WIDTH {
        let y = GAP + BAR + TICK + LABEL_GAP;
        let right = width - text_width("1");
        let middle = (width - 1) / 2 - text_width("0.5") / 2;
        for (text, x) in [("0", 0), ("0.5", middle), ("1", right)] {
            legend.text(x, y, text);
        }
    }
    rgb.extend_from_slice(&legend.rgb);
    HeatMap {
        width,
        height: total_height,
        rgb,
    }
}

impl HeatMap {
    /// Writes an 8-bit RGB PNG, atomically.
    pub fn write_png(&self, path: &Path) -> Result<(), OutputError> {
        write_atomic(path, |w| {
            use image::ImageEncoder;
            image::codecs::png::PngEncoder::new(w)
                .write_image(
                    &self.rgb,
                    self.width,
                    self.height,
                    image::ExtendedColorType::Rgb8,
                )
                .map_err(std::io::Error::other)
        })
    }
}

/// The legend's pixels.
struct Canvas {
    width: u32,
    rgb: Vec<u8>,
}

impl Canvas {
    fn set(&mut self, x: u32, y: u32, c: [u8; 3]) {
        let i = (y as usize * self.width as usize + x as usize) * 3;
        self.rgb[i..i + 3].copy_from_slice(&c);
    }

    fn text(&mut self, x: u32, y: u32, text: &str) {
        for (k, ch) in text.chars().enumerate() {
            let x0 = x + k as u32 * (GLYPH_W + 1);
            for (row, bits) in glyph(ch).iter().enumerate() {
                for col in 0..GLYPH_W {
                    if bits & (0b100 >> col) != 0 {
                        self.set(x0 + col, y + row as u32, INK);
                    }
                }
            }
        }
    }
}

/// Width in pixels of `text` in the label font, one blank column between glyphs.
fn text_width(text: &str) -> u32 {
    let n = text.chars().count() as u32;
    n * (GLYPH_W + 1) - 1
}

/// The 3×5 glyphs of the labels, one row per entry, most significant bit on the left.
fn glyph(ch: char) -> [u8; 5] {
    match ch {
        '0' => [0b111, 0b101, 0b101, 0b101, 0b111],
        '1' => [0b010, 0b110, 0b010, 0b010, 0b111],
        '5' => [0b111, 0b100, 0b111, 0b001, 0b111],
        '.' => [0b000, 0b000, 0b000, 0b000, 0b010],
        _ => [0; 5],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn legend_strip_runs_from_the_colour_of_zero_to_the_colour_of_one() {
        let (w, h) = (40, 3);
        let map = heat_map(&[0.0; 120], w, h);
        assert_eq!(map.rgb.len(), (w * (h + LEGEND_HEIGHT) * 3) as usize);
        let lut = nv_flip::magma_lut().to_vec();
        let px = |x: u32, y: u32| {
            let i = ((y * w + x) * 3) as usize;
            map.rgb[i..i + 3].to_vec()
        };
        let bar_row = h + GAP + BAR / 2;
        assert_eq!(px(0, bar_row), lut[0..3].to_vec());
        assert_eq!(px(w - 1, bar_row), lut[765..768].to_vec());
        // The image rows show the colour of 0 and the first tick is drawn in ink.
        assert_eq!(px(5, 1), lut[0..3].to_vec());
        assert_eq!(px(0, h + GAP + BAR), INK.to_vec());
        assert_eq!(px(w - 1, h + GAP + BAR), INK.to_vec());
    }
}
