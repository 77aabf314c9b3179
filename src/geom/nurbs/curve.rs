//! NURBS curves with homogeneous premultiplied control points. The surface algorithms are
//! the curve algorithms applied to every row (or column) of the control net, as *The NURBS
//! Book* does for surfaces (A5.3 knot insertion, A5.7 decomposition), so the curve is the
//! unit they are written and tested on.

use glam::{DVec3, DVec4};

use super::basis::span_basis;
use crate::geom::bezier::dehomogenize;

/// A NURBS curve of degree `degree` with `points.len() + degree + 1` knots.
/// Its methods expect what [`knots::validate`](super::knots::validate) checks and
/// positive weights; curves taken from a valid [`NurbsSurface`](super::NurbsSurface)
/// satisfy both.
#[derive(Clone, Debug, PartialEq)]
pub struct NurbsCurve {
    pub degree: usize,
    pub knots: Vec<f64>,
    /// Homogeneous premultiplied `(w x, w y, w z, w)`.
    pub points: Vec<DVec4>,
}

impl NurbsCurve {
    /// Homogeneous curve point at `t` (clamped into the domain), by Cox–de Boor (A4.1 on
    /// homogeneous points).
    pub fn eval_homogeneous(&self, t: f64) -> DVec4 {
        let p = self.degree;
        let (span, n) = span_basis(p, &self.knots, t);
        (0..=p).map(|r| self.points[span - p + r] * n[r]).sum()
    }

    /// Curve point at `t`.
    pub fn eval(&self, t: f64) -> DVec3 {
        dehomogenize(self.eval_homogeneous(t))
    }
}
