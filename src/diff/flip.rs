//! FLIP (Andersson et al. 2020, "FLIP: A Difference Evaluator for Alternating Images"),
//! through NVIDIA's reference implementation in the `nv-flip` crate. FLIP compares 8-bit
//! sRGB images as a viewer would see them; linear images are clamped to [0, 1] and
//! sRGB-encoded first (see [`Image::to_srgb8_rgb`]).

use serde::Serialize;

use super::image::Image;

/// FLIP statistics over the per-pixel error map (each value in [0, 1]).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct FlipStats {
    /// The single number FLIP's authors recommend.
    pub mean: f64,
    /// Median of the histogram weighted by error value, as FLIP's own tool reports it.
    pub weighted_median: f64,
    pub max: f64,
}

/// The FLIP error map (row-major) and its statistics, at the default viewing distance
/// (`nv_flip::DEFAULT_PIXELS_PER_DEGREE`: a 0.7 m wide 4K monitor seen from 0.7 m). The
/// images must have the same size; `nv_flip::flip` panics otherwise.
pub fn flip(a: &Image, b: &Image) -> (Vec<f32>, FlipStats) {
    let rgb8 =
        |img: &Image| nv_flip::FlipImageRgb8::with_data(img.width, img.height, &img.to_srgb8_rgb());
    let map = nv_flip::flip(rgb8(a), rgb8(b), nv_flip::DEFAULT_PIXELS_PER_DEGREE);
    let mut pool = nv_flip::FlipPool::from_image(&map);
    let values = map.to_vec();
    // Mean and max straight from the map, in f64: the pool's max starts at
    // f32::MIN_POSITIVE, so identical images would not report 0. The weighted median
    // needs the pool's histogram.
    let n = values.len() as f64;
    let stats = FlipStats {
        mean: values.iter().map(|&v| f64::from(v)).sum::<f64>() / n,
        weighted_median: f64::from(pool.get_percentile(0.5, true)),
        max: values.iter().fold(0.0f64, |m, &v| m.max(f64::from(v))),
    };
    (values, stats)
}
