//! A surface's trimmed region, and per Bézier patch the culled part of it that the kernels
//! test a hit against.
//!
//! A point (u, v) of the trim parameter space is kept when the half-line from it toward +u
//! crosses the pieces of all loops an odd number of times (even–odd rule: outer loops,
//! holes and islands in holes need no orientation or nesting information). Where every loop
//! is a hole, the domain's boundary is the outer loop (OBJ `hole` without `trim`, an IGES
//! 144 whose outer boundary is the domain's): every point of the domain lies inside that
//! boundary, so the parity is inverted rather than the boundary traced.
//!
//! Culling: for a patch covering the rectangle R of the trim space, only pieces
//! that can cross a half-line starting in R matter: a piece wholly left of R, above it or
//! below it never does. A piece wholly right of R crosses every such half-line to the right
//! of its start, so its end points alone decide (it is kept as its chord). The rest overlap
//! R and are kept whole. A patch with no piece overlapping R is wholly inside or wholly
//! outside: it is kept trim-free or dropped.

use glam::DVec2;

use super::crossing::crosses_odd;
use super::pieces::{Piece, loop_pieces};
use super::{AxisMap, TrimLoop};
use crate::geom::bezier::ParamRect;

#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum TrimError {
    #[error("trim segment {0}: {1}")]
    Segment(usize, String),
}

/// The region of a surface's domain its trim loops keep.
#[derive(Clone, Debug, PartialEq)]
pub struct TrimRegion {
    pieces: Vec<Piece>,
    map: [AxisMap; 2],
    /// No outer loop: the domain's boundary is one (module docs).
    outer_is_domain: bool,
}

/// How a patch's rectangle relates to a region.
#[derive(Clone, Debug, PartialEq)]
pub enum Coverage {
    /// Wholly trimmed away: the patch is dropped.
    Outside,
    /// Wholly kept: the patch needs no trim test.
    Inside,
    /// Cut by the loops: hits are tested.
    Partial(Box<PatchTrim>),
}

/// The loops as one patch sees them: the pieces overlapping its rectangle and the chords of
/// those to the right of it (module docs).
#[derive(Clone, Debug, PartialEq)]
pub struct PatchTrim {
    /// The patch's rectangle in the surface's (NURBS) parameters.
    domain: ParamRect,
    map: [AxisMap; 2],
    /// The rectangle in trim parameters.
    lo: DVec2,
    hi: DVec2,
    near: Vec<Piece>,
    far: Vec<(DVec2, DVec2)>,
    outer_is_domain: bool,
}

impl TrimRegion {
    /// The region of `loops` in the trim space `map` leads to; `None` without loops.
    pub fn new(loops: &[TrimLoop], map: &[AxisMap; 2]) -> Result<Option<TrimRegion>, TrimError> {
        if loops.is_empty() {
            return Ok(None);
        }
        let mut pieces = Vec::new();
        for l in loops {
            pieces.extend(loop_pieces(l)?);
        }
        Ok(Some(TrimRegion {
            pieces,
            map: map.clone(),
            outer_is_domain: loops.iter().all(|l| l.hole),
        }))
    }

    /// The number of Bézier pieces of all loops (after the monotone split).
    pub fn piece_count(&self) -> usize {
        self.pieces.len()
    }

    /// The Bézier pieces of all loops in trim parameters; each loop's pieces follow one
    /// another end to start (the tessellator samples them as constraint edges).
    pub fn pieces(&self) -> &[Piece] {
        &self.pieces
    }

    /// The maps from the surface's parameters to the trim parameters the pieces are in.
    pub fn maps(&self) -> &[AxisMap; 2] {
        &self.map
    }

    /// Whether every loop is a hole, so that the domain's boundary is the outer loop
    /// (module docs).
    pub fn outer_is_domain(&self) -> bool {
        self.outer_is_domain
    }

    /// Whether the surface exists at (u, v), in the surface's own parameters.
    pub fn contains(&self, u: f64, v: f64) -> bool {
        let p = DVec2::new(self.map[0].apply(u), self.map[1].apply(v));
        let odd = self.pieces.iter().filter(|q| crosses_odd(q, p)).count() % 2 == 1;
        odd != self.outer_is_domain
    }

    /// How the patch over `domain` (the surface's parameters) relates to the region.
    pub fn coverage(&self, domain: ParamRect) -> Coverage {
        let (a, b) = (
            DVec2::new(self.map[0].apply(domain.u0), self.map[1].apply(domain.v0)),
            DVec2::new(self.map[0].apply(domain.u1), self.map[1].apply(domain.v1)),
        );
        let (lo, hi) = (a.min(b), a.max(b));
        let mut near = Vec::new();
        let mut far = Vec::new();
        for piece in &self.pieces {
            if piece.hi.y <= lo.y || piece.lo.y > hi.y || piece.hi.x <= lo.x {
                continue;
            }
            if piece.lo.x > hi.x {
                far.push((piece.start(), piece.end()));
            } else {
                near.push(piece.clone());
            }
        }
        let trim = PatchTrim {
            domain,
            map: self.map.clone(),
            lo,
            hi,
            near,
            far,
            outer_is_domain: self.outer_is_domain,
        };
        if !trim.near.is_empty() {
            Coverage::Partial(Box::new(trim))
        } else if trim.keeps(0.5, 0.5) {
            Coverage::Inside
        } else {
            Coverage::Outside
        }
    }
}

impl PatchTrim {
    /// Whether the surface exists at (u, v) in the patch's own [0,1]².
    #[inline]
    pub fn keeps(&self, u: f64, v: f64) -> bool {
        let (pu, pv) = self.domain.to_parent(u, v);
        self.keeps_in_surface(pu, pv)
    }

    /// Whether any of `part` (a rectangle inside the patch's, in the surface's parameters)
    /// survives: where no piece overlaps it, it is wholly kept or wholly cut away, as its
    /// centre is. Used to bound the surviving part of a patch at load.
    pub fn keeps_any_of(&self, part: ParamRect) -> bool {
        let (a, b) = (
            DVec2::new(self.map[0].apply(part.u0), self.map[1].apply(part.v0)),
            DVec2::new(self.map[0].apply(part.u1), self.map[1].apply(part.v1)),
        );
        let (lo, hi) = (a.min(b), a.max(b));
        let overlaps =
            |q: &Piece| q.lo.x <= hi.x && q.hi.x >= lo.x && q.lo.y <= hi.y && q.hi.y >= lo.y;
        self.near.iter().any(overlaps)
            || self.keeps_in_surface(0.5 * (part.u0 + part.u1), 0.5 * (part.v0 + part.v1))
    }

    /// Whether the surface exists at (u, v) in the surface's parameters, for (u, v) in
    /// the patch's rectangle.
    fn keeps_in_surface(&self, pu: f64, pv: f64) -> bool {
        let p = DVec2::new(self.map[0].apply(pu), self.map[1].apply(pv)).clamp(self.lo, self.hi);
        let mut odd = false;
        for &(a, b) in &self.far {
            odd ^= (a.y > p.y) != (b.y > p.y);
        }
        for piece in &self.near {
            odd ^= crosses_odd(piece, p);
        }
        odd != self.outer_is_domain
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::trim::ParamCurve;

    fn circle(c: DVec2, r: f64) -> ParamCurve {
        ParamCurve::circle(c, r)
    }

    fn whole(curve: ParamCurve, hole: bool) -> TrimLoop {
        TrimLoop::closed(curve, hole)
    }

    /// The boundary of `[a, b]²` as one degree-1 curve, counter-clockwise or clockwise.
    fn square(a: f64, b: f64, ccw: bool) -> ParamCurve {
        let mut corners = vec![
            DVec2::new(a, a),
            DVec2::new(b, a),
            DVec2::new(b, b),
            DVec2::new(a, b),
        ];
        if !ccw {
            corners.reverse();
        }
        ParamCurve::polygon(&corners)
    }

    fn identity() -> [AxisMap; 2] {
        Default::default()
    }

    #[test]
    fn a_square_with_a_round_hole_and_an_island() {
        // Outer square [0,1]², hole of radius 0.3 at the centre, island square inside the
        // hole: parity alone sorts them out, whatever the orientations.
        let c = DVec2::splat(0.5);
        let loops = [
            whole(square(0.0, 1.0, true), false),
            whole(circle(c, 0.3), true),
            whole(square(0.45, 0.55, false), false),
        ];
        let region = TrimRegion::new(&loops, &identity()).unwrap().unwrap();
        let inside_hole = |p: DVec2| (p - c).length() < 0.3;
        let island = |p: DVec2| p.x > 0.45 && p.x < 0.55 && p.y > 0.45 && p.y < 0.55;
        for i in 0..40 {
            for j in 0..40 {
                let p = DVec2::new((i as f64 + 0.37) / 40.0, (j as f64 + 0.61) / 40.0);
                let want = !inside_hole(p) || island(p);
                assert_eq!(region.contains(p.x, p.y), want, "{p}");
            }
        }
        assert!(!region.contains(1.5, 0.5) && !region.contains(-0.1, 0.5));
    }

    #[test]
    fn holes_without_an_outer_loop_cut_the_whole_domain() {
        let c = DVec2::new(0.3, 0.6);
        let region = TrimRegion::new(&[whole(circle(c, 0.2), true)], &identity())
            .unwrap()
            .unwrap();
        assert!(!region.contains(0.3, 0.6) && !region.contains(0.45, 0.6));
        assert!(region.contains(0.9, 0.1) && region.contains(0.3, 0.85));
        // As an outer loop the same circle keeps only its inside.
        let outer = TrimRegion::new(&[whole(circle(c, 0.2), false)], &identity())
            .unwrap()
            .unwrap();
        assert!(outer.contains(0.3, 0.6) && !outer.contains(0.9, 0.1));
    }

    #[test]
    fn patch_coverage_drops_culls_and_agrees_with_the_whole_region() {
        let c = DVec2::new(0.6, 0.4);
        let loops = [
            whole(square(0.0, 1.0, true), false),
            whole(circle(c, 0.2), true),
        ];
        let region = TrimRegion::new(&loops, &identity()).unwrap().unwrap();
        // Patches of a 5 × 5 split of [0, 1.25]²: the outer column and row lie outside.
        let n = 5;
        let step = 1.25 / n as f64;
        let (mut inside, mut outside, mut partial) = (0, 0, 0);
        for j in 0..n {
            for i in 0..n {
                let domain = ParamRect {
                    u0: i as f64 * step,
                    u1: (i + 1) as f64 * step,
                    v0: j as f64 * step,
                    v1: (j + 1) as f64 * step,
                };
                let cov = region.coverage(domain);
                for (a, b) in [(0.1, 0.2), (0.5, 0.5), (0.93, 0.71), (0.02, 0.97)] {
                    let (u, v) = domain.to_parent(a, b);
                    let want = region.contains(u, v);
                    let got = match &cov {
                        Coverage::Outside => false,
                        Coverage::Inside => true,
                        Coverage::Partial(t) => t.keeps(a, b),
                    };
                    assert_eq!(got, want, "patch ({i}, {j}) at ({u}, {v})");
                }
                match cov {
                    Coverage::Outside => outside += 1,
                    Coverage::Inside => inside += 1,
                    Coverage::Partial(_) => partial += 1,
                }
            }
        }
        assert!(
            inside > 0 && outside > 0 && partial > 0,
            "{inside} {outside} {partial}"
        );
    }
}
