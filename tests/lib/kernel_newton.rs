//! The `f32` subdivision kernel against an independent solution: Newton's method in `f64`
//! on `S(u, v) − (o + t d) = 0`, started from the local minima of the ray distance over a
//! dense (u, v) grid, on random bicubic (fast path) and rational (degree 2–4, weights
//! 0.2–5, general path) patches.
//!
//! Exclusion rule (rays where f32 hit/miss is legitimately undecidable, decided from the
//! f64 geometry alone): a reference hit whose root is grazing, `|n̂ · d̂| < GRAZING_COS`, or
//! within `EDGE_MARGIN` of a patch edge in u or v; a reference miss whose ray passes within
//! `NEAR_MISS` (relative to the patch size) of the patch. Excluded rays are counted and must
//! be a small fraction.

use crate::kernel_common;

use glam::DVec3;
use kernel_common::{Rng, min_ray_distance, nearest_root};
use patchtrace::geom::{BezierPatch, Ray};
use patchtrace::kernel::KernelStats;
use patchtrace::kernel::subdivision::{PreparedPatch, SubdivisionConfig, intersect};

/// Cosine below which a reference hit is too grazing to decide in f32.
const GRAZING_COS: f64 = 0.01;
/// Parameter distance from an edge below which a reference hit is excluded.
const EDGE_MARGIN: f64 = 1e-4;
/// Ray-to-patch distance (relative to the patch diagonal) below which a miss is excluded:
/// above `SPLIT_ROUNDING_ULPS` for the patches used here.
const NEAR_MISS: f64 = 1e-4;
/// Bound on the distance between the f32 sub-nets' surface and the exact one, in ulps of
/// the largest coordinate: ½ at input plus 1½ per split over 2·32 splits (see `check`).
const SPLIT_ROUNDING_ULPS: f64 = 0.5 + 1.5 * 64.0;
/// Grid of Newton seeds per direction.
const GRID: usize = 24;

fn random_patch(rng: &mut Rng, rational: bool) -> BezierPatch {
    let (du, dv) = if rational {
        (
            2 + (rng.next_u64() % 3) as usize,
            2 + (rng.next_u64() % 3) as usize,
        )
    } else {
        (3, 3)
    };
    // A random frame and offset so no patch is axis aligned.
    let a = rng.direction();
    let b = a.any_orthonormal_vector();
    let c = a.cross(b);
    let offset = DVec3::new(
        rng.range(-5.0, 5.0),
        rng.range(-5.0, 5.0),
        rng.range(-5.0, 5.0),
    );
    let mut pts = Vec::new();
    let mut weights = Vec::new();
    for j in 0..=dv {
        for i in 0..=du {
            let x = 2.0 * i as f64 / du as f64 + rng.range(-0.15, 0.15);
            let y = 2.0 * j as f64 / dv as f64 + rng.range(-0.15, 0.15);
            let z = rng.range(-0.6, 0.6);
            pts.push(offset + x * a + y * b + z * c);
            // Log-uniform weights in [0.2, 5].
            weights.push(if rational {
                (rng.range(-1.0, 1.0) * 5f64.ln()).exp()
            } else {
                1.0
            });
        }
    }
    BezierPatch::from_weighted(du, dv, &pts, &weights).unwrap()
}

#[derive(Default, Debug)]
struct Tally {
    rays: usize,
    hits: usize,
    excluded: usize,
    /// Largest distance of the f64 root outside the final box, times |cos θ|, in ulps of
    /// the coordinates.
    max_outside_ulps: f64,
    /// Largest t error beyond the box extent, as a distance times |cos θ|, in ulps.
    max_t_err_ulps: f64,
}

fn check(rational: bool, patches: usize, rays_per_patch: usize, seed: u64) -> Tally {
    let mut rng = Rng::new(seed);
    let cfg = SubdivisionConfig::default();
    let mut tally = Tally::default();
    for _ in 0..patches {
        let p = random_patch(&mut rng, rational);
        let prepared = PreparedPatch::new(&p);
        let cbox = p.control_box();
        let size = cbox.diagonal();
        let coord_ulp = (cbox.min.abs().max(cbox.max.abs()).max_element() as f32).next_up() as f64
            - cbox.min.abs().max(cbox.max.abs()).max_element() as f32 as f64;
        for r in 0..rays_per_patch {
            // Most rays aim at a surface point, the rest at a random point of the box.
            let target = if r % 4 != 0 {
                p.eval(rng.uniform(), rng.uniform())
            } else {
                cbox.min
                    + (cbox.max - cbox.min)
                        * DVec3::new(rng.uniform(), rng.uniform(), rng.uniform())
            };
            let origin = target + rng.direction() * rng.range(3.0, 6.0);
            let dir = (target - origin) * rng.range(0.5, 2.0);
            let ray = Ray::new(origin.as_vec3(), dir.as_vec3());
            let (o, d) = (ray.origin.as_dvec3(), ray.dir.as_dvec3());
            let mut stats = KernelStats::default();
            let got = intersect(&prepared, None, &ray, &cfg, &mut stats);
            let seeds: Vec<(f64, f64)> = got.iter().map(|h| (h.u as f64, h.v as f64)).collect();
            let want = nearest_root(&p, o, d, GRID, &seeds);
            tally.rays += 1;
            let excluded = match want {
                Some((u, v, _)) => {
                    let n = p.normal(u, v);
                    let edge = [u, v, 1.0 - u, 1.0 - v].iter().any(|&x| x < EDGE_MARGIN);
                    n.dot(d.normalize()).abs() < GRAZING_COS || edge
                }
                None => min_ray_distance(&p, o, d, GRID) < NEAR_MISS * size,
            };
            if excluded {
                tally.excluded += 1;
                continue;
            }
            match (got, want) {
                (None, None) => {}
                (Some(h), Some((u, v, t))) => {
                    tally.hits += 1;
                    // The kernel's sub-nets are the exact net rounded to f32 and then split
                    // in f32: each point is off by ½ ulp of the coordinates at input and by
                    // at most 1½ ulps per split (three rounded averages), over at most
                    // 2·32 splits. The f32 surface the final box encloses can therefore be
                    // SPLIT_ROUNDING_ULPS away from the f64 surface, which moves the ray's
                    // crossing by that much over |cos θ| along the ray.
                    let cos = p.normal(u, v).dot(d.normalize()).abs();
                    let slack = SPLIT_ROUNDING_ULPS * coord_ulp / cos;
                    let q = o + t * d;
                    let b = h.hit_box;
                    let outside = (0..3)
                        .map(|i| {
                            (b.min[i] as f64 - q[i])
                                .max(q[i] - b.max[i] as f64)
                                .max(0.0)
                        })
                        .fold(0.0, f64::max);
                    let extent = (b.max - b.min).as_dvec3().element_sum();
                    let t_err = (h.t as f64 - t).abs() * d.length();
                    assert!(
                        outside <= slack && t_err <= extent + slack,
                        "root {q:?} (t {t}, uv {u} {v}) vs box {b:?} t {} uv {} {}",
                        h.t,
                        h.u,
                        h.v
                    );
                    tally.max_outside_ulps = tally.max_outside_ulps.max(outside * cos / coord_ulp);
                    tally.max_t_err_ulps = tally
                        .max_t_err_ulps
                        .max((t_err - extent).max(0.0) * cos / coord_ulp);
                }
                (got, want) => panic!(
                    "hit/miss disagree: kernel {got:?}, Newton {want:?}, ray {ray:?}, patch {p:?}"
                ),
            }
        }
    }
    tally
}

fn assert_tally(t: &Tally) {
    eprintln!("{t:?}");
    assert!(t.hits > t.rays / 2, "too few hits tested: {t:?}");
    assert!(t.excluded * 50 < t.rays, "more than 2% excluded: {t:?}");
}

#[test]
fn bicubic_kernel_agrees_with_newton() {
    let t = check(false, 40, 50, 1);
    assert_tally(&t);
}

#[test]
fn rational_kernel_agrees_with_newton() {
    let t = check(true, 40, 50, 2);
    assert_tally(&t);
}

#[test]
fn hit_box_entry_is_not_behind_tmin_or_beyond_tmax() {
    // A ray clipped before the surface misses; clipped just after it still hits, at t
    // within [tmin, tmax].
    let mut rng = Rng::new(3);
    let p = random_patch(&mut rng, false);
    let prepared = PreparedPatch::new(&p);
    let target = p.eval(0.4, 0.6);
    let n = p.normal(0.4, 0.6);
    let origin = target + 3.0 * n;
    let ray = Ray::new(origin.as_vec3(), (target - origin).as_vec3());
    let cfg = SubdivisionConfig::default();
    let mut s = KernelStats::default();
    let full = intersect(&prepared, None, &ray, &cfg, &mut s).expect("aimed at the surface");
    let short = Ray { tmax: 0.9, ..ray };
    assert!(intersect(&prepared, None, &short, &cfg, &mut s).is_none());
    let late = Ray {
        tmin: 0.5,
        tmax: 1.1,
        ..ray
    };
    let h = intersect(&prepared, None, &late, &cfg, &mut s).unwrap();
    assert!(h.t >= 0.5 && h.t <= 1.1);
    let extent = full.hit_box.l1_diameter() + h.hit_box.l1_diameter();
    assert!((h.t - full.t).abs() * ray.dir.length() <= extent);
}
