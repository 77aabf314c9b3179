//! Helpers shared by the tests of the Toth and cached kernels (LG90 §4): random patches
//! and rays, and the check of a kernel against the `f64` subdivision reference
//! (`intersect_f64`, an independent algorithm: Dammertz's box subdivision in double
//! precision).

pub mod render;

use glam::DVec3;
use patchtrace::geom::{BezierPatch, Ray};
use patchtrace::kernel::PatchHit;
use patchtrace::kernel::subdivision::{SubdivisionConfig, intersect_f64};

use crate::kernel_common::{Rng, min_ray_distance};

/// A random wavy patch of the given degrees in a 4-unit box, rational with weights in
/// [0.5, 2] when `rational`.
pub fn random_patch(rng: &mut Rng, du: usize, dv: usize, rational: bool) -> BezierPatch {
    let mut pts = Vec::new();
    let mut w = Vec::new();
    for j in 0..=dv {
        for i in 0..=du {
            let (x, y) = (
                4.0 * i as f64 / du as f64 - 2.0,
                4.0 * j as f64 / dv as f64 - 2.0,
            );
            pts.push(DVec3::new(x, y, rng.range(-1.5, 1.5)));
            w.push(if rational { rng.range(0.5, 2.0) } else { 1.0 });
        }
    }
    BezierPatch::from_weighted(du, dv, &pts, &w).unwrap()
}

/// A ray from a random point above the patch towards a random point near it, rounded to
/// `f32` (the kernel's ray), with the `f64` copy of the same rounded ray.
pub fn random_ray(rng: &mut Rng) -> (Ray, DVec3, DVec3) {
    let o = DVec3::new(
        rng.range(-3.0, 3.0),
        rng.range(-3.0, 3.0),
        rng.range(4.0, 8.0),
    );
    let target = DVec3::new(
        rng.range(-2.5, 2.5),
        rng.range(-2.5, 2.5),
        rng.range(-1.0, 1.0),
    );
    let ray = Ray::new(o.as_vec3(), (target - o).as_vec3());
    (ray, ray.origin.as_dvec3(), ray.dir.as_dvec3())
}

/// Rays passing closer than this to the patch (in units of the 4-unit patch) without a
/// reference hit, or with one, are grazing: the two kernels may disagree on them by the
/// `f32`-level precision each stops at.
pub const SILHOUETTE: f64 = 1e-4;

/// Largest distance along the ray between the two kernels' hit points. The reference
/// reports the entry of a final box up to 8 ulps of coordinates below 8 units wide
/// (8 · 4.8e-7 ≈ 3.8e-6), Toth a converged Newton point; along a ray meeting the surface
/// at angle θ that is 3.8e-6 / sin θ, so this allows incidence down to about 2°.
pub const HIT_DISTANCE: f64 = 1e-4;

/// Hits and misses of a run of [`agrees_with_reference`].
pub struct Agreement {
    pub hits: u32,
    pub misses: u32,
    pub rays: u32,
}

/// Checks `kernel` against the `f64` reference on `rays_per_patch` random rays at each of
/// 60 random patches (bicubic, rational bicubic, and lower degrees): hit or miss alike
/// except at grazing rays, hit points within [`HIT_DISTANCE`], and each hit point inside
/// its hit box.
pub fn agrees_with_reference(
    seed: u64,
    rays_per_patch: usize,
    mut kernel: impl FnMut(&BezierPatch, &Ray) -> Option<PatchHit>,
) -> Agreement {
    let mut rng = Rng::new(seed);
    let reference = SubdivisionConfig::default();
    let (mut hits, mut misses, mut rays) = (0, 0, 0);
    for k in 0..60 {
        let (du, dv, rational) = match k % 3 {
            0 => (3, 3, false),
            1 => (3, 3, true),
            _ => (1 + k % 4, 2, k % 2 == 0),
        };
        let patch = random_patch(&mut rng, du, dv, rational);
        for _ in 0..rays_per_patch {
            let (ray, o, d) = random_ray(&mut rng);
            rays += 1;
            let want = intersect_f64(&patch, o, d, 0.0, f64::INFINITY, &reference, None);
            let got = kernel(&patch, &ray);
            match (want, got) {
                (Some(w), Some(g)) => {
                    hits += 1;
                    // Both stop at the f32 precision of the coordinates (≈ 8 ulps of 8
                    // units): compare the hit points along the ray.
                    let dt = (g.t as f64 - w.t).abs() * d.length();
                    // A different root of the same ray is only allowed when the ray grazes
                    // the patch somewhere (near a silhouette).
                    assert!(
                        dt <= HIT_DISTANCE || min_ray_distance(&patch, o, d, 24) < SILHOUETTE,
                        "patch {k}: t {} vs reference {}",
                        g.t,
                        w.t
                    );
                    let p = o + d * g.t as f64;
                    let b = g.hit_box;
                    let grow = 1e-5;
                    assert!(
                        (0..3)
                            .all(|i| p[i] >= b.min[i] as f64 - grow
                                && p[i] <= b.max[i] as f64 + grow),
                        "patch {k}: hit point {p} outside its hit box {b:?}"
                    );
                }
                (None, None) => misses += 1,
                (w, g) => {
                    let dist = min_ray_distance(&patch, o, d, 24);
                    assert!(
                        dist < SILHOUETTE,
                        "patch {k} ({du}x{dv}, rational {rational}): reference {w:?} vs kernel {g:?}, ray at distance {dist}"
                    );
                }
            }
        }
    }
    Agreement { hits, misses, rays }
}
