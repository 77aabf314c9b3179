//! Progress bars: the long steps advance their bar to its end, counted
//! independently of the code (primitives of the scene, methods of the bench), and the
//! binary draws bars on a terminal only, never with `--quiet` or into a pipe.

use crate::common;

use std::process::Command;

use common::{run, stderr, testdata};
use patchtrace::accel::bvh::Bvh;
use patchtrace::accel::scene::SceneGeometry;
use patchtrace::geom::Aabb;
use patchtrace::progress::ProgressBar;
use patchtrace::scene::{Geometry, load_scene};

#[test]
fn bvh_builds_count_every_primitive_once_per_phase() {
    let boxes: Vec<Aabb> = (0..37)
        .map(|i| {
            let p = glam::Vec3::new(i as f32, (i * 7 % 5) as f32, 0.0);
            Aabb::new(p, p + glam::Vec3::ONE)
        })
        .collect();
    let bar = ProgressBar::hidden();
    Bvh::build_packed_with(&boxes, boxes.len(), &bar);
    assert_eq!(bar.position(), 37);

    // The teapot scene: its patches (teapot.bpt) and the one-patch floor, each bounded
    // and then placed in a leaf.
    let scene = load_scene(&testdata("teapot.ron")).unwrap();
    let patches: usize = scene
        .objects
        .iter()
        .map(|o| match &o.geometry {
            Geometry::Surfaces(s) => s.len(),
            _ => 0,
        })
        .sum();
    let teapot = patchtrace::scene::bpt::read_bpt(&testdata("teapot.bpt")).unwrap();
    assert_eq!(patches, teapot.len() + 1);
    let bar = ProgressBar::hidden();
    SceneGeometry::build_with(&scene, &bar);
    assert_eq!(
        (bar.position(), bar.length()),
        (2 * patches as u64, Some(2 * patches as u64))
    );
}

/// `patchtrace ARGS` with stderr on a pseudo-terminal, by util-linux `script`; its
/// terminal output, or `None` where `script` is not installed.
fn on_a_terminal(args: &[&str]) -> Option<String> {
    let line = std::iter::once(env!("CARGO_BIN_EXE_patchtrace"))
        .chain(args.iter().copied())
        .map(|a| format!("'{a}'"))
        .collect::<Vec<_>>()
        .join(" ");
    let o = Command::new("script")
        .args(["-qec", &line, "/dev/null"])
        .output()
        .ok()?;
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    Some(String::from_utf8_lossy(&o.stdout).into_owned())
}

#[test]
fn bars_draw_on_a_terminal_only_and_never_with_quiet() {
    let dir = tempfile::tempdir().unwrap();
    let scene = testdata("teapot.ron");
    let bvh = dir.path().join("t.bvh");
    let mesh = dir.path().join("t.obj");
    let commands: [(Vec<&str>, &str); 2] = [
        (
            vec!["bvh", scene.to_str().unwrap(), "-o", bvh.to_str().unwrap()],
            "building BVH",
        ),
        (
            vec![
                "tessellate",
                scene.to_str().unwrap(),
                "-o",
                mesh.to_str().unwrap(),
            ],
            "tessellating",
        ),
    ];
    for (args, label) in &commands {
        // Into a pipe (how `cargo test` captures it): no bar, no carriage returns.
        let o = run(args);
        assert!(o.status.success(), "{}", stderr(&o));
        assert!(
            !stderr(&o).contains(label) && !stderr(&o).contains('\r'),
            "{}",
            stderr(&o)
        );
        let Some(shown) = on_a_terminal(args) else {
            eprintln!("`script` is not installed: the terminal half is not checked");
            return;
        };
        assert!(shown.contains(label), "{args:?}: {shown}");
        let quiet: Vec<&str> = args.iter().copied().chain(["--quiet"]).collect();
        let hidden = on_a_terminal(&quiet).unwrap();
        assert!(!hidden.contains(label), "{quiet:?}: {hidden}");
    }
}
