//! Catmull–Clark cages on the command line: every OpenSubdiv regression cage in
//! `testdata/opensubdiv` renders or is refused with its reason, RON scenes take
//! `Subdivision(File(..))`, and `trace` reports the quad after the first step.

use crate::common;

use common::{run, stderr, stdout, testdata};

const CAGES: [&str; 14] = [
    "catmark_bishop",
    "catmark_car",
    "catmark_cube",
    "catmark_edgeonly",
    "catmark_fan",
    "catmark_gregory_test1",
    "catmark_helmet",
    "catmark_pawn",
    "catmark_pyramid",
    "catmark_quadstrips",
    "catmark_rook",
    "catmark_square_hedit0",
    "catmark_torus",
    "catmark_torus_creases0",
];

#[test]
fn every_opensubdiv_cage_renders_or_is_refused_with_its_reason() {
    let dir = tempfile::tempdir().unwrap();
    for name in CAGES {
        let cage = testdata(&format!("opensubdiv/{name}.obj"));
        let out = dir.path().join(format!("{name}.png"));
        let o = run(&[
            "render",
            cage.to_str().unwrap(),
            "--subdivide",
            "catmull-clark",
            "-o",
            out.to_str().unwrap(),
            "-q",
            "--width",
            "24",
            "--height",
            "24",
        ]);
        if name == "catmark_fan" {
            // PROVENANCE.txt: 4 non-manifold edges (3 faces each).
            assert_eq!(o.status.code(), Some(2), "{name}: {}", stderr(&o));
            assert!(
                stderr(&o).contains("is used by 3 faces (non-manifold)"),
                "{name}: {}",
                stderr(&o)
            );
        } else {
            assert!(o.status.success(), "{name}: {}", stderr(&o));
            let img = image::open(&out).unwrap().to_rgb8();
            // The surface covers some pixels: not every pixel is the background.
            let bg = img.get_pixel(0, 0);
            assert!(img.pixels().any(|p| p != bg), "{name}: empty image");
        }
    }
}

#[test]
fn trace_reports_the_quad_after_the_first_step() {
    let dir = tempfile::tempdir().unwrap();
    let rays = dir.path().join("rays.txt");
    // Down the z axis onto the cube cage (±1.414 in x, y; ±1 in z): hits the top.
    std::fs::write(&rays, "0.05 0.1 5 0 0 -1\n0.3 -0.2 -5 0 0 1\n").unwrap();
    let cage = testdata("opensubdiv/catmark_cube.obj");
    let o = run(&[
        "trace",
        cage.to_str().unwrap(),
        "--subdivide",
        "catmull-clark",
        "--rays",
        rays.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = stdout(&o);
    let rows: Vec<Vec<&str>> = text
        .lines()
        .skip(1)
        .map(|l| l.split(',').collect())
        .collect();
    assert_eq!(rows.len(), 2);
    for (k, r) in rows.iter().enumerate() {
        assert_eq!(r[1], "1", "ray {k} hits: {text}");
        // 6 quads of the cage make 24 quads after one step.
        let patch: u32 = r[4].parse().unwrap();
        assert!(patch < 24, "{text}");
        let (u, v): (f64, f64) = (r[5].parse().unwrap(), r[6].parse().unwrap());
        assert!(
            (0.0..=1.0).contains(&u) && (0.0..=1.0).contains(&v),
            "{text}"
        );
    }
    // Cage face 0 (`f 1 2 4 3`, z = +1) makes quads 0..4, face 2 (`f 5 6 8 7`, z = -1)
    // quads 8..12: the top ray lands in the first, the bottom ray in the second.
    let (top, bottom): (u32, u32) = (rows[0][4].parse().unwrap(), rows[1][4].parse().unwrap());
    assert!(top < 4, "{text}");
    assert!((8..12).contains(&bottom), "{text}");
}

#[test]
fn ron_scenes_take_a_subdivision_cage_and_bad_uses_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::copy(
        testdata("opensubdiv/catmark_torus.obj"),
        dir.path().join("cage.obj"),
    )
    .unwrap();
    let scene = dir.path().join("s.ron");
    std::fs::write(
        &scene,
        r#"Scene(
    camera: (eye: (0, -6, 3), look_at: (0, 0, 0), up: (0, 0, 1), fov_y: 40, width: 16, height: 16),
    lights: [Point(position: (4, -4, 6), intensity: (1, 1, 1))],
    objects: [(geometry: Subdivision(File("cage.obj")), transform: [Scale(2.0)])],
)"#,
    )
    .unwrap();
    let o = run(&["info", scene.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    // 32 quads, all regular: 128 quads after one step, each one Bézier patch.
    assert!(stdout(&o).contains("patches: 128 "), "{}", stdout(&o));
    // --subdivide is for bare meshes, and a Bézier file is no cage.
    let o = run(&[
        "info",
        scene.to_str().unwrap(),
        "--subdivide",
        "catmull-clark",
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("Subdivision(File"), "{}", stderr(&o));
    let o = run(&[
        "info",
        testdata("teapot.bpt").to_str().unwrap(),
        "--subdivide",
        "catmull-clark",
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("not a polygon mesh"), "{}", stderr(&o));
}
