//! `patchtrace render SCENE -o OUT.png|OUT.exr`.

use std::io::Write;
use std::process::ExitCode;
use std::time::Instant;

use serde::Serialize;

use crate::cli::args::{Aov, RenderArgs};
use crate::cli::setup::{precision, prepare, thread_pool};
use crate::render::film::{ImageFormat, write_effort};
use crate::render::integrator::{Integrator, TraceSettings};
use crate::render::plan::EffectPlan;
use crate::render::renderer::{progress_bar, render_image_in_order};
use crate::render::stats::{PhaseTimes, RayReport};
use crate::scene::LoadError;

#[derive(Serialize)]
struct RenderStats {
    plan: EffectPlan,
    width: u32,
    height: u32,
    threads: usize,
    patches: usize,
    rays: RayReport,
    seconds: PhaseTimes,
}

pub fn run(args: RenderArgs) -> anyhow::Result<ExitCode> {
    if ImageFormat::of(&args.output).is_none() {
        return Err(LoadError::invalid(
            &args.output,
            "unsupported image type: expected .png or .exr",
        )
        .into());
    }
    if let Some(dir) = args.output.parent().filter(|d| !d.as_os_str().is_empty())
        && !dir.is_dir()
    {
        return Err(LoadError::invalid(
            &args.output,
            format!("the directory {} does not exist", dir.display()),
        )
        .into());
    }
    let pool = thread_pool(args.threads)?;
    let mut prepared = prepare(&args.scene, &args.kernel)?;
    let scene = &mut prepared.scene;
    args.size.apply(&mut scene.camera)?;
    let precision = precision(&args.kernel, &scene.camera)?;
    let plan = EffectPlan {
        trims: prepared.trims,
        ..EffectPlan::for_scene(scene)
    };
    eprintln!("{plan}");
    let integrator = Integrator {
        scene,
        geometry: &prepared.geometry,
        settings: TraceSettings {
            precision,
            ulps: args.ulps,
            plan,
        },
    };
    let bar = progress_bar(args.quiet, "rendering");
    let start = Instant::now();
    let rendered = pool.install(|| render_image_in_order(&integrator, args.order, &bar));
    let (film, tally) = (&rendered.film, &rendered.tally);
    let render_seconds = start.elapsed().as_secs_f64();
    let start = Instant::now();
    film.write(&args.output)?;
    if args.aov.contains(&Aov::Effort) {
        let [exr, png] = write_effort(&args.output, film.width, film.height, &rendered.effort)?;
        if !args.quiet {
            eprintln!(
                "wrote effort (splits per pixel) to {} and {}",
                exr.display(),
                png.display()
            );
        }
    }
    let write_seconds = start.elapsed().as_secs_f64();
    if args.stats {
        let mut out = std::io::stdout().lock();
        let stats = RenderStats {
            plan,
            width: film.width,
            height: film.height,
            threads: pool.current_num_threads(),
            patches: prepared.geometry.patch_count(),
            rays: tally.report(),
            seconds: PhaseTimes {
                load: prepared.load_seconds,
                prepare: prepared.prepare_seconds,
                render: render_seconds,
                write: write_seconds,
            },
        };
        writeln!(out, "{}", serde_json::to_string_pretty(&stats)?)?;
    }
    if !args.quiet {
        eprintln!(
            "wrote {} ({}x{}, {} rays, {:.3} s)",
            args.output.display(),
            film.width,
            film.height,
            tally.total(),
            render_seconds
        );
    }
    Ok(ExitCode::SUCCESS)
}
