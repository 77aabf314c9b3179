//! `patchtrace render SCENE -o OUT.png|OUT.exr`.

use std::io::Write;
use std::path::Path;
use std::process::ExitCode;
use std::time::Instant;

use serde::Serialize;

use crate::cli::args::{Aov, RenderArgs};
use crate::cli::setup::{Prepared, precision, prepare, thread_pool};
use crate::formats::LoadError;
use crate::render::aov;
use crate::render::film::{ImageFormat, sibling, write_effort_png};
use crate::render::integrator::{Integrator, TraceSettings};
use crate::render::piece::{PieceInfo, fingerprint, write_exr, write_png};
use crate::render::plan::EffectPlan;
use crate::render::renderer::{RenderJob, render};
use crate::render::sampler::SampleCount;
use crate::render::stats::{PhaseTimes, RayReport};
use crate::render::window::Window;
use crate::scene::animation::frame_path;

/// How many samples a render took.
#[derive(Serialize)]
struct SamplingReport {
    /// `--spp` as given (or the scene's `samples`).
    spp: String,
    total: u64,
    per_pixel: f64,
    /// Pixels that got more than the first samples (adaptive sampling).
    refined_pixels: usize,
}

impl SamplingReport {
    fn of(per_pixel: &[u32], spp: SampleCount) -> SamplingReport {
        let total: u64 = per_pixel.iter().map(|&n| n as u64).sum();
        let first = match spp {
            SampleCount::Adaptive { max } => crate::render::sampler::ADAPTIVE_FIRST.min(max),
            SampleCount::Fixed(n) => n,
        };
        SamplingReport {
            spp: spp.to_string(),
            total,
            per_pixel: total as f64 / per_pixel.len().max(1) as f64,
            refined_pixels: per_pixel.iter().filter(|&&n| n > first).count(),
        }
    }
}

/// What made the image, as pieces record it so `merge` can refuse pieces of different
/// renders: the program version, fingerprints of the scene as loaded (after `--width` and
/// `--height`; everything but object names, which change no pixel: the geometry by its
/// inputs' key, `scene::source_key`, the same whether the geometry was read or mapped from
/// a BVH file) and of the kernel flags, and every setting that changes pixels. `--bvh` is
/// left out: a BVH file is the BVH the scene builds, wherever it is stored.
fn provenance(prepared: &Prepared, args: &RenderArgs, samples: SampleCount, frame: u32) -> String {
    let scene = &prepared.scene;
    let kernel = crate::cli::args::KernelArgs {
        bvh: None,
        ..args.kernel.clone()
    };
    let aov: Vec<String> = aov::expand(&args.aov)
        .iter()
        .map(|a| format!("{a:?}"))
        .collect();
    format!(
        "patchtrace {}; scene {:016x}; size {}x{}; frame {frame}; spp {samples}; filter {:?}; ulps {}; kernel {:016x}; aov [{}]",
        env!("CARGO_PKG_VERSION"),
        fingerprint(&(
            &scene.camera,
            (scene.background, scene.ambient, scene.max_depth),
            &scene.lights,
            &scene.materials,
            scene.objects.iter().map(|o| o.material).collect::<Vec<_>>(),
            prepared.source_key,
        )),
        scene.camera.width,
        scene.camera.height,
        args.filter,
        args.ulps,
        fingerprint(&kernel),
        aov.join(",")
    )
}

#[derive(Serialize)]
struct RenderStats {
    plan: EffectPlan,
    width: u32,
    height: u32,
    threads: usize,
    patches: usize,
    samples: SamplingReport,
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
    let frames: Vec<u32> = match (args.frame, args.frames) {
        (Some(f), _) => vec![f],
        (None, Some(range)) => range.frames().collect(),
        (None, None) => vec![0],
    };
    if frames.len() > 1 && frame_path(&args.output, 0).is_none() {
        return Err(LoadError::invalid(
            &args.output,
            "several frames need a # in the output name for the frame number, e.g. turn_####.png",
        )
        .into());
    }
    let pool = thread_pool(args.threads)?;
    // The image window is checked as soon as the camera is read, before the BVH is built.
    let check = |scene: &crate::scene::Scene| {
        let c = &scene.camera;
        let size = (
            args.size.width.unwrap_or(c.width),
            args.size.height.unwrap_or(c.height),
        );
        window(&args, size.0, size.1).map(|_| ())
    };
    let mut prepared = prepare(&args.scene, &args.mesh, &args.kernel, args.quiet, &check)?;
    args.size.apply(&args.scene, &mut prepared.scene)?;
    let plan = EffectPlan {
        trims: prepared.trims,
        ..EffectPlan::for_scene(&prepared.scene)
    };
    eprintln!("{plan}");
    let still = prepared.scene.camera.clone();
    for frame in frames {
        if let Some(path) = &prepared.scene.animation {
            let camera = path.camera_at(&still, frame);
            let forward = camera.look_at - camera.eye;
            ensure_arg!(
                forward.cross(camera.up).length_squared() > 0.0
                    && camera.fov_y > 0.0
                    && camera.fov_y < 180.0,
                "frame {frame}: the interpolated camera looks along its up direction or has no field of view"
            );
            prepared.scene.camera = camera;
        }
        let output = frame_path(&args.output, frame).unwrap_or_else(|| args.output.clone());
        render_frame(&prepared, &args, &pool, (frame, plan), &output)?;
    }
    Ok(ExitCode::SUCCESS)
}

/// The part of the `width` × `height` image this render makes: `--crop`, `--tile` or the
/// whole image, refused (bad input) when it does not fit or its film is over budget.
fn window(args: &RenderArgs, width: u32, height: u32) -> Result<Window, crate::cli::BadArgument> {
    let window = match (args.crop, args.tile) {
        (Some(crop), _) => {
            crop.check(width, height)
                .map_err(|e| crate::cli::BadArgument(format!("--crop {crop}: {e}")))?;
            crop
        }
        (None, Some(tile)) => Window::tile(tile, width, height).map_err(crate::cli::BadArgument)?,
        (None, None) => Window::full(width, height),
    };
    crate::scene::check_film_pixels(window.width(), window.height())
        .map_err(crate::cli::BadArgument)?;
    Ok(window)
}

/// Renders one frame of the prepared scene, whose camera is posed for it, to `output`.
fn render_frame(
    prepared: &Prepared,
    args: &RenderArgs,
    pool: &rayon::ThreadPool,
    (frame, plan): (u32, EffectPlan),
    output: &Path,
) -> anyhow::Result<()> {
    let scene = &prepared.scene;
    let precision = precision(&args.kernel, &scene.camera)?;
    let integrator = Integrator {
        scene,
        geometry: &prepared.geometry,
        settings: TraceSettings {
            precision,
            ulps: args.ulps,
            plan,
        },
    };
    let samples = args
        .spp
        .or(scene.samples.map(SampleCount::Fixed))
        .unwrap_or_default();
    let (width, height) = (scene.camera.width, scene.camera.height);
    let window = window(args, width, height)?;
    let aovs = aov::expand(&args.aov);
    let job = RenderJob {
        order: args.order,
        samples,
        filter: args.filter,
        window,
        hits: aov::needs_hits(&aovs),
    };
    let info = PieceInfo {
        width,
        height,
        window,
        provenance: provenance(prepared, args, samples, frame),
    };
    let bar = crate::progress::bar(args.quiet, "rendering");
    let start = Instant::now();
    let rendered = pool.install(|| render(&integrator, &job, &bar));
    let (film, tally) = (&rendered.film, &rendered.tally);
    let render_seconds = start.elapsed().as_secs_f64();
    let sampling = SamplingReport::of(&rendered.samples, samples);
    if let (SampleCount::Adaptive { max }, false) = (samples, args.quiet) {
        eprintln!(
            "adaptive sampling: {} of {} pixels refined to {max} samples, {} samples in all ({:.2} per pixel)",
            sampling.refined_pixels,
            rendered.samples.len(),
            sampling.total,
            sampling.per_pixel
        );
    }
    let start = Instant::now();
    let layers = aov::channels(&aovs, &rendered, prepared.origin);
    let mut written = Vec::new();
    match ImageFormat::of(output) {
        Some(ImageFormat::Exr) => {
            let mut channels = film.rgba_channels();
            channels.extend(layers);
            write_exr(output, &info, channels)?
        }
        _ => {
            write_png(output, &info, &film.to_srgb8())?;
            if !layers.is_empty() {
                let path = sibling(output, "aov", "exr");
                write_exr(&path, &info, layers)?;
                written.push(path);
            }
        }
    }
    if aovs.contains(&Aov::Effort) {
        written.push(write_effort_png(
            output,
            film.width,
            film.height,
            &rendered.effort,
        )?);
    }
    if !args.quiet {
        for path in &written {
            eprintln!("wrote {}", path.display());
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
            samples: sampling,
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
            output.display(),
            film.width,
            film.height,
            tally.total(),
            render_seconds
        );
    }
    Ok(())
}
