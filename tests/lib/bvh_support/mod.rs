//! Shared helpers for the BVH tests: a seeded generator (no `rand` dependency), random scenes
//! of boxes, random rays, and an independent `f64` ray–sphere test used as the primitive.

use glam::{DVec3, Vec3};
use patchtrace::geom::{Aabb, Ray};
use patchtrace::scene::generate::SplitMix64;

/// The library's seeded SplitMix64 generator, drawing `f32` values.
pub struct Rng(SplitMix64);

impl Rng {
    pub fn new(seed: u64) -> Self {
        Rng(SplitMix64::new(seed))
    }

    pub fn next_u64(&mut self) -> u64 {
        self.0.next_u64()
    }

    /// Uniform in [lo, hi).
    pub fn range(&mut self, lo: f32, hi: f32) -> f32 {
        self.0.range(lo as f64, hi as f64) as f32
    }

    pub fn vec(&mut self, lo: f32, hi: f32) -> Vec3 {
        Vec3::new(self.range(lo, hi), self.range(lo, hi), self.range(lo, hi))
    }
}

/// `n` boxes scattered in a cube of side 20, sizes from tiny to large so that they overlap.
pub fn random_boxes(rng: &mut Rng, n: usize) -> Vec<Aabb> {
    (0..n)
        .map(|_| {
            let c = rng.vec(-10.0, 10.0);
            let size = rng.range(0.0, 1.0).powi(3) * 4.0 + 0.01;
            let h = Vec3::new(
                rng.range(0.2, 1.0),
                rng.range(0.2, 1.0),
                rng.range(0.2, 1.0),
            ) * size;
            Aabb::new(c - h, c + h)
        })
        .collect()
}

/// A ray from outside or inside the scene towards a random point in it.
pub fn random_ray(rng: &mut Rng) -> Ray {
    let origin = rng.vec(-15.0, 15.0);
    let target = rng.vec(-10.0, 10.0);
    Ray::new(origin, target - origin)
}

/// Sphere strictly inside a box: centred, radius 0.45 of the smallest extent.
pub fn inner_sphere(b: &Aabb) -> (DVec3, f64) {
    (
        b.center().as_dvec3(),
        0.45 * b.extent().min_element() as f64,
    )
}

/// Nearest `t` in `[tmin, tmax]` where the ray meets the sphere, in `f64` (closed form).
pub fn ray_sphere(ray: &Ray, (c, r): (DVec3, f64), tmin: f32, tmax: f32) -> Option<f32> {
    let o = ray.origin.as_dvec3() - c;
    let d = ray.dir.as_dvec3();
    let a = d.dot(d);
    let b = o.dot(d);
    let disc = b * b - a * (o.dot(o) - r * r);
    if disc < 0.0 || r <= 0.0 {
        return None;
    }
    let s = disc.sqrt();
    [(-b - s) / a, (-b + s) / a]
        .into_iter()
        .map(|t| t as f32)
        .find(|&t| t >= tmin && t <= tmax)
}

/// The nearest hit over all spheres by brute force: (t, prim).
pub fn brute_nearest(spheres: &[(DVec3, f64)], ray: &Ray) -> Option<(f32, u32)> {
    spheres
        .iter()
        .enumerate()
        .filter_map(|(i, &s)| ray_sphere(ray, s, ray.tmin, ray.tmax).map(|t| (t, i as u32)))
        .min_by(|a, b| a.0.total_cmp(&b.0))
}
