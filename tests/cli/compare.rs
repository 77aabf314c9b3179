//! `tessellate` and `compare` through the binary, and meshes rendering like patches.

use crate::common;

use common::{run, stderr, stdout, testdata};

#[test]
fn obj_and_gltf_of_the_same_mesh_render_the_same_pixels() {
    let dir = tempfile::tempdir().unwrap();
    let mut images = Vec::new();
    for name in ["quad_mesh.obj", "quad_mesh.gltf"] {
        let out = dir.path().join(format!("{name}.png"));
        let o = run(&[
            "render",
            testdata(name).to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
            "-q",
            "--width",
            "48",
            "--height",
            "48",
            // glTF is framed y-up by default, OBJ z-up: the same framing for both.
            "--up",
            "z",
        ]);
        assert!(o.status.success(), "{name}: {}", stderr(&o));
        // The pixels, not the file: the file records the scene's fingerprint, and the two
        // readers' meshes differ in what the fingerprint sees (e.g. stored normals).
        images.push(image::open(&out).unwrap().to_rgba8().into_raw());
    }
    assert!(images[0] == images[1]);
}

#[test]
fn a_tessellated_scene_renders_close_to_the_direct_one() {
    // 4608 triangles per patch: the image differs from the exact surfaces only by shading
    // and silhouette details (Dammertz Table 2.1's middle row).
    let dir = tempfile::tempdir().unwrap();
    let o = run(&[
        "compare",
        testdata("teapot.ron").to_str().unwrap(),
        "--triangles",
        "8,4608",
        "--out-dir",
        dir.path().to_str().unwrap(),
        "--width",
        "64",
        "--height",
        "64",
        "-q",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let csv = std::fs::read_to_string(dir.path().join("compare.csv")).unwrap();
    let rows: Vec<Vec<&str>> = csv
        .lines()
        .skip(1)
        .map(|l| l.split(',').collect())
        .collect();
    assert_eq!(rows.len(), 3);
    assert_eq!(rows[0][6], "inf", "the direct image against itself");
    let rmse = |r: &Vec<&str>| r[5].parse::<f64>().unwrap();
    // More triangles, less error; both well below an unrelated image's (RMSE ~0.3).
    assert!(rmse(&rows[2]) < rmse(&rows[1]), "{csv}");
    assert!(rmse(&rows[2]) < 0.02, "{csv}");
    let triangles = |r: &Vec<&str>| r[1].parse::<u64>().unwrap();
    assert!(triangles(&rows[2]) > 100 * triangles(&rows[1]));
    for f in [
        "direct.png",
        "tess8.png",
        "tess4608.png",
        "flip8.png",
        "flip4608.png",
        "compare.md",
    ] {
        assert!(dir.path().join(f).exists(), "{f} missing");
    }
    assert!(stdout(&o).starts_with("| method |"));
}

#[test]
fn tessellate_writes_each_format_and_reports_counts() {
    let dir = tempfile::tempdir().unwrap();
    for (ext, args) in [
        ("obj", vec!["--triangles-per-patch", "512"]),
        ("gltf", vec!["--grid", "4,3"]),
        ("glb", vec!["--tolerance", "0.01"]),
    ] {
        let out = dir.path().join(format!("t.{ext}"));
        let input = testdata("teapot.bpt");
        let mut a = vec![
            "tessellate",
            input.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
            "--json",
        ];
        a.extend(args.iter().copied());
        let o = run(&a);
        assert!(o.status.success(), "{ext}: {}", stderr(&o));
        let r: serde_json::Value = serde_json::from_str(&stdout(&o)).unwrap();
        assert!(r["triangles"].as_u64().unwrap() > 0);
        assert_eq!(
            r["file_bytes"].as_u64().unwrap(),
            std::fs::metadata(&out).unwrap().len()
        );
        // The written mesh loads back as a scene with that many triangles.
        let scene = patchtrace::formats::load_scene(&out).unwrap();
        let tris: usize = scene
            .objects
            .iter()
            .map(|o| match &o.geometry {
                patchtrace::scene::Geometry::Mesh(m) => m.indices.len(),
                _ => 0,
            })
            .sum();
        assert_eq!(tris as u64, r["triangles"].as_u64().unwrap(), "{ext}");
    }
    let o = run(&[
        "tessellate",
        testdata("teapot.bpt").to_str().unwrap(),
        "-o",
        dir.path().join("x.obj").to_str().unwrap(),
        "--triangles-per-patch",
        "7",
    ]);
    assert_ne!(o.status.code(), Some(0));
    assert!(stderr(&o).contains("even count"), "{}", stderr(&o));
}

/// `compare --tolerance` tessellates by chord height as `tessellate --tolerance` does, and
/// `--against` a mesh file of that same tessellation (written as OBJ with its normals, read
/// back) renders the same pixels as the in-memory tessellation: two paths to one image.
#[test]
fn chord_tolerances_and_a_mesh_from_elsewhere_take_their_rows() {
    let dir = tempfile::tempdir().unwrap();
    let teapot = testdata("teapot.bpt");
    let mesh_file = dir.path().join("teapot.obj");
    let o = run(&[
        "tessellate",
        teapot.to_str().unwrap(),
        "-o",
        mesh_file.to_str().unwrap(),
        "--tolerance",
        "0.05",
        "--json",
        "-q",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let report: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let out = dir.path().join("cmp");
    let o = run(&[
        "compare",
        teapot.to_str().unwrap(),
        "--tolerance",
        "0.05mm",
        "--against",
        mesh_file.to_str().unwrap(),
        "--out-dir",
        out.to_str().unwrap(),
        "--width",
        "64",
        "--height",
        "64",
        "-q",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let csv = std::fs::read_to_string(out.join("compare.csv")).unwrap();
    let rows: Vec<Vec<&str>> = csv
        .lines()
        .skip(1)
        .map(|l| l.split(',').collect())
        .collect();
    // The direct render, the chord row, the mesh from the file; no default triangle rows.
    assert_eq!(rows.len(), 3, "{csv}");
    assert_eq!(rows[1][0], "chord 0.05 mm");
    assert_eq!(rows[2][0], "teapot.obj");
    let triangles = report["triangles"].as_u64().unwrap().to_string();
    assert_eq!(rows[1][1], triangles, "{csv}");
    assert_eq!(rows[2][1], triangles, "{csv}");
    // One material in the bare teapot: the same reference, the same pixels, the same error.
    assert_eq!(rows[1][5..9], rows[2][5..9], "{csv}");
    assert_ne!(rows[1][6], "inf", "{csv}");
    for f in [
        "chord5.000e-2.png",
        "flip-chord5.000e-2.png",
        "against0.png",
        "direct-plain.png",
    ] {
        assert!(out.join(f).exists(), "{f} missing");
    }
    // A tolerance that is not a length, and a file that is not a mesh, are bad input.
    for extra in [
        ["--tolerance", "0"],
        ["--against", teapot.to_str().unwrap()],
    ] {
        let mut args = vec!["compare", teapot.to_str().unwrap(), "-q"];
        args.extend_from_slice(&extra);
        args.extend_from_slice(&["--out-dir", out.to_str().unwrap()]);
        let o = run(&args);
        assert_eq!(o.status.code(), Some(2), "{extra:?}: {}", stderr(&o));
        assert!(
            stderr(&o).contains(extra[0]) || stderr(&o).contains("mesh"),
            "{}",
            stderr(&o)
        );
    }
}

/// The surface-error columns (max, p99, mean) of `compare`'s CSV, per row.
fn surface_errors(csv: &str) -> Vec<[f64; 3]> {
    csv.lines()
        .skip(1)
        .map(|l| {
            let cells: Vec<&str> = l.split(',').collect();
            [10, 11, 12].map(|k| cells[k].parse::<f64>().unwrap())
        })
        .collect()
}

#[test]
fn surface_error_is_rounding_on_a_plane_and_not_on_a_coarse_teapot() {
    // A mesh of a plane lies in the plane: along every ray that hits both, the two hits
    // are one point up to f32 rounding. Eight triangles per patch of the teapot cut
    // through its curvature: the mesh lies visibly off the surface.
    let dir = tempfile::tempdir().unwrap();
    let plane = dir.path().join("plane.obj");
    std::fs::write(
        &plane,
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\ncstype bezier\ndeg 1 1\nsurf 0 1 0 1 1 2 3 4\nparm u 0 1\nparm v 0 1\nend\n",
    )
    .unwrap();
    let mut errors = Vec::new();
    // Heat maps are named after the mesh's image: chord height 0.01 of the plane's
    // diagonal, √2, and 8 triangles per patch.
    for (scene, mode, heat) in [
        (plane.clone(), ["--tolerance", "0.01"], "chord1.414e-2"),
        (testdata("teapot.ron"), ["--triangles", "8"], "tess8"),
    ] {
        let out = dir.path().join(scene.file_stem().unwrap());
        let o = run(&[
            "compare",
            scene.to_str().unwrap(),
            mode[0],
            mode[1],
            "--out-dir",
            out.to_str().unwrap(),
            "--width",
            "64",
            "--height",
            "64",
            "-q",
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        let csv = std::fs::read_to_string(out.join("compare.csv")).unwrap();
        let rows = surface_errors(&csv);
        assert_eq!(
            rows[0],
            [0.0, 0.0, 0.0],
            "the direct render against itself: {csv}"
        );
        assert!(out.join(format!("{heat}-distance.png")).exists());
        errors.push(rows[1]);
    }
    // The plane is 1.41 across, the teapot about 7.
    assert!(errors[0][0] < 1e-5, "plane: {:?}", errors[0]);
    assert!(errors[1][2] > 1e-3 * 7.0, "teapot: {:?}", errors[1]);
}

/// `compare --tolerance 0.5mm` on a USD stage in centimetres (metersPerUnit 0.01) is a
/// chord of 0.05 stage units, so its images are named for 5e-2; the bare teapot, which
/// declares no unit, keeps millimetres as its own units (the test above).
#[test]
fn an_absolute_tolerance_is_millimetres_in_a_usd_stages_units() {
    let dir = tempfile::tempdir().unwrap();
    let part = std::fs::read_to_string(testdata("usd/part.usda")).unwrap();
    let stage = dir.path().join("part_cm.usda");
    std::fs::write(
        &stage,
        part.replacen("metersPerUnit = 1\n", "metersPerUnit = 0.01\n", 1),
    )
    .unwrap();
    let out = dir.path().join("cmp");
    let o = run(&[
        "compare",
        stage.to_str().unwrap(),
        "--tolerance",
        "0.5mm",
        "--out-dir",
        out.to_str().unwrap(),
        "--width",
        "32",
        "--height",
        "32",
        "-q",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        out.join("chord5.000e-2.png").exists(),
        "{:?}",
        std::fs::read_dir(&out)
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect::<Vec<_>>()
    );
    let o = run(&["info", stage.to_str().unwrap(), "-q"]);
    assert!(
        stdout(&o).contains("unit: lengths in stage units of 10 mm"),
        "{}",
        stdout(&o)
    );
}
