//! The image check shared by the Toth and cached kernels' render tests: a kernel's image
//! of the teapot against the float-precision subdivision kernel's.

use std::path::Path;

use patchtrace::diff::{DiffOptions, diff_images, read_image};

/// Size of the test images: small enough for the dev profile, large enough that the
/// teapot covers about a thousand pixels.
pub const SIZE: (u32, u32) = (64, 64);

/// Per-pixel difference (linear RGB, max over channels) above which a pixel counts as
/// different: well above the shading noise of hit points that differ by f32 ulps, below
/// any visible change of a surface's shade.
pub const PIXEL_THRESHOLD: f64 = 0.05;

/// Share of differing pixels allowed: a silhouette or shadow-boundary pixel may flip when
/// the two kernels' hit points differ by their f32 precision; at 64² the teapot's outline
/// and shadow edge are a few hundred pixels, of which at most a handful are that close.
pub const MAX_DIFFERING_SHARE: f64 = 0.005;

/// Root-mean-square difference allowed over the whole image.
pub const MAX_RMSE: f64 = 0.01;

/// Asserts that `image` differs from `reference` by at most the thresholds above.
pub fn assert_matches(reference: &Path, image: &Path) {
    let r = diff_images(
        &read_image(reference).unwrap(),
        &read_image(image).unwrap(),
        DiffOptions {
            threshold: PIXEL_THRESHOLD,
        },
    )
    .unwrap();
    assert!(
        r.rmse <= MAX_RMSE && r.above_share <= MAX_DIFFERING_SHARE,
        "{}: rmse {} and {} pixels above {PIXEL_THRESHOLD}",
        image.display(),
        r.rmse,
        r.above_count
    );
}
