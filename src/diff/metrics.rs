//! Pixel-wise error metrics between two images of the same size, taken on RGB in one space
//! (see [`Space`]); alpha enters only through the coverage count.

use glam::Vec4;
use serde::Serialize;

use super::image::{Encoding, Image};
use crate::render::film::linear_to_srgb;

/// The space the pixel metrics are taken in, with peak value 1 for PSNR.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Space {
    /// sRGB-encoded values in [0, 1], when both images are 8-bit sRGB (PNG): the values the
    /// files store, so an error of one 8-bit level is 1/255.
    Srgb,
    /// Linear values clamped to [0, 1], when either image is linear (EXR): radiance error
    /// in the displayable range.
    Linear,
}

impl Space {
    /// sRGB only when both sides were stored as sRGB; comparing a PNG with an EXR is done
    /// in linear space, where the EXR's values are not requantised.
    pub fn for_pair(a: &Image, b: &Image) -> Space {
        if a.encoding == Encoding::Srgb8 && b.encoding == Encoding::Srgb8 {
            Space::Srgb
        } else {
            Space::Linear
        }
    }

    fn rgb(self, p: Vec4) -> [f32; 3] {
        let f = |c: f32| match self {
            Space::Srgb => linear_to_srgb(c),
            Space::Linear => c.clamp(0.0, 1.0),
        };
        [f(p.x), f(p.y), f(p.z)]
    }
}

/// The pixel metrics of one image pair.
#[derive(Clone, Debug, PartialEq)]
pub struct PixelMetrics {
    pub rmse: f64,
    pub mae: f64,
    pub max_abs: f64,
    /// Pixels whose largest channel error exceeds the threshold.
    pub above_count: u64,
    /// Largest channel error of each pixel, row-major: the absolute-error heat map.
    pub abs_map: Vec<f32>,
}

/// RMSE and MAE over all RGB samples, the largest sample error, and the pixels whose
/// largest channel error is above `threshold`. The images must have the same size.
pub fn pixel_metrics(a: &Image, b: &Image, space: Space, threshold: f64) -> PixelMetrics {
    let mut sum_sq = 0.0f64;
    let mut sum_abs = 0.0f64;
    let mut max_abs = 0.0f64;
    let mut above_count = 0u64;
    let mut abs_map = Vec::with_capacity(a.pixels.len());
    for (&pa, &pb) in a.pixels.iter().zip(&b.pixels) {
        let (ca, cb) = (space.rgb(pa), space.rgb(pb));
        let mut pixel_max = 0.0f64;
        for k in 0..3 {
            let d = (f64::from(ca[k]) - f64::from(cb[k])).abs();
            sum_sq += d * d;
            sum_abs += d;
            pixel_max = pixel_max.max(d);
        }
        max_abs = max_abs.max(pixel_max);
        if pixel_max > threshold {
            above_count += 1;
        }
        abs_map.push(pixel_max as f32);
    }
    let samples = 3.0 * a.pixels.len() as f64;
    PixelMetrics {
        rmse: (sum_sq / samples).sqrt(),
        mae: sum_abs / samples,
        max_abs,
        above_count,
        abs_map,
    }
}

/// Peak signal-to-noise ratio in dB for peak value 1: `-20 log10(rmse)`, infinite for
/// identical images.
pub fn psnr(rmse: f64) -> f64 {
    if rmse == 0.0 {
        f64::INFINITY
    } else {
        -20.0 * rmse.log10()
    }
}

/// Pixels where exactly one image hit geometry (alpha > 0) and the other shows background
/// (alpha == 0): the silhouette error. `None` unless both images carry alpha.
pub fn coverage_mismatch(a: &Image, b: &Image) -> Option<u64> {
    if !(a.has_alpha && b.has_alpha) {
        return None;
    }
    let covered = |p: &Vec4| p.w > 0.0;
    Some(
        a.pixels
            .iter()
            .zip(&b.pixels)
            .filter(|(pa, pb)| covered(pa) != covered(pb))
            .count() as u64,
    )
}
