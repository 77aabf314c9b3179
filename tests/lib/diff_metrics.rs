//! `diff` metrics against closed forms on synthetic images.

use glam::Vec4;
use patchtrace::diff::{DiffError, DiffOptions, Image, Space, diff_images, read_image};
use patchtrace::render::film::Film;

const W: u32 = 24;
const H: u32 = 16;

/// A deterministic image whose RGB values lie in [0, top] (a hash, not a smooth ramp, so
/// FLIP sees structure).
fn pattern(top: f32) -> Vec<Vec4> {
    (0..W * H)
        .map(|i| {
            let h = |k: u32| {
                ((i.wrapping_mul(2_654_435_761).wrapping_add(k * 97)) % 1000) as f32 / 999.0
            };
            Vec4::new(h(1) * top, h(2) * top, h(3) * top, 1.0)
        })
        .collect()
}

fn image(pixels: Vec<Vec4>, has_alpha: bool) -> Image {
    Image::linear(W, H, pixels, has_alpha)
}

#[test]
fn identical_images_have_zero_error_and_infinite_psnr() {
    let a = image(pattern(1.0), true);
    let r = diff_images(&a, &a.clone(), DiffOptions::default()).unwrap();
    assert_eq!(r.rmse, 0.0);
    assert_eq!(r.mae, 0.0);
    assert_eq!(r.max_abs, 0.0);
    assert_eq!(r.above_count, 0);
    assert_eq!(r.psnr, f64::INFINITY);
    assert!(r.identical);
    assert_eq!(r.flip.mean, 0.0);
    assert_eq!(r.flip.max, 0.0);
    assert_eq!(r.flip.weighted_median, 0.0);
    assert!(r.maps.flip.iter().all(|&v| v == 0.0));
    assert_eq!(r.coverage_mismatch, Some(0));
    let json = serde_json::to_value(&r).unwrap();
    assert_eq!(json["psnr"], "inf");
}

#[test]
fn constant_offset_gives_rmse_mae_max_and_psnr_in_closed_form() {
    for c in [0.01f32, 0.05, 0.25] {
        let a = pattern(1.0 - c);
        let b = a.iter().map(|p| *p + Vec4::new(c, c, c, 0.0)).collect();
        let r = diff_images(&image(a, false), &image(b, false), DiffOptions::default()).unwrap();
        let c = f64::from(c);
        // f32 sums a + c round by at most half an ulp of 1.
        let tol = 1e-7;
        assert!((r.rmse - c).abs() < tol, "c {c}: rmse {}", r.rmse);
        assert!((r.mae - c).abs() < tol, "c {c}: mae {}", r.mae);
        assert!((r.max_abs - c).abs() < tol, "c {c}: max {}", r.max_abs);
        let psnr = -20.0 * c.log10();
        assert!(
            (r.psnr - psnr).abs() < 1e-4,
            "c {c}: psnr {} vs {psnr}",
            r.psnr
        );
        assert_eq!(r.space, Space::Linear);
        assert!(!r.identical);
        // Every pixel is off by c in every channel: all above the threshold or none.
        let expect_above = if c > 0.1 { u64::from(W * H) } else { 0 };
        assert_eq!(r.above_count, expect_above);
    }
}

#[test]
fn max_abs_error_and_mae_of_a_sparse_difference() {
    let a = vec![Vec4::new(0.5, 0.5, 0.5, 1.0); (W * H) as usize];
    let mut b = a.clone();
    b[7].y = 0.5 - 0.375; // the largest error, 0.375
    b[100].x = 0.5 + 0.25;
    b[200].z = 0.5 + 0.125;
    let r = diff_images(&image(a, false), &image(b, false), DiffOptions::default()).unwrap();
    let samples = 3.0 * f64::from(W * H);
    assert_eq!(r.max_abs, 0.375);
    assert!((r.mae - (0.375 + 0.25 + 0.125) / samples).abs() < 1e-15);
    let mse = (0.375f64.powi(2) + 0.25f64.powi(2) + 0.125f64.powi(2)) / samples;
    assert!((r.rmse - mse.sqrt()).abs() < 1e-15);
    // The absolute-error map holds each pixel's largest channel error.
    assert_eq!(r.maps.abs[7], 0.375);
    assert_eq!(r.maps.abs[8], 0.0);
}

#[test]
fn share_above_threshold_counts_the_differing_pixels() {
    let a = pattern(0.5);
    let mut b = a.clone();
    // Every pixel differs by 0.05 (below the 0.1 threshold); every 9th by 0.3 on green.
    let mut expected = 0u64;
    for (i, p) in b.iter_mut().enumerate() {
        p.x += 0.05;
        if i % 9 == 0 {
            p.y += 0.3;
            expected += 1;
        }
    }
    let r = diff_images(
        &image(a.clone(), false),
        &image(b.clone(), false),
        DiffOptions::default(),
    )
    .unwrap();
    assert_eq!(r.above_count, expected);
    assert!((r.above_share - expected as f64 / f64::from(W * H)).abs() < 1e-15);
    // A threshold below 0.05 counts every pixel.
    let low = DiffOptions { threshold: 0.04 };
    let r = diff_images(&image(a, false), &image(b, false), low).unwrap();
    assert_eq!(r.above_count, u64::from(W * H));
}

#[test]
fn flip_of_very_different_images_is_large() {
    let black = image(vec![Vec4::new(0.0, 0.0, 0.0, 1.0); (W * H) as usize], false);
    let white = image(vec![Vec4::ONE; (W * H) as usize], false);
    let r = diff_images(&black, &white, DiffOptions::default()).unwrap();
    assert!(r.flip.mean > 0.5, "FLIP mean {}", r.flip.mean);
    assert!(r.flip.max >= r.flip.mean && r.flip.max <= 1.0);
    assert!(r.flip.weighted_median > 0.5);
    assert_eq!(r.rmse, 1.0);
    assert_eq!(r.psnr, 0.0);
}

#[test]
fn coverage_mismatch_counts_silhouette_pixels_exactly() {
    // A covers columns x < 8, B covers x < 11 (partial alpha counts as covered), so they
    // disagree on 3 columns of H pixels.
    let covered = |limit: u32, partial: f32| -> Vec<Vec4> {
        (0..W * H)
            .map(|i| {
                let alpha = if i % W < limit { partial } else { 0.0 };
                Vec4::new(0.2, 0.2, 0.2, alpha)
            })
            .collect()
    };
    let a = image(covered(8, 1.0), true);
    let b = image(covered(11, 0.5), true);
    let r = diff_images(&a, &b, DiffOptions::default()).unwrap();
    assert_eq!(r.coverage_mismatch, Some(u64::from(3 * H)));
    assert!(
        !r.identical,
        "equal RGB but different coverage is not identical"
    );
    // Without alpha on one side there is nothing to count.
    let b_opaque = image(covered(11, 0.5), false);
    let r = diff_images(&a, &b_opaque, DiffOptions::default()).unwrap();
    assert_eq!(r.coverage_mismatch, None);
}

#[test]
fn different_sizes_are_refused() {
    let a = image(pattern(1.0), false);
    let b = Image::linear(H, W, pattern(1.0), false);
    let err = diff_images(&a, &b, DiffOptions::default()).unwrap_err();
    assert_eq!(
        err,
        DiffError::SizeMismatch {
            a: (W, H),
            b: (H, W)
        }
    );
    assert!(err.to_string().contains("24x16 and 16x24"), "{err}");
}

#[test]
fn film_written_as_exr_and_png_reads_back() {
    let dir = tempfile::tempdir().unwrap();
    let mut pixels = pattern(1.5); // above 1: EXR keeps it, PNG clamps it
    pixels[3].w = 0.0;
    let film = Film {
        width: W,
        height: H,
        pixels: pixels.clone(),
    };
    let exr = dir.path().join("f.exr");
    film.write(&exr).unwrap();
    let img = read_image(&exr).unwrap();
    assert_eq!((img.width, img.height), (W, H));
    assert!(img.has_alpha);
    assert_eq!(img.pixels, pixels);

    let png = dir.path().join("f.png");
    film.write(&png).unwrap();
    let img = read_image(&png).unwrap();
    assert!(img.has_alpha);
    // sRGB bytes go back to linear: within one 8-bit level of the clamped value after
    // re-encoding, which is what the PNG stores.
    let bytes = film.to_srgb8();
    assert_eq!(img.to_srgb8_rgb(), {
        let mut rgb = Vec::new();
        for p in bytes.chunks(4) {
            rgb.extend_from_slice(&p[..3]);
        }
        rgb
    });
    assert_eq!(img.pixels[3].w, 0.0);
    // The film against its own PNG compares in linear space (one side is linear), and the
    // only error is 8-bit quantisation plus the clamp of values above 1.
    let exr_img = read_image(&exr).unwrap();
    let r = diff_images(&exr_img, &img, DiffOptions::default()).unwrap();
    assert_eq!(r.space, Space::Linear);
    assert!(r.max_abs < 0.01, "max {}", r.max_abs);
    assert_eq!(r.coverage_mismatch, Some(0));
}
