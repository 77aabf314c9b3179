//! Trims through the binary on `testdata/holed_plate.ron`: rays through the
//! plate's round holes reach the floor, rays beside them stop on the plate, rays at the
//! boss stop on it below its cut edge (a loop of three `curv2` pieces with ranges) and pass
//! above it; `--ignore-trims` gives the plate back its holes' discs. The answers are the
//! closed forms the scene was written from (holes of radius 0.45 about (0.9, 1) and 0.3
//! about (2, 1); the boss of radius 0.5 about (3.2, 1), cut at height 0.8 · v(u) along its
//! quadratic top edge).

use crate::common;

use common::testdata;

/// `object` of every row of `trace` for `rays`.
fn objects(rays: &str, extra: &[&str]) -> Vec<String> {
    common::trace_rows(&testdata("holed_plate.ron"), rays, extra)
        .into_iter()
        .map(|row| row[3].clone())
        .collect()
}

/// A ray straight down at (x, y) from above everything.
fn down(x: f64, y: f64) -> String {
    format!("{x} {y} 5 0 0 -1\n")
}

#[test]
fn holes_show_the_floor_and_the_plate_stops_rays_beside_them() {
    // The plate is object 0 (raised to z = 0.5), the floor object 1.
    let mut rays = String::new();
    let cases = [
        ((0.9, 1.0), "1"),
        ((0.9 + 0.44, 1.0), "1"),
        ((0.9 + 0.46, 1.0), "0"),
        ((0.9, 1.0 - 0.44), "1"),
        ((2.0, 1.0), "1"),
        ((2.0, 1.29), "1"),
        ((2.0, 1.31), "0"),
        ((1.5, 0.2), "0"),
        ((3.9, 1.9), "0"),
    ];
    for ((x, y), _) in cases {
        rays.push_str(&down(x, y));
    }
    let got = objects(&rays, &[]);
    for (((x, y), want), got) in cases.iter().zip(&got) {
        assert_eq!(got, want, "ray down at ({x}, {y})");
    }
    // Untrimmed, the holes are plate again.
    let untrimmed = objects(&rays, &["--ignore-trims"]);
    assert!(untrimmed[..2].iter().all(|o| o == "0"), "{untrimmed:?}");
}

#[test]
fn the_boss_is_cut_along_its_curved_top_edge() {
    // Horizontal rays towards the boss's axis from -y, which meet the cylinder at u = 3/4
    // (the point (3.2, 0.5) of the 9-point circle: angle 270°), where the cut's quadratic
    // top edge is at v(3/4)... The quadratic runs from (1, 1) through (0.5, -0.3) to (0, 1)
    // in (u, v), so at its parameter s it is at u = 1 - s, v = 1 - 2.6 s (1 - s): at
    // u = 3/4 (s = 1/4), v = 1 - 2.6 · 3/16 = 0.5125, height 0.5 + 0.8 · 0.5125 = 0.91.
    let edge = 0.5 + 0.8 * (1.0 - 2.6 * 0.25 * 0.75);
    let mut rays = String::new();
    for z in [0.6, edge - 0.02, edge + 0.02, 1.25] {
        rays.push_str(&format!("3.2 -3 {z} 0 1 0\n"));
    }
    let got = objects(&rays, &[]);
    assert_eq!(got[0], "0", "below the cut: the boss");
    assert_eq!(got[1], "0", "just below the cut: the boss");
    assert_eq!(got[2], "", "just above the cut the ray passes: {got:?}");
    assert_eq!(got[3], "", "{got:?}");
}
