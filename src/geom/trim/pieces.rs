//! Trim loops as rational Bézier pieces in the parameter plane, converted once, exactly:
//! each loop segment's B-spline gets its range ends `t0`, `t1` inserted as knots and is
//! decomposed into Bézier pieces (Piegl & Tiller A5.1 and A5.6, the conversion surfaces use,
//! Dammertz §2.8), so a circular hole stays a rational quadratic. Gaps between consecutive
//! segments, and between the last and the first, are closed by straight pieces: the
//! even–odd rule needs closed loops, and a chord across a gap left by a CAD exporter is the
//! least surprising closure.

use glam::{DVec2, DVec3, DVec4};

use super::TrimLoop;
use super::region::TrimError;
use crate::geom::MAX_DEGREE;
use crate::geom::nurbs::NurbsCurve;
use crate::geom::nurbs::knots;

/// Halvings by which a piece is pre-split at load, at most, to make it monotone in both
/// parameters (its control box is then the box of its end points, as tight as it gets).
/// Pieces around a tangent parallel to an axis never become monotone by halving; after
/// this many levels they stay as they are, which costs only a few more subdivisions in
/// [`super::crossing`], never a wrong answer.
const MONOTONE_SPLIT_LEVELS: u32 = 6;

/// One rational Bézier piece of a loop: homogeneous points `(w u, w v, w)`, weights
/// positive, with the box of its projected control points, which contains the piece
/// (convex hull property).
#[derive(Clone, Debug, PartialEq)]
pub struct Piece {
    pub points: Vec<DVec3>,
    pub lo: DVec2,
    pub hi: DVec2,
}

/// The Euclidean point of a homogeneous one.
#[inline]
pub fn project(p: DVec3) -> DVec2 {
    DVec2::new(p.x / p.z, p.y / p.z)
}

/// The box of projected homogeneous points.
pub fn hull(points: &[DVec3]) -> (DVec2, DVec2) {
    points.iter().fold(
        (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY)),
        |(lo, hi), &p| {
            let q = project(p);
            (lo.min(q), hi.max(q))
        },
    )
}

/// The homogeneous point of a rational Bézier curve at `t` (de Casteljau).
pub fn point_at(points: &[DVec3], t: f64) -> DVec3 {
    let mut q = points.to_vec();
    for level in 1..q.len() {
        for i in 0..q.len() - level {
            q[i] = q[i] * (1.0 - t) + q[i + 1] * t;
        }
    }
    q[0]
}

/// de Casteljau at 1/2 on homogeneous points: `points` becomes the lower half, `upper`
/// receives the upper half (both of `points.len()` points).
pub fn halve(points: &mut [DVec3], upper: &mut [DVec3]) {
    let n = points.len() - 1;
    upper[n] = points[n];
    for level in 1..=n {
        for i in (level..=n).rev() {
            points[i] = (points[i] + points[i - 1]) * 0.5;
        }
        upper[n - level] = points[n];
    }
}

impl Piece {
    pub fn new(points: Vec<DVec3>) -> Piece {
        let (lo, hi) = hull(&points);
        Piece { points, lo, hi }
    }

    /// The straight piece from `a` to `b`.
    pub fn line(a: DVec2, b: DVec2) -> Piece {
        Piece::new(vec![a.extend(1.0), b.extend(1.0)])
    }

    pub fn start(&self) -> DVec2 {
        project(self.points[0])
    }

    pub fn end(&self) -> DVec2 {
        project(self.points[self.points.len() - 1])
    }

    /// The two halves at parameter 1/2.
    pub fn split(&self) -> (Piece, Piece) {
        let mut lower = self.points.clone();
        let mut upper = self.points.clone();
        halve(&mut lower, &mut upper);
        (Piece::new(lower), Piece::new(upper))
    }

    /// Whether the projected control polygon is monotone in u and in v; a rational Bézier
    /// curve with positive weights varies no more than its control polygon, so the piece is
    /// monotone too and its box is the box of its end points.
    fn is_monotone(&self) -> bool {
        let q: Vec<DVec2> = self.points.iter().map(|&p| project(p)).collect();
        let monotone = |axis: usize| {
            let d: Vec<f64> = q.windows(2).map(|w| w[1][axis] - w[0][axis]).collect();
            d.iter().all(|&x| x >= 0.0) || d.iter().all(|&x| x <= 0.0)
        };
        monotone(0) && monotone(1)
    }

    /// This piece split into monotone pieces, appended to `out` in curve order.
    fn split_monotone(self, levels: u32, out: &mut Vec<Piece>) {
        if levels == 0 || self.is_monotone() {
            out.push(self);
            return;
        }
        let (a, b) = self.split();
        a.split_monotone(levels - 1, out);
        b.split_monotone(levels - 1, out);
    }
}

/// The pieces of a closed loop, in order, with straight pieces across any gaps.
pub fn loop_pieces(l: &TrimLoop) -> Result<Vec<Piece>, TrimError> {
    let mut pieces: Vec<Piece> = Vec::new();
    for (k, segment) in l.segments.iter().enumerate() {
        let first = pieces.len();
        for piece in segment_pieces(&segment.curve, segment.t0, segment.t1)
            .map_err(|e| TrimError::Segment(k, e))?
        {
            piece.split_monotone(MONOTONE_SPLIT_LEVELS, &mut pieces);
        }
        if let (Some(prev), Some(next)) = (first.checked_sub(1), pieces.get(first)) {
            let (a, b) = (pieces[prev].end(), next.start());
            if a != b {
                pieces.insert(first, Piece::line(a, b));
            }
        }
    }
    if let (Some(first), Some(last)) = (pieces.first(), pieces.last()) {
        let (a, b) = (last.end(), first.start());
        if a != b {
            pieces.push(Piece::line(a, b));
        }
    }
    Ok(pieces)
}

/// The Bézier pieces of `curve` over `[t0, t1]` (either order), in the direction from `t0`
/// to `t1`'s end of the range; the range is clamped to the curve's domain.
fn segment_pieces(curve: &super::ParamCurve, t0: f64, t1: f64) -> Result<Vec<Piece>, String> {
    let p = curve.degree;
    if p == 0 || p > MAX_DEGREE {
        return Err(format!("degree {p} is outside 1..={MAX_DEGREE}"));
    }
    knots::validate(p, &curve.knots, curve.points.len()).map_err(|e| e.to_string())?;
    if let Some(i) = curve
        .points
        .iter()
        .position(|q| !(q.is_finite() && q.z > 0.0))
    {
        return Err(format!(
            "control point {i} is not finite or has a weight that is not positive"
        ));
    }
    if !(t0.is_finite() && t1.is_finite()) {
        return Err("the parameter range is not finite".into());
    }
    let mut nurbs = NurbsCurve {
        degree: p,
        knots: curve.knots.clone(),
        points: curve
            .points
            .iter()
            .map(|q| DVec4::new(q.x, q.y, 0.0, q.z))
            .collect(),
    };
    let (a, b) = knots::domain(p, &nurbs.knots);
    let lo = t0.min(t1).clamp(a, b);
    let hi = t0.max(t1).clamp(a, b);
    if lo >= hi {
        return Ok(Vec::new());
    }
    for t in [lo, hi] {
        if t > a && t < b {
            let times = p.saturating_sub(knots::multiplicity(&nurbs.knots, t));
            nurbs = nurbs.insert_knot(t, times).map_err(|e| e.to_string())?;
        }
    }
    let mut pieces: Vec<Piece> = nurbs
        .bezier_segments()
        .into_iter()
        .filter(|s| s.t0 >= lo && s.t1 <= hi)
        .map(|s| Piece::new(s.points.iter().map(|q| DVec3::new(q.x, q.y, q.w)).collect()))
        .collect();
    if t1 < t0 {
        pieces.reverse();
        for piece in &mut pieces {
            piece.points.reverse();
        }
    }
    Ok(pieces)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::trim::{ParamCurve, TrimSegment};

    fn circle(c: DVec2, r: f64) -> ParamCurve {
        ParamCurve::circle(c, r)
    }

    #[test]
    fn circle_pieces_lie_on_the_circle_and_close() {
        let l = TrimLoop {
            hole: true,
            segments: vec![TrimSegment {
                t0: 0.0,
                t1: 1.0,
                curve: circle(DVec2::new(0.5, 0.25), 0.125),
            }],
        };
        let pieces = loop_pieces(&l).unwrap();
        assert!(pieces.len() >= 4);
        for w in pieces.windows(2) {
            assert_eq!(w[0].end(), w[1].start());
        }
        for piece in &pieces {
            // Evaluate each piece by de Casteljau at a few parameters, in homogeneous form.
            for k in 0..=8 {
                let s = k as f64 / 8.0;
                let mut q = piece.points.clone();
                for level in 1..q.len() {
                    for i in 0..q.len() - level {
                        q[i] = q[i] * (1.0 - s) + q[i + 1] * s;
                    }
                }
                let e = project(q[0]) - DVec2::new(0.5, 0.25);
                assert!((e.length() - 0.125).abs() < 1e-15, "{}", e.length());
            }
        }
    }

    #[test]
    fn a_range_selects_part_of_the_curve_and_the_gap_is_closed() {
        // Half the circle (t in [0, 0.5], the upper half) closes with the diameter.
        let l = TrimLoop {
            hole: false,
            segments: vec![TrimSegment {
                t0: 0.5,
                t1: 0.0,
                curve: circle(DVec2::ZERO, 1.0),
            }],
        };
        let pieces = loop_pieces(&l).unwrap();
        assert_eq!(pieces[0].start(), DVec2::new(-1.0, 0.0));
        let closing = pieces.last().unwrap();
        assert_eq!(closing.points.len(), 2);
        assert_eq!(closing.start(), DVec2::new(1.0, 0.0));
        assert!(pieces.iter().all(|p| p.lo.y >= 0.0));
    }
}
