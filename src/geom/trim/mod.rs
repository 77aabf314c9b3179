//! Trimmed surfaces (Dammertz §2.6): loops of curves in a surface's parameter domain (OBJ
//! `trim` / `hole` with `curv2`, IGES 144/142, STEP face bounds) cut the surface down to
//! the region where the even–odd (Jordan) parity over all its loops is odd; a surface
//! without loops keeps its whole domain.
//!
//! - [`pieces`]: the loops converted once, exactly, to rational Bézier pieces in the
//!   parameter plane (knot insertion, as for surfaces), split where cheap into pieces
//!   monotone in both parameters so that their control boxes are tight.
//! - [`crossing`]: the parity of the crossings of a half-line with a piece, by subdividing
//!   the piece until its box stops shrinking in `f64` (no polyline, no fixed epsilon).
//! - [`region`]: a surface's trimmed region and, per Bézier patch, the culled part of it
//!   the kernels test a hit against ([`PatchTrim`]); patches wholly outside are dropped and
//!   wholly inside ones become trim-free at load.
//! - [`axis_map`]: the map from a NURBS parameter to the (angle) parameter CAD files write
//!   trims of analytic surfaces in.

pub mod axis_map;
pub mod crossing;
pub mod pieces;
pub mod region;

pub use axis_map::AxisMap;
pub use region::{Coverage, PatchTrim, TrimError, TrimRegion};

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
