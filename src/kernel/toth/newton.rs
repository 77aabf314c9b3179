//! Simple Newton iteration in a safe region (Lischinski & Gonczarowski 1990, §4.1): the
//! matrix `Y` stays the inverse Jacobian at the safe region's midpoint, so the iteration
//! converges linearly with the rate `r` Krawczyk's test proved, and the a-posteriori bound
//! `|x_k − x*| ≤ r / (1 − r) · |x_k − x_{k−1}|` of a contraction bounds the error.

use crate::geom::interval::{Interval, IntervalNet, ParamBox};

use super::krawczyk::{Mat2, newton_step};

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

/// Simple Newton from the midpoint of `start` (a safe region with root inside `region`
/// and contraction rate `contraction`) on the equations of the projected `net`.
pub fn simple_newton(
    net: &IntervalNet,
    start: &ParamBox,
    region: &ParamBox,
    contraction: f64,
    inverse: &Mat2,
) -> Option<NewtonResult> {
    let (mut u, mut v) = start.mid();
    let mut last = f64::INFINITY;
    let mut iterations = 0;
    while iterations < NEWTON_MAX_ITERATIONS {
        let (g, _, _) = net.eval(u, v);
        let [du, dv] = newton_step(inverse, &g);
        if !(du.is_finite() && dv.is_finite()) {
            return None;
        }
        // The iteration maps the safe region into K, so clamping to K only removes
        // rounding overshoot.
        u = (u + du).max(region.u.lo()).min(region.u.hi());
        v = (v + dv).max(region.v.lo()).min(region.v.hi());
        iterations += 1;
        last = du.abs().max(dv.abs());
        if last <= NEWTON_STEP_LIMIT {
            break;
        }
    }
    let radius = ERROR_BOUND_SAFETY * contraction / (1.0 - contraction) * last;
    let around = |x: f64, side: Interval| {
        Interval::new((x - radius).next_down(), (x + radius).next_up())
            .and_then(|b| b.intersect(side))
            .unwrap_or(side)
    };
    Some(NewtonResult {
        u,
        v,
        enclosure: ParamBox {
            u: around(u, region.u),
            v: around(v, region.v),
        },
        iterations,
    })
}
