//! Helpers for tests that drive the real binary.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

pub fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_patchtrace"))
}

pub fn testdata(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("testdata")
        .join(name)
}

/// Runs the binary with `args`, returning its output.
pub fn run(args: &[&str]) -> Output {
    bin().args(args).output().expect("run patchtrace")
}

pub fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

pub fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

/// `patchtrace render SCENE -o OUT -q --width W --height H EXTRA...`.
pub fn render(scene: &Path, out: &Path, (width, height): (u32, u32), extra: &[&str]) -> Output {
    let (w, h) = (width.to_string(), height.to_string());
    let mut args = vec![
        "render",
        scene.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "-q",
        "--width",
        &w,
        "--height",
        &h,
    ];
    args.extend_from_slice(extra);
    run(&args)
}

/// `patchtrace trace SCENE --rays FILE EXTRA...` on the ray text `rays`: the CSV rows
/// after the contract header (checked), split at commas.
pub fn trace_rows(scene: &Path, rays: &str, extra: &[&str]) -> Vec<Vec<String>> {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("rays.txt");
    std::fs::write(&file, rays).unwrap();
    let mut args = vec![
        "trace",
        scene.to_str().unwrap(),
        "--rays",
        file.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    let o = run(&args);
    assert!(o.status.success(), "{}", stderr(&o));
    let out = stdout(&o);
    let mut lines = out.lines();
    assert_eq!(
        lines.next(),
        Some("ray,hit,t,object,patch,u,v,px,py,pz,nx,ny,nz")
    );
    lines
        .map(|l| l.split(',').map(str::to_string).collect())
        .collect()
}

/// The hit point and normal of each ray `(origin, direction)` through `trace`, `None` for a
/// miss.
pub fn trace_hits(
    scene: &Path,
    rays: &[(glam::DVec3, glam::DVec3)],
) -> Vec<Option<(glam::DVec3, glam::DVec3)>> {
    let text: String = rays
        .iter()
        .map(|(o, d)| format!("{} {} {} {} {} {}\n", o.x, o.y, o.z, d.x, d.y, d.z))
        .collect();
    trace_rows(scene, &text, &[])
        .iter()
        .map(|f| {
            let v = |k: usize| {
                glam::DVec3::new(
                    f[k].parse().unwrap(),
                    f[k + 1].parse().unwrap(),
                    f[k + 2].parse().unwrap(),
                )
            };
            (f[1] == "1").then(|| (v(7), v(10)))
        })
        .collect()
}
