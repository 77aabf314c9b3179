//! `trace` against the DESIGN.md contract.

use crate::common;

use common::{run, stderr, testdata};

fn trace(rays: &str, extra: &[&str]) -> Vec<Vec<String>> {
    common::trace_rows(&testdata("teapot.ron"), rays, extra)
}

#[test]
fn rows_follow_the_contract() {
    // Ray 0 hits the floor from above at (3, 3, 0) (t = 5 with a unit direction scaled by
    // 2: t is in units of the given direction, so 2.5). Ray 1 misses upwards. Ray 2 hits the
    // floor patch's plane outside the teapot, 1 unit ahead, but tmax = 0.5 stops it.
    let rows = trace(
        "# comment\n3 3 5 0 0 -2\n\n0 0 10 0 0 1\n15 15 1 0 0 -1 0 0.5\n",
        &[],
    );
    assert_eq!(rows.len(), 3);
    assert_eq!(rows[0][0], "0");
    assert_eq!(rows[0][1], "1");
    let t: f64 = rows[0][2].parse().unwrap();
    assert!((t - 2.5).abs() < 1e-5, "t = {t}");
    assert_eq!(rows[0][3], "1", "floor is object 1");
    assert_eq!(rows[0][4], "0");
    let (u, v): (f64, f64) = (rows[0][5].parse().unwrap(), rows[0][6].parse().unwrap());
    // The floor maps (u, v) linearly onto [-20, 20]²: (3, 3) is at u = v = 23/40.
    assert!(
        (u - 23.0 / 40.0).abs() < 1e-5 && (v - 23.0 / 40.0).abs() < 1e-5,
        "{u} {v}"
    );
    let pz: f64 = rows[0][9].parse().unwrap();
    assert!(pz.abs() < 1e-5);
    let n: Vec<f64> = rows[0][10..13].iter().map(|s| s.parse().unwrap()).collect();
    assert!((n[2].abs() - 1.0).abs() < 1e-12, "{n:?}");
    for miss in [&rows[1], &rows[2]] {
        assert_eq!(miss[1], "0");
        assert!(miss[2..].iter().all(String::is_empty), "{miss:?}");
        assert_eq!(miss.len(), 13);
    }
}

#[test]
fn f32_and_f64_paths_agree_on_camera_rays() {
    // Rays from the scene camera towards the teapot body.
    let mut rays = String::new();
    for k in 0..20 {
        let x = -1.0 + 0.1 * k as f64;
        rays.push_str(&format!("0 -8 4.5 {x} 8 {}\n", -3.0 + 0.05 * k as f64));
    }
    let a = trace(&rays, &["--precision", "f32"]);
    let b = trace(&rays, &["--precision", "f64"]);
    let mut hits = 0;
    for (ra, rb) in a.iter().zip(&b) {
        assert_eq!(ra[1], rb[1], "hit/miss differ: {ra:?} {rb:?}");
        if ra[1] == "1" {
            hits += 1;
            let (ta, tb): (f64, f64) = (ra[2].parse().unwrap(), rb[2].parse().unwrap());
            assert!((ta - tb).abs() <= 1e-5 * tb.abs(), "{ta} vs {tb}");
            assert_eq!(ra[3], rb[3], "object");
            if ra[4] != rb[4] {
                // A ray along a shared edge may report either neighbour; then both hits
                // are on a patch boundary (u or v at 0 or 1).
                let on_edge = |r: &Vec<String>| {
                    r[5..7].iter().any(|s| {
                        let x: f64 = s.parse().unwrap();
                        x.min(1.0 - x).abs() < 1e-6
                    })
                };
                assert!(
                    on_edge(ra) && on_edge(rb),
                    "different patches off an edge: {ra:?} {rb:?}"
                );
            }
        }
    }
    assert!(hits >= 10, "only {hits} hits");
}

#[test]
fn a_bad_ray_file_names_line_and_column() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("rays.txt");
    std::fs::write(&file, "0 0 0 0 0 1\n0 0 0 0 zero 1\n").unwrap();
    let scene = testdata("teapot.ron");
    let o = run(&[
        "trace",
        scene.to_str().unwrap(),
        "--rays",
        file.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2));
    let err = stderr(&o);
    assert!(err.contains("rays.txt:2:9: expected dy"), "{err}");
}
