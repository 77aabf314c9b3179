//! A trimmed region cut down to a rectangle of its parameter plane, as closed loops of
//! pieces: for writers of formats whose curves on a surface must lie in the surface's
//! domain (IGES 5.3 §4.32, entity 142: "the curve lies in the domain of the surface"),
//! where our loops may run past it (a loop around a closed surface is closed beyond the
//! range it winds around; a seam vertex may round a hair outside).
//!
//! The region is the even–odd one over all loops (`geom::trim`), so it is cut by each of
//! the rectangle's four half-planes in turn, as Sutherland and Hodgman cut a polygon
//! ("Reentrant polygon clipping", CACM 17(1), 1974), with curved edges: every piece is
//! split where it crosses the half-plane's line and the parts outside are dropped; the
//! line itself bounds the cut region over those of its intervals, between consecutive
//! crossings, along which the region lies on the inner side (decided by parity at a
//! point just inside). Pieces lying on the line are dropped first, since the intervals
//! stand in for them. At the end the pieces are chained into closed loops by their
//! shared end points, which are exact: a crossing point is computed once and given to
//! both pieces it joins.

use glam::{DVec2, DVec3};

use super::pieces::{Piece, loop_pieces, point_at, project};
use super::{ParamCurve, TrimError, TrimLoop, TrimSegment};
use crate::geom::bezier::ParamRect;

/// Bisection steps for a crossing parameter: 2^-64 of a piece's range is below the
/// resolution of an `f64` parameter.
const BISECTIONS: usize = 64;
/// Samples along a piece that is not monotone in the line's coordinate, between which
/// crossings are bracketed.
const SAMPLES: usize = 64;
/// Control points this near a side, in sizes of the rectangle, are moved onto it: far
/// above the rounding of a coordinate, far below any feature a trim draws.
const SNAP: f64 = 4e-9;

/// One of the rectangle's sides as a half-plane: coordinate `axis` at least `at`
/// (`keep_above`) or at most `at`.
#[derive(Clone, Copy)]
struct HalfPlane {
    axis: usize,
    at: f64,
    keep_above: bool,
}

impl HalfPlane {
    fn signed(&self, q: DVec2) -> f64 {
        let d = q[self.axis] - self.at;
        if self.keep_above { d } else { -d }
    }
}

/// The loops (each closed, as [`super::pieces::loop_pieces`] gives them) cut down to
/// `rect`: `None` when every piece already lies in it, else the closed loops bounding the
/// part of the even–odd region inside `rect` (none when nothing of it is).
pub fn clip_to_rect(loops: &[Vec<Piece>], rect: ParamRect) -> Option<Vec<Vec<Piece>>> {
    let (lo, hi) = (DVec2::new(rect.u0, rect.v0), DVec2::new(rect.u1, rect.v1));
    let inside = loops
        .iter()
        .flatten()
        .all(|p| p.lo.cmpge(lo).all() && p.hi.cmple(hi).all());
    if inside {
        return None;
    }
    let snap_distance = SNAP * (hi - lo).length();
    // A loop edge a rounding off the domain's edge (a seam) is put on it, where the side's
    // intervals stand in for it, rather than left to bound a sliver with the side.
    let snap = |q: DVec2| {
        let near = |x: f64, a: f64, b: f64| match () {
            _ if (x - a).abs() <= snap_distance => a,
            _ if (x - b).abs() <= snap_distance => b,
            _ => x,
        };
        DVec2::new(near(q.x, lo.x, hi.x), near(q.y, lo.y, hi.y))
    };
    let mut pieces: Vec<Piece> = loops
        .iter()
        .flatten()
        .map(|p| {
            let mut points = p.points.clone();
            for q in &mut points {
                *q = (snap(project(*q)) * q.z).extend(q.z);
            }
            Piece::new(standard_form(&points, snap(p.start()), snap(p.end())))
        })
        .collect();
    for h in [
        HalfPlane {
            axis: 0,
            at: rect.u0,
            keep_above: true,
        },
        HalfPlane {
            axis: 0,
            at: rect.u1,
            keep_above: false,
        },
        HalfPlane {
            axis: 1,
            at: rect.v0,
            keep_above: true,
        },
        HalfPlane {
            axis: 1,
            at: rect.v1,
            keep_above: false,
        },
    ] {
        pieces = cut(&pieces, h);
    }
    Some(chain(pieces))
}

/// `loops` cut down to `rect` as trim loops (each piece a Bézier segment of its own; the
/// largest loop first, as the outer one, the others holes): `Some(loops)` unchanged when
/// they lie in `rect` already (an empty list stays the whole domain), `None` when they keep
/// nothing of it.
pub fn loops_within(
    loops: &[TrimLoop],
    rect: ParamRect,
) -> Result<Option<Vec<TrimLoop>>, TrimError> {
    let pieces = loops
        .iter()
        .map(loop_pieces)
        .collect::<Result<Vec<_>, _>>()?;
    let Some(mut cut) = clip_to_rect(&pieces, rect) else {
        return Ok(Some(loops.to_vec()));
    };
    if cut.is_empty() {
        return Ok(None);
    }
    // Twice the area of the polygon of the pieces' ends: enough to tell the outer loop.
    let area = |l: &Vec<Piece>| {
        let q: Vec<DVec2> = l.iter().map(Piece::start).collect();
        let twice: f64 = (0..q.len())
            .map(|i| q[i].perp_dot(q[(i + 1) % q.len()]))
            .sum();
        twice.abs()
    };
    let largest = (0..cut.len())
        .max_by(|&a, &b| area(&cut[a]).total_cmp(&area(&cut[b])))
        .unwrap_or(0);
    cut.swap(0, largest);
    Ok(Some(
        cut.into_iter()
            .enumerate()
            .map(|(k, l)| TrimLoop {
                hole: k > 0,
                segments: l.into_iter().map(|p| bezier_segment(p.points)).collect(),
            })
            .collect(),
    ))
}

/// A rational Bézier piece as a trim segment over `[0, 1]`.
fn bezier_segment(points: Vec<DVec3>) -> TrimSegment {
    let n = points.len();
    let knots = [vec![0.0; n], vec![1.0; n]].concat();
    TrimSegment {
        t0: 0.0,
        t1: 1.0,
        curve: ParamCurve {
            degree: n - 1,
            knots,
            points,
        },
    }
}

/// The pieces bounding the even–odd region of `pieces` within the half-plane `h`: their
/// parts inside it, and the intervals of its line between the points where those parts
/// end on it, every other one: far along the line it is outside the (bounded) region, and
/// each part ending on the line crosses its boundary there, so the line is inside the
/// region's closure exactly after an odd number of such ends. Counting ends, rather than
/// taking the region's parity beside each interval, keeps every end point met by an even
/// number of pieces, so the result always chains into closed loops.
fn cut(pieces: &[Piece], h: HalfPlane) -> Vec<Piece> {
    let mut kept = Vec::new();
    let mut ends: Vec<f64> = Vec::new();
    let other = 1 - h.axis;
    for piece in pieces {
        for part in split_at_line(piece, h) {
            let along = part.points.iter().all(|&p| project(p)[h.axis] == h.at);
            if along || h.signed(midpoint(&part)) <= 0.0 {
                continue;
            }
            for q in [part.start(), part.end()] {
                if q[h.axis] == h.at {
                    ends.push(q[other]);
                }
            }
            kept.push(part);
        }
    }
    ends.sort_by(f64::total_cmp);
    // Ends at one point pair off with each other; an odd count leaves one to the line.
    let mut odd: Vec<f64> = Vec::new();
    for x in ends {
        if odd.last() == Some(&x) {
            odd.pop();
        } else {
            odd.push(x);
        }
    }
    for pair in odd.chunks_exact(2) {
        let (mut a, mut b) = (DVec2::ZERO, DVec2::ZERO);
        a[h.axis] = h.at;
        b[h.axis] = h.at;
        a[other] = pair[0];
        b[other] = pair[1];
        kept.push(Piece::line(a, b));
    }
    kept
}

fn midpoint(piece: &Piece) -> DVec2 {
    project(point_at(&piece.points, 0.5))
}

/// `piece` split where it crosses the line of `h`, in order; the split points get the
/// line's coordinate exactly.
fn split_at_line(piece: &Piece, h: HalfPlane) -> Vec<Piece> {
    let f = |t: f64| h.signed(project(point_at(&piece.points, t)));
    let mut ts: Vec<f64> = Vec::new();
    if piece.lo[h.axis] < h.at && piece.hi[h.axis] > h.at {
        let mut prev = (0.0, f(0.0));
        for k in 1..=SAMPLES {
            let t = k as f64 / SAMPLES as f64;
            let next = (t, f(t));
            if (prev.1 < 0.0 && next.1 > 0.0) || (prev.1 > 0.0 && next.1 < 0.0) {
                ts.push(bisect(&f, prev, next));
            } else if next.1 == 0.0 && k < SAMPLES {
                // On the line at a sample: split there (a touch as well as a crossing;
                // parts on the same side both stay or go).
                ts.push(t);
            }
            prev = next;
        }
    }
    let mut parts = Vec::with_capacity(ts.len() + 1);
    let mut rest = piece.points.clone();
    let (mut from, mut done) = (piece.start(), 0.0);
    for t in ts {
        // The remaining part spans [done, 1] of the piece.
        let (lower, upper) = split_points(&rest, (t - done) / (1.0 - done));
        let mut q = project(lower[lower.len() - 1]);
        q[h.axis] = h.at;
        parts.push(Piece::new(standard_form(&lower, from, q)));
        (rest, from, done) = (upper, q, t);
    }
    parts.push(Piece::new(standard_form(&rest, from, piece.end())));
    parts
}

/// A rational Bézier piece in standard form, end weights 1 (the rational linear
/// reparameterisation w_i ↦ w_i c^i / w_0, c = (w_0 / w_n)^(1/n), which leaves the curve
/// as it is; Farin, *Curves and Surfaces for CAGD*, rational Bézier curves), with its end
/// points set to `a` and `b`: an end point then projects to exactly the point given, and
/// pieces meeting there share it bit for bit.
fn standard_form(points: &[DVec3], a: DVec2, b: DVec2) -> Vec<DVec3> {
    let n = points.len() - 1;
    let (w0, wn) = (points[0].z, points[n].z);
    let c = (w0 / wn).powf(1.0 / n as f64);
    points
        .iter()
        .enumerate()
        .map(|(i, &p)| match i {
            0 => a.extend(1.0),
            _ if i == n => b.extend(1.0),
            _ => {
                let w = p.z / w0 * c.powi(i as i32);
                (project(p) * w).extend(w)
            }
        })
        .collect()
}

/// The parameter in `(a, b)` where `f` changes sign, by bisection.
fn bisect(f: &dyn Fn(f64) -> f64, mut a: (f64, f64), mut b: (f64, f64)) -> f64 {
    for _ in 0..BISECTIONS {
        let t = 0.5 * (a.0 + b.0);
        if t <= a.0 || t >= b.0 {
            break;
        }
        let m = (t, f(t));
        if (m.1 < 0.0) == (a.1 < 0.0) && m.1 != 0.0 {
            a = m;
        } else {
            b = m;
        }
    }
    0.5 * (a.0 + b.0)
}

/// The control points of the two parts of a Bézier curve at `t` (de Casteljau).
fn split_points(points: &[DVec3], t: f64) -> (Vec<DVec3>, Vec<DVec3>) {
    let n = points.len();
    let mut q = points.to_vec();
    let mut lower = Vec::with_capacity(n);
    let mut upper = Vec::with_capacity(n);
    lower.push(q[0]);
    upper.push(q[n - 1]);
    for level in 1..n {
        for i in 0..n - level {
            q[i] = q[i] * (1.0 - t) + q[i + 1] * t;
        }
        lower.push(q[0]);
        upper.push(q[n - 1 - level]);
    }
    upper.reverse();
    (lower, upper)
}

/// Pieces whose ends meet exactly, joined into closed loops (a piece taken backwards
/// where that continues the loop; at a point where several loops touch, any pairing
/// bounds the same even–odd region).
fn chain(pieces: Vec<Piece>) -> Vec<Vec<Piece>> {
    // `+ 0.0` makes −0 and +0, which compare equal, one key.
    let key = |q: DVec2| ((q.x + 0.0).to_bits(), (q.y + 0.0).to_bits());
    let mut at: std::collections::HashMap<(u64, u64), Vec<usize>> = Default::default();
    for (i, p) in pieces.iter().enumerate() {
        if p.start() == p.end() && p.points.len() == 2 {
            continue;
        }
        at.entry(key(p.start())).or_default().push(i);
        at.entry(key(p.end())).or_default().push(i);
    }
    let mut used = vec![false; pieces.len()];
    let mut loops = Vec::new();
    for first in 0..pieces.len() {
        if used[first] || !at.contains_key(&key(pieces[first].start())) {
            continue;
        }
        used[first] = true;
        let start = pieces[first].start();
        let mut out = vec![pieces[first].clone()];
        let mut end = pieces[first].end();
        while end != start {
            let Some(&next) = at[&key(end)].iter().find(|&&i| !used[i]) else {
                break;
            };
            used[next] = true;
            let mut p = pieces[next].clone();
            if p.start() != end {
                p.points.reverse();
                p = Piece::new(p.points);
            }
            end = p.end();
            out.push(p);
        }
        if out.len() < 3 && out.iter().all(|p| p.points.len() == 2) {
            // Two lines there and back bound nothing.
            continue;
        }
        if end != start {
            // Open only if a crossing was found on one side of the line and not on the
            // other, which exact shared points rule out; close it as the loaders would.
            out.push(Piece::line(end, start));
        }
        loops.push(out);
    }
    loops
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::trim::crossing::crosses_odd;

    fn parity(loops: &[Vec<Piece>], q: DVec2) -> bool {
        loops.iter().flatten().filter(|p| crosses_odd(p, q)).count() % 2 == 1
    }

    fn grid_agrees(original: &[Vec<Piece>], clipped: &[Vec<Piece>], rect: ParamRect) {
        let n = 97;
        let mut wrong = 0;
        for i in 0..n {
            for j in 0..n {
                // A grid over twice the rectangle, off every line the tests draw.
                let q = DVec2::new(
                    rect.u0 - 0.5 * (rect.u1 - rect.u0)
                        + (i as f64 + 0.37) / n as f64 * 2.0 * (rect.u1 - rect.u0),
                    rect.v0 - 0.5 * (rect.v1 - rect.v0)
                        + (j as f64 + 0.61) / n as f64 * 2.0 * (rect.v1 - rect.v0),
                );
                let in_rect = q.x > rect.u0 && q.x < rect.u1 && q.y > rect.v0 && q.y < rect.v1;
                let want = in_rect && parity(original, q);
                if parity(clipped, q) != want {
                    wrong += 1;
                }
            }
        }
        assert_eq!(wrong, 0, "grid points classified differently");
        for p in clipped.iter().flatten() {
            assert!(p.lo.x >= rect.u0 && p.hi.x <= rect.u1, "{p:?}");
            assert!(p.lo.y >= rect.v0 && p.hi.y <= rect.v1, "{p:?}");
        }
        for l in clipped {
            assert_eq!(l[0].start(), l[l.len() - 1].end(), "loop not closed");
            for w in l.windows(2) {
                assert_eq!(w[0].end(), w[1].start(), "loop not chained");
            }
        }
    }

    #[test]
    fn a_loop_inside_is_left_alone() {
        let l = TrimLoop::closed(ParamCurve::circle(DVec2::new(0.5, 0.5), 0.3), false);
        let pieces = vec![loop_pieces(&l).unwrap()];
        assert!(clip_to_rect(&pieces, ParamRect::UNIT).is_none());
    }

    #[test]
    fn a_circle_across_a_corner_and_a_hole_across_an_edge() {
        // A disc over the corner (1, 1) of the unit square with a circular hole reaching
        // past the edge v = 0: the expected region is decided point by point from the
        // original loops (parity) and the rectangle, independently of the cut.
        let outer = TrimLoop::closed(ParamCurve::circle(DVec2::new(0.9, 0.6), 0.7), false);
        let hole = TrimLoop::closed(ParamCurve::circle(DVec2::new(0.6, 0.05), 0.2), true);
        let pieces = vec![loop_pieces(&outer).unwrap(), loop_pieces(&hole).unwrap()];
        let clipped = clip_to_rect(&pieces, ParamRect::UNIT).unwrap();
        grid_agrees(&pieces, &clipped, ParamRect::UNIT);
    }

    #[test]
    fn a_crossing_at_a_sample() {
        // A square whose sides cross v = 0 at 3/8 of their length, where the crossing
        // search samples (1/64 steps): the crossing is found there, not missed.
        let square = ParamCurve::polygon(&[
            DVec2::new(0.25, -0.375),
            DVec2::new(0.75, -0.375),
            DVec2::new(0.75, 0.625),
            DVec2::new(0.25, 0.625),
            DVec2::new(0.25, -0.375),
        ]);
        let pieces = vec![loop_pieces(&TrimLoop::closed(square, false)).unwrap()];
        let clipped = clip_to_rect(&pieces, ParamRect::UNIT).unwrap();
        grid_agrees(&pieces, &clipped, ParamRect::UNIT);
    }

    #[test]
    fn an_edge_a_rounding_inside_a_side_goes_onto_it() {
        // A loop past u = 0 whose right side runs 1e-14 inside u = 1, slanting, as a seam
        // edge projected by a CAD reader does: one loop comes out (no sliver between the
        // side and the edge), with the same region.
        let near = 1.0 - 1e-14;
        let l = ParamCurve::polygon(&[
            DVec2::new(-0.5, 0.2),
            DVec2::new(near, 0.2),
            DVec2::new(near - 1e-14, 0.8),
            DVec2::new(-0.5, 0.8),
            DVec2::new(-0.5, 0.2),
        ]);
        let pieces = vec![loop_pieces(&TrimLoop::closed(l, false)).unwrap()];
        let clipped = clip_to_rect(&pieces, ParamRect::UNIT).unwrap();
        grid_agrees(&pieces, &clipped, ParamRect::UNIT);
        assert_eq!(clipped.len(), 1);
        assert!(
            clipped[0]
                .iter()
                .any(|p| p.points.iter().all(|q| q.x / q.z == 1.0))
        );
    }

    #[test]
    fn a_band_closed_beyond_the_range() {
        // A loop winding around u (a band between two curves) closed far above the range,
        // as the STEP reader closes loops around a closed surface: clipped, the band's
        // upper side is the rectangle's edge.
        let wave = ParamCurve::polygon(&[
            DVec2::new(0.0, 0.3),
            DVec2::new(0.25, 0.45),
            DVec2::new(0.5, 0.2),
            DVec2::new(0.75, 0.4),
            DVec2::new(1.0, 0.3),
            DVec2::new(1.0, 3.0),
            DVec2::new(0.0, 3.0),
            DVec2::new(0.0, 0.3),
        ]);
        let pieces = vec![loop_pieces(&TrimLoop::closed(wave, false)).unwrap()];
        let clipped = clip_to_rect(&pieces, ParamRect::UNIT).unwrap();
        grid_agrees(&pieces, &clipped, ParamRect::UNIT);
        assert_eq!(clipped.len(), 1);
    }
}
