//! Throughput of the `f32` subdivision kernel on the teapot's primary rays (the view of
//! DESIGN.md's sample scene, 512²). The (ray, patch) pairs whose ray hits the patch by the
//! `f64` reference are collected first; then `intersect` is timed over them, single
//! threaded, median of several runs after a warm-up. Besides wall time the bench reports
//! the thread's CPU time (Linux `/proc/thread-self/schedstat`), which stays meaningful
//! when other processes share the cores; the rates are computed from the CPU time.
//!
//! `cargo bench --bench kernel` (optionally `-- cross` for the cross-product heuristic,
//! `end=K` for the end-game threshold in ulps, `size=N` for an N² image, e.g. under
//! callgrind). Accuracy is reported as the distance between the `f32` and `f64` hit points
//! in ulps of the patch's largest coordinate.

use std::path::Path;
use std::time::Instant;

use glam::DVec3;
use patchtrace::formats::bpt::read_bpt;
use patchtrace::geom::ulp::ulp_of;
use patchtrace::kernel::KernelStats;
use patchtrace::kernel::subdivision::{
    PreparedPatch, SplitHeuristic, SubdivisionConfig, intersect, intersect_f64,
};
use patchtrace::render::camera::CameraRays;
use patchtrace::scene::Camera;

/// Timed runs after the warm-up; the median is reported.
const RUNS: usize = 7;

/// Nanoseconds this thread has run on a CPU (the first field of `schedstat`), or `None`
/// where the kernel does not provide it.
fn thread_cpu_ns() -> Option<u64> {
    std::fs::read_to_string("/proc/thread-self/schedstat")
        .ok()?
        .split_whitespace()
        .next()?
        .parse()
        .ok()
}

fn main() {
    let args: Vec<String> = std::env::args()
        .skip(1)
        .filter(|a| a != "--bench")
        .collect();
    let mut cfg = SubdivisionConfig::default();
    if args.iter().any(|a| a == "cross") {
        cfg.heuristic = SplitHeuristic::CrossProduct;
    }
    if let Some(k) = args
        .iter()
        .find_map(|a| a.strip_prefix("end=")?.parse().ok())
    {
        cfg.end_ulps = k;
    }
    let size: u32 = args
        .iter()
        .find_map(|a| a.strip_prefix("size=")?.parse().ok())
        .unwrap_or(512);
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("testdata/teapot.bpt");
    let patches = read_bpt(&path).expect("testdata/teapot.bpt");
    let prepared: Vec<PreparedPatch> = patches.iter().map(PreparedPatch::new).collect();
    let cam = CameraRays::new(&Camera {
        eye: DVec3::new(0.0, -8.0, 4.5),
        look_at: DVec3::new(0.0, 0.0, 1.2),
        up: DVec3::Z,
        fov_y: 40.0,
        width: size,
        height: size,
    });
    let t0 = Instant::now();
    let mut pairs = Vec::new();
    for y in 0..size {
        for x in 0..size {
            let ray = cam.ray(x, y);
            let inv = ray.dir.recip();
            for (k, p) in prepared.iter().enumerate() {
                if p.bounds()
                    .intersect(ray.origin, inv, 0.0, f32::INFINITY)
                    .is_none()
                {
                    continue;
                }
                let (o, d) = (ray.origin.as_dvec3(), ray.dir.as_dvec3());
                if let Some(h) = intersect_f64(&patches[k], o, d, 0.0, f64::INFINITY, &cfg, None) {
                    pairs.push((ray, k, o + h.t * d));
                }
            }
        }
    }
    println!(
        "{} (ray, patch) pairs hit by the f64 reference, collected in {:.1} s",
        pairs.len(),
        t0.elapsed().as_secs_f64()
    );
    let mut times = Vec::new();
    let mut stats = KernelStats::default();
    let mut max_splits = 0;
    let mut hits = 0;
    let mut errors = Vec::new();
    for run in 0..=RUNS {
        let mut s = KernelStats::default();
        let start = Instant::now();
        let cpu_start = thread_cpu_ns();
        hits = 0;
        errors.clear();
        for (ray, k, want) in &pairs {
            let before = s.splits;
            if let Some(h) = intersect(&prepared[*k], None, ray, &cfg, &mut s) {
                hits += 1;
                let got = (ray.origin + h.t * ray.dir).as_dvec3();
                let b = prepared[*k].bounds();
                let scale = b.min.abs().max(b.max.abs()).max_element();
                errors.push((got - *want).length() / ulp_of(scale));
            }
            max_splits = max_splits.max(s.splits - before);
        }
        let wall = start.elapsed().as_secs_f64();
        let cpu = thread_cpu_ns()
            .zip(cpu_start)
            .map_or(wall, |(end, begin)| (end - begin) as f64 * 1e-9);
        if run > 0 {
            times.push((cpu, wall));
        }
        stats = s;
    }
    times.sort_by(|a, b| a.0.total_cmp(&b.0));
    let (median, wall) = times[times.len() / 2];
    let n = pairs.len() as f64;
    println!("config: {cfg:?}");
    println!(
        "f32 hits: {hits} of {} pairs ({} misses)",
        pairs.len(),
        pairs.len() - hits
    );
    println!(
        "median {:.3} s CPU ({:.3} s wall): {:.3} M ray-patch tests/s/core, {:.0} ns/test",
        median,
        wall,
        n / median * 1e-6,
        median / n * 1e9
    );
    println!(
        "splits/test: mean {:.1}, max {}; jumps/test {:.2} (+ {:.2} cells dropped); box tests/test {:.1}; {:.1} ns/split",
        stats.splits as f64 / n,
        max_splits,
        stats.jumps as f64 / n,
        stats.jump_drops as f64 / n,
        stats.box_tests as f64 / n,
        median / stats.splits as f64 * 1e9
    );
    errors.sort_by(f64::total_cmp);
    println!(
        "hit point vs f64 (ulps of the patch scale): mean {:.2}, 99% {:.1}, max {:.1}",
        errors.iter().sum::<f64>() / errors.len().max(1) as f64,
        errors.get(errors.len() * 99 / 100).copied().unwrap_or(0.0),
        errors.last().copied().unwrap_or(0.0)
    );
}
