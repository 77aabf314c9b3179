//! `patchtrace bvh SCENE -o FILE`: build and write the acceleration structure.

use std::process::ExitCode;
use std::time::Instant;

use crate::cli::args::BvhArgs;
use crate::cli::setup::{build_bvh, load};

pub fn run(args: BvhArgs) -> anyhow::Result<ExitCode> {
    let scene = load(&args.scene, &args.mesh, args.quiet)?;
    let start = Instant::now();
    let geometry = build_bvh(&scene, args.quiet);
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
