//! Turning shared flags into a validated configuration: the scene, its prepared geometry
//! (BVH built or loaded, or grid built), the kernel settings and the worker pool.

use std::path::Path;
use std::time::Instant;

use anyhow::Context;
use glam::DVec3;

use crate::accel::scene::{FromFile, SceneGeometry};
use crate::cli::args::{
    AccelChoice, HeuristicChoice, KernelArgs, KernelChoice, MeshArgs, PrecisionChoice,
    TerminationChoice,
};
use crate::formats::{load_scene_keyed, load_scene_with};
use crate::kernel::Kernel;
use crate::kernel::cached::{CachedConfig, DEFAULT_CACHE_BYTES, DEFAULT_MAX_DEPTH};
use crate::kernel::subdivision::{SplitHeuristic, SubdivisionConfig, Termination};
use crate::kernel::toth::TothConfig;
use crate::render::camera::CameraRays;
use crate::render::plan::TrimEffect;
use crate::scene::{Camera, Scene};
use crate::tessellate::{
    TessellateError, TessellationMode, TessellationReport, tessellate_scene_with,
};

/// The kernel path selected by the flags, or why the flags do not go together; `camera`
/// sizes the pixels of adaptive termination.
pub fn precision(args: &KernelArgs, camera: &Camera) -> anyhow::Result<Kernel> {
    if args.kernel != KernelChoice::Cached {
        for (flag, given) in [
            ("--cache-size", args.cache_size.is_some()),
            ("--cache-depth", args.cache_depth.is_some()),
        ] {
            ensure_arg!(
                !given,
                "{flag} sizes the surface-tree cache, which only --kernel cached has; add --kernel cached or drop {flag}"
            );
        }
    }
    if matches!(args.kernel, KernelChoice::Toth | KernelChoice::Cached) {
        ensure_arg!(
            args.precision == PrecisionChoice::F32,
            "--kernel toth and --kernel cached work on f32 rays and have no --precision f64 variant; use --kernel subdivision --precision f64 for the reference"
        );
        let toth = TothConfig {
            isrt: args.isrt,
            ..TothConfig::default()
        };
        return Ok(match args.kernel {
            KernelChoice::Cached => Kernel::Cached(CachedConfig::new(
                toth,
                args.cache_size
                    .map_or(DEFAULT_CACHE_BYTES, |mib| mib.saturating_mul(1 << 20)),
                args.cache_depth.unwrap_or(DEFAULT_MAX_DEPTH),
            )),
            _ => Kernel::Toth(toth),
        });
    }
    ensure_arg!(
        !args.isrt,
        "--isrt applies to the Toth kernels only; add --kernel toth or --kernel cached"
    );
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
    Ok(match args.precision {
        PrecisionChoice::F32 => Kernel::F32(cfg),
        PrecisionChoice::F64 => Kernel::F64(cfg),
    })
}

/// Loaded scene and prepared geometry, with the seconds each took.
pub struct Prepared {
    pub scene: Scene,
    pub geometry: SceneGeometry,
    pub load_seconds: f64,
    pub prepare_seconds: f64,
    /// The trim loops as read, and whether `--ignore-trims` dropped them.
    pub trims: TrimEffect,
    /// The key of the scene's inputs ([`load_scene_keyed`]): what its geometry is made from.
    pub source_key: u64,
    /// The floating origin ([`crate::scene::origin`]): `scene` and `geometry` are the scene
    /// as read moved by minus it, and a world position is a position in them plus it.
    pub origin: DVec3,
}

/// Reads the scene at `path` with `--subdivide`'s options, under a spinner when the file is
/// large ([`while_reading`](crate::progress::while_reading)), unless `quiet`.
pub fn load(path: &Path, mesh: &MeshArgs, quiet: bool) -> Result<Scene, crate::formats::LoadError> {
    let scene =
        crate::progress::while_reading(quiet, path, || load_scene_with(path, mesh.load_options()))?;
    print_warnings(&scene);
    Ok(scene)
}

/// Prints what reading the scene's files left out or tolerated, once, on stderr.
pub fn print_warnings(scene: &Scene) {
    for w in &scene.warnings {
        eprintln!("{w}");
    }
}

/// A check of the command's own flags against the scene as read (its camera), made before
/// the geometry is prepared, so that a bad flag costs no BVH build.
pub type SceneCheck<'a> = dyn Fn(&Scene) -> Result<(), crate::cli::BadArgument> + 'a;

/// Loads the scene, runs `check` on it, and prepares its geometry: builds the BVH or loads
/// `--bvh`, or builds the grid for `--accel grid`, with progress unless `quiet`.
pub fn prepare(
    scene_path: &Path,
    mesh: &MeshArgs,
    args: &KernelArgs,
    quiet: bool,
    check: &SceneCheck,
) -> anyhow::Result<Prepared> {
    ensure_arg!(
        args.accel == AccelChoice::Bvh || args.bvh.is_none(),
        "--bvh loads a BVH file, which --accel grid does not use; drop one of the two flags"
    );
    let start = Instant::now();
    if let (AccelChoice::Bvh, Some(path)) = (args.accel, &args.bvh) {
        return prepare_from_file(scene_path, mesh, args, path, (quiet, check));
    }
    let (mut scene, source_key) = load_keyed(scene_path, mesh, quiet, (false, None))?;
    check(&scene)?;
    let trims = TrimEffect::of(&scene, args.ignore_trims);
    if args.ignore_trims {
        scene = scene.without_trims();
    }
    let origin = scene.floating_origin();
    scene.translate(-origin);
    let load_seconds = start.elapsed().as_secs_f64();
    let start = Instant::now();
    let geometry = match args.accel {
        AccelChoice::Bvh => build_bvh(&scene, quiet),
        AccelChoice::Grid => {
            let spinner = crate::progress::spinner(quiet, "building the grid");
            let grid = SceneGeometry::build_grid(&scene, args.grid_budget.saturating_mul(1 << 20));
            spinner.finish_and_clear();
            grid
        }
    };
    Ok(Prepared {
        scene,
        geometry,
        load_seconds,
        prepare_seconds: start.elapsed().as_secs_f64(),
        trims,
        source_key,
        origin,
    })
}

/// Reads the scene at `path` with `--subdivide`'s options and its inputs' key
/// ([`load_scene_keyed`]); with `defer`, without parsing a RON scene's geometry files.
pub fn load_keyed(
    path: &Path,
    mesh: &MeshArgs,
    quiet: bool,
    (defer, parsed): (bool, Option<(u64, &[u8])>),
) -> Result<(Scene, u64), crate::formats::LoadError> {
    let (scene, key) = crate::progress::while_reading(quiet, path, || {
        load_scene_keyed(path, mesh.load_options(), defer, parsed)
    })?;
    print_warnings(&scene);
    Ok((scene, key))
}

/// [`prepare`] with `--bvh FILE`: the file is mapped, the scene read without its geometry
/// files (and from the parse the file keeps when the scene's text is unchanged), and the
/// file's prepared patches used in place; only a file that holds the tree alone (the scene
/// has geometry its records cannot hold) makes the scene be read again, with its geometry.
fn prepare_from_file(
    scene_path: &Path,
    mesh: &MeshArgs,
    args: &KernelArgs,
    bvh_path: &Path,
    (quiet, check): (bool, &SceneCheck),
) -> anyhow::Result<Prepared> {
    let start = Instant::now();
    let opened = crate::accel::mapped::map(bvh_path)?;
    // A bare file's shell stands in for its scene only where the file holds the patches:
    // a tree-only file's geometry is built from the scene, which must then be read whole.
    let bare = crate::formats::load::InputKind::of(scene_path)
        != Some(crate::formats::load::InputKind::Ron);
    let parsed = (!bare || opened.has_patches()).then(|| opened.cached_scene());
    let (scene, source) = load_keyed(scene_path, mesh, quiet, (true, parsed))?;
    check(&scene)?;
    let load_seconds = start.elapsed().as_secs_f64();
    let start = Instant::now();
    let key = crate::accel::mapped::key(source, args.ignore_trims);
    let file = opened.check(bvh_path, key, scene.objects.len())?;
    let origin = file.origin;
    let (scene, geometry, trims) = match SceneGeometry::from_file(file) {
        FromFile::Mapped(geometry, loops) => {
            let trims = TrimEffect {
                loops,
                ignored: args.ignore_trims,
            };
            let mut scene = scene;
            scene.translate(-origin);
            let pieces = geometry.mapped_pieces(scene.objects.len());
            for (object, pieces) in scene.objects.iter_mut().zip(pieces) {
                if !pieces.is_empty() {
                    object.geometry = crate::scene::Geometry::Subdivision(
                        crate::geom::subdiv::SubdivisionSurface::reporting(pieces),
                    );
                }
            }
            (scene, *geometry, trims)
        }
        FromFile::TreeOnly(bvh) => {
            // A RON scene was read without its geometry files; bare geometry with it.
            let mut scene = match crate::formats::load::InputKind::of(scene_path) {
                Some(crate::formats::load::InputKind::Ron) => load(scene_path, mesh, quiet)?,
                _ => scene,
            };
            let trims = TrimEffect::of(&scene, args.ignore_trims);
            if args.ignore_trims {
                scene = scene.without_trims();
            }
            scene.translate(-origin);
            let geometry = SceneGeometry::with_tree(&scene, bvh, bvh_path)?;
            (scene, geometry, trims)
        }
    };
    Ok(Prepared {
        scene,
        geometry,
        load_seconds,
        prepare_seconds: start.elapsed().as_secs_f64(),
        trims,
        source_key: source,
        origin,
    })
}

/// Prepares the scene's geometry and builds its BVH under a progress bar, unless `quiet`.
pub fn build_bvh(scene: &Scene, quiet: bool) -> SceneGeometry {
    let bar = crate::progress::bar(quiet, "building BVH");
    let geometry = SceneGeometry::build_with(scene, &bar);
    bar.finish_and_clear();
    geometry
}

/// Tessellates `scene` under a progress bar labelled `label`, one step per patch, unless
/// `quiet`.
pub fn tessellate(
    scene: &Scene,
    mode: TessellationMode,
    quiet: bool,
    label: &str,
) -> Result<(Scene, TessellationReport), TessellateError> {
    let bar = crate::progress::bar(quiet, label);
    bar.set_length(scene.patch_count() as u64);
    let result = tessellate_scene_with(scene, mode, &mut || bar.inc(1));
    bar.finish_and_clear();
    result
}

/// Most `--threads` per core. Work is split into many more pieces than threads, so more
/// threads than cores only add switching; a few per core leave room for a machine whose
/// core count is misreported, while 10000 spent 20 s starting threads.
pub const MAX_THREADS_PER_CORE: usize = 4;

/// A rayon pool with `threads` workers (all cores when `None`), at most
/// [`MAX_THREADS_PER_CORE`] per core.
pub fn thread_pool(threads: Option<usize>) -> anyhow::Result<rayon::ThreadPool> {
    let mut b = rayon::ThreadPoolBuilder::new();
    if let Some(n) = threads {
        let cores = std::thread::available_parallelism().map_or(1, |c| c.get());
        let limit = MAX_THREADS_PER_CORE * cores;
        if n == 0 || n > limit {
            return Err(crate::cli::BadArgument(format!(
                "--threads must be 1 to {limit} ({MAX_THREADS_PER_CORE} per core, {cores} cores), found {n}"
            ))
            .into());
        }
        b = b.num_threads(n);
    }
    b.build().context("starting worker threads")
}
