//! End to end: `patchtrace info` on good and bad free-form OBJ files.

use std::process::Command;

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
