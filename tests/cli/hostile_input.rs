//! hostile input. Each test is a regression test with the minimal input that
//! crashed, hung or ran away on main before the fix, and checks that the command now ends
//! with exit status 2 and an error that says where the problem is and which limit it hit.

use crate::common;

use std::path::{Path, PathBuf};
use std::process::Output;

use common::{run, stderr, stdout, testdata};

struct Dir {
    dir: tempfile::TempDir,
}

impl Dir {
    fn new() -> Dir {
        Dir {
            dir: tempfile::tempdir().unwrap(),
        }
    }

    fn file(&self, name: &str, text: &str) -> PathBuf {
        let path = self.dir.path().join(name);
        std::fs::write(&path, text).unwrap();
        path
    }

    fn path(&self, name: &str) -> PathBuf {
        self.dir.path().join(name)
    }

    /// teapot.ron with `edit` applied, its geometry file referenced by absolute path.
    fn teapot(&self, name: &str, edit: impl Fn(String) -> String) -> PathBuf {
        let text = std::fs::read_to_string(testdata("teapot.ron"))
            .unwrap()
            .replace(
                "File(\"teapot.bpt\")",
                &format!("File({:?})", testdata("teapot.bpt")),
            );
        self.file(name, &edit(text))
    }
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// Checks exit status 2 without a panic and returns stderr.
fn refused(o: &Output) -> String {
    let err = stderr(o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        !err.contains("panicked") && !err.contains("overflow"),
        "{err}"
    );
    err
}

#[test]
fn a_ray_beyond_f32_is_refused_at_its_line_and_column() {
    // Main: the origin rounded to inf and overflowed the BVH traversal stack (panic).
    let d = Dir::new();
    let rays = d.file("r.rays", "0 0 -5 0 0 1\n4e38 -8e38 4e38 -1 2 -1\n");
    let o = run(&["trace", s(&testdata("teapot.ron")), "--rays", s(&rays)]);
    let err = refused(&o);
    assert!(
        err.contains("r.rays:2:1: expected ox within the f32 range"),
        "{err}"
    );
}

#[test]
fn a_patch_whose_box_overflows_f32_is_refused_naming_the_object() {
    // Main: corners at ±3e38 fit f32 but the box's width does not; the default camera
    // stood at infinity and `render` overflowed the traversal stack.
    let d = Dir::new();
    let bpt = d.file(
        "big.bpt",
        "1\n1 1\n-3e38 -3e38 0\n3e38 -3e38 0\n-3e38 3e38 0\n3e38 3e38 0\n",
    );
    let o = common::render(&bpt, &d.path("big.png"), (4, 4), &[]);
    let err = refused(&o);
    assert!(
        err.contains("object \"big.bpt\"") && err.contains("f32 range"),
        "{err}"
    );
    assert!(!d.path("big.png").exists());
}

#[test]
fn max_depth_above_the_cap_is_refused_at_its_key() {
    // Main: `max_depth: 100000` with --kernel cached overflowed the thread's stack.
    let d = Dir::new();
    let scene = d.teapot("deep.ron", |t| {
        t.replacen("Scene(", "Scene(\n    max_depth: 100000,", 1)
    });
    let o = common::render(&scene, &d.path("x.png"), (4, 4), &["--kernel", "cached"]);
    let err = refused(&o);
    assert!(
        err.contains("deep.ron:3:5: expected max_depth from 1 to 64, found 100000"),
        "{err}"
    );
}

#[test]
fn a_ray_tree_that_doubles_per_bounce_is_cut_by_weight() {
    // Main: reflect 0.5 + transmit 0.5 at max depth 64 never finished. Every ray's weight
    // halves at least per bounce, so no path passes 1/255 beyond depth 1 + log2(255) < 10:
    // the tree of a pixel has at most 3^9 rays of each kind, and most are cut.
    let d = Dir::new();
    let scene = d.teapot("split.ron", |t| {
        t.replace("reflect: 0.3", "reflect: 0.5, transmit: 0.5")
            .replacen("Scene(", "Scene(\n    max_depth: 64,", 1)
    });
    let o = common::render(&scene, &d.path("x.png"), (16, 16), &["--stats"]);
    let err = stderr(&o);
    assert!(o.status.success(), "{err}");
    assert!(err.contains("rays below weight 1/255 not traced"), "{err}");
    let stats: serde_json::Value = serde_json::from_str(&stdout(&o)).unwrap();
    let rays = &stats["rays"];
    assert!(rays["cut_off"].as_u64().unwrap() > 0, "{rays}");
    let secondary = rays["reflection"].as_u64().unwrap() + rays["refraction"].as_u64().unwrap();
    assert!(secondary < 256 * 3u64.pow(9), "{rays}");
    assert_eq!(
        stats["plan"]["min_weight"].as_f64().unwrap() as f32,
        1.0 / 255.0
    );
}

#[test]
fn flags_beyond_their_limits_exit_2_naming_the_limit() {
    let d = Dir::new();
    let teapot = testdata("teapot.ron");
    let out = d.path("x.png");
    let cases: [(&[&str], &str); 5] = [
        (&["--threads", "10000"], "per core"),
        (&["--ulps", "4294967295"], "0..=4096"),
        (&["--width", "0"], "1..=32768"),
        (&["--width", "100000"], "1..=32768"),
        (
            &["--width", "30000", "--height", "30000"],
            "budget of 67108864 (8192x8192: 1 GiB of f32 RGBA); render it in pieces",
        ),
    ];
    for (flags, limit) in cases {
        let mut args = vec!["render", s(&teapot), "-o", s(&out), "-q"];
        args.extend_from_slice(flags);
        let err = refused(&run(&args));
        assert!(err.contains(limit), "{flags:?}: {err}");
    }
    assert!(!out.exists());
}

#[test]
fn tessellations_beyond_the_triangle_budget_are_refused_before_allocating() {
    // Main: --grid 100000,100000 asked for 40 GB; --tolerance 1e-30 never ended.
    let d = Dir::new();
    let teapot = testdata("teapot.ron");
    let out = d.path("x.obj");
    for flags in [["--grid", "100000,100000"], ["--tolerance", "1e-30"]] {
        let mut args = vec!["tessellate", s(&teapot), "-o", s(&out), "-q"];
        args.extend_from_slice(&flags);
        let err = refused(&run(&args));
        assert!(
            err.contains("above the budget of 16777216"),
            "{flags:?}: {err}"
        );
    }
    assert!(!out.exists());
}

#[test]
fn a_missing_referenced_file_names_the_scene_line_that_refers_to_it() {
    let d = Dir::new();
    let scene = d.file(
        "ref.ron",
        "Scene(camera: (eye: (0, -5, 0), look_at: (0, 0, 0), up: (0, 0, 1), fov_y: 40, width: 8, height: 8),\n    objects: [\n        (geometry: File(\"missing.bpt\")),\n    ])",
    );
    let err = refused(&run(&["info", s(&scene)]));
    assert!(
        err.contains("ref.ron:3:10: object 0 refers to geometry file \"missing.bpt\""),
        "{err}"
    );
    assert!(err.contains("missing.bpt: No such file"), "{err}");
}

/// `File("")` would name the scene's own directory: it is refused at the object as an
/// empty name, not as "unknown file type" of a directory.
#[test]
fn an_empty_geometry_file_name_is_refused_at_the_object() {
    let d = Dir::new();
    let scene = d.file(
        "empty.ron",
        "Scene(camera: (eye: (0, -5, 0), look_at: (0, 0, 0), up: (0, 0, 1), fov_y: 40, width: 8, height: 8),\n    objects: [\n        (geometry: File(\"\")),\n    ])",
    );
    let err = refused(&run(&["info", s(&scene)]));
    assert!(
        err.contains("empty.ron:3:10: object 0: expected a geometry file name in File(\"...\"), found an empty string"),
        "{err}"
    );
}

/// Bytes that are not UTF-8 in a text format are refused at their line and column (the
/// message was "stream did not contain valid UTF-8", with no place), for every reader
/// that takes text as UTF-8 (IGES and STEP locate a stray byte by their own syntax).
#[test]
fn bytes_that_are_not_utf8_are_located() {
    let d = Dir::new();
    for name in ["bad.bpt", "bad.obj", "bad.pbrt", "bad.ron"] {
        let path = d.path(name);
        std::fs::write(&path, b"1\n3 \xff 3\n").unwrap();
        let err = refused(&run(&["info", s(&path)]));
        assert!(
            err.contains(&format!(
                "{name}:2:3: expected UTF-8 text, found the byte 0xff"
            )),
            "{err}"
        );
    }
}

#[test]
fn ron_value_checks_are_located() {
    let d = Dir::new();
    let scene = d.file(
        "v.ron",
        "Scene(camera: (eye: (0, -5, 0), look_at: (0, 0, 0), up: (0, 0, 1), fov_y: 40, width: 8, height: 8),\n    materials: {\n        \"m\": (ior: -1),\n    },\n    objects: [(geometry: Surfaces([\n        Bezier(degree: (1, 1), points: [(0, 0, 0)]),\n    ]), material: \"m\")])",
    );
    let err = refused(&run(&["info", s(&scene)]));
    assert!(err.contains("v.ron:3:9: material \"m\""), "{err}");
    let fixed = std::fs::read_to_string(&scene)
        .unwrap()
        .replace("ior: -1", "ior: 1.5");
    std::fs::write(&scene, fixed).unwrap();
    let err = refused(&run(&["info", s(&scene)]));
    assert!(err.contains("v.ron:6:9: object 0, surface 0: "), "{err}");
}

#[test]
fn bvh_traversal_from_an_infinite_origin_ends_without_visiting_anything() {
    // Main: every lane of every wide node passed the slab test from an infinite origin, so
    // unused lanes pushed the root again and again until the stack overflowed.
    use glam::Vec3;
    use patchtrace::accel::bvh::Bvh;
    use patchtrace::geom::{Aabb, Ray};
    let boxes: Vec<Aabb> = (0..40)
        .map(|i| Aabb::new(Vec3::splat(i as f32), Vec3::splat(i as f32 + 0.5)))
        .collect();
    let bvh = Bvh::build(&boxes);
    for origin in [
        Vec3::new(f32::INFINITY, f32::NEG_INFINITY, f32::INFINITY),
        Vec3::new(f32::NAN, 0.0, 0.0),
    ] {
        let ray = Ray {
            origin,
            dir: Vec3::new(-1.0, 2.0, -1.0),
            tmin: 0.0,
            tmax: f32::INFINITY,
        };
        let mut calls = 0;
        bvh.traverse(&ray, |_, _| {
            calls += 1;
            None
        });
        assert_eq!(calls, 0);
    }
}

#[test]
fn trace_streams_chunks_in_order_and_a_bad_line_leaves_no_output() {
    // Rays are read, traced and written a chunk (2^16 rays) at a time: more rays than one
    // chunk must come out in input order, and a bad line after the first chunk must leave
    // no output file behind.
    let d = Dir::new();
    let n = (1 << 16) + 10;
    let mut text = String::with_capacity(n * 16);
    for i in 0..n {
        // Rays from below the teapot straight up, alternately missing far to the side.
        let x = if i % 2 == 0 { 0.0 } else { 100.0 };
        text.push_str(&format!("{x} 0 -5 0 0 1\n"));
    }
    let rays = d.file("many.rays", &text);
    let out = d.path("out.csv");
    let o = run(&[
        "trace",
        s(&testdata("teapot.ron")),
        "--rays",
        s(&rays),
        "-o",
        s(&out),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let csv = std::fs::read_to_string(&out).unwrap();
    let rows: Vec<&str> = csv.lines().skip(1).collect();
    assert_eq!(rows.len(), n);
    for (i, r) in rows.iter().enumerate() {
        let mut f = r.split(',');
        assert_eq!(f.next(), Some(i.to_string().as_str()));
        assert_eq!(
            f.next(),
            Some(if i % 2 == 0 { "1" } else { "0" }),
            "row {r}"
        );
    }
    std::fs::remove_file(&out).unwrap();
    let bad = d.file("bad.rays", &format!("{text}0 0 0 0 0 x\n"));
    let o = run(&[
        "trace",
        s(&testdata("teapot.ron")),
        "--rays",
        s(&bad),
        "-o",
        s(&out),
    ]);
    let err = refused(&o);
    assert!(
        err.contains(&format!("bad.rays:{}:11: expected dz", n + 1)),
        "{err}"
    );
    assert!(!out.exists());
}
