//! Trimming loops in a surface's parameter domain (OBJ `trim` / `hole` with `curv2`).
//! They are parsed and kept; the kernels do not evaluate them yet (Dammertz §2.6).

use glam::DVec3;

/// A planar parameter-space curve (OBJ `curv2`) as a B-spline: homogeneous premultiplied
/// points `(w u, w v, w)` (w = 1 for non-rational) and a knot vector of
/// `points.len() + degree + 1` values. A piecewise Bézier curve is stored as the B-spline
/// with the same breakpoints (end knots repeated `degree + 1` times, interior ones
/// `degree` times), which is the same curve.
#[derive(Clone, Debug, PartialEq)]
pub struct ParamCurve {
    pub degree: usize,
    pub knots: Vec<f64>,
    pub points: Vec<DVec3>,
}

/// A piece of a loop: a parameter curve restricted to `[t0, t1]`.
#[derive(Clone, Debug, PartialEq)]
pub struct TrimSegment {
    pub t0: f64,
    pub t1: f64,
    pub curve: ParamCurve,
}

/// A closed loop: the outer boundary (`trim`) or a hole (`hole`).
#[derive(Clone, Debug, PartialEq)]
pub struct TrimLoop {
    pub hole: bool,
    pub segments: Vec<TrimSegment>,
}
