//! Scenes far from the world origin render and trace at the precision of the model's own
//! size (the floating origin, `scene::origin`), through a BVH file as without one.

use crate::common;

use std::path::{Path, PathBuf};

use common::{render, run, stderr, testdata, trace_rows};
use glam::DVec3;

/// Where the teapot is moved: 14 m from the origin in millimetre terms, 2,300 teapot
/// extents, where an `f32` ulp (2^-10) is 4,000 times the teapot's own (2^-22 at 3).
const FAR: DVec3 = DVec3::new(14_000.0, -3_000.0, 250.0);

/// The bundled teapot and a point light, moved by `offset`, camera in front of it.
fn teapot_at(dir: &Path, offset: DVec3) -> PathBuf {
    let path = dir.join("far.ron");
    let (e, l, p) = (
        offset + DVec3::new(0.0, -8.0, 4.5),
        offset + DVec3::new(0.0, 0.0, 1.2),
        offset + DVec3::new(6.0, -6.0, 10.0),
    );
    let text = format!(
        "Scene(camera: (eye: ({}, {}, {}), look_at: ({}, {}, {}), up: (0, 0, 1), fov_y: 40, width: 32, height: 32),
        lights: [Point(position: ({}, {}, {}), intensity: (1, 1, 1))],
        materials: {{\"pink\": (diffuse: (0.9, 0.5, 0.6), specular: 0.6, shininess: 40, reflect: 0.3)}},
        objects: [(name: \"teapot\", geometry: File({:?}), material: \"pink\", transform: [Translate({}, {}, {})])])",
        e.x,
        e.y,
        e.z,
        l.x,
        l.y,
        l.z,
        p.x,
        p.y,
        p.z,
        testdata("teapot.bpt"),
        offset.x,
        offset.y,
        offset.z
    );
    std::fs::write(&path, text).unwrap();
    path
}

/// Rays from the camera across the teapot, in the frame moved by `offset`.
fn camera_rays(offset: DVec3) -> String {
    let eye = offset + DVec3::new(0.0, -8.0, 4.5);
    (0..24)
        .flat_map(|i| (0..6).map(move |j| (i, j)))
        .map(|(i, j)| {
            let target = offset + DVec3::new(-3.0 + 0.25 * i as f64, 0.0, 0.3 + 0.45 * j as f64);
            let d = target - eye;
            format!("{} {} {} {} {} {}\n", eye.x, eye.y, eye.z, d.x, d.y, d.z)
        })
        .collect()
}

fn field(row: &[String], k: usize) -> f64 {
    row[k].parse().unwrap()
}

fn vec_at(row: &[String], k: usize) -> DVec3 {
    DVec3::new(field(row, k), field(row, k + 1), field(row, k + 2))
}

#[test]
fn a_far_teapot_is_hit_to_the_ulps_of_its_own_size() {
    let dir = tempfile::tempdir().unwrap();
    let scene = teapot_at(dir.path(), FAR);
    let rays = camera_rays(FAR);
    let f32_rows = trace_rows(&scene, &rays, &["--precision", "f32"]);
    let f64_rows = trace_rows(&scene, &rays, &["--precision", "f64"]);
    // The teapot's coordinates reach 3.5 about its centre: its own ulp there is 2^-22.
    let model_ulp = f64::from(f32::EPSILON) * 2.0;
    let mut hits = 0;
    for (a, r) in f32_rows.iter().zip(&f64_rows) {
        assert_eq!(a[1], r[1], "hit or miss differ: {a:?} {r:?}");
        if r[1] != "1" || a[4] != r[4] {
            continue;
        }
        hits += 1;
        let (p, pr, n) = (vec_at(a, 7), vec_at(r, 7), vec_at(r, 10));
        // The hit point lies within 64 of the model's ulps across the surface (along the
        // ray a grazing hit may move by that over the cosine, which the normal removes).
        let across = (p - pr).dot(n).abs();
        assert!(
            across <= 64.0 * model_ulp,
            "{a:?} vs {r:?}: {across} across"
        );
        // And it is a point of the teapot, not of something else.
        assert!((p - FAR).length() < 4.0, "{p} is not on the teapot");
    }
    assert!(hits > 100, "{hits} hits");
}

#[test]
fn a_bvh_file_of_a_far_scene_renders_and_traces_as_the_scene_itself() {
    let dir = tempfile::tempdir().unwrap();
    let scene = teapot_at(dir.path(), FAR);
    let bvh = dir.path().join("far.bvh");
    let o = run(&[
        "bvh",
        scene.to_str().unwrap(),
        "-o",
        bvh.to_str().unwrap(),
        "-q",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let rays = camera_rays(FAR);
    let direct = trace_rows(&scene, &rays, &[]);
    let mapped = trace_rows(&scene, &rays, &["--bvh", bvh.to_str().unwrap()]);
    assert_eq!(direct, mapped);
    let (a, b) = (dir.path().join("a.png"), dir.path().join("b.png"));
    let o = render(&scene, &a, (32, 32), &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    let o = render(&scene, &b, (32, 32), &["--bvh", bvh.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
}

#[test]
fn the_far_teapot_renders_as_the_teapot_at_home() {
    // Moving the whole scene changes only roundings of the model's own size: the image
    // of the far scene differs from the one at home in a few edge pixels at most.
    let dir = tempfile::tempdir().unwrap();
    let far = teapot_at(dir.path(), FAR);
    let home_dir = tempfile::tempdir().unwrap();
    let home = teapot_at(home_dir.path(), DVec3::ZERO);
    let (a, b) = (dir.path().join("far.png"), dir.path().join("home.png"));
    for (scene, out) in [(&far, &a), (&home, &b)] {
        let o = render(scene, out, (32, 32), &[]);
        assert!(o.status.success(), "{}", stderr(&o));
    }
    let (a, b) = (
        image::open(&a).unwrap().to_rgba8(),
        image::open(&b).unwrap().to_rgba8(),
    );
    let differing = a
        .pixels()
        .zip(b.pixels())
        .filter(|(p, q)| p.0.iter().zip(q.0).any(|(x, y)| x.abs_diff(y) > 2))
        .count();
    assert!(differing <= 8, "{differing} of 1024 pixels differ");
}
