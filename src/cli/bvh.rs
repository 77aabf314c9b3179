//! `patchtrace bvh SCENE -o FILE`: build and write the acceleration structure.

use std::process::ExitCode;
use std::time::Instant;

use crate::accel::scene::SceneGeometry;
use crate::cli::args::BvhArgs;
use crate::scene::load_scene_with;

pub fn run(args: BvhArgs) -> anyhow::Result<ExitCode> {
    let scene = load_scene_with(&args.scene, args.mesh.load_options())?;
    let start = Instant::now();
    let geometry = SceneGeometry::build(&scene);
    let build = start.elapsed().as_secs_f64();
    geometry.save_bvh(&args.output)?;
    eprintln!(
        "wrote {}: {} patches, {} nodes, built in {:.3} s",
        args.output.display(),
        geometry.patch_count(),
        geometry.bvh().map_or(0, |b| b.node_count()),
        build
    );
    Ok(ExitCode::SUCCESS)
}
