//! `--kernel toth` through the real binary: the teapot scene rendered by the Toth kernel
//! (with and without ISRT shadow rays) against the float-precision subdivision kernel's
//! image, and the flag checks.

mod common;

use common::{render, stderr, testdata};
use patchtrace::diff::{DiffOptions, diff_images, read_image};

/// Size of the test images: small enough for the dev profile, large enough that the
/// teapot covers about a thousand pixels.
const SIZE: (u32, u32) = (64, 64);

/// Per-pixel difference (linear RGB, max over channels) above which a pixel counts as
/// different: well above the shading noise of hit points that differ by f32 ulps, below
/// any visible change of a surface's shade.
const PIXEL_THRESHOLD: f64 = 0.05;

/// Share of differing pixels allowed: a silhouette or shadow-boundary pixel may flip when
/// the two kernels' hit points differ by their f32 precision; at 64² the teapot's outline
/// and shadow edge are a few hundred pixels, of which at most a handful are that close.
const MAX_DIFFERING_SHARE: f64 = 0.005;

/// Root-mean-square difference allowed over the whole image.
const MAX_RMSE: f64 = 0.01;

#[test]
fn teapot_with_toth_matches_the_subdivision_kernel() {
    let dir = tempfile::tempdir().unwrap();
    let scene = testdata("teapot.ron");
    let path = |name: &str| dir.path().join(name);
    let cases: [(&str, &[&str]); 3] = [
        ("subdivision.exr", &[]),
        ("toth.exr", &["--kernel", "toth"]),
        ("isrt.exr", &["--kernel", "toth", "--isrt"]),
    ];
    for (name, extra) in cases {
        let out = render(&scene, &path(name), SIZE, extra);
        assert!(out.status.success(), "{name}: {}", stderr(&out));
    }
    let reference = read_image(&path("subdivision.exr")).unwrap();
    for name in ["toth.exr", "isrt.exr"] {
        let image = read_image(&path(name)).unwrap();
        let opts = DiffOptions {
            threshold: PIXEL_THRESHOLD,
        };
        let r = diff_images(&reference, &image, opts).unwrap();
        assert!(
            r.rmse <= MAX_RMSE && r.above_share <= MAX_DIFFERING_SHARE,
            "{name}: rmse {} and {} pixels above {PIXEL_THRESHOLD}",
            r.rmse,
            r.above_count
        );
    }
}

#[test]
fn isrt_requires_the_toth_kernel() {
    let dir = tempfile::tempdir().unwrap();
    let out = render(
        &testdata("teapot.ron"),
        &dir.path().join("x.png"),
        (4, 4),
        &["--isrt"],
    );
    assert!(!out.status.success());
    assert!(stderr(&out).contains("--kernel toth"), "{}", stderr(&out));
    let out = render(
        &testdata("teapot.ron"),
        &dir.path().join("x.png"),
        (4, 4),
        &["--kernel", "toth", "--precision", "f64"],
    );
    assert!(!out.status.success());
    assert!(stderr(&out).contains("--precision f64"), "{}", stderr(&out));
}
