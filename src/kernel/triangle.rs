//! Watertight ray–triangle intersection (Woop, Benthin, Wald, "Watertight Ray/Triangle
//! Intersection", JCGT 2(1), 2013), in `f32`.
//!
//! The ray is sheared once ([`RayShear`]) so that it runs along +z from the origin; the
//! triangle's vertices are transformed the same way and the 2D edge functions decide the
//! hit. Because every edge function of a shared edge is computed from the same two
//! transformed vertices in the same arithmetic, a ray through an edge or vertex hits at
//! least one of the triangles sharing it (§3 of the paper). Edge functions that round to
//! exactly 0 are recomputed in `f64`, where the products are exact (§4, "fallback to
//! double precision").
//!
//! The hit box for secondary rays is the barycentric point rounded outward by the error
//! bound of computing it in `f32` (pbrt-v3 §3.9.5, "Bounding intersection point error",
//! triangles: γ₇ (|b0 p0| + |b1 p1| + |b2 p2|)), so the renderer's ulp-robust offset from
//! a corner of the hit box (Dammertz §2.4) applies to triangles as it does to patches.

use glam::Vec3;

use crate::geom::{Aabb, Ray};

/// The per-ray precomputation of Woop et al. §3: the axis `kz` along which the direction
/// is largest, the other two axes (swapped when `dir[kz] < 0` to keep the winding), and the
/// shear constants.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RayShear {
    pub origin: Vec3,
    pub kx: usize,
    pub ky: usize,
    pub kz: usize,
    pub sx: f32,
    pub sy: f32,
    pub sz: f32,
}

impl RayShear {
    pub fn new(ray: &Ray) -> RayShear {
        let d = ray.dir;
        let a = d.abs();
        let kz = if a.x >= a.y && a.x >= a.z {
            0
        } else if a.y >= a.z {
            1
        } else {
            2
        };
        let mut kx = (kz + 1) % 3;
        let mut ky = (kx + 1) % 3;
        if d[kz] < 0.0 {
            std::mem::swap(&mut kx, &mut ky);
        }
        RayShear {
            origin: ray.origin,
            kx,
            ky,
            kz,
            sx: d[kx] / d[kz],
            sy: d[ky] / d[kz],
            sz: 1.0 / d[kz],
        }
    }
}

/// A triangle hit: the ray parameter and the barycentric weights of p0, p1, p2 (summing
/// to 1).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TriangleHit {
    pub t: f32,
    pub b0: f32,
    pub b1: f32,
    pub b2: f32,
}

/// The hit of the sheared ray with triangle (p0, p1, p2) for `t` in `[tmin, tmax]`, either
/// side facing (no culling).
pub fn intersect_triangle(
    s: &RayShear,
    p0: Vec3,
    p1: Vec3,
    p2: Vec3,
    tmin: f32,
    tmax: f32,
) -> Option<TriangleHit> {
    let (a, b, c) = (p0 - s.origin, p1 - s.origin, p2 - s.origin);
    let shear = |p: Vec3| (p[s.kx] - s.sx * p[s.kz], p[s.ky] - s.sy * p[s.kz]);
    let ((ax, ay), (bx, by), (cx, cy)) = (shear(a), shear(b), shear(c));
    let mut u = cx * by - cy * bx;
    let mut v = ax * cy - ay * cx;
    let mut w = bx * ay - by * ax;
    if u == 0.0 || v == 0.0 || w == 0.0 {
        // Products of two f32 are exact in f64, so the differences are correctly rounded
        // and the sign is right (Woop et al. §4).
        let e = |p: f32, q: f32, r: f32, t: f32| {
            ((p as f64) * (q as f64) - (r as f64) * (t as f64)) as f32
        };
        u = e(cx, by, cy, bx);
        v = e(ax, cy, ay, cx);
        w = e(bx, ay, by, ax);
    }
    if (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0) {
        return None;
    }
    let det = u + v + w;
    if det == 0.0 {
        return None;
    }
    let (az, bz, cz) = (s.sz * a[s.kz], s.sz * b[s.kz], s.sz * c[s.kz]);
    let t_scaled = u * az + v * bz + w * cz;
    // Compare t = T / det with the interval without dividing: flip signs so det > 0.
    let (t_scaled, det_abs) = if det < 0.0 {
        (-t_scaled, -det)
    } else {
        (t_scaled, det)
    };
    if t_scaled < tmin * det_abs || t_scaled > tmax * det_abs {
        return None;
    }
    let r = 1.0 / det;
    Some(TriangleHit {
        t: t_scaled / det_abs,
        b0: u * r,
        b1: v * r,
        b2: w * r,
    })
}

/// γₙ = n u / (1 - n u) with u = 2⁻²⁴ the unit round-off of f32 (Higham; pbrt-v3 §3.9.1).
fn gamma(n: u32) -> f32 {
    let u = f32::EPSILON * 0.5;
    (n as f32 * u) / (1.0 - n as f32 * u)
}

/// Floating-point operations behind the bound of the barycentric point, pbrt-v3 §3.9.5:
/// the barycentrics themselves and the weighted sum together are within γ₇.
const HIT_POINT_GAMMA: u32 = 7;

/// The barycentric hit point `b0 p0 + b1 p1 + b2 p2` in `f32`.
pub fn hit_point(hit: &TriangleHit, p0: Vec3, p1: Vec3, p2: Vec3) -> Vec3 {
    hit.b0 * p0 + hit.b1 * p1 + hit.b2 * p2
}

/// A box certain to contain the exact point of the triangle at the computed barycentrics:
/// the `f32` barycentric point widened by γ₇ (|b0 p0| + |b1 p1| + |b2 p2|) and rounded
/// outward by one ulp so that the widening itself cannot round inward. As in pbrt-v3
/// §3.9.5 the bound is on the distance to the surface (what the offset of a secondary
/// ray must escape), not on where along the surface the ray crossed it, which is
/// ill-conditioned at grazing angles.
pub fn hit_box(hit: &TriangleHit, p0: Vec3, p1: Vec3, p2: Vec3) -> Aabb {
    let p = hit_point(hit, p0, p1, p2);
    let abs_sum = (hit.b0 * p0).abs() + (hit.b1 * p1).abs() + (hit.b2 * p2).abs();
    let err = gamma(HIT_POINT_GAMMA) * abs_sum;
    Aabb::new((p - err).map(f32::next_down), (p + err).map(f32::next_up))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hits_a_triangle_with_closed_form_t_and_barycentrics() {
        let (p0, p1, p2) = (
            Vec3::new(0.0, 0.0, 2.0),
            Vec3::new(1.0, 0.0, 2.0),
            Vec3::new(0.0, 1.0, 2.0),
        );
        let ray = Ray::new(Vec3::new(0.25, 0.5, 0.0), Vec3::new(0.0, 0.0, 0.5));
        let h = intersect_triangle(&RayShear::new(&ray), p0, p1, p2, 0.0, f32::INFINITY).unwrap();
        assert_eq!(h.t, 4.0); // z = 2 at t = 2 / 0.5
        assert_eq!((h.b0, h.b1, h.b2), (0.25, 0.25, 0.5));
        assert!(intersect_triangle(&RayShear::new(&ray), p0, p1, p2, 0.0, 3.9).is_none());
        let miss = Ray::new(Vec3::new(0.75, 0.5, 0.0), Vec3::Z);
        assert!(
            intersect_triangle(&RayShear::new(&miss), p0, p1, p2, 0.0, f32::INFINITY).is_none()
        );
    }

    #[test]
    fn hit_box_contains_the_exact_point() {
        // A skewed triangle far from the origin; the exact hit is computed in f64.
        let (p0, p1, p2) = (
            Vec3::new(1000.1, -3.7, 50.3),
            Vec3::new(1001.9, 2.2, 51.7),
            Vec3::new(999.3, 0.4, 49.1),
        );
        let mut state = 12345u64;
        let mut rnd = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 40) as f32 / (1u64 << 24) as f32
        };
        for _ in 0..2000 {
            let (b1, b2) = (rnd() * 0.5, rnd() * 0.5);
            let target = p0 * (1.0 - b1 - b2) + p1 * b1 + p2 * b2;
            let origin = Vec3::new(990.0, -10.0 + 20.0 * rnd(), 40.0 + 20.0 * rnd());
            let ray = Ray::new(origin, target - origin);
            let Some(h) = intersect_triangle(&RayShear::new(&ray), p0, p1, p2, 0.0, f32::INFINITY)
            else {
                continue;
            };
            // Exact point of the triangle at the computed barycentrics, in f64.
            let b = [h.b0, h.b1, h.b2].map(f64::from);
            let sum = b[0] + b[1] + b[2];
            let exact = (p0.as_dvec3() * b[0] + p1.as_dvec3() * b[1] + p2.as_dvec3() * b[2]) / sum;
            let b = hit_box(&h, p0, p1, p2);
            let inside =
                (0..3).all(|k| (b.min[k] as f64) <= exact[k] && exact[k] <= (b.max[k] as f64));
            assert!(inside, "exact {exact} outside {b:?}");
        }
    }
}
