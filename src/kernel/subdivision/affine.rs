//! The closed form for affine patches: a patch whose surface is `S(u, v) = O + u A + v B`
//! (a bilinear parallelogram such as a scene's floor, a CAD plane's Bézier pieces, any
//! patch whose net is the affine image of the uniform grid `(i / du, j / dv)`) meets a ray
//! at most once, where the ray crosses its plane. `t` comes from the plane, (u, v) from
//! the dual basis of `A, B`, all in `f64` from the patch's `f64` points (the `f32` ray's
//! values are exact in `f64`), and the hit box is the point widened by a bound on that
//! arithmetic's rounding and rounded outward to `f32`: it contains the exact crossing, like
//! the subdivision's final box (Dammertz §2.3), and is about an ulp wide instead of the
//! search's 8. The test is chosen when the patch is prepared (Dammertz §2.7.1), so no ray
//! pays for the choice.

use glam::DVec3;

use super::float::GRay;
use crate::geom::bbox::DAabb;
use crate::geom::{Aabb, BezierPatch};

/// Largest distance, in `f64` ulps of the patch's coordinate scale (its largest coordinate
/// magnitude), by which a control point may miss the affine image of its grid position for
/// the patch to take the closed form. Knot insertion and Bézier extraction of a CAD plane
/// compute each inner point as a chain of convex combinations of the plane's corners, each
/// rounding by half an ulp of the scale; 16 covers such chains with room, and is 2^-25 of
/// the `f32` ulp the kernel works to. The bound itself is added to every hit box
/// ([`AffinePatch::margin`]), so the box still contains the crossing of the patch's own
/// surface: by the convex hull property that surface lies within the largest deviation of
/// a control point from the plane's.
pub const AFFINE_TOLERANCE_ULPS: f64 = 16.0;

/// Smallest sine of the angle between `A` and `B` the closed form takes: the dual basis
/// amplifies rounding by about its inverse. Below it (a sliver or a patch collapsed to a
/// curve) the subdivision search takes the patch.
const MIN_SINE: f64 = 1.0 / 1024.0;

/// Rounding allowance of the closed form, in `f64` epsilons of the magnitudes it combines.
/// The plane's `t` is a quotient of two dot products (γ₄ each, Higham 2002 §3.1, and one
/// division), the point one product and one sum, (u, v) one more dot product; the normal
/// and the dual basis are themselves rounded cross products. Each of those is a few units
/// of 2^-53; 64 covers their sum with a factor 4 of room and is still 2^-23 of an `f32`
/// ulp.
const ROUNDING_EPSILONS: f64 = 64.0;

/// An affine patch prepared for the closed form.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AffinePatch {
    /// `S(0, 0)`.
    origin: DVec3,
    /// `A × B`: constant, so the normal is exact (the hit's normal is still taken from the
    /// `f64` patch, which gives the same vector and orientation).
    normal: DVec3,
    /// `(B × n) / |n|²` and `(n × A) / |n|²`: `u = dual_u · (P − O)`, `v = dual_v · (P − O)`
    /// for `P` in the plane.
    dual_u: DVec3,
    dual_v: DVec3,
    /// [`AFFINE_TOLERANCE_ULPS`] twice over, in scene units: the most the patch's surface
    /// can lie off the plane (the measured deviation plus the rounding of measuring it).
    margin: f64,
    /// The parallelogram's box widened by `margin` and rounded outward to `f32`: it holds
    /// every hit box [`AffinePatch::hit`] reports short of grazing rays, whose boxes grow
    /// along the ray (and are then in the ray's box test anyway).
    bounds: Aabb,
}

/// A ray's crossing of an affine patch.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AffineHit {
    pub t: f32,
    pub u: f64,
    pub v: f64,
    /// Contains the exact crossing of the `f32` ray with the patch.
    pub hit_box: Aabb,
}

impl AffinePatch {
    /// The closed form of `patch` when its surface is affine: integral (or rational with
    /// equal weights), every control point within [`AFFINE_TOLERANCE_ULPS`] of the affine
    /// image of its grid position, and `A`, `B` not nearly parallel. `None` for any other
    /// patch.
    pub fn of(patch: &BezierPatch) -> Option<AffinePatch> {
        let w = patch.homogeneous(0, 0).w;
        if patch.homogeneous_points().iter().any(|p| p.w != w) {
            return None;
        }
        let (du, dv) = (patch.degree_u(), patch.degree_v());
        let o = patch.point(0, 0);
        let (a, b) = (patch.point(du, 0) - o, patch.point(0, dv) - o);
        let affine = AffinePatch::new(o, a, b)?;
        let tolerance = AFFINE_TOLERANCE_ULPS * f64::EPSILON * scale(o, a, b);
        let on_grid = (0..=dv).all(|j| {
            (0..=du).all(|i| {
                let grid = o + (i as f64 / du as f64) * a + (j as f64 / dv as f64) * b;
                (patch.point(i, j) - grid).abs().max_element() <= tolerance
            })
        });
        on_grid.then_some(affine)
    }

    /// The closed form of the affine map `O + u A + v B` (no check that a patch is one):
    /// `None` when `A` and `B` are nearly parallel ([`MIN_SINE`]) or not finite.
    pub fn new(o: DVec3, a: DVec3, b: DVec3) -> Option<AffinePatch> {
        let n = a.cross(b);
        let n2 = n.length_squared();
        let conditioned = n2 >= MIN_SINE * MIN_SINE * a.length_squared() * b.length_squared();
        if !(conditioned && n2 > 0.0 && n2.is_finite() && o.is_finite()) {
            return None;
        }
        let scale = scale(o, a, b);
        let margin = 2.0 * AFFINE_TOLERANCE_ULPS * f64::EPSILON * scale;
        let mut corners = DAabb::EMPTY;
        for c in [o, o + a, o + b, o + a + b] {
            corners.grow(c);
        }
        // The corners' own rounding is below an ulp of the scale: the margin covers it.
        let m = DVec3::splat(2.0 * margin);
        Some(AffinePatch {
            origin: o,
            normal: n,
            dual_u: b.cross(n) / n2,
            dual_v: n.cross(a) / n2,
            margin,
            bounds: DAabb {
                min: corners.min - m,
                max: corners.max + m,
            }
            .to_f32_outward(),
        })
    }

    /// The box of the patch ([`AffinePatch::bounds`] field).
    pub fn bounds(&self) -> Aabb {
        self.bounds
    }

    /// The crossing of `ray` with `t` in `[ray.tmin, tmax]` and (u, v) in the unit square up
    /// to the rounding of (u, v) (so two patches sharing an edge leave no crack between them;
    /// the reported (u, v) is clamped into the square).
    #[inline]
    pub fn hit(&self, ray: &GRay<f32>, tmax: f32) -> Option<AffineHit> {
        let orig = DVec3::from_array(ray.origin.map(f64::from));
        let dir = DVec3::from_array(ray.dir.map(f64::from));
        let denom = self.normal.dot(dir);
        let w = self.origin - orig;
        let t = self.normal.dot(w) / denom;
        // Refuses a ray in the plane (0/0) or parallel to it (±∞, which an infinite
        // `tmax` would admit).
        if !(t.is_finite() && (f64::from(ray.tmin)..=f64::from(tmax)).contains(&t)) {
            return None;
        }
        let p = orig + t * dir;
        let q = p - self.origin;
        let (u, v) = (self.dual_u.dot(q), self.dual_v.dot(q));
        // A grazing ray turns an error across the plane into one along it, by about
        // |n| |d| / |n · d|; the rounding is relative to the lengths the ray spans.
        let grazing = self.normal.abs().element_sum() * dir.abs().max_element() / denom.abs();
        let reach = w.abs().max_element() + (t * dir).abs().max_element();
        let err = grazing * (ROUNDING_EPSILONS * f64::EPSILON * reach + 2.0 * self.margin);
        let slack = |dual: DVec3| {
            dual.abs().element_sum()
                * (err + ROUNDING_EPSILONS * f64::EPSILON * q.abs().max_element())
        };
        let (su, sv) = (slack(self.dual_u), slack(self.dual_v));
        if !((-su..=1.0 + su).contains(&u) && (-sv..=1.0 + sv).contains(&v)) {
            return None;
        }
        Some(AffineHit {
            t: t as f32,
            u: u.clamp(0.0, 1.0),
            v: v.clamp(0.0, 1.0),
            hit_box: DAabb {
                min: p - DVec3::splat(err),
                max: p + DVec3::splat(err),
            }
            .to_f32_outward(),
        })
    }
}

/// The largest coordinate magnitude of the parallelogram `o, o + a, o + b, o + a + b`: the
/// largest of any affine patch's control points, which lie in it.
fn scale(o: DVec3, a: DVec3, b: DVec3) -> f64 {
    [o, o + a, o + b, o + a + b]
        .iter()
        .fold(0.0, |m, c| m.max(c.abs().max_element()))
}

#[cfg(test)]
mod tests;
