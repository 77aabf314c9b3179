//! `patchtrace bench accuracy SCENE`: what accuracy costs in time.

use std::io::Write;
use std::process::ExitCode;

use anyhow::Context;

use crate::bench::accuracy::{self, Method, plot};
use crate::cli::args::AccuracyArgs;
use crate::cli::setup::load;
use crate::formats::error::read_text;
use crate::formats::rays::{RayQuery, parse_rays};
use crate::io::write_atomic;
use crate::render::camera::CameraRays;

pub fn run(args: AccuracyArgs) -> anyhow::Result<ExitCode> {
    let mut scene = load(&args.scene, &args.mesh, args.quiet)?;
    if let Some(n) = args.size {
        ensure_arg!(n > 0, "--size must be at least 1");
        scene.camera.width = n;
        scene.camera.height = n;
    }
    let rays = match &args.rays {
        Some(path) => parse_rays(path, &read_text(path)?)?,
        None => {
            let cam = CameraRays::new(&scene.camera);
            let (w, h) = (scene.camera.width, scene.camera.height);
            (0..h)
                .flat_map(|y| (0..w).map(move |x| (x, y)))
                .map(|(x, y)| {
                    let (origin, dir) = cam.ray_f64(x, y, 0.5, 0.5);
                    RayQuery {
                        origin,
                        dir,
                        tmin: 0.0,
                        tmax: f64::INFINITY,
                    }
                })
                .collect()
        }
    };
    let rational = scene
        .objects
        .iter()
        .flat_map(|o| o.bezier_patches())
        .any(|p| p.is_rational());
    let dists: &[u32] = if rational { &args.dists } else { &[] };
    let methods = Method::list(&args.depths, dists, &args.triangles);
    let quiet = args.quiet;
    let bar = crate::progress::bar(quiet, "accuracy");
    let results = accuracy::run(&scene, &rays, &methods, &bar)?;
    bar.finish_and_clear();

    std::fs::create_dir_all(&args.out_dir)
        .with_context(|| format!("creating {}", args.out_dir.display()))?;
    let table = accuracy::markdown(&results);
    let title = format!("{}: error against time per ray", args.scene.display());
    let svg = plot::svg(&results, &title).map_err(|e| anyhow::anyhow!("drawing the plot: {e}"))?;
    let png = plot::png(&results, &title).map_err(|e| anyhow::anyhow!("drawing the plot: {e}"))?;
    for (name, bytes) in [
        ("accuracy.md", table.as_bytes()),
        ("accuracy.csv", accuracy::csv(&results).as_bytes()),
        ("accuracy.svg", svg.as_bytes()),
        ("accuracy.png", &png),
    ] {
        write_atomic(&args.out_dir.join(name), |w| w.write_all(bytes))?;
    }
    let mut out = std::io::stdout().lock();
    if args.json {
        writeln!(out, "{}", serde_json::to_string_pretty(&results)?)?;
    } else {
        writeln!(out, "{table}")?;
    }
    if !quiet {
        eprintln!(
            "wrote accuracy.md, accuracy.csv, accuracy.svg and accuracy.png to {}",
            args.out_dir.display()
        );
    }
    Ok(ExitCode::SUCCESS)
}
