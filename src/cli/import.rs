//! `patchtrace import IN -o OUT`: read any supported input, write a scene or patches.

use std::process::ExitCode;

use crate::cli::args::ImportArgs;
use crate::scene::{load_scene_with, write::write_scene_as};

pub fn run(args: ImportArgs) -> anyhow::Result<ExitCode> {
    let scene = load_scene_with(&args.input, args.mesh.load_options())?;
    write_scene_as(&args.output, &scene)?;
    eprintln!(
        "imported {} object(s), {} patch(es) from {} to {}",
        scene.objects.len(),
        scene.patch_count(),
        args.input.display(),
        args.output.display()
    );
    Ok(ExitCode::SUCCESS)
}
