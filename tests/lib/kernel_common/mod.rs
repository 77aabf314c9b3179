//! Helpers shared by the kernel tests: a seeded generator and f64 surface math independent
//! of the kernel (Newton's method on the ray–surface equations).

use glam::DVec3;
use patchtrace::geom::BezierPatch;

/// The library's seeded SplitMix64 generator.
pub use patchtrace::scene::generate::SplitMix64 as Rng;

/// Solves `S(u, v) = o + t d` by Newton's method from (u, v); returns `(u, v, t)` when it
/// converges to a root with (u, v) in [0,1]² and `t >= 0`.
pub fn newton(
    p: &BezierPatch,
    o: DVec3,
    d: DVec3,
    mut u: f64,
    mut v: f64,
) -> Option<(f64, f64, f64)> {
    let mut t = (p.eval(u, v) - o).dot(d) / d.length_squared();
    let scale = p.control_box().diagonal().max(o.abs().max_element());
    for _ in 0..50 {
        let (s, su, sv) = p.derivatives(u, v);
        let f = s - o - t * d;
        if f.length() <= 4.0 * f64::EPSILON * scale {
            let inside = |x: f64| (0.0..=1.0).contains(&x);
            return (inside(u) && inside(v) && t >= 0.0).then_some((u, v, t));
        }
        // Cramer's rule on [su sv -d] (du dv dt)ᵀ = -f.
        let nd = -d;
        let det = su.dot(sv.cross(nd));
        if det == 0.0 || !det.is_finite() {
            return None;
        }
        let du = -f.dot(sv.cross(nd)) / det;
        let dv = -su.dot(f.cross(nd)) / det;
        let dt = -su.dot(sv.cross(f)) / det;
        // Keep the iterate near the domain so the polynomial stays well behaved.
        u = (u + du).clamp(-0.5, 1.5);
        v = (v + dv).clamp(-0.5, 1.5);
        t += dt;
    }
    None
}

/// Distance from `q` to the ray `o + t d`, `t >= 0`.
pub fn ray_distance(q: DVec3, o: DVec3, d: DVec3) -> f64 {
    let t = ((q - o).dot(d) / d.length_squared()).max(0.0);
    (q - o - t * d).length()
}

/// The nearest root of the ray on the patch, by Newton from the local minima of the
/// ray distance over an `n × n` grid of (u, v) and from the extra seeds given.
pub fn nearest_root(
    p: &BezierPatch,
    o: DVec3,
    d: DVec3,
    n: usize,
    extra: &[(f64, f64)],
) -> Option<(f64, f64, f64)> {
    let grid: Vec<f64> = (0..n * n)
        .map(|k| {
            let (i, j) = (k % n, k / n);
            ray_distance(
                p.eval(i as f64 / (n - 1) as f64, j as f64 / (n - 1) as f64),
                o,
                d,
            )
        })
        .collect();
    let mut seeds: Vec<(f64, f64)> = extra.to_vec();
    for j in 0..n {
        for i in 0..n {
            let g = grid[j * n + i];
            let neighbours = [(-1i64, 0i64), (1, 0), (0, -1), (0, 1)];
            let is_min = neighbours.iter().all(|&(di, dj)| {
                let (a, b) = (i as i64 + di, j as i64 + dj);
                a < 0
                    || b < 0
                    || a >= n as i64
                    || b >= n as i64
                    || grid[b as usize * n + a as usize] >= g
            });
            if is_min {
                seeds.push((i as f64 / (n - 1) as f64, j as f64 / (n - 1) as f64));
            }
        }
    }
    seeds
        .iter()
        .filter_map(|&(u, v)| newton(p, o, d, u, v))
        .min_by(|a, b| a.2.total_cmp(&b.2))
}

/// Smallest distance from the ray to the patch: the best of an `n × n` grid refined by a
/// shrinking pattern search in (u, v) over [0,1]².
pub fn min_ray_distance(p: &BezierPatch, o: DVec3, d: DVec3, n: usize) -> f64 {
    let f = |u: f64, v: f64| ray_distance(p.eval(u, v), o, d);
    let mut starts: Vec<(f64, f64, f64)> = (0..n * n)
        .map(|k| {
            let (u, v) = (
                (k % n) as f64 / (n - 1) as f64,
                (k / n) as f64 / (n - 1) as f64,
            );
            (f(u, v), u, v)
        })
        .collect();
    starts.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut best = f64::INFINITY;
    for &(mut g, mut u, mut v) in starts.iter().take(4) {
        let mut h = 1.0 / (n - 1) as f64;
        while h > 1e-12 {
            let mut moved = false;
            for (du, dv) in [(h, 0.0), (-h, 0.0), (0.0, h), (0.0, -h)] {
                let (a, b) = ((u + du).clamp(0.0, 1.0), (v + dv).clamp(0.0, 1.0));
                let ga = f(a, b);
                if ga < g {
                    (g, u, v, moved) = (ga, a, b, true);
                }
            }
            if !moved {
                h *= 0.5;
            }
        }
        best = best.min(g);
    }
    best
}
