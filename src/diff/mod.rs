//! `diff`: how far apart two renders are, as numbers and as a picture (the comparison of
//! Dammertz 2005 Fig. 2.1/2.2 and §3.4, where direct and tessellated renders are set side
//! by side).
//!
//! Metrics (pixel metrics on RGB only, in the [`Space`] chosen for the pair):
//! - RMSE, MAE over all RGB samples; max abs error, the largest sample error;
//! - PSNR = `-20 log10(RMSE)` in dB for peak value 1: on the stored sRGB values when both
//!   images are 8-bit PNG, on linear values clamped to [0, 1] otherwise; infinite for
//!   identical images (written as the string `"inf"` in JSON, which has no infinity);
//! - the share of pixels whose largest channel error exceeds a threshold
//!   ([`DEFAULT_THRESHOLD`]);
//! - FLIP mean, weighted median and max ([`flip`]), on 8-bit sRGB (linear images clamped to
//!   [0, 1], then sRGB-encoded: the renderer's own PNG tone mapping);
//! - coverage mismatch: pixels where one image's alpha is > 0 (a primary ray hit geometry)
//!   and the other's is 0 (background), counted when both images carry alpha.

pub mod flip;
pub mod image;
pub mod limit;
pub mod metrics;

use serde::{Serialize, Serializer};
use thiserror::Error;

pub use self::flip::FlipStats;
pub use self::image::{Encoding, Image, read_image};
pub use self::limit::{Exceeded, Limit, LimitMetric};
pub use self::metrics::Space;

/// Default per-pixel error threshold for the `above` share: a tenth of the displayable
/// range (about 26 levels of 8-bit sRGB), an error anyone sees; finer differences are what
/// RMSE and FLIP measure.
pub const DEFAULT_THRESHOLD: f64 = 0.1;

/// Options of [`diff_images`].
#[derive(Clone, Copy, Debug)]
pub struct DiffOptions {
    /// A pixel counts as `above` when its largest channel error exceeds this.
    pub threshold: f64,
}

impl Default for DiffOptions {
    fn default() -> Self {
        DiffOptions {
            threshold: DEFAULT_THRESHOLD,
        }
    }
}

#[derive(Debug, Error, PartialEq)]
pub enum DiffError {
    #[error("the images differ in size: {}x{} and {}x{}", a.0, a.1, b.0, b.1)]
    SizeMismatch { a: (u32, u32), b: (u32, u32) },
    #[error("the images have no pixels")]
    Empty,
    #[error("the threshold {0} is not a finite non-negative number")]
    BadThreshold(f64),
}

/// Per-pixel error maps (row-major, values in [0, 1]) for heat maps.
#[derive(Clone, Debug, Default)]
pub struct ErrorMaps {
    pub flip: Vec<f32>,
    /// Largest channel error per pixel, in the metric space.
    pub abs: Vec<f32>,
}

/// Everything `diff` measures about an image pair.
#[derive(Clone, Debug, Serialize)]
pub struct DiffReport {
    pub width: u32,
    pub height: u32,
    pub space: Space,
    /// Every RGB sample equal in the metric space and no coverage mismatch.
    pub identical: bool,
    pub rmse: f64,
    /// In dB; `f64::INFINITY` for identical RGB, serialised as `"inf"`.
    #[serde(serialize_with = "serialize_psnr")]
    pub psnr: f64,
    pub mae: f64,
    pub max_abs: f64,
    pub threshold: f64,
    pub above_count: u64,
    /// `above_count` over the number of pixels.
    pub above_share: f64,
    pub flip: FlipStats,
    /// `None` (JSON null) unless both images carry alpha.
    pub coverage_mismatch: Option<u64>,
    #[serde(skip)]
    pub maps: ErrorMaps,
}

fn serialize_psnr<S: Serializer>(psnr: &f64, s: S) -> Result<S::Ok, S::Error> {
    if psnr.is_finite() {
        s.serialize_f64(*psnr)
    } else {
        s.serialize_str("inf")
    }
}

/// Compares `b` (test) against `a` (reference).
///
/// # Examples
///
/// ```
/// use glam::Vec4;
/// use patchtrace::diff::{DiffOptions, Image, diff_images};
///
/// let a = Image::linear(8, 8, vec![Vec4::new(0.2, 0.2, 0.2, 1.0); 64], true);
/// let b = Image::linear(8, 8, vec![Vec4::new(0.3, 0.3, 0.3, 1.0); 64], true);
/// let r = diff_images(&a, &b, DiffOptions::default()).unwrap();
/// assert!((r.rmse - 0.1).abs() < 1e-6);
/// assert!((r.psnr - 20.0).abs() < 1e-4);
/// assert_eq!(r.coverage_mismatch, Some(0));
/// ```
pub fn diff_images(a: &Image, b: &Image, opts: DiffOptions) -> Result<DiffReport, DiffError> {
    if (a.width, a.height) != (b.width, b.height) {
        return Err(DiffError::SizeMismatch {
            a: (a.width, a.height),
            b: (b.width, b.height),
        });
    }
    if a.pixels.is_empty() {
        return Err(DiffError::Empty);
    }
    if !(opts.threshold.is_finite() && opts.threshold >= 0.0) {
        return Err(DiffError::BadThreshold(opts.threshold));
    }
    let space = Space::for_pair(a, b);
    let px = metrics::pixel_metrics(a, b, space, opts.threshold);
    let (flip_map, flip) = flip::flip(a, b);
    let coverage_mismatch = metrics::coverage_mismatch(a, b);
    Ok(DiffReport {
        width: a.width,
        height: a.height,
        space,
        identical: px.max_abs == 0.0 && coverage_mismatch.unwrap_or(0) == 0,
        rmse: px.rmse,
        psnr: metrics::psnr(px.rmse),
        mae: px.mae,
        max_abs: px.max_abs,
        threshold: opts.threshold,
        above_count: px.above_count,
        above_share: px.above_count as f64 / a.pixels.len() as f64,
        flip,
        coverage_mismatch,
        maps: ErrorMaps {
            flip: flip_map,
            abs: px.abs_map,
        },
    })
}

impl DiffReport {
    /// The limits this report exceeds, in the order given. A coverage limit on images
    /// without alpha cannot be checked and is returned as `Err` with that limit.
    pub fn exceeded(&self, limits: &[Limit]) -> Result<Vec<Exceeded>, Limit> {
        let mut out = Vec::new();
        for &limit in limits {
            let value = limit.metric.value(self).ok_or(limit)?;
            if value > limit.max {
                out.push(Exceeded {
                    metric: limit.metric,
                    value,
                    max: limit.max,
                });
            }
        }
        Ok(out)
    }
}
