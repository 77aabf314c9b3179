//! `--kernel toth` through the real binary: the teapot scene rendered by the Toth kernel
//! (with and without ISRT shadow rays) against the float-precision subdivision kernel's
//! image, and the flag checks.

use crate::common;
use crate::toth_common;

use common::{render, stderr, testdata};
use toth_common::render::{SIZE, assert_matches};

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
    for name in ["toth.exr", "isrt.exr"] {
        assert_matches(&path("subdivision.exr"), &path(name));
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
