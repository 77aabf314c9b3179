//! The batch-rendering examples run as a user types them: `examples/parallel-tiles.sh`
//! (GNU parallel, when it is installed: CI installs it) renders tiles and merges them into
//! the image a single render writes, byte for byte. The Slurm example needs a cluster; it
//! is checked by hand on a one-node Slurm (README, "Batch rendering").

use std::path::Path;
use std::process::Command;

use crate::common::{render, stderr, testdata};

#[test]
fn parallel_tiles_example_merges_to_the_single_render() {
    let found = Command::new("parallel").arg("--version").output();
    if !found.is_ok_and(|o| o.status.success()) {
        eprintln!("skipped: GNU parallel is not installed");
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let (tiled, single) = (dir.path().join("tiled.png"), dir.path().join("single.png"));
    let scene = testdata("teapot.ron");
    let bin_dir = Path::new(env!("CARGO_BIN_EXE_patchtrace"))
        .parent()
        .unwrap();
    let path = format!(
        "{}:{}",
        bin_dir.display(),
        std::env::var("PATH").unwrap_or_default()
    );
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/parallel-tiles.sh");
    let o = Command::new(script)
        .args([scene.to_str().unwrap(), tiled.to_str().unwrap(), "3"])
        .env("PATH", path)
        .env("SPP", "1")
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    let o = render(&scene, &single, (512, 512), &["--spp", "1"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        std::fs::read(&tiled).unwrap() == std::fs::read(&single).unwrap(),
        "the merged tiles differ from the single render"
    );
}
