//! The `f64` reference path against closed forms, and `bench accuracy` end to end.

use crate::common;

use glam::DVec3;
use patchtrace::geom::nurbs::shapes::sphere;
use patchtrace::kernel::subdivision::{SubdivisionConfig, intersect_f64};

use common::{run, stderr, stdout, testdata};

#[test]
fn f64_reference_hits_a_rational_sphere_where_the_closed_form_says() {
    let radius = 1.5;
    let patches = sphere(radius).unwrap().to_bezier_patches();
    let cfg = SubdivisionConfig::default();
    let mut rng = patchtrace::scene::generate::SplitMix64::new(11);
    let mut checked = 0;
    for _ in 0..300 {
        // From a random point outside towards a random point near the centre.
        let origin = rng.direction() * 5.0;
        let target = DVec3::new(
            rng.range(-1.0, 1.0),
            rng.range(-1.0, 1.0),
            rng.range(-1.0, 1.0),
        );
        let dir = target - origin;
        // |o + t d|² = r²: a t² + b t + c = 0, nearer root.
        let (a, b, c) = (
            dir.dot(dir),
            2.0 * origin.dot(dir),
            origin.dot(origin) - radius * radius,
        );
        let disc = b * b - 4.0 * a * c;
        let nearest = patches
            .iter()
            .filter_map(|p| intersect_f64(p, origin, dir, 0.0, f64::INFINITY, &cfg, None))
            .map(|h| h.t)
            .fold(f64::INFINITY, f64::min);
        if disc <= 0.0 {
            assert!(nearest.is_infinite(), "hit a sphere the ray misses");
            continue;
        }
        let t = (-b - disc.sqrt()) / (2.0 * a);
        assert!(
            (nearest - t).abs() <= 1e-12 * t,
            "t = {nearest}, closed form {t}"
        );
        let p = origin + dir * nearest;
        assert!((p.length() - radius).abs() <= 1e-12 * radius);
        checked += 1;
    }
    assert!(checked > 200, "only {checked} rays hit");
}

#[test]
fn bench_accuracy_writes_table_csv_and_plot() {
    let dir = tempfile::tempdir().unwrap();
    let o = run(&[
        "bench",
        "accuracy",
        testdata("teapot.ron").to_str().unwrap(),
        "--size",
        "24",
        "--triangles",
        "8,4608",
        "--out-dir",
        dir.path().to_str().unwrap(),
        "--json",
        "-q",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let results: serde_json::Value = serde_json::from_str(&stdout(&o)).unwrap();
    let rows = results.as_array().unwrap();
    // Both heuristics, adaptive, the four default depths, the two tessellations and the
    // two LG90 kernels (the teapot has no rational patches, so no dist rows).
    assert_eq!(rows.len(), 11, "{results}");
    let row = |name: &str| {
        rows.iter()
            .find(|r| r["method"] == name)
            .unwrap_or_else(|| panic!("no row {name}: {results}"))
    };
    let mean = |name: &str| row(name)["hit_error"]["mean"].as_f64().unwrap();
    // The float-precision kernel is more accurate than either tessellation, and more
    // triangles are more accurate than fewer (the shape of Dammertz Table 2.1).
    let float = "float, length heuristic";
    assert!(
        mean(float) < mean("4608 triangles/patch")
            && mean("4608 triangles/patch") < mean("8 triangles/patch"),
        "{results}"
    );
    // The LG90 kernels converge to the surface as well: below the coarse tessellation.
    for lg90 in ["LG90 Toth", "LG90 cached"] {
        assert!(mean(lg90) < mean("8 triangles/patch"), "{results}");
    }
    assert_eq!(row(float)["holes"], 0);
    assert_eq!(row(float)["rays"], 24 * 24);
    for f in [
        "accuracy.md",
        "accuracy.csv",
        "accuracy.svg",
        "accuracy.png",
    ] {
        assert!(dir.path().join(f).exists(), "{f}");
    }
}
