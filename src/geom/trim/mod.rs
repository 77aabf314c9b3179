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
//! - [`clip`]: a region cut down to a rectangle, as closed loops, for writers whose
//!   curves must lie in the surface's domain.
//! - [`reparam`]: loops moved from that parameter to the NURBS one, for the writers of
//!   formats that have no such map.

pub mod axis_map;
pub mod clip;
pub mod crossing;
pub mod pieces;
pub mod region;
pub mod reparam;

pub use axis_map::AxisMap;
pub use region::{Coverage, PatchTrim, TrimError, TrimRegion};

use glam::{DVec2, DVec3};

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

impl ParamCurve {
    /// The circle of radius `r` about `c`, once counter-clockwise from angle 0 over
    /// `[0, 1]`: the 9-point rational quadratic of Piegl & Tiller §7.5 (four quadrants,
    /// corner weights √2/2), exact.
    pub fn circle(c: DVec2, r: f64) -> ParamCurve {
        use crate::geom::nurbs::shapes;
        ParamCurve {
            degree: 2,
            knots: shapes::CIRCLE_KNOTS.to_vec(),
            points: shapes::circle()
                .iter()
                .map(|&(x, y, w)| DVec3::new((c.x + r * x) * w, (c.y + r * y) * w, w))
                .collect(),
        }
    }

    /// The closed polygon through `corners` (the first repeated at the end) as a degree-1
    /// curve over `[0, 1]`.
    pub fn polygon(corners: &[DVec2]) -> ParamCurve {
        let n = corners.len() + 1;
        let mut knots = vec![0.0];
        knots.extend((0..n).map(|i| i as f64 / (n - 1) as f64));
        knots.push(1.0);
        ParamCurve {
            degree: 1,
            knots,
            points: corners
                .iter()
                .chain(corners.first())
                .map(|p| p.extend(1.0))
                .collect(),
        }
    }

    /// The curve's parameter domain.
    pub fn domain(&self) -> (f64, f64) {
        crate::geom::nurbs::knots::domain(self.degree, &self.knots)
    }

    /// The point at parameter `t` (de Boor on the homogeneous points, then divided).
    pub fn point(&self, t: f64) -> DVec2 {
        let c = crate::geom::nurbs::NurbsCurve {
            degree: self.degree,
            knots: self.knots.clone(),
            points: self
                .points
                .iter()
                .map(|p| glam::DVec4::new(p.x, p.y, 0.0, p.z))
                .collect(),
        };
        c.eval(t).truncate()
    }
}

impl TrimSegment {
    /// The polyline through `points` as a degree-1 segment, parameter k at point k, over
    /// `[0, n − 1]` (CAD readers' projected trim curves and domain rectangles).
    pub fn polyline(points: &[DVec2]) -> TrimSegment {
        let n = points.len();
        let mut knots = vec![0.0];
        knots.extend((0..n).map(|k| k as f64));
        knots.push((n - 1) as f64);
        TrimSegment {
            t0: 0.0,
            t1: (n - 1) as f64,
            curve: ParamCurve {
                degree: 1,
                knots,
                points: points.iter().map(|p| p.extend(1.0)).collect(),
            },
        }
    }
}

impl TrimLoop {
    /// The loop with its two parameters exchanged, exactly (each homogeneous point
    /// `(w x, w y, w)` becomes `(w y, w x, w)`), for a surface that was transposed.
    pub fn transposed(&self) -> TrimLoop {
        let segments = self
            .segments
            .iter()
            .map(|s| {
                let mut s = s.clone();
                for p in &mut s.curve.points {
                    std::mem::swap(&mut p.x, &mut p.y);
                }
                s
            })
            .collect();
        TrimLoop {
            hole: self.hole,
            segments,
        }
    }

    /// A loop of one closed curve, taken over its whole domain.
    pub fn closed(curve: ParamCurve, hole: bool) -> TrimLoop {
        let (t0, t1) = curve.domain();
        TrimLoop {
            hole,
            segments: vec![TrimSegment { t0, t1, curve }],
        }
    }
}
