//! The film: linear RGBA pixels, written as 8-bit sRGB PNG or linear f32 RGBA EXR. Alpha is
//! 1 where the primary ray hit geometry and 0 on the background, so `diff` can count
//! silhouette (coverage) mismatches.

use std::path::Path;

use glam::Vec4;

use crate::io::OutputError;
use crate::io::{temporary_name, write_atomic};

pub struct Film {
    pub width: u32,
    pub height: u32,
    /// Row-major, row 0 at the top.
    pub pixels: Vec<Vec4>,
}

/// Output image formats, by extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ImageFormat {
    Png,
    Exr,
}

impl ImageFormat {
    pub fn of(path: &Path) -> Option<ImageFormat> {
        match path.extension()?.to_str()?.to_ascii_lowercase().as_str() {
            "png" => Some(ImageFormat::Png),
            "exr" => Some(ImageFormat::Exr),
            _ => None,
        }
    }
}

/// One linear channel as an 8-bit sRGB code, rounded to nearest.
pub fn linear_to_srgb8(x: f32) -> u8 {
    (linear_to_srgb(x) * 255.0 + 0.5) as u8
}

/// The sRGB transfer function (IEC 61966-2-1).
pub fn linear_to_srgb(x: f32) -> f32 {
    let x = x.clamp(0.0, 1.0);
    if x <= 0.003_130_8 {
        12.92 * x
    } else {
        1.055 * x.powf(1.0 / 2.4) - 0.055
    }
}

impl Film {
    /// Encodes 8-bit sRGB RGBA.
    pub fn to_srgb8(&self) -> Vec<u8> {
        let mut out = Vec::with_capacity(self.pixels.len() * 4);
        for p in &self.pixels {
            out.extend([p.x, p.y, p.z].map(linear_to_srgb8));
            out.push((p.w.clamp(0.0, 1.0) * 255.0 + 0.5) as u8);
        }
        out
    }

    /// The pixels as the EXR channels `R`, `G`, `B`, `A` (linear f32).
    pub fn rgba_channels(&self) -> Vec<exr::prelude::AnyChannel<exr::prelude::FlatSamples>> {
        use exr::prelude::{AnyChannel, FlatSamples};
        let channel = |name: &str, c: fn(&Vec4) -> f32| {
            AnyChannel::new(name, FlatSamples::F32(self.pixels.iter().map(c).collect()))
        };
        vec![
            channel("R", |p| p.x),
            channel("G", |p| p.y),
            channel("B", |p| p.z),
            channel("A", |p| p.w),
        ]
    }

    /// A film from the `R`, `G`, `B`, `A` f32 channels among `channels`; `None` when one
    /// is missing or has another type or length.
    pub fn from_rgba_channels(
        width: u32,
        height: u32,
        channels: &[exr::prelude::AnyChannel<exr::prelude::FlatSamples>],
    ) -> Option<Film> {
        let n = width as usize * height as usize;
        let get = |name: &str| {
            channels
                .iter()
                .find(|c| c.name.to_string() == name)
                .and_then(|c| match &c.sample_data {
                    exr::prelude::FlatSamples::F32(v) if v.len() == n => Some(v),
                    _ => None,
                })
        };
        let [r, g, b, a] = [get("R")?, get("G")?, get("B")?, get("A")?];
        Some(Film {
            width,
            height,
            pixels: (0..n).map(|i| Vec4::new(r[i], g[i], b[i], a[i])).collect(),
        })
    }

    /// Writes by extension, atomically.
    pub fn write(&self, path: &Path) -> Result<(), OutputError> {
        match ImageFormat::of(path) {
            Some(ImageFormat::Png) => {
                let bytes = self.to_srgb8();
                write_atomic(path, |w| {
                    use image::ImageEncoder;
                    image::codecs::png::PngEncoder::new(w)
                        .write_image(
                            &bytes,
                            self.width,
                            self.height,
                            image::ExtendedColorType::Rgba8,
                        )
                        .map_err(std::io::Error::other)
                })
            }
            Some(ImageFormat::Exr) => self.write_exr(path),
            None => Err(OutputError::invalid(
                path,
                "unsupported image type: expected .png or .exr",
            )),
        }
    }

    fn write_exr(&self, path: &Path) -> Result<(), OutputError> {
        use exr::prelude::*;
        let (w, h) = (self.width as usize, self.height as usize);
        let tmp = temporary_name(path);
        let pixels = &self.pixels;
        let image = Image::from_channels(
            (w, h),
            SpecificChannels::rgba(|Vec2(x, y)| {
                let p: Vec4 = pixels[y * w + x];
                (p.x, p.y, p.z, p.w)
            }),
        );
        image.write().to_file(&tmp).map_err(|e| {
            let _ = std::fs::remove_file(&tmp);
            OutputError::invalid(path, format!("writing EXR: {e}"))
        })?;
        std::fs::rename(&tmp, path).map_err(|e| OutputError::io(path, e))
    }
}

/// Draws the effort AOV (splits per pixel) as `<stem>-effort.png`, colour-mapped on a log
/// scale from 0 to the largest count, with a legend. Returns the path.
pub fn write_effort_png(
    image_path: &Path,
    width: u32,
    height: u32,
    effort: &[u32],
) -> Result<std::path::PathBuf, OutputError> {
    let png_path = sibling(image_path, "effort", "png");
    let values: Vec<f32> = effort.iter().map(|&e| e as f32).collect();
    let max = values.iter().copied().fold(1.0f32, f32::max).ln_1p();
    let normalized: Vec<f32> = values.iter().map(|v| v.ln_1p() / max).collect();
    super::heatmap::heat_map(&normalized, width, height).write_png(&png_path)?;
    Ok(png_path)
}

/// `<stem>-<suffix>.<ext>` beside `image_path`.
pub fn sibling(image_path: &Path, suffix: &str, ext: &str) -> std::path::PathBuf {
    let stem = image_path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    image_path.with_file_name(format!("{stem}-{suffix}.{ext}"))
}
