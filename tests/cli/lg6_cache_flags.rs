//! `--cache-size` and `--cache-depth` size the surface-tree cache of `--kernel cached`;
//! with any other kernel they would be silently ignored, so they are an error there.
//! `bench lg90 --cache-size` sizes the cached methods of the paper's tables.

use crate::common;

use common::{render, run, stderr, testdata};

/// Every kernel without a surface-tree cache rejects each cache flag, in `render` and
/// `trace`, naming the flag and the kernel that takes it, and writes no image.
#[test]
fn cache_flags_need_the_cached_kernel() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out.png");
    let scene = testdata("distorted_patch.ron");
    let rays = testdata("camera_probe.rays");
    for kernel in ["subdivision", "toth"] {
        for flag in [["--cache-size", "4"], ["--cache-depth", "3"]] {
            let extra = ["--kernel", kernel, flag[0], flag[1]];
            let r = render(&scene, &out, (8, 8), &extra);
            let mut trace_args = vec!["trace", scene.to_str().unwrap()];
            trace_args.extend_from_slice(&["--rays", rays.to_str().unwrap()]);
            trace_args.extend_from_slice(&extra);
            let t = run(&trace_args);
            for (cmd, o) in [("render", r), ("trace", t)] {
                let err = stderr(&o);
                assert_eq!(o.status.code(), Some(2), "{cmd} {extra:?}: {err}");
                assert!(!err.contains("panicked"), "{err}");
                assert!(err.contains(flag[0]), "{cmd} {extra:?}: {err}");
                assert!(err.contains("--kernel cached"), "{cmd} {extra:?}: {err}");
            }
            assert!(!out.exists(), "render {extra:?} wrote an image");
        }
    }
}

/// The same flags with `--kernel cached` render.
#[test]
fn cache_flags_work_with_the_cached_kernel() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out.png");
    let extra = [
        "--kernel",
        "cached",
        "--cache-size",
        "1",
        "--cache-depth",
        "3",
    ];
    let o = render(&testdata("distorted_patch.ron"), &out, (8, 8), &extra);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(out.exists());
}

/// `bench lg90 --cache-size` sizes the cached methods' caches: zero is refused with a
/// message naming the flag; a size runs the cached method, whose first test of each
/// surface is a cache miss, so the table's row of misses is not zero.
#[test]
fn bench_lg90_takes_a_cache_size() {
    let bench = |extra: &[&str]| {
        let mut args = vec!["bench", "lg90", "--size", "8", "--cases", "1"];
        args.extend_from_slice(extra);
        run(&args)
    };
    let refused = bench(&["--cache-size", "0"]);
    let err = stderr(&refused);
    assert!(!refused.status.success());
    assert!(!err.contains("panicked"), "{err}");
    assert!(err.contains("--cache-size"), "{err}");
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("t.csv");
    let ok = bench(&[
        "--methods",
        "SCAN",
        "--threads",
        "1",
        "--cache-size",
        "1",
        "-q",
        "--csv",
        csv.to_str().unwrap(),
    ]);
    assert!(ok.status.success(), "{}", stderr(&ok));
    let text = std::fs::read_to_string(&csv).unwrap();
    let misses: f64 = text
        .lines()
        .find(|l| l.contains(",SCAN,") && l.contains("cache misses / surface"))
        .and_then(|l| l.split(',').nth(5)?.parse().ok())
        .unwrap_or_else(|| panic!("no cache-miss row in\n{text}"));
    assert!(misses > 0.0, "{misses} misses per surface");
}
