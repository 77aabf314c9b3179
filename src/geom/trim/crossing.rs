//! The parity of the crossings of a horizontal half-line with a loop piece, decided in
//! `f64` by subdividing the piece where its box straddles the half-line's start, until the
//! box stops shrinking (the float-precision rule of Dammertz §2.2 applied to the trim
//! curve, §2.6). No polyline, no fixed epsilon: a point is classified exactly unless it
//! lies within the rounding of the curve itself, where the sub-piece's chord decides.
//!
//! Conventions: the half-line runs from `p` toward +u, and counts crossings at u > p.u; a
//! point is above the line when its v exceeds p.v. A continuous piece whose end points lie
//! on the same side crosses an even number of times, on opposite sides an odd number; so a
//! piece wholly right of `p` is decided by its end points alone, one wholly left, above or
//! below does not cross at all.

use glam::{DVec2, DVec3};

use super::pieces::{Piece, halve, hull, project};
use crate::geom::MAX_DEGREE;

/// Halvings of a piece at most. After 64 the sub-piece spans 2^-64 of the piece's
/// parameter range, finer than `f64` resolves the parameter itself, so its box cannot
/// shrink further in any meaningful way; the chord decides from there.
const MAX_LEVELS: usize = 64;

/// Whether the half-line from `p` toward +u crosses `piece` an odd number of times.
pub fn crosses_odd(piece: &Piece, p: DVec2) -> bool {
    if piece.hi.y <= p.y || piece.lo.y > p.y || piece.hi.x <= p.x {
        return false;
    }
    let (a, b) = (piece.start(), piece.end());
    if piece.lo.x > p.x {
        return (a.y > p.y) != (b.y > p.y);
    }
    subdivide(&piece.points, piece.hi - piece.lo, p)
}

/// The parity for a piece whose box straddles `p`'s vertical: halve it, decide each half
/// by its box, and go on with the halves that still straddle. Recursive, so that a query
/// touches only as many levels of halves as it descends (a stack sized for the deepest
/// case cost more to clear than most queries spend).
fn subdivide(points: &[DVec3], size: DVec2, p: DVec2) -> bool {
    descend(points, size, p, 0)
}

fn descend(points: &[DVec3], parent: DVec2, p: DVec2, level: usize) -> bool {
    let n = points.len();
    let mut lower = [DVec3::ZERO; MAX_DEGREE + 1];
    let mut upper = [DVec3::ZERO; MAX_DEGREE + 1];
    lower[..n].copy_from_slice(points);
    halve(&mut lower[..n], &mut upper[..n]);
    let mut odd = false;
    for half in [&lower[..n], &upper[..n]] {
        let (lo, hi) = hull(half);
        if hi.y <= p.y || lo.y > p.y || hi.x <= p.x {
            continue;
        }
        let (a, b) = (project(half[0]), project(half[n - 1]));
        let ends = (a.y > p.y) != (b.y > p.y);
        if lo.x > p.x {
            odd ^= ends;
            continue;
        }
        let extent = hi - lo;
        let shrinking = extent.x + extent.y < parent.x + parent.y;
        if !shrinking || level + 1 >= MAX_LEVELS {
            // Within rounding of the curve: the chord decides.
            if ends {
                let u = a.x + (p.y - a.y) * (b.x - a.x) / (b.y - a.y);
                odd ^= u > p.x;
            }
            continue;
        }
        odd ^= descend(half, extent, p, level + 1);
    }
    odd
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A quarter circle of radius 1 about the origin as a rational quadratic, from (1, 0)
    /// to (0, 1).
    fn quarter() -> Piece {
        let w = std::f64::consts::FRAC_1_SQRT_2;
        Piece::new(vec![
            DVec3::new(1.0, 0.0, 1.0),
            DVec3::new(w, w, w),
            DVec3::new(0.0, 1.0, 1.0),
        ])
    }

    #[test]
    fn points_just_inside_and_outside_an_arc_are_told_apart() {
        // Along the ray at 30°, points at radius 1 ± k ulps: inside the circle the
        // half-line toward +u crosses the arc once, outside it does not.
        let q = quarter();
        let dir = DVec2::new(30f64.to_radians().cos(), 30f64.to_radians().sin());
        for k in [4.0, 16.0, 1e3, 1e6] {
            let d = k * f64::EPSILON;
            assert!(crosses_odd(&q, dir * (1.0 - d)), "inside by {k} ulps");
            assert!(!crosses_odd(&q, dir * (1.0 + d)), "outside by {k} ulps");
        }
    }

    #[test]
    fn pieces_away_from_the_point_are_decided_by_their_boxes() {
        let q = quarter();
        assert!(crosses_odd(&q, DVec2::new(-5.0, 0.5)));
        assert!(!crosses_odd(&q, DVec2::new(5.0, 0.5)));
        assert!(!crosses_odd(&q, DVec2::new(0.5, 2.0)));
        assert!(!crosses_odd(&q, DVec2::new(0.5, -1.0)));
    }
}
