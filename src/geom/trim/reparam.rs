//! Trim loops moved from the parameter CAD files write them in (an angle, [`AxisMap`]) to
//! the NURBS surface's own parameter, for writers whose formats have no such map (OBJ
//! free-form `curv2`, IGES 142 parameter-space curves: both live in the surface's own
//! parameter space, OBJ Appendix B1 `trim`, IGES 5.3 §4.32).
//!
//! The map from an angle to the NURBS parameter (the inverse of a rational quadratic arc's
//! parameterisation, [`AxisMap::invert`]) is not rational, so a curve is not carried over
//! exactly in general. Two cases are: loops whose maps are both the identity (copied), and
//! straight pieces along which every mapped parameter is constant but one (the map is
//! monotone, so the image is the straight piece between the mapped ends: the lines of
//! constant angle or height that bound most faces of cylinders, cones and revolutions).
//! Any other piece is approximated by cubic Bézier pieces interpolating the mapped curve
//! at four points each, halved until the mapped curve and the cubic agree to within
//! [`RELATIVE_TOLERANCE`] of the domain's extent at the check points.

use glam::DVec2;

use super::pieces::{Piece, loop_pieces, point_at, project};
use super::{AxisMap, ParamCurve, TrimError, TrimLoop, TrimSegment};
use crate::geom::bezier::ParamRect;

/// Largest distance, as a share of the domain's extent in each parameter, allowed between
/// an approximated piece and the mapped curve at the check points: far below what a ray
/// can resolve on a model (a 1 m part's trims are then placed to a nanometre).
pub const RELATIVE_TOLERANCE: f64 = 1e-9;

/// Halvings of one piece at most; a piece crossing a break of the map (where the mapped
/// curve has a corner) reaches the tolerance after about 30.
const MAX_DEPTH: u32 = 48;

/// Check points per cubic, at `(2k + 1) / (2 CHECKS)`: between and away from the four
/// interpolated points.
const CHECKS: usize = 8;

/// The loops in the NURBS parameter space of a surface with domain `domain` whose loops
/// are written in the parameters `maps` give. Identity maps return the loops unchanged.
pub fn loops_in_nurbs_space(
    loops: &[TrimLoop],
    maps: &[AxisMap; 2],
    domain: ParamRect,
) -> Result<Vec<TrimLoop>, TrimError> {
    if maps.iter().all(|m| *m == AxisMap::Identity) {
        return Ok(loops.to_vec());
    }
    let tolerance = DVec2::new(domain.u1 - domain.u0, domain.v1 - domain.v0) * RELATIVE_TOLERANCE;
    let map = |p: DVec2| DVec2::new(maps[0].invert(p.x), maps[1].invert(p.y));
    loops
        .iter()
        .map(|l| {
            let segments = loop_pieces(l)?
                .iter()
                .map(|piece| mapped_piece(piece, maps, &map, tolerance))
                .collect();
            Ok(TrimLoop {
                hole: l.hole,
                segments,
            })
        })
        .collect()
}

/// One piece carried over: exactly where it is a line along one mapped parameter (or
/// mapping changes nothing along it), else as interpolating cubics.
fn mapped_piece(
    piece: &Piece,
    maps: &[AxisMap; 2],
    map: &dyn Fn(DVec2) -> DVec2,
    tolerance: DVec2,
) -> TrimSegment {
    let (a, b) = (piece.start(), piece.end());
    let straight = piece.points.len() == 2;
    let varies = |axis: usize| a[axis] != b[axis] && maps[axis] != AxisMap::Identity;
    let other_constant = |axis: usize| a[1 - axis] == b[1 - axis];
    if straight && (0..2).all(|k| !varies(k) || other_constant(k)) {
        return line_segment(map(a), map(b));
    }
    let f = |s: f64| map(project(point_at(&piece.points, s)));
    let mut cubics: Vec<[DVec2; 4]> = Vec::new();
    approximate(&f, 0.0, 1.0, tolerance, MAX_DEPTH, &mut cubics);
    piecewise_cubic(&cubics)
}

/// Appends to `out`, in order, cubics that interpolate `f` on `[s0, s1]` at its ends and
/// thirds, halving the interval until every check point is within `tolerance`.
fn approximate(
    f: &dyn Fn(f64) -> DVec2,
    s0: f64,
    s1: f64,
    tolerance: DVec2,
    depth: u32,
    out: &mut Vec<[DVec2; 4]>,
) {
    let at = |x: f64| f(s0 + (s1 - s0) * x);
    let (f0, f1, f2, f3) = (at(0.0), at(1.0 / 3.0), at(2.0 / 3.0), at(1.0));
    // The cubic through f0..f3 at 0, 1/3, 2/3, 1 in Bézier form (solving the Bernstein
    // system at those parameters).
    let cubic = [
        f0,
        (-5.0 * f0 + 18.0 * f1 - 9.0 * f2 + 2.0 * f3) / 6.0,
        (2.0 * f0 - 9.0 * f1 + 18.0 * f2 - 5.0 * f3) / 6.0,
        f3,
    ];
    let close = (0..CHECKS).all(|k| {
        let x = (2 * k + 1) as f64 / (2 * CHECKS) as f64;
        let e = (cubic_at(&cubic, x) - at(x)).abs();
        e.x <= tolerance.x && e.y <= tolerance.y
    });
    if close || depth == 0 {
        out.push(cubic);
        return;
    }
    let mid = 0.5 * (s0 + s1);
    approximate(f, s0, mid, tolerance, depth - 1, out);
    approximate(f, mid, s1, tolerance, depth - 1, out);
}

fn cubic_at(c: &[DVec2; 4], x: f64) -> DVec2 {
    let y = 1.0 - x;
    c[0] * (y * y * y) + c[1] * (3.0 * x * y * y) + c[2] * (3.0 * x * x * y) + c[3] * (x * x * x)
}

/// The straight segment from `a` to `b` over `[0, 1]`.
fn line_segment(a: DVec2, b: DVec2) -> TrimSegment {
    TrimSegment {
        t0: 0.0,
        t1: 1.0,
        curve: ParamCurve {
            degree: 1,
            knots: vec![0.0, 0.0, 1.0, 1.0],
            points: vec![a.extend(1.0), b.extend(1.0)],
        },
    }
}

/// Consecutive cubics as one piecewise cubic B-spline over `[0, n]` (interior knots of
/// multiplicity 3, so each cubic is kept as it is; consecutive cubics share their joint,
/// which both interpolate).
fn piecewise_cubic(cubics: &[[DVec2; 4]]) -> TrimSegment {
    let n = cubics.len();
    let mut knots = vec![0.0; 4];
    let mut points = vec![cubics[0][0].extend(1.0)];
    for (k, c) in cubics.iter().enumerate() {
        points.extend(c[1..].iter().map(|p| p.extend(1.0)));
        let repeat = if k + 1 == n { 4 } else { 3 };
        knots.extend(std::iter::repeat_n((k + 1) as f64, repeat));
    }
    TrimSegment {
        t0: 0.0,
        t1: n as f64,
        curve: ParamCurve {
            degree: 3,
            knots,
            points,
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    /// The map of a full turn in four quarter arcs, as the analytic surfaces build it (the
    /// NURBS parameter equals the angle at the arcs' ends).
    fn turn() -> AxisMap {
        let quarters: Vec<f64> = (0..=4).map(|k| k as f64 * 0.5 * PI).collect();
        AxisMap::Arcs {
            breaks: quarters.clone(),
            angles: quarters,
        }
    }

    #[test]
    fn identity_maps_keep_the_loops() {
        let l = TrimLoop::closed(ParamCurve::circle(DVec2::new(0.5, 0.5), 0.25), false);
        let out = loops_in_nurbs_space(
            std::slice::from_ref(&l),
            &Default::default(),
            ParamRect::UNIT,
        )
        .unwrap();
        assert_eq!(out, vec![l]);
    }

    #[test]
    fn lines_of_constant_angle_or_height_map_exactly() {
        let map = [turn(), AxisMap::Identity];
        let corners = [
            DVec2::new(0.3, 0.0),
            DVec2::new(2.0, 0.0),
            DVec2::new(2.0, 1.0),
            DVec2::new(0.3, 1.0),
        ];
        let l = TrimLoop::closed(ParamCurve::polygon(&corners), false);
        let domain = ParamRect {
            u0: 0.0,
            u1: 2.0 * PI,
            v0: 0.0,
            v1: 1.0,
        };
        let out = loops_in_nurbs_space(&[l], &map, domain).unwrap();
        let ends: Vec<DVec2> = out[0]
            .segments
            .iter()
            .map(|s| {
                assert_eq!(s.curve.degree, 1);
                project(s.curve.points[0])
            })
            .collect();
        for (e, c) in ends.iter().zip(corners) {
            assert_eq!(*e, DVec2::new(map[0].invert(c.x), c.y));
        }
    }

    #[test]
    fn a_circle_in_angles_is_followed_within_the_tolerance() {
        // A circle in (angle, height) space on a full turn: its image under the inverse map
        // is checked against the map applied to points of the circle, independently of
        // the approximation's own check points.
        let map = [turn(), AxisMap::Identity];
        let domain = ParamRect {
            u0: 0.0,
            u1: 2.0 * PI,
            v0: 0.0,
            v1: 2.0,
        };
        let (c, r) = (DVec2::new(1.4, 1.0), 0.5);
        let l = TrimLoop::closed(ParamCurve::circle(c, r), true);
        let out = loops_in_nurbs_space(&[l], &map, domain).unwrap();
        let pieces = loop_pieces(&out[0]).unwrap();
        let mut worst: f64 = 0.0;
        for p in &pieces {
            for k in 0..=16 {
                let q = project(point_at(&p.points, k as f64 / 16.0));
                // Back to angles exactly, then the distance from the circle there.
                let a = DVec2::new(map[0].apply(q.x), q.y);
                worst = worst.max(((a - c).length() - r).abs());
            }
        }
        // A NURBS-parameter error of 1e-9 · 2π moves the angle by at most about twice that
        // (the map's slope on a quarter arc is below 2).
        assert!(worst < 4.0 * PI * RELATIVE_TOLERANCE, "{worst}");
        assert!(pieces.len() < 400, "{} pieces", pieces.len());
    }
}
