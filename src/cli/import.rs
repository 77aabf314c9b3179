//! `patchtrace import IN -o OUT`: read any supported input, write a scene or patches.

use std::process::ExitCode;

use crate::cli::args::ImportArgs;
use crate::cli::setup::load;
use crate::formats::write::write_scene_as;

pub fn run(args: ImportArgs) -> anyhow::Result<ExitCode> {
    let scene = load(&args.input, &args.mesh, args.quiet)?;
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
