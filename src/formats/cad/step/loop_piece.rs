//! A piece of a face's trim loop as the STEP reader assembles it: an edge's curve in the
//! surface's parameter plane, traversed either way, moved by whole periods, its ends
//! evaluated once.

use glam::{DVec2, DVec3};

use crate::geom::nurbs::NurbsCurve;
use crate::geom::trim::{ParamCurve, TrimSegment};

/// A piece of a loop: a curve segment in the parameter plane, traversed backwards when
/// `reversed`.
#[derive(Clone, Debug)]
pub(super) struct Piece {
    pub(super) seg: TrimSegment,
    pub(super) reversed: bool,
    /// Where the traversal starts and ends, evaluated once.
    ends: [DVec2; 2],
}

/// A NURBS curve lying in z = 0 (a pcurve) as a parameter-plane curve.
pub(super) fn as_param(c: &NurbsCurve) -> ParamCurve {
    ParamCurve {
        degree: c.degree,
        knots: c.knots.clone(),
        points: c.points.iter().map(|p| DVec3::new(p.x, p.y, p.w)).collect(),
    }
}

impl Piece {
    pub(super) fn new(seg: TrimSegment, reversed: bool) -> Piece {
        let (a, b) = (seg.curve.point(seg.t0), seg.curve.point(seg.t1));
        Piece {
            ends: if reversed { [b, a] } else { [a, b] },
            seg,
            reversed,
        }
    }

    pub(super) fn start(&self) -> DVec2 {
        self.ends[0]
    }

    pub(super) fn end(&self) -> DVec2 {
        self.ends[1]
    }

    /// Moves the piece by `d`, exactly: each homogeneous point gains `w · d`.
    pub(super) fn shift(&mut self, d: DVec2) {
        for p in &mut self.seg.curve.points {
            p.x += p.z * d.x;
            p.y += p.z * d.y;
        }
        self.ends = self.ends.map(|e| e + d);
    }

    /// Moves the piece's start (`which` 0) or end (1) onto `to` where the piece is a
    /// polyline over its whole range (a projected edge), by moving that vertex; false,
    /// moving nothing, for any other curve.
    pub(super) fn move_end(&mut self, which: usize, to: DVec2) -> bool {
        let c = &mut self.seg.curve;
        let (d0, d1) = c.domain();
        if c.degree != 1 || self.seg.t0.min(self.seg.t1) != d0 || self.seg.t0.max(self.seg.t1) != d1
        {
            return false;
        }
        let curve_end = (which == 1) != self.reversed;
        let forwards = self.seg.t0 <= self.seg.t1;
        let k = if curve_end == forwards {
            c.points.len() - 1
        } else {
            0
        };
        let w = c.points[k].z;
        c.points[k] = (to * w).extend(w);
        self.ends[which] = to;
        true
    }

    /// Points along the piece, for its extent.
    pub(super) fn samples(&self) -> impl Iterator<Item = DVec2> + '_ {
        let (t0, t1) = (self.seg.t0, self.seg.t1);
        (0..=16).map(move |k| self.seg.curve.point(t0 + (t1 - t0) * k as f64 / 16.0))
    }
}
