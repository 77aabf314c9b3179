//! `convert` end to end: NURBS files become Bézier patches exactly, and what we write reads
//! back as the same patches.

use crate::common;

use common::{run, stderr, stdout, testdata};
use patchtrace::formats::load_geometry;
use patchtrace::geom::BezierPatch;
use patchtrace::scene::{Geometry, SurfaceGeometry};

fn patches_of(path: &std::path::Path) -> Vec<BezierPatch> {
    match load_geometry(path).unwrap() {
        Geometry::Surfaces(s) => s
            .into_iter()
            .flat_map(|s| match s.geometry {
                SurfaceGeometry::Bezier(p) => vec![p],
                SurfaceGeometry::Nurbs(n) => n.to_bezier_patches(),
            })
            .collect(),
        other => panic!("expected surfaces, found {other:?}"),
    }
}

#[test]
fn converted_torus_lies_exactly_on_the_torus() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("t.obj");
    let o = run(&[
        "convert",
        testdata("torus.obj").to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--json",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let report: serde_json::Value = serde_json::from_str(&stdout(&o)).unwrap();
    assert_eq!(report["nurbs_surfaces"], 1);
    assert_eq!(report["nurbs_control_points"], 81);
    // Knots 0 0 0 .25 .25 .5 .5 .75 .75 1 1 1 in each direction: 4 spans each.
    assert_eq!(report["bezier_patches_from_nurbs"], 16);
    assert_eq!(report["bezier_control_points_from_nurbs"], 16 * 9);
    let patches = patches_of(&out);
    assert_eq!(patches.len(), 16);
    let (major, minor) = (2.0f64, 0.5f64);
    for p in &patches {
        assert!(p.is_rational());
        for i in 0..=16 {
            for j in 0..=16 {
                let q = p.eval(i as f64 / 16.0, j as f64 / 16.0);
                let ring = (q.x.hypot(q.y) - major).hypot(q.z);
                assert!(
                    (ring - minor).abs() <= 1e-12 * major,
                    "point {q} is {ring} from the core circle"
                );
            }
        }
    }
}

#[test]
fn import_convert_write_read_gives_the_same_patches() {
    let dir = tempfile::tempdir().unwrap();
    for name in [
        "bspline_multiknot.obj",
        "bezier_pieces.obj",
        "torus.obj",
        "nurbs_patch.pbrt",
    ] {
        let ron = dir.path().join(format!("{name}.ron"));
        let o = run(&[
            "import",
            testdata(name).to_str().unwrap(),
            "-o",
            ron.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{name}: {}", stderr(&o));
        // A trimmed scene goes to OBJ, which keeps its loops as `curv2` trims; the .bpt
        // writer would drop them, so it refuses (checked below).
        let trimmed = name == "bspline_multiknot.obj";
        let obj = dir.path().join(format!("{name}.obj"));
        let o = run(&[
            "convert",
            ron.to_str().unwrap(),
            "-o",
            obj.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{name}: {}", stderr(&o));
        if trimmed {
            let refused = dir.path().join("trimmed.bpt");
            let o = run(&[
                "convert",
                ron.to_str().unwrap(),
                "-o",
                refused.to_str().unwrap(),
            ]);
            assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
            assert!(
                stderr(&o).contains("write .obj, .igs or .ron instead"),
                "{}",
                stderr(&o)
            );
            assert!(!refused.exists());
        }
        // Decomposition straight from the source file, independent of the RON and OBJ
        // round trip.
        let direct = patches_of(&testdata(name));
        let scene = patchtrace::formats::load_scene(&obj).unwrap();
        // OBJ keeps each Bézier patch's loops and domain.
        assert_eq!(scene.trim_loop_count() > 0, trimmed, "{name}");
        let back: Vec<BezierPatch> = scene
            .objects
            .iter()
            .flat_map(|o| o.bezier_patches())
            .collect();
        assert_eq!(direct.len(), back.len(), "{name}");
        for (a, b) in direct.iter().zip(&back) {
            assert_eq!((a.degree_u(), a.degree_v()), (b.degree_u(), b.degree_v()));
            for (p, q) in a.euclidean_points().zip(b.euclidean_points()) {
                // OBJ stores x y z w; (w x / w) · w may differ from w x by an ulp.
                assert!(
                    (p - q).length() <= 4.0 * f64::EPSILON * p.length().max(1.0),
                    "{name}: {p} vs {q}"
                );
            }
            for (p, q) in a.homogeneous_points().iter().zip(b.homogeneous_points()) {
                assert!(
                    (p.w - q.w).abs() <= 4.0 * f64::EPSILON * p.w,
                    "{name}: weights {p} vs {q}"
                );
            }
        }
    }
}

#[test]
fn convert_to_bpt_refuses_rational_patches() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("t.bpt");
    let o = run(&[
        "convert",
        testdata("torus.obj").to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("cannot store rational patches"),
        "{}",
        stderr(&o)
    );
    assert!(!out.exists());
}
