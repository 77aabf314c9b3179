//! Every bad-input path prints `file:line:col: what was expected` (or names the file) and
//! exits with status 2, never panics, and never leaves an output file behind.

use crate::common;

use std::path::{Path, PathBuf};

use common::{run, stderr, testdata};

struct Case {
    _dir: tempfile::TempDir,
    path: PathBuf,
}

fn file(name: &str, text: &str) -> Case {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join(name);
    std::fs::write(&path, text).unwrap();
    Case { _dir: dir, path }
}

/// Runs `info` on the file and returns stderr after checking status 2 and no panic.
fn info_fails(path: &Path) -> String {
    let o = run(&["info", path.to_str().unwrap()]);
    let err = stderr(&o);
    assert_eq!(
        o.status.code(),
        Some(2),
        "status for {}: {err}",
        path.display()
    );
    assert!(!err.contains("panicked"), "{err}");
    err
}

fn bpt_patch(coords: &str) -> String {
    format!("1\n1 1\n{coords}\n1 0 0\n0 1 0\n1 1 0\n")
}

#[test]
fn bpt_nan_coordinate() {
    let c = file("nan.bpt", &bpt_patch("0 nan 0"));
    let err = info_fails(&c.path);
    assert!(err.contains("nan.bpt:3:3: expected coordinate of control point 0 of patch 0 as a finite number, found `nan`"), "{err}");
}

#[test]
fn bpt_infinite_coordinate() {
    let c = file("inf.bpt", &bpt_patch("0 0 inf"));
    let err = info_fails(&c.path);
    assert!(
        err.contains("inf.bpt:3:5:") && err.contains("finite"),
        "{err}"
    );
}

#[test]
fn bpt_degree_above_fifteen() {
    let c = file("deg.bpt", "1\n16 1\n");
    let err = info_fails(&c.path);
    assert!(
        err.contains("deg.bpt:2:1: expected a degree from 1 to 15 for patch 0, found `16`"),
        "{err}"
    );
}

#[test]
fn bpt_too_few_points() {
    let c = file("short.bpt", "1\n1 1\n0 0 0\n1 0 0\n");
    let err = info_fails(&c.path);
    assert!(
        err.contains("short.bpt:")
            && err.contains("expected coordinate of control point 2 of patch 0, found end of file"),
        "{err}"
    );
}

#[test]
fn bpt_more_data_than_the_count_says() {
    let c = file("long.bpt", &format!("{}7\n", bpt_patch("0 0 0")));
    let err = info_fails(&c.path);
    assert!(
        err.contains("long.bpt:7:1: expected end of file, found `7`"),
        "{err}"
    );
}

#[test]
fn bpt_bad_count() {
    let c = file("count.bpt", "-3\n");
    let err = info_fails(&c.path);
    assert!(
        err.contains("count.bpt:1:1: expected the patch count"),
        "{err}"
    );
}

#[test]
fn ron_syntax_error_has_line_and_column() {
    let c = file(
        "bad.ron",
        "Scene(\n    camera: (eye: (0, 0, 1), look_at: (0, 0, 0) up: (0, 1, 0)),\n)\n",
    );
    let err = info_fails(&c.path);
    assert!(err.contains("bad.ron:2:"), "{err}");
}

#[test]
fn ron_unknown_material() {
    let text = std::fs::read_to_string(testdata("teapot.ron"))
        .unwrap()
        .replace("material: \"pink\"", "material: \"chrome\"")
        .replace(
            "File(\"teapot.bpt\")",
            &format!("File({:?})", testdata("teapot.bpt")),
        );
    let c = file("mat.ron", &text);
    let err = info_fails(&c.path);
    // Located at the object's `geometry:` key (line 11 of teapot.ron).
    assert!(
        err.contains("mat.ron:11:") && err.contains("object 0 uses material \"chrome\""),
        "{err}"
    );
}

#[test]
fn ron_negative_weight_inline() {
    let c = file(
        "w.ron",
        r#"Scene(camera: (eye: (0, -5, 0), look_at: (0, 0, 0), up: (0, 0, 1), fov_y: 40, width: 8, height: 8),
           objects: [(geometry: Surfaces([Bezier(degree: (1, 1), points: [(0,0,0),(1,0,0),(0,1,0),(1,1,0)], weights: [1, 1, -1, 1])]))])"#,
    );
    let err = info_fails(&c.path);
    assert!(err.contains("control point 2 has weight -1"), "{err}");
}

#[test]
fn missing_file_names_the_path() {
    let err = info_fails(Path::new("/nonexistent/dir/scene.ron"));
    assert!(err.contains("/nonexistent/dir/scene.ron"), "{err}");
}

#[test]
fn referenced_geometry_missing_names_that_file() {
    let c = file(
        "ref.ron",
        r#"Scene(camera: (eye: (0, -5, 0), look_at: (0, 0, 0), up: (0, 0, 1), fov_y: 40, width: 8, height: 8),
           objects: [(geometry: File("missing.bpt"))])"#,
    );
    let err = info_fails(&c.path);
    assert!(err.contains("missing.bpt"), "{err}");
}

#[test]
fn unknown_extension() {
    let c = file("scene.txt", "whatever");
    let err = info_fails(&c.path);
    assert!(err.contains("unknown file type"), "{err}");
}

#[test]
fn bad_camera_is_refused() {
    let c = file(
        "cam.ron",
        r#"Scene(camera: (eye: (0, 0, 0), look_at: (0, 0, 0), up: (0, 0, 1), fov_y: 40, width: 8, height: 8), objects: [])"#,
    );
    let err = info_fails(&c.path);
    assert!(err.contains("look_at must differ from eye"), "{err}");
}

#[test]
fn writing_rational_patches_to_bpt_is_refused_and_leaves_no_file() {
    let c = file(
        "rat.ron",
        r#"Scene(camera: (eye: (0, -5, 0), look_at: (0, 0, 0), up: (0, 0, 1), fov_y: 40, width: 8, height: 8),
           objects: [(geometry: Surfaces([Bezier(degree: (1, 1), points: [(0,0,0),(1,0,0),(0,1,0),(1,1,0)], weights: [1, 2, 1, 1])]))])"#,
    );
    let out = c.path.with_file_name("out.bpt");
    let o = run(&[
        "import",
        c.path.to_str().unwrap(),
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
    let leftovers: Vec<_> = std::fs::read_dir(c.path.parent().unwrap())
        .unwrap()
        .collect();
    assert_eq!(leftovers.len(), 1, "only the input remains");
}

#[test]
fn render_to_an_unknown_image_type_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("x.jpg");
    let o = run(&[
        "render",
        testdata("teapot.ron").to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "-q",
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("expected .png or .exr"));
    assert!(!out.exists());
}

#[test]
fn bpt_round_trips_through_import() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("t.bpt");
    let o = run(&[
        "import",
        testdata("teapot.bpt").to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let a = patchtrace::scene::bpt::read_bpt(&testdata("teapot.bpt")).unwrap();
    let b = patchtrace::scene::bpt::read_bpt(&out).unwrap();
    assert_eq!(a, b);
}

#[test]
fn ron_round_trips_through_import() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("t.ron");
    let o = run(&[
        "import",
        testdata("teapot.ron").to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let a = patchtrace::scene::load_scene(&testdata("teapot.ron")).unwrap();
    let b = patchtrace::scene::load_scene(&out).unwrap();
    assert_eq!(a.camera, b.camera);
    assert_eq!(a.lights, b.lights);
    assert_eq!(a.objects.len(), b.objects.len());
    for (x, y) in a.objects.iter().zip(&b.objects) {
        assert_eq!(x.bezier_patches(), y.bezier_patches());
        assert_eq!(a.materials[x.material], b.materials[y.material]);
    }
}

#[test]
fn a_closed_pipe_is_not_an_error() {
    // `patchtrace info x | head -1`: stdout closes early; no panic, status 0.
    use std::process::Stdio;
    let mut child = common::bin()
        .args(["info", testdata("teapot.ron").to_str().unwrap()])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stdout.take());
    let o = child.wait_with_output().unwrap();
    assert!(!stderr(&o).contains("panicked"), "{}", stderr(&o));
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
}

#[test]
fn coordinates_beyond_f32_after_transforms_are_refused_naming_the_object() {
    let text = std::fs::read_to_string(testdata("teapot.ron"))
        .unwrap()
        .replace(
            "material: \"pink\")",
            "material: \"pink\", transform: [Scale(1e38)])",
        )
        .replace(
            "File(\"teapot.bpt\")",
            &format!("File({:?})", testdata("teapot.bpt")),
        );
    let c = file("huge.ron", &text);
    let err = info_fails(&c.path);
    assert!(
        err.contains("object \"teapot\": coordinates reach") && err.contains("f32 range"),
        "{err}"
    );
}

#[test]
fn objects_in_the_subnormal_range_are_refused_naming_the_object() {
    let text = std::fs::read_to_string(testdata("teapot.ron"))
        .unwrap()
        .replace(
            "material: \"pink\")",
            "material: \"pink\", transform: [Scale(1e-35)])",
        )
        .replace(
            "File(\"teapot.bpt\")",
            &format!("File({:?})", testdata("teapot.bpt")),
        );
    let c = file("tiny.ron", &text);
    let err = info_fails(&c.path);
    assert!(
        err.contains("object \"teapot\" is only") && err.contains("subnormal"),
        "{err}"
    );
}
