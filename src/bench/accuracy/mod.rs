//! `bench accuracy`: what accuracy costs in time. Every method traces the same rays (the
//! camera's primary rays, or a ray file, rounded once to `f32`) and is compared with the
//! `f64` reference path on those rays
//! (the same subdivision algorithm in `f64`): hit-point and normal error (L1, as Dammertz
//! Tables 2.1–2.4, and relative to the hit's coordinate magnitude), holes and false hits,
//! time per ray (median of several single-threaded runs after a warm-up) and memory.
//! The plot of mean error against time per ray, log-log, with the Pareto front, is in
//! [`plot`].

pub mod plot;

use std::time::Instant;

use glam::DVec3;
use serde::Serialize;

use crate::accel::scene::{QueryStats, SceneGeometry, SceneHit};
use crate::formats::rays::RayQuery;
use crate::geom::Ray;
use crate::kernel::Kernel;
use crate::kernel::cached::CachedConfig;
use crate::kernel::subdivision::{SplitHeuristic, SubdivisionConfig, Termination};
use crate::kernel::toth::TothConfig;
use crate::progress::ProgressBar;
use crate::render::camera::CameraRays;
use crate::scene::{Camera, Scene};
use crate::tessellate::{TessellationMode, TessellationReport, tessellate_scene};

/// Timed runs per method after one warm-up run; the median is reported.
pub const TIMED_RUNS: usize = 3;

/// A way of intersecting rays with the scene.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Method {
    /// The float-precision subdivision kernel in `f32` (Dammertz §2.3) with this split
    /// heuristic (§2.3.2, §2.5.2).
    Float(SplitHeuristic),
    /// Adaptive screen-space termination at half a pixel of the scene camera (§2.5.3,
    /// Tables 2.8–2.9); the rays are taken to start at the camera.
    Adaptive,
    /// A fixed depth: this many splits in total (Table 2.5's "fixed termination").
    Depth(u8),
    /// The mantissa distance `dist` on rational patches (§2.7.2, Table 2.12).
    RationalDist(u32),
    /// The scene tessellated with this many triangles per patch (Dammertz Tables 2.1–2.4).
    Tessellated(u32),
    /// Toth's interval Newton kernel (LG90 §4.1).
    Toth,
    /// The cached surface-tree kernel (LG90 §4.2–4.3), with a fresh cache.
    Cached,
}

impl Method {
    pub fn name(&self) -> String {
        match self {
            Method::Float(SplitHeuristic::Length) => "float, length heuristic".into(),
            Method::Float(SplitHeuristic::CrossProduct) => "float, cross-product heuristic".into(),
            Method::Adaptive => "adaptive, half pixel".into(),
            Method::Depth(d) => format!("depth {d}"),
            Method::RationalDist(d) => format!("rational dist {d}"),
            Method::Tessellated(n) => format!("{n} triangles/patch"),
            Method::Toth => "LG90 Toth".into(),
            Method::Cached => "LG90 cached".into(),
        }
    }

    /// Both heuristics and adaptive, then the given depths, distances and tessellations,
    /// then the LG90 kernels.
    pub fn list(depths: &[u8], dists: &[u32], triangles: &[u32]) -> Vec<Method> {
        let mut methods = vec![
            Method::Float(SplitHeuristic::Length),
            Method::Float(SplitHeuristic::CrossProduct),
            Method::Adaptive,
        ];
        methods.extend(depths.iter().map(|&d| Method::Depth(d)));
        methods.extend(dists.iter().map(|&d| Method::RationalDist(d)));
        methods.extend(triangles.iter().map(|&n| Method::Tessellated(n)));
        methods.extend([Method::Toth, Method::Cached]);
        methods
    }

    /// The kernel path of the method. `camera` sizes the pixels of adaptive termination;
    /// a tessellation has no patches left, so the default is as good as any.
    pub fn precision(&self, camera: &Camera) -> Kernel {
        let base = SubdivisionConfig::default();
        Kernel::F32(match *self {
            Method::Toth => return Kernel::Toth(TothConfig::default()),
            Method::Cached => return Kernel::Cached(CachedConfig::default()),
            Method::Float(heuristic) => SubdivisionConfig { heuristic, ..base },
            Method::Adaptive => SubdivisionConfig {
                termination: Termination::Adaptive(CameraRays::new(camera).footprint()),
                ..base
            },
            Method::Depth(d) => SubdivisionConfig {
                termination: Termination::Depth(d),
                ..base
            },
            Method::RationalDist(rational_dist) => SubdivisionConfig {
                rational_dist,
                ..base
            },
            Method::Tessellated(_) => base,
        })
    }
}

/// Depths of the fixed-depth rows: Dammertz gives no number for his Table 2.5; 8 to 20
/// splits cover 16² to 1024² parameter cells per patch, from coarser than 512 triangles
/// to finer than 131,072.
pub const DEFAULT_DEPTHS: [u8; 4] = [8, 12, 16, 20];
/// Mantissa distances of the rational rows, from Dammertz Table 2.12's range: 16 is our
/// default, 64 and 2048 are his crack-free values with and without directed rounding.
pub const DEFAULT_DISTS: [u32; 4] = [16, 64, 256, 2048];
/// Triangles per patch of Dammertz Tables 2.1–2.4.
pub const DEFAULT_TRIANGLES: [u32; 3] = [512, 4608, 131072];

/// Minimum, maximum, mean and variance of an error over the rays where both hit.
#[derive(Clone, Copy, Debug, Default, Serialize, PartialEq)]
pub struct ErrorStats {
    pub min: f64,
    pub max: f64,
    pub mean: f64,
    pub variance: f64,
}

impl ErrorStats {
    fn of(values: &[f64]) -> ErrorStats {
        if values.is_empty() {
            return ErrorStats::default();
        }
        let n = values.len() as f64;
        let mean = values.iter().sum::<f64>() / n;
        ErrorStats {
            min: values.iter().copied().fold(f64::INFINITY, f64::min),
            max: values.iter().copied().fold(0.0, f64::max),
            mean,
            variance: values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n,
        }
    }
}

/// One row of the report.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct MethodResult {
    pub method: String,
    /// Hit-point error, L1 distance to the reference hit point.
    pub hit_error: ErrorStats,
    /// Hit-point error divided by the largest coordinate magnitude of the reference hit.
    pub hit_error_relative: ErrorStats,
    /// Normal error, L1 distance between unit normals (orientation ignored).
    pub normal_error: ErrorStats,
    /// Rays the reference hits and the method misses.
    pub holes: u64,
    /// Rays the method hits and the reference misses.
    pub false_hits: u64,
    pub rays: u64,
    pub nanoseconds_per_ray: f64,
    /// Geometry memory: patch control points in f32, or the triangle mesh.
    pub memory_bytes: u64,
}

/// The reference answer for one ray.
struct Reference {
    hit: Option<(DVec3, DVec3)>,
}

/// The point a method reports: the middle of the ray's chord through the hit box, in
/// `f64`. Dammertz §2.3.4 takes "the middle of the returned interval"; the box centre
/// itself can lie off the ray by half the box, and `origin + t dir` with the `f32` entry
/// `t` is off by half an ulp of the hit distance, either of which would swamp the
/// kernel's own error. For a triangle the box is the barycentric point widened by its
/// rounding bound. If the box rounds off the ray, the entry point is used.
fn hit_point(h: &SceneHit, r: &Ray) -> DVec3 {
    let (origin, dir) = (r.origin.as_dvec3(), r.dir.as_dvec3());
    let b = h.hit_box.to_f64();
    let t = b
        .intersect(origin, dir.recip(), r.tmin as f64, f64::INFINITY)
        .map_or(h.t, |(t0, t1)| 0.5 * (t0 + t1));
    origin + dir * t
}

/// The normal a method is judged by: the shading normal of a tessellation (interpolated
/// vertex normals, as Dammertz's triangles), the geometric one of a patch.
fn normal(h: &SceneHit, use_shading: bool) -> DVec3 {
    if use_shading {
        h.shading_normal
    } else {
        h.normal
    }
}

/// Runs every method over `rays` and compares with the `f64` reference; `progress` counts
/// the reference and each method as it finishes, with the one running as its message.
pub fn run(
    scene: &Scene,
    rays: &[RayQuery],
    methods: &[Method],
    progress: &ProgressBar,
) -> anyhow::Result<Vec<MethodResult>> {
    progress.set_length(1 + methods.len() as u64);
    let step = |what: &str| progress.set_message(format!("tracing {} rays: {what}", rays.len()));
    let exact = SceneGeometry::build(scene);
    // Every method traces the rays rounded once to f32, and so does the reference, in
    // f64 (an f32 ray is exact in f64): the rounding of the ray itself moves the hit by
    // about its distance times 2^-24 for every method alike and is the camera's error, not
    // the intersector's, so it is kept out of the comparison (Dammertz §2.3.4 compares
    // the kernels, not the ray generation).
    let f32_rays: Vec<Ray> = rays
        .iter()
        .map(|q| Ray {
            origin: q.origin.as_vec3(),
            dir: q.dir.as_vec3(),
            tmin: q.tmin as f32,
            tmax: q.tmax as f32,
        })
        .collect();
    step("f64 reference");
    let reference_cfg = SubdivisionConfig::default();
    let reference: Vec<Reference> = f32_rays
        .iter()
        .map(|r| {
            let mut stats = QueryStats::default();
            let (origin, dir) = (r.origin.as_dvec3(), r.dir.as_dvec3());
            let hit = exact
                .intersect_f64(
                    origin,
                    dir,
                    r.tmin as f64,
                    r.tmax as f64,
                    &reference_cfg,
                    &mut stats,
                )
                .map(|h| (origin + dir * h.t, h.normal));
            Reference { hit }
        })
        .collect();

    let mut results = Vec::new();
    for method in methods {
        progress.inc(1);
        step(&method.name());
        let (geometry, memory) = match *method {
            Method::Tessellated(n) => {
                let (meshes, report): (Scene, TessellationReport) =
                    tessellate_scene(scene, TessellationMode::TrianglesPerPatch(n))?;
                (Some(SceneGeometry::build(&meshes)), report.bytes)
            }
            _ => (None, patch_memory(scene)),
        };
        let geometry = geometry.as_ref().unwrap_or(&exact);
        let shading = matches!(method, Method::Tessellated(_));
        let mut answers = Vec::new();
        let mut times = Vec::new();
        for run in 0..=TIMED_RUNS {
            // A fresh configuration per run: the cached kernel then starts every run with
            // an empty cache instead of the trees of the previous pass over the same rays.
            let precision = method.precision(&scene.camera);
            let start = Instant::now();
            let mut stats = QueryStats::default();
            answers = f32_rays
                .iter()
                .map(|r| geometry.intersect(r, &precision, &mut stats))
                .collect();
            if run > 0 {
                times.push(start.elapsed().as_secs_f64());
            }
        }
        times.sort_by(f64::total_cmp);
        let seconds = times[times.len() / 2];

        let (mut hit_err, mut rel_err, mut normal_err) = (Vec::new(), Vec::new(), Vec::new());
        let (mut holes, mut false_hits) = (0, 0);
        for ((answer, reference), r) in answers.iter().zip(&reference).zip(&f32_rays) {
            match (answer, &reference.hit) {
                (Some(h), Some((p_ref, n_ref))) => {
                    let (p, n) = (hit_point(h, r), normal(h, shading));
                    let e = (p - p_ref).abs().element_sum();
                    hit_err.push(e);
                    rel_err.push(e / p_ref.abs().max_element().max(f64::MIN_POSITIVE));
                    normal_err.push(
                        (n - n_ref)
                            .abs()
                            .element_sum()
                            .min((n + n_ref).abs().element_sum()),
                    );
                }
                (None, Some(_)) => holes += 1,
                (Some(_), None) => false_hits += 1,
                (None, None) => {}
            }
        }
        results.push(MethodResult {
            method: method.name(),
            hit_error: ErrorStats::of(&hit_err),
            hit_error_relative: ErrorStats::of(&rel_err),
            normal_error: ErrorStats::of(&normal_err),
            holes,
            false_hits,
            rays: rays.len() as u64,
            nanoseconds_per_ray: seconds * 1e9 / rays.len().max(1) as f64,
            memory_bytes: memory,
        });
    }
    progress.inc(1);
    Ok(results)
}

/// Bytes of the scene's patches as the kernel stores them: x, y, z (and w) in f32.
pub fn patch_memory(scene: &Scene) -> u64 {
    scene
        .objects
        .iter()
        .flat_map(|o| o.bezier_patches())
        .map(|p| p.point_count() as u64 * if p.is_rational() { 16 } else { 12 })
        .sum()
}

/// The report as a Markdown table.
pub fn markdown(results: &[MethodResult]) -> String {
    let mut s = String::from(
        "| method | mean hit error | max hit error | mean rel. error | mean normal error | max normal error | holes | false hits | ns/ray | memory (bytes) |\n|---|---|---|---|---|---|---|---|---|---|\n",
    );
    for r in results {
        s.push_str(&format!(
            "| {} | {:.3e} | {:.3e} | {:.3e} | {:.3e} | {:.3e} | {} | {} | {:.0} | {} |\n",
            r.method,
            r.hit_error.mean,
            r.hit_error.max,
            r.hit_error_relative.mean,
            r.normal_error.mean,
            r.normal_error.max,
            r.holes,
            r.false_hits,
            r.nanoseconds_per_ray,
            r.memory_bytes
        ));
    }
    s
}

/// The report as CSV, every statistic in its own column.
pub fn csv(results: &[MethodResult]) -> String {
    let mut s = String::from(
        "method,hit_min,hit_max,hit_mean,hit_variance,rel_min,rel_max,rel_mean,rel_variance,normal_min,normal_max,normal_mean,normal_variance,holes,false_hits,rays,ns_per_ray,memory_bytes\n",
    );
    for r in results {
        let e = |x: &ErrorStats| format!("{:e},{:e},{:e},{:e}", x.min, x.max, x.mean, x.variance);
        s.push_str(&format!(
            "{},{},{},{},{},{},{},{},{}\n",
            r.method,
            e(&r.hit_error),
            e(&r.hit_error_relative),
            e(&r.normal_error),
            r.holes,
            r.false_hits,
            r.rays,
            r.nanoseconds_per_ray,
            r.memory_bytes
        ));
    }
    s
}
