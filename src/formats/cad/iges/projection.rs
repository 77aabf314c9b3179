//! Model-space trim curves of IGES 142/141 projected into a converted surface's NURBS
//! parameters (`geom::pcurve`), as one loop: the projected parts placed by whole periods
//! next to the given ones, so that a loop crossing a closed surface's seam stays
//! continuous and one through a pole keeps its angle.

use glam::{DVec2, DVec3};

use super::trimmed::CLOSED;
use crate::formats::cad::projection_tolerance;
use crate::geom::bezier::ParamRect;
use crate::geom::nurbs::NurbsSurface;
use crate::geom::pcurve::{self, NurbsTarget, ParamSurface};
use crate::geom::trim::{AxisMap, TrimSegment};

/// A converted surface as the projection of model-space trim curves sees it: its NURBS
/// parameters, periodic in each direction in which the surface closes (so that a loop
/// crossing the seam stays continuous and one through a pole keeps its angle).
pub(super) struct Target<'s> {
    nurbs: NurbsTarget<'s>,
    domain: ParamRect,
    periods: [Option<f64>; 2],
    /// The projection's tolerances, relative to the surface's net.
    pub(super) tolerance: pcurve::Tolerance,
}

impl<'s> Target<'s> {
    pub(super) fn new(surface: &'s NurbsSurface) -> Target<'s> {
        let size = surface.net_diagonal();
        let d = surface.domain();
        let closed = [
            surface.is_closed_u(CLOSED * size),
            surface.transposed().is_closed_u(CLOSED * size),
        ];
        Target {
            nurbs: NurbsTarget::new(surface),
            domain: d,
            periods: [
                closed[0].then_some(d.u1 - d.u0),
                closed[1].then_some(d.v1 - d.v0),
            ],
            tolerance: projection_tolerance(size),
        }
    }

    /// Axis `k`'s domain.
    fn range(&self, k: usize) -> (f64, f64) {
        let d = self.domain;
        if k == 0 { (d.u0, d.u1) } else { (d.v0, d.v1) }
    }

    /// The trim parameters of NURBS parameters `uv` that may lie whole periods outside
    /// the domain: mapped from within it, then moved by as many periods of the trim
    /// parameter (the map's rise over the domain: a turn for an angle).
    fn to_trim(&self, maps: &[AxisMap; 2], uv: DVec2) -> DVec2 {
        let mut out = DVec2::ZERO;
        for k in 0..2 {
            let (a, b) = self.range(k);
            out[k] = match self.periods[k] {
                Some(p) => {
                    let turns = ((uv[k] - a) / p).floor();
                    maps[k].apply(uv[k] - turns * p) + turns * (maps[k].apply(b) - maps[k].apply(a))
                }
                None => maps[k].apply(uv[k]),
            };
        }
        out
    }
}

impl ParamSurface for Target<'_> {
    fn point(&self, uv: DVec2) -> DVec3 {
        let mut w = uv;
        for k in 0..2 {
            if let Some(p) = self.periods[k] {
                let (a, _) = self.range(k);
                w[k] = a + (w[k] - a).rem_euclid(p);
            }
        }
        self.nurbs.point(w)
    }

    fn parameters(&self, p: DVec3) -> Option<DVec2> {
        self.nurbs.parameters(p)
    }

    fn periods(&self) -> [Option<f64>; 2] {
        self.periods
    }
}

/// A piece of a trim loop: a parameter-space curve as the file gives it, or a model-space
/// curve projected into the surface's NURBS parameters (each unwrapped along itself).
pub(super) enum Part {
    Given(TrimSegment),
    Projected(Vec<DVec2>),
}

impl Target<'_> {
    /// The loop's pieces as trim segments. Projected curves follow on from the one before
    /// by whole periods; where that one ends at a pole, the angle they follow on from
    /// means nothing (the loop runs along the pole from one angle to another), so when a
    /// loop of projected curves then fails to close by whole periods, the curves after the
    /// last pole are moved back by them.
    pub(super) fn join(&self, mut parts: Vec<Part>, maps: &[AxisMap; 2]) -> Vec<TrimSegment> {
        let mut last: Option<DVec2> = None;
        let mut after_pole = [None; 2];
        for (i, part) in parts.iter_mut().enumerate() {
            let Part::Projected(points) = part else {
                last = None;
                continue;
            };
            if let Some(prev) = last {
                for k in 0..2 {
                    let by = pcurve::unwrap(points[0][k], prev[k], self.periods[k]) - points[0][k];
                    points.iter_mut().for_each(|p| p[k] += by);
                    if pcurve::collapsed(self, prev, k, self.tolerance.point) {
                        after_pole[k] = Some(i);
                    }
                }
            }
            last = points.last().copied();
        }
        let all_projected = parts.iter().all(|p| matches!(p, Part::Projected(_)));
        if let (true, Some(Part::Projected(first)), Some(Part::Projected(end))) =
            (all_projected, parts.first(), parts.last())
        {
            let gap = end[end.len() - 1] - first[0];
            for k in 0..2 {
                let Some(p) = self.periods[k] else { continue };
                if let Some(i) = after_pole[k] {
                    let turns = (gap[k] / p).round();
                    shift(&mut parts[i..], k, -turns * p);
                }
                // The whole loop by whole periods to start within the domain, where the
                // surface is.
                let lowest = parts
                    .iter()
                    .flat_map(|part| match part {
                        Part::Projected(points) => points.as_slice(),
                        Part::Given(_) => &[],
                    })
                    .fold(f64::INFINITY, |m, q| m.min(q[k]));
                let (a, _) = self.range(k);
                shift(&mut parts, k, -((lowest - a) / p + 1e-9).floor() * p);
            }
        }
        parts
            .into_iter()
            .map(|p| match p {
                Part::Given(s) => s,
                Part::Projected(points) => {
                    let trim: Vec<DVec2> =
                        points.iter().map(|&uv| self.to_trim(maps, uv)).collect();
                    TrimSegment::polyline(&trim)
                }
            })
            .collect()
    }
}

/// Moves the projected parts by `by` along axis `k`.
fn shift(parts: &mut [Part], k: usize, by: f64) {
    for part in parts {
        if let Part::Projected(points) = part {
            points.iter_mut().for_each(|q| q[k] += by);
        }
    }
}
