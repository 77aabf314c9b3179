//! Turning shared flags into a validated configuration: the scene, its prepared geometry
//! (BVH built or loaded), the kernel settings and the worker pool.

use std::path::Path;
use std::time::Instant;

use anyhow::Context;

use crate::accel::scene::{Precision, SceneGeometry};
use crate::cli::args::{
    HeuristicChoice, KernelArgs, KernelChoice, PrecisionChoice, TerminationChoice,
};
use crate::kernel::subdivision::{SplitHeuristic, SubdivisionConfig, Termination};
use crate::render::camera::CameraRays;
use crate::scene::{Camera, Scene, load_scene};

/// The kernel path selected by the flags; `camera` sizes the pixels of adaptive
/// termination.
pub fn precision(args: &KernelArgs, camera: &Camera) -> Precision {
    let KernelChoice::Subdivision = args.kernel;
    let mut cfg = SubdivisionConfig {
        heuristic: match args.heuristic {
            HeuristicChoice::Length => SplitHeuristic::Length,
            HeuristicChoice::Cross => SplitHeuristic::CrossProduct,
        },
        termination: match args.termination {
            TerminationChoice::Float => Termination::Float,
            TerminationChoice::Depth(d) => Termination::Depth(d),
            TerminationChoice::Adaptive => {
                Termination::Adaptive(CameraRays::new(camera).footprint())
            }
        },
        ..SubdivisionConfig::default()
    };
    if let Some(d) = args.rational_dist {
        cfg.rational_dist = d;
    }
    match args.precision {
        PrecisionChoice::F32 => Precision::F32(cfg),
        PrecisionChoice::F64 => Precision::F64(cfg),
    }
}

/// Loaded scene and prepared geometry, with the seconds each took.
pub struct Prepared {
    pub scene: Scene,
    pub geometry: SceneGeometry,
    pub load_seconds: f64,
    pub prepare_seconds: f64,
}

/// Loads the scene and prepares its geometry, building the BVH or loading `--bvh`.
pub fn prepare(scene_path: &Path, args: &KernelArgs) -> anyhow::Result<Prepared> {
    let start = Instant::now();
    let scene = load_scene(scene_path)?;
    let load_seconds = start.elapsed().as_secs_f64();
    let start = Instant::now();
    let geometry = match &args.bvh {
        Some(path) => SceneGeometry::load(&scene, path)?,
        None => SceneGeometry::build(&scene),
    };
    Ok(Prepared {
        scene,
        geometry,
        load_seconds,
        prepare_seconds: start.elapsed().as_secs_f64(),
    })
}

/// A rayon pool with `threads` workers (all cores when `None`).
pub fn thread_pool(threads: Option<usize>) -> anyhow::Result<rayon::ThreadPool> {
    let mut b = rayon::ThreadPoolBuilder::new();
    if let Some(n) = threads {
        anyhow::ensure!(n > 0, "--threads must be at least 1");
        b = b.num_threads(n);
    }
    b.build().context("starting worker threads")
}
