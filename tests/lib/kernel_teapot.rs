//! The subdivision kernel on the teapot (testdata/teapot.bpt): no cracks at shared patch
//! edges and collapsed points (Dammertz §2.2: boxes of neighbouring sub-patches touch), and
//! no self-intersections of secondary rays started at `secondary_origin` (§2.4) at three
//! scales, near the world origin and 1e4 away from it.

use crate::kernel_common;

use std::path::Path;

use glam::{DAffine3, DVec3};
use kernel_common::Rng;
use patchtrace::geom::{Aabb, BezierPatch, Ray};
use patchtrace::kernel::secondary::{DEFAULT_ULPS, secondary_origin};
use patchtrace::kernel::subdivision::{
    PreparedPatch, SubdivisionConfig, intersect, occluded, widen_by_net_rounding,
};
use patchtrace::kernel::{KernelStats, PatchHit};
use patchtrace::scene::bpt::read_bpt;

fn teapot() -> Vec<BezierPatch> {
    read_bpt(
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("testdata/teapot.bpt")
            .as_path(),
    )
    .unwrap()
}

/// Nearest hit over all patches, by brute force: (patch index, hit).
fn nearest(prepared: &[PreparedPatch], ray: &Ray) -> Option<(usize, PatchHit)> {
    let cfg = SubdivisionConfig::default();
    let mut stats = KernelStats::default();
    let mut ray = *ray;
    let mut best = None;
    for (k, p) in prepared.iter().enumerate() {
        if let Some(h) = intersect(p, None, &ray, &cfg, &mut stats) {
            ray.tmax = h.t;
            best = Some((k, h));
        }
    }
    best
}

/// Points where patches meet: samples of every patch edge that lies on another patch's
/// edge, and the collapsed edges (all points equal) such as the lid's pole.
fn edge_points(patches: &[BezierPatch], rng: &mut Rng, count: usize) -> Vec<(DVec3, DVec3)> {
    let edge = |p: &BezierPatch, e: usize, s: f64| match e {
        0 => p.eval(s, 0.0),
        1 => p.eval(s, 1.0),
        2 => p.eval(0.0, s),
        _ => p.eval(1.0, s),
    };
    let uv = |e: usize, s: f64| match e {
        0 => (s, 0.0),
        1 => (s, 1.0),
        2 => (0.0, s),
        _ => (1.0, s),
    };
    // (patch, edge) pairs whose edge is shared with another patch (as a point set: the
    // samples at 1/4, 1/2, 3/4 each lie on some edge of another patch) or collapsed.
    let close = |a: DVec3, b: DVec3| (a - b).length() < 1e-9 * (1.0 + a.length());
    let on_other_edge = |k: usize, q: DVec3| {
        patches.iter().enumerate().any(|(m, o)| {
            m != k
                && (0..4).any(|f| {
                    // Shared teapot edges have matching parameters (possibly reversed), so
                    // the same fractions of the other edge are compared.
                    [0.25, 0.5, 0.75].iter().any(|&s| close(edge(o, f, s), q))
                })
        })
    };
    let mut shared = Vec::new();
    let mut collapsed = Vec::new();
    for (k, p) in patches.iter().enumerate() {
        for e in 0..4 {
            let samples = [0.25, 0.5, 0.75].map(|s| edge(p, e, s));
            if samples.iter().all(|&q| close(q, samples[0])) {
                collapsed.push((k, e));
            } else if samples.iter().all(|&q| on_other_edge(k, q)) {
                shared.push((k, e));
            }
        }
    }
    assert!(
        shared.len() >= 32,
        "expected the teapot's shared edges, found {}",
        shared.len()
    );
    assert!(
        !collapsed.is_empty(),
        "expected the lid's and bottom's collapsed points"
    );
    (0..count)
        .map(|i| {
            // One ray in ten goes to a collapsed point.
            let (k, e) = if i % 10 == 0 {
                collapsed[i / 10 % collapsed.len()]
            } else {
                shared[rng.next_u64() as usize % shared.len()]
            };
            let s = if i % 10 == 0 { 0.5 } else { rng.uniform() };
            let (u, v) = uv(e, s);
            (edge(&patches[k], e, s), patches[k].normal(u, v))
        })
        .collect()
}

#[test]
fn rays_at_shared_edges_and_collapsed_points_always_hit() {
    let patches = teapot();
    let prepared: Vec<PreparedPatch> = patches.iter().map(PreparedPatch::new).collect();
    let mut rng = Rng::new(11);
    let targets = edge_points(&patches, &mut rng, 10_000);
    let mut misses = Vec::new();
    for (target, n) in targets {
        // From outside (20 units away) on either side of the surface, not grazing: the
        // ray must cross the surface at the target or hit something before it.
        let mut w = rng.direction();
        if w.dot(n).abs() < 0.2 {
            w = (w + n.signum() * n * 0.5).normalize();
        }
        let origin = target + 20.0 * w;
        let ray = Ray::new(origin.as_vec3(), (target - origin).as_vec3());
        if nearest(&prepared, &ray).is_none() {
            misses.push(ray);
        }
    }
    assert!(
        misses.is_empty(),
        "{} rays slipped through, e.g. {:?}",
        misses.len(),
        misses.first()
    );
}

/// A hit box that overlaps `b` (closed boxes): a re-hit at t ≈ 0, scale-free.
fn overlaps(a: &Aabb, b: &Aabb) -> bool {
    a.min.cmple(b.max).all() && b.min.cmple(a.max).all()
}

#[test]
fn secondary_rays_do_not_hit_their_own_patch_at_their_origin() {
    let base = teapot();
    let cfg = SubdivisionConfig::default();
    let mut rng = Rng::new(12);
    let mut checked = 0;
    let mut self_hits = Vec::new();
    for scale in [1e-3, 1.0, 1e3] {
        for offset in [DVec3::ZERO, DVec3::splat(1e4)] {
            let m = DAffine3::from_translation(offset) * DAffine3::from_scale(DVec3::splat(scale));
            let patches: Vec<BezierPatch> = base
                .iter()
                .map(|p| {
                    let mut q = p.clone();
                    q.transform(&m);
                    q
                })
                .collect();
            let prepared: Vec<PreparedPatch> = patches.iter().map(PreparedPatch::new).collect();
            let centre = m.transform_point3(DVec3::new(0.0, 0.0, 1.5));
            let mut hits = 0;
            while hits < 1700 {
                let k = rng.next_u64() as usize % patches.len();
                let target = patches[k].eval(rng.uniform(), rng.uniform());
                let origin = centre + rng.direction() * 10.0 * scale;
                let ray = Ray::new(origin.as_vec3(), (target - origin).as_vec3());
                let Some((k, h)) = nearest(&prepared, &ray) else {
                    continue;
                };
                hits += 1;
                let n = patches[k].normal(h.u as f64, h.v as f64);
                assert!(
                    n.is_finite() && (n.length() - 1.0).abs() < 1e-9,
                    "normal {n:?}"
                );
                let n = n.as_vec3();
                let mut stats = KernelStats::default();
                // Reflection (outside) and refraction (inside) rays: a random direction in
                // the hemisphere the origin's corner was chosen for.
                for outside in [true, false] {
                    let side = if outside { n } else { -n };
                    let mut d = rng.direction().as_vec3();
                    if d.dot(side) <= 0.0 {
                        d = -d;
                    }
                    if d.dot(side) <= 0.0 {
                        continue;
                    }
                    // The renderer's origin box: the hit box widened by the net's rounding.
                    let leave = widen_by_net_rounding(h.hit_box, &prepared[k].bounds());
                    let o = secondary_origin(&leave, n, outside, DEFAULT_ULPS);
                    let sec = Ray::new(o, d);
                    checked += 1;
                    if let Some(s) = intersect(&prepared[k], None, &sec, &cfg, &mut stats)
                        && overlaps(&s.hit_box, &h.hit_box)
                    {
                        self_hits.push((scale, offset, outside, h, s));
                    }
                    // Shadow ray: may its own patch block the segment up to a few box
                    // diameters? It must not.
                    let reach = 4.0 * h.hit_box.l1_diameter().max(f32::MIN_POSITIVE) / d.length();
                    let shadow = Ray { tmax: reach, ..sec };
                    if outside && occluded(&prepared[k], None, &shadow, &cfg, &mut stats) {
                        let s = intersect(&prepared[k], None, &shadow, &cfg, &mut stats).unwrap();
                        if overlaps(&s.hit_box, &h.hit_box) {
                            self_hits.push((scale, offset, outside, h, s));
                        }
                    }
                }
            }
        }
    }
    assert!(checked >= 19_000);
    assert!(
        self_hits.is_empty(),
        "{} self-hits of {checked}, e.g. {:?}",
        self_hits.len(),
        self_hits.first()
    );
}
