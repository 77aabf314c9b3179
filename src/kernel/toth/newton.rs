//! Simple Newton iteration in a safe region (Lischinski & Gonczarowski 1990, §4.1): the
//! matrix `Y` stays the inverse Jacobian at the safe region's midpoint, so the iteration
//! converges linearly with the rate `r` Krawczyk's test proved, and the a-posteriori bound
//! `|x_k − x*| ≤ r / (1 − r) · |x_k − x_{k−1}|` of a contraction bounds the error.
//!
//! The same bound gives LG90's third triviality test (§6) for rays leaving the surface:
//! with a bound on the ray parameter's derivatives over the safe region, each iterate
//! encloses the root's `t`, and once that enclosure ends before `tmin` the root is the
//! trivial one and the iteration stops ([`Trivial`]).

use crate::geom::MAX_DEGREE;
use crate::geom::bezier::de_casteljau_generic;
use crate::geom::interval::{IPoint, Interval, IntervalNet, ParamBox};

use super::krawczyk::{SafeRegion, newton_step};
use super::raynet::{G1, G2, TAU, W};

/// Newton stops when a step moves (u, v) by less than this: one ulp of `f32` in the upper
/// half `[0.5, 1)` of the parameter domain (2⁻²⁴). The kernel reports (u, v) in `f32`, so
/// smaller steps no longer change the result.
pub const NEWTON_STEP_LIMIT: f64 = f32::EPSILON as f64 * 0.5;

/// Upper bound of simple Newton iterations per start. With the contraction rate `r < 1`
/// proved by Krawczyk's test, 64 steps shrink the error by `r⁶⁴`; LG90 report 1.1–1.4
/// iterations per call (Tables 2–6), so the bound only guards slow contractions.
pub const NEWTON_MAX_ITERATIONS: u32 = 64;

/// The rounding of the evaluated equations (an `f64` de Casteljau, relative error a few
/// `f64` ulps) perturbs the contraction's a-posteriori bound; it is doubled so that a box
/// of that radius still holds the root.
const ERROR_BOUND_SAFETY: f64 = 2.0;

/// A converged Newton iterate and a box of parameter space around it that holds the root.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NewtonResult {
    pub u: f64,
    pub v: f64,
    pub enclosure: ParamBox,
    pub iterations: u32,
}

/// LG90's third triviality test (§6) for one safe region: the root is trivial when its ray
/// parameter is proved below `tmin`. `du`, `dv` enclose the partial derivatives of the
/// projected net over a convex box holding the root and every iterate after the first
/// (`K` or the safe region; `IntervalNet::derivative_hulls`), so along the segment from an
/// iterate to the root `τ` and `w` change by at most their magnitude times the distance.
#[derive(Clone, Copy, Debug)]
pub struct Trivial {
    pub tmin: f64,
    pub du: IPoint,
    pub dv: IPoint,
}

impl Trivial {
    /// True when every point within `radius` (max-norm, inside the region) of the point
    /// whose projected value is `g` has ray parameter `τ / w < tmin`.
    fn proves(&self, g: &IPoint, radius: f64) -> bool {
        let spread = |c: usize| {
            let r = ((self.du[c].mag() + self.dv[c].mag()) * radius).next_up();
            Interval::spanning(-r, r)
        };
        let t = (g[TAU] + spread(TAU)).checked_div(g[W] + spread(W));
        t.is_some_and(|t| t.hi() < self.tmin)
    }
}

/// How simple Newton ended.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Newton {
    /// Converged (the step fell below [`NEWTON_STEP_LIMIT`] or the iteration bound ran out).
    Converged(NewtonResult),
    /// The [`Trivial`] test proved the root's `t` below `tmin` after `iterations` steps.
    Trivial { iterations: u32 },
    /// A step was not finite (a singular or overflowing evaluation).
    Failed,
}

/// Simple Newton in the safe region `safe` on the equations of the projected `net`, from
/// the box's midpoint, whose step Krawczyk's test has already computed; with `trivial`,
/// stops as soon as that test proves the root lies before the ray's start.
///
/// Only the triviality test proves something at the iterates, so only for it are they
/// evaluated in interval arithmetic; a plain `f64` evaluation gives the step (the interval
/// evaluation's midpoints up to `f64` rounding, which the contraction's error bound
/// already allows for).
pub fn simple_newton(net: &IntervalNet, safe: &SafeRegion, trivial: Option<&Trivial>) -> Newton {
    let region = &safe.region;
    let bound = |step: f64| ERROR_BOUND_SAFETY * safe.contraction / (1.0 - safe.contraction) * step;
    let (mut u, mut v) = safe.start;
    let mut step = safe.step;
    let mut iterations = 0;
    let last = loop {
        let [du, dv] = step;
        if !(du.is_finite() && dv.is_finite()) {
            return Newton::Failed;
        }
        // The iteration maps the safe region into K, so clamping to K only removes
        // rounding overshoot.
        u = (u + du).max(region.u.lo()).min(region.u.hi());
        v = (v + dv).max(region.v.lo()).min(region.v.hi());
        iterations += 1;
        let last = du.abs().max(dv.abs());
        if last <= NEWTON_STEP_LIMIT || iterations >= NEWTON_MAX_ITERATIONS {
            break last;
        }
        let g = eval_point(net, u, v);
        // The test can only prove the root trivial where the iterate's own `t` is before
        // `tmin` (its enclosure holds that `t`, up to rounding); only there is the iterate
        // evaluated again in intervals. Skipping the test elsewhere costs no hit: a root
        // after `tmin` is not trivial, and one Newton converges to before `tmin` is
        // dropped by the caller's `t ≥ tmin`.
        if let Some(test) = trivial.filter(|t| g[TAU] / g[W] < t.tmin) {
            let (enclosure, _, _) = net.eval(u, v);
            if test.proves(&enclosure, bound(last)) {
                return Newton::Trivial { iterations };
            }
        }
        step = newton_step(&safe.inverse, [g[G1], g[G2]]);
    };
    let radius = bound(last);
    let around = |x: f64, side: Interval| {
        Interval::new((x - radius).next_down(), (x + radius).next_up())
            .and_then(|b| b.intersect(side))
            .unwrap_or(side)
    };
    Newton::Converged(NewtonResult {
        u,
        v,
        enclosure: ParamBox {
            u: around(u, region.u),
            v: around(v, region.v),
        },
        iterations,
    })
}

/// The projected net's value `(g₁, g₂, τ, w)` at (u, v) in plain `f64`: de Casteljau on
/// the midpoints of its control intervals. Encloses nothing, so it serves only where a
/// point will do (Newton's iterates, a hit's ray parameter); it costs a fraction of the
/// interval evaluation, whose every operation takes four products and two roundings.
pub fn eval_point(net: &IntervalNet, u: f64, v: f64) -> [f64; 4] {
    let (nu, nv) = (net.degree_u() + 1, net.degree_v() + 1);
    let mut rows = [[0.0; 4]; MAX_DEGREE + 1];
    let mut work = rows;
    for (row, points) in rows.iter_mut().zip(net.points().chunks_exact(nu)) {
        for (w, p) in work.iter_mut().zip(points) {
            *w = p.map(Interval::mid);
        }
        *row = de_casteljau_generic(&mut work[..nu], u);
    }
    de_casteljau_generic(&mut rows[..nv], v)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::{BezierPatch, Ray};
    use crate::kernel::toth::krawczyk::{Classification, classify};
    use crate::kernel::toth::raynet::RayFrame;
    use glam::{DVec3, Vec3};

    /// Simple Newton with the triviality test 3 on a bilinear plane patch hit at a known
    /// ray parameter: `tmin` just after the root proves it trivial, `tmin` just before it
    /// lets Newton converge to it. Returns both outcomes and the closed-form `t`.
    fn newton_around_root(margin: f64) -> (Newton, Newton, f64) {
        let p = [
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(2.0, 0.0, 0.5),
            DVec3::new(0.0, 2.0, 0.0),
            DVec3::new(2.0, 2.0, 0.5),
        ];
        let patch = BezierPatch::from_points(1, 1, &p).unwrap();
        let o = Vec3::new(0.7, 0.9, 3.0);
        let ray = Ray::new(o, Vec3::new(0.1, 0.2, -1.0));
        // The plane z = x / 4: o.z + t d.z = (o.x + t d.x) / 4.
        let (ox, oz, dx, dz) = (0.7f64, 3.0f64, 0.1f32 as f64, -1.0f64);
        let t = (ox / 4.0 - oz) / (dz - dx / 4.0);
        let mut net = IntervalNet::default();
        RayFrame::new(&ray).project(patch.homogeneous_points(), 2, 2, &mut net);
        let x = ParamBox::UNIT;
        let mut sub = IntervalNet::default();
        net.subnet_into(&x, &mut sub);
        let Classification::Safe(safe) = classify(&net, &sub, &x) else {
            panic!("a plane is a safe region");
        };
        let (du, dv) = sub.derivative_hulls(&x).unwrap();
        let run = |tmin: f64| {
            let test = Trivial { tmin, du, dv };
            simple_newton(&net, &safe, Some(&test))
        };
        (run(t + margin), run(t - margin), t)
    }

    /// How far from the root `tmin` is put: far above the `f32` rounding of the ray
    /// (≈ 1e-7 relative on t ≈ 3) and the f64 evaluation, far below the plane's size.
    const MARGIN: f64 = 1e-4;

    #[test]
    fn test_3_proves_a_root_before_tmin_trivial() {
        let (fires, _, _) = newton_around_root(MARGIN);
        assert!(matches!(fires, Newton::Trivial { .. }), "{fires:?}");
    }

    #[test]
    fn test_3_lets_newton_converge_to_a_root_after_tmin() {
        let (_, converges, t) = newton_around_root(MARGIN);
        let Newton::Converged(n) = converges else {
            panic!("{converges:?}");
        };
        // The converged point is on the plane at the closed-form parameter.
        let (ox, dx) = (0.7, 0.1f32 as f64);
        let u = (ox + t * dx) / 2.0;
        assert!((n.u - u).abs() < MARGIN, "u {} vs {u}", n.u);
    }

    /// The plain `f64` evaluation agrees with the interval evaluation, an independent
    /// algorithm whose result encloses the exact value: on a rational bicubic net with
    /// non-degenerate control intervals it lies within that enclosure widened by a few
    /// `f64` ulps of rounding.
    #[test]
    fn point_evaluation_lies_in_the_interval_enclosure() {
        let p: Vec<DVec3> = (0..16)
            .map(|k| {
                let (i, j) = ((k % 4) as f64, (k / 4) as f64);
                DVec3::new(i, j, (i * 1.3 - j * 0.7).sin())
            })
            .collect();
        let weights: Vec<f64> = (0..16).map(|k| 1.0 + (k % 3) as f64 * 0.25).collect();
        let patch = BezierPatch::from_weighted(3, 3, &p, &weights).unwrap();
        let ray = Ray::new(Vec3::new(0.3, -0.2, 5.0), Vec3::new(0.1, 0.2, -1.0));
        let mut net = IntervalNet::default();
        RayFrame::new(&ray).project(patch.homogeneous_points(), 4, 4, &mut net);
        for (u, v) in [(0.0, 0.0), (0.3, 0.7), (0.5, 0.5), (0.91, 0.12), (1.0, 0.4)] {
            let (g, _, _) = net.eval(u, v);
            let x = eval_point(&net, u, v);
            for c in 0..4 {
                let slack = 8.0 * f64::EPSILON * g[c].mag().max(1.0);
                assert!(
                    x[c] >= g[c].lo() - slack && x[c] <= g[c].hi() + slack,
                    "({u}, {v}) component {c}: {} outside {:?}",
                    x[c],
                    g[c]
                );
            }
        }
    }
}
