//! `--kernel cached` through the real binary: the teapot rendered by the cached
//! surface-tree kernel (at the default and a shallow tree depth, and with ISRT shadows)
//! against the float-precision subdivision kernel's image, and its `--stats` cache rows.

use crate::common;
use crate::toth_common;

use common::{render, stderr, stdout, testdata};
use toth_common::render::{SIZE, assert_matches};

#[test]
fn teapot_with_the_cached_kernel_matches_the_subdivision_kernel() {
    let dir = tempfile::tempdir().unwrap();
    let scene = testdata("teapot.ron");
    let path = |name: &str| dir.path().join(name);
    let cases: [(&str, &[&str]); 4] = [
        ("subdivision.exr", &[]),
        ("cached.exr", &["--kernel", "cached", "--stats"]),
        ("shallow.exr", &["--kernel", "cached", "--cache-depth", "2"]),
        ("isrt.exr", &["--kernel", "cached", "--isrt"]),
    ];
    for (name, extra) in cases {
        let out = render(&scene, &path(name), SIZE, extra);
        assert!(out.status.success(), "{name}: {}", stderr(&out));
        if name == "cached.exr" {
            let s: serde_json::Value = serde_json::from_str(&stdout(&out)).unwrap();
            let cache = &s["rays"]["cache"];
            let (hits, misses) = (cache["hits"].as_u64(), cache["misses"].as_u64());
            assert!(hits > Some(0) && misses > Some(0), "{cache}");
            // Neighbouring pixels test the same few patches: most tests find a tree.
            assert!(cache["hit_ratio"].as_f64() > Some(0.5), "{cache}");
            assert!(s["rays"]["toth"]["surfaces_searched_per_ray"].as_f64() > Some(0.0));
        }
    }
    for name in ["cached.exr", "shallow.exr", "isrt.exr"] {
        assert_matches(&path("subdivision.exr"), &path(name));
    }
}

#[test]
fn cached_kernel_flags_are_checked() {
    let dir = tempfile::tempdir().unwrap();
    let out = render(
        &testdata("teapot.ron"),
        &dir.path().join("x.png"),
        (4, 4),
        &["--kernel", "cached", "--precision", "f64"],
    );
    assert!(!out.status.success());
    assert!(stderr(&out).contains("--precision f64"), "{}", stderr(&out));
}
