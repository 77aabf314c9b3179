//! Patch boundary curves as shared objects. A boundary curve of a Bézier patch depends only
//! on its own row (or column) of control points, so two patches that share an edge share
//! that row, possibly reversed. Keying the edge by its control points in a canonical
//! direction and sampling it once, from that direction, gives both patches bit-identical
//! vertices: the crack-free rule of the issue ("the sampling of an edge shared by two
//! patches is decided once, from the edge").

use glam::{DVec3, DVec4};

use crate::geom::BezierPatch;
use crate::geom::bezier::{de_casteljau_point, dehomogenize};
use crate::geom::segment::distance_to_segment;

/// The four sides of a patch's parameter square, counter-clockwise from (0, 0).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Side {
    /// v = 0, u from 0 to 1.
    Bottom,
    /// u = 1, v from 0 to 1.
    Right,
    /// v = 1, u from 1 to 0.
    Top,
    /// u = 0, v from 1 to 0.
    Left,
}

impl Side {
    pub const ALL: [Side; 4] = [Side::Bottom, Side::Right, Side::Top, Side::Left];

    /// The patch parameters at position `t` ∈ [0, 1] along the side, walking
    /// counter-clockwise around the parameter square.
    pub fn param(self, t: f64) -> (f64, f64) {
        match self {
            Side::Bottom => (t, 0.0),
            Side::Right => (1.0, t),
            Side::Top => (1.0 - t, 1.0),
            Side::Left => (0.0, 1.0 - t),
        }
    }

    /// The side's homogeneous control points in counter-clockwise order.
    pub fn control_points(self, patch: &BezierPatch) -> Vec<DVec4> {
        let (du, dv) = (patch.degree_u(), patch.degree_v());
        match self {
            Side::Bottom => (0..=du).map(|i| patch.homogeneous(i, 0)).collect(),
            Side::Right => (0..=dv).map(|j| patch.homogeneous(du, j)).collect(),
            Side::Top => (0..=du).rev().map(|i| patch.homogeneous(i, dv)).collect(),
            Side::Left => (0..=dv).rev().map(|j| patch.homogeneous(0, j)).collect(),
        }
    }
}

/// A boundary curve in its canonical direction (the lexicographically smaller of the two
/// bit sequences of its control points), with `-0.0` folded into `+0.0` so that the
/// teapot's mirrored seams, written with both zeros, still match.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct EdgeKey(Vec<[u64; 4]>);

/// A side's curve: its canonical key, its control points in canonical order, and whether
/// the side runs against the canonical direction.
pub struct EdgeCurve {
    pub key: EdgeKey,
    pub points: Vec<DVec4>,
    pub reversed: bool,
}

impl EdgeCurve {
    pub fn of(patch: &BezierPatch, side: Side) -> EdgeCurve {
        let forward: Vec<DVec4> = side
            .control_points(patch)
            .into_iter()
            .map(|p| p + DVec4::ZERO)
            .collect();
        let bits = |pts: &[DVec4]| -> Vec<[u64; 4]> {
            pts.iter().map(|p| p.to_array().map(f64::to_bits)).collect()
        };
        let fwd_bits = bits(&forward);
        let mut backward = forward.clone();
        backward.reverse();
        let back_bits = bits(&backward);
        if back_bits < fwd_bits {
            EdgeCurve {
                key: EdgeKey(back_bits),
                points: backward,
                reversed: true,
            }
        } else {
            EdgeCurve {
                key: EdgeKey(fwd_bits),
                points: forward,
                reversed: false,
            }
        }
    }

    /// The curve point at canonical parameter `k / n`. The end points are the end control
    /// points themselves, so corners shared by several patches are bit-identical; a curve
    /// collapsed to one point (the teapot's lid knob and bottom centre) is that point, since
    /// de Casteljau's `(1 - t) a + t a` need not round back to `a`.
    pub fn sample(&self, k: usize, n: usize) -> DVec3 {
        let collapsed = self.points.iter().all(|&p| p == self.points[0]);
        let p = if k == 0 || collapsed {
            self.points[0]
        } else if k == n {
            self.points[self.points.len() - 1]
        } else {
            de_casteljau_point(&self.points, k as f64 / n as f64)
        };
        dehomogenize(p) + DVec3::ZERO
    }

    /// Segments needed so that the chord height stays within `tolerance`, decided from the
    /// curve alone (so both patches of a shared edge agree).
    pub fn adaptive_segments(&self, tolerance: f64) -> usize {
        let curve = |t: f64| dehomogenize(de_casteljau_point(&self.points, t));
        segments_for_tolerance(&curve, self.points.len() - 1, tolerance)
    }
}

/// Most segments the adaptive mode puts on one curve: 2^12 per side, i.e. at most 2^25
/// triangles per patch, so a tolerance far below the model's size cannot exhaust memory.
pub const MAX_ADAPTIVE_SEGMENTS: usize = 1 << 12;

/// Interior points per segment at which the chord height is measured. The chord height of
/// a short polynomial arc peaks near the segment's middle; three points cover the middle
/// and the quarter points, where an S-shaped cubic segment peaks.
pub(super) const CHORD_PROBES: [f64; 3] = [0.25, 0.5, 0.75];

/// Doubles the segment count, starting from the degree (a degree-d curve has up to d - 1
/// inflections, so fewer segments can miss its shape), until every segment's distance from
/// its chord, probed at [`CHORD_PROBES`], is within `tolerance`.
pub fn segments_for_tolerance(
    curve: &dyn Fn(f64) -> DVec3,
    degree: usize,
    tolerance: f64,
) -> usize {
    segments_until(degree, &|t0, t1| {
        let (a, b) = (curve(t0), curve(t1));
        CHORD_PROBES.iter().all(|&f| {
            let p = curve(t0 + (t1 - t0) * f);
            distance_to_segment(p, a, b) <= tolerance
        })
    })
}

/// The first count of equal parameter segments, doubling from the degree up to
/// [`MAX_ADAPTIVE_SEGMENTS`], for which `fine(t0, t1)` holds on every segment.
pub fn segments_until(degree: usize, fine: &dyn Fn(f64, f64) -> bool) -> usize {
    let mut n = degree.max(1);
    while n < MAX_ADAPTIVE_SEGMENTS {
        if (0..n).all(|s| fine(s as f64 / n as f64, (s + 1) as f64 / n as f64)) {
            return n;
        }
        n *= 2;
    }
    MAX_ADAPTIVE_SEGMENTS
}
