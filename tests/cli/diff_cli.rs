//! `patchtrace diff` end to end on PNGs written here: JSON fields, `--fail-above` exit
//! status, the heat map file, and status 2 for bad input.

use crate::common;

use std::path::{Path, PathBuf};

use common::{run, stderr, stdout};
use patchtrace::render::heatmap::LEGEND_HEIGHT;

const W: u32 = 32;
const H: u32 = 24;
/// 8-bit levels added to red in the test image: no pixel clips (red ≤ 200 + 10).
const OFFSET: u8 = 10;

/// The reference pattern, RGBA8; `dark_columns` columns at the right have alpha 0.
fn rgba(red_offset: u8, dark_columns: u32) -> Vec<u8> {
    let mut out = Vec::new();
    for y in 0..H {
        for x in 0..W {
            let r = ((x * 37 + y * 11) % 200) as u8 + red_offset;
            let a = if x >= W - dark_columns { 0 } else { 255 };
            out.extend_from_slice(&[r, (y * 9) as u8, ((x ^ y) * 7) as u8, a]);
        }
    }
    out
}

fn write_png(path: &Path, w: u32, h: u32, data: &[u8]) {
    image::RgbaImage::from_raw(w, h, data.to_vec())
        .unwrap()
        .save(path)
        .unwrap();
}

struct Pair {
    dir: tempfile::TempDir,
    a: PathBuf,
    b: PathBuf,
}

/// `a.png` and `b.png`, B with red raised by OFFSET levels and 2 background columns.
fn pair() -> Pair {
    let dir = tempfile::tempdir().unwrap();
    let a = dir.path().join("a.png");
    let b = dir.path().join("b.png");
    write_png(&a, W, H, &rgba(0, 0));
    write_png(&b, W, H, &rgba(OFFSET, 2));
    Pair { dir, a, b }
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn json(args: &[&str]) -> serde_json::Value {
    let o = run(args);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    serde_json::from_str(&stdout(&o)).unwrap()
}

#[test]
fn json_reports_the_offset_in_srgb_levels() {
    let p = pair();
    let v = json(&["diff", s(&p.a), s(&p.b), "--json"]);
    // Only red differs, by OFFSET/255 in every pixel: over three channels the mean square
    // error is d²/3 and the mean absolute error d/3.
    let d = f64::from(OFFSET) / 255.0;
    let close = |key: &str, want: f64| {
        let got = v[key].as_f64().unwrap_or_else(|| panic!("{key} in {v}"));
        assert!((got - want).abs() < 1e-6, "{key}: {got} vs {want}");
    };
    close("rmse", d / 3f64.sqrt());
    close("mae", d / 3.0);
    close("max_abs", d);
    close("psnr", -20.0 * (d / 3f64.sqrt()).log10());
    assert_eq!(v["space"], "srgb");
    assert_eq!(v["width"], W);
    assert_eq!(v["height"], H);
    assert_eq!(v["identical"], false);
    assert_eq!(v["coverage_mismatch"], u64::from(2 * H));
    assert_eq!(v["above_count"], 0);
    assert!(v["flip"]["mean"].as_f64().unwrap() > 0.0);
    assert!(v["flip"]["weighted_median"].is_number());
    assert!(v["flip"]["max"].as_f64().unwrap() <= 1.0);
    assert_eq!(v["exceeded"], serde_json::json!([]));
    assert_eq!(v["a"], s(&p.a));
}

#[test]
fn identical_images_report_infinite_psnr_as_a_string() {
    let p = pair();
    let v = json(&["diff", s(&p.a), s(&p.a), "--json"]);
    assert_eq!(v["psnr"], "inf");
    assert_eq!(v["identical"], true);
    assert_eq!(v["rmse"], 0.0);
}

#[test]
fn fail_above_exits_1_only_when_a_limit_is_exceeded() {
    let p = pair();
    let rmse = f64::from(OFFSET) / 255.0 / 3f64.sqrt(); // about 0.0226
    let above = format!("rmse={}", rmse * 2.0);
    let o = run(&["diff", s(&p.a), s(&p.b), "--fail-above", &above]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));

    let below = format!("rmse={}", rmse / 2.0);
    let o = run(&[
        "diff",
        s(&p.a),
        s(&p.b),
        "--fail-above",
        &above,
        "--fail-above",
        &below,
    ]);
    assert_eq!(o.status.code(), Some(1));
    let err = stderr(&o);
    assert!(err.contains("rmse") && err.contains("exceeds"), "{err}");
    // The table is still printed for the log.
    assert!(stdout(&o).contains("RMSE"));

    let o = run(&["diff", s(&p.a), s(&p.b), "--fail-above", "coverage=47"]);
    assert_eq!(o.status.code(), Some(1), "48 coverage pixels > 47");
    let o = run(&["diff", s(&p.a), s(&p.b), "--fail-above", "coverage=48"]);
    assert_eq!(o.status.code(), Some(0));
}

#[test]
fn malformed_limit_is_a_usage_error() {
    let p = pair();
    let o = run(&["diff", s(&p.a), s(&p.b), "--fail-above", "psnr=30"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("unknown metric 'psnr'"),
        "{}",
        stderr(&o)
    );
}

#[test]
fn heatmap_has_the_image_size_plus_the_legend() {
    let p = pair();
    for metric in ["flip", "abs"] {
        let out = p.dir.path().join(format!("heat-{metric}.png"));
        let o = run(&[
            "diff",
            s(&p.a),
            s(&p.b),
            "--heatmap",
            s(&out),
            "--heatmap-metric",
            metric,
        ]);
        assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
        let img = image::open(&out).unwrap();
        assert_eq!((img.width(), img.height()), (W, H + LEGEND_HEIGHT));
    }
}

#[test]
fn bad_inputs_exit_2() {
    let p = pair();
    let missing = p.dir.path().join("missing.png");
    let o = run(&["diff", s(&p.a), s(&missing)]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("missing.png"), "{}", stderr(&o));

    let small = p.dir.path().join("small.png");
    write_png(&small, 2, 2, &[0; 16]);
    let o = run(&["diff", s(&p.a), s(&small)]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("differ in size"), "{}", stderr(&o));

    let text = p.dir.path().join("text.png");
    std::fs::write(&text, "not a png").unwrap();
    let o = run(&["diff", s(&p.a), s(&text)]);
    assert_eq!(o.status.code(), Some(2));
    assert!(!stderr(&o).contains("panicked"));
}

#[test]
fn coverage_limit_without_alpha_is_refused() {
    let p = pair();
    let rgb = p.dir.path().join("rgb.png");
    let data: Vec<u8> = rgba(0, 0).chunks(4).flat_map(|c| c[..3].to_vec()).collect();
    image::RgbImage::from_raw(W, H, data)
        .unwrap()
        .save(&rgb)
        .unwrap();
    let v = json(&["diff", s(&p.a), s(&rgb), "--json"]);
    assert_eq!(v["coverage_mismatch"], serde_json::Value::Null);
    assert_eq!(v["identical"], true);
    let o = run(&["diff", s(&p.a), s(&rgb), "--fail-above", "coverage=0"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("no alpha"), "{}", stderr(&o));
}
