//! Images as `diff` sees them: linear f32 RGBA read from the renderer's outputs (8-bit sRGB
//! PNG, linear f32 EXR; see `render::film`), remembering how they were stored so metrics can
//! be taken in the space the file was written in.

use std::path::Path;

use glam::Vec4;

use crate::formats::LoadError;
use crate::render::film::{Film, ImageFormat, linear_to_srgb8};

/// How an image's values were stored, which decides the space its metrics are taken in.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Encoding {
    /// 8-bit sRGB-encoded values (PNG): display-referred.
    Srgb8,
    /// Linear floating-point values (EXR, or a film in memory): scene-referred.
    Linear,
}

/// A decoded image: row-major linear RGBA, row 0 at the top.
#[derive(Clone, Debug)]
pub struct Image {
    pub width: u32,
    pub height: u32,
    pub pixels: Vec<Vec4>,
    /// Whether the file carried an alpha channel; without one, alpha reads as 1.
    pub has_alpha: bool,
    pub encoding: Encoding,
}

impl Image {
    /// A linear image from its pixels (row-major, `width * height` of them).
    pub fn linear(width: u32, height: u32, pixels: Vec<Vec4>, has_alpha: bool) -> Image {
        debug_assert_eq!(pixels.len(), width as usize * height as usize);
        Image {
            width,
            height,
            pixels,
            has_alpha,
            encoding: Encoding::Linear,
        }
    }

    /// The renderer's film as it would be written to EXR: linear, with its coverage alpha.
    pub fn from_film(film: &Film) -> Image {
        Image::linear(film.width, film.height, film.pixels.clone(), true)
    }

    /// RGB as 8-bit sRGB, the input FLIP expects. Values are clamped to [0, 1] (the only
    /// tone mapping, the same as the renderer's PNG writer), so a PNG read here gives back
    /// its stored bytes exactly.
    pub fn to_srgb8_rgb(&self) -> Vec<u8> {
        self.pixels
            .iter()
            .flat_map(|p| [p.x, p.y, p.z])
            .map(linear_to_srgb8)
            .collect()
    }
}

/// The inverse of [`crate::render::film::linear_to_srgb`] (IEC 61966-2-1).
pub fn srgb_to_linear(x: f32) -> f32 {
    if x <= 0.040_45 {
        x / 12.92
    } else {
        ((x + 0.055) / 1.055).powf(2.4)
    }
}

/// Reads a PNG (8-bit grey, RGB or RGBA) or an EXR (its first layer with R, G, B and
/// optionally A channels) by extension. Every failure is a [`LoadError`] naming the file.
pub fn read_image(path: &Path) -> Result<Image, LoadError> {
    let image = match ImageFormat::of(path) {
        Some(ImageFormat::Png) => read_png(path)?,
        Some(ImageFormat::Exr) => read_exr(path)?,
        None => {
            return Err(LoadError::invalid(
                path,
                "unsupported image type: expected .png or .exr",
            ));
        }
    };
    if image.pixels.is_empty() {
        return Err(LoadError::invalid(path, "the image has no pixels"));
    }
    if let Some(i) = image.pixels.iter().position(|p| p.is_nan()) {
        let w = image.width as usize;
        return Err(LoadError::invalid(
            path,
            format!("pixel ({}, {}) is NaN", i % w, i / w),
        ));
    }
    Ok(image)
}

fn read_png(path: &Path) -> Result<Image, LoadError> {
    let bytes = std::fs::read(path).map_err(|e| LoadError::io(path, e))?;
    let decoded = image::load_from_memory_with_format(&bytes, image::ImageFormat::Png)
        .map_err(|e| LoadError::invalid(path, format!("reading PNG: {e}")))?;
    let color = decoded.color();
    if color.bits_per_pixel() != 8 * u16::from(color.channel_count()) {
        return Err(LoadError::invalid(
            path,
            format!("expected an 8-bit PNG, found {color:?}"),
        ));
    }
    let has_alpha = color.has_alpha();
    let rgba = decoded.into_rgba8();
    let (width, height) = rgba.dimensions();
    let channel = |b: u8| srgb_to_linear(f32::from(b) / 255.0);
    let pixels = rgba
        .pixels()
        .map(|p| {
            let [r, g, b, a] = p.0;
            Vec4::new(channel(r), channel(g), channel(b), f32::from(a) / 255.0)
        })
        .collect();
    Ok(Image {
        width,
        height,
        pixels,
        has_alpha,
        encoding: Encoding::Srgb8,
    })
}

fn read_exr(path: &Path) -> Result<Image, LoadError> {
    use exr::prelude::{Vec2, read_first_rgba_layer_from_file};
    let image = read_first_rgba_layer_from_file(
        path,
        |resolution, _| {
            (
                resolution.width(),
                vec![Vec4::ZERO; resolution.width() * resolution.height()],
            )
        },
        |(w, pixels): &mut (usize, Vec<Vec4>), Vec2(x, y), (r, g, b, a): (f32, f32, f32, f32)| {
            pixels[y * *w + x] = Vec4::new(r, g, b, a);
        },
    )
    .map_err(|e| LoadError::invalid(path, format!("reading EXR: {e}")))?;
    let layer = image.layer_data;
    let size = layer.size;
    let (width, height) = (u32::try_from(size.width()), u32::try_from(size.height()));
    let (Ok(width), Ok(height)) = (width, height) else {
        return Err(LoadError::invalid(path, "the EXR image is too large"));
    };
    Ok(Image {
        width,
        height,
        pixels: layer.channel_data.pixels.1,
        has_alpha: layer.channel_data.channels.3.is_some(),
        encoding: Encoding::Linear,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn srgb_round_trip_recovers_every_byte() {
        for b in 0..=255u8 {
            let back = linear_to_srgb8(srgb_to_linear(f32::from(b) / 255.0));
            assert_eq!(back, b);
        }
    }
}
