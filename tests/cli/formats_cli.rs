//! End to end: `patchtrace info` on good and bad free-form OBJ files, and `import` to OBJ.

use std::process::Command;

use patchtrace::geom::BezierPatch;
use patchtrace::geom::bezier::ParamRect;
use patchtrace::scene::SurfaceGeometry;
use patchtrace::scene::obj::parse_obj_freeform;

fn patchtrace() -> Command {
    Command::new(env!("CARGO_BIN_EXE_patchtrace"))
}

#[test]
fn a_bad_obj_file_exits_2_with_its_position() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bad.obj");
    std::fs::write(&path, "cstype bezier\ndeg 1 1\nv 0 0 0\nv 1 nan 0\n").unwrap();
    let out = patchtrace().arg("info").arg(&path).output().unwrap();
    assert_eq!(out.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&out.stderr);
    let prefix = format!("patchtrace: {}:4:5: expected y coordinate", path.display());
    assert!(stderr.starts_with(&prefix), "{stderr}");
}

#[test]
fn info_counts_the_patches_of_a_piecewise_bezier_file() {
    let file = concat!(env!("CARGO_MANIFEST_DIR"), "/testdata/bezier_pieces.obj");
    let out = patchtrace().args(["info", file]).output().unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(stdout.contains("patches: 4 (0 rational)"), "{stdout}");
    assert!(stdout.contains("3x2: 4"), "{stdout}");
}

#[test]
fn import_to_obj_writes_patches_that_read_back_unchanged() {
    let input = concat!(env!("CARGO_MANIFEST_DIR"), "/testdata/bezier_pieces.obj");
    let dir = tempfile::tempdir().unwrap();
    let output = dir.path().join("out.obj");
    let out = patchtrace()
        .args(["import", input, "-o"])
        .arg(&output)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let read = |path: &std::path::Path| -> Vec<BezierPatch> {
        let src = std::fs::read_to_string(path).unwrap();
        parse_obj_freeform(path, &src)
            .unwrap()
            .into_iter()
            .map(|s| match s.geometry {
                // The writer does not store domains; compare the control nets.
                SurfaceGeometry::Bezier(p) => p.with_domain(ParamRect::UNIT),
                other => panic!("expected Bézier patches, found {other:?}"),
            })
            .collect()
    };
    let original = read(std::path::Path::new(input));
    assert_eq!(original.len(), 4);
    assert_eq!(read(&output), original);
}
