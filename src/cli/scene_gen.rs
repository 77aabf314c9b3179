//! `patchtrace scene teapots`: write a generated test scene.

use std::process::ExitCode;

use crate::cli::args::TeapotsArgs;
use crate::formats::LoadError;
use crate::io::write_atomic;
use crate::scene::generate::{TEAPOT_BPT, TeapotsSpec, teapots_scene};

pub fn teapots(args: TeapotsArgs) -> anyhow::Result<ExitCode> {
    if args.output.extension().is_none_or(|e| e != "ron") {
        return Err(LoadError::invalid(
            &args.output,
            "the scene is written as RON: use a .ron output name",
        )
        .into());
    }
    ensure_arg!(
        args.width > 0 && args.height > 0,
        "--width and --height must be at least 1"
    );
    let spec = TeapotsSpec {
        count: args.count,
        seed: args.seed,
        reflective: args.reflective,
        lights: args.lights,
        width: args.width,
        height: args.height,
        flatten: args.flatten,
    };
    let bpt = args.output.with_file_name("teapot.bpt");
    if !bpt.exists() {
        write_atomic(&bpt, |w| w.write_all(TEAPOT_BPT.as_bytes()))?;
    }
    write_atomic(&args.output, |w| {
        w.write_all(teapots_scene(&spec).as_bytes())
    })?;
    eprintln!(
        "wrote {} ({} teapots, {} patches, {} light(s)) and {}",
        args.output.display(),
        spec.count,
        32 * spec.count,
        spec.lights,
        bpt.display()
    );
    Ok(ExitCode::SUCCESS)
}
