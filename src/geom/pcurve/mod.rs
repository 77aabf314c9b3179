//! Trim curves from model-space edges: a 3D curve lying on a surface brought into the
//! surface's parameters, for CAD readers whose files give an edge only in space (STEP
//! edges without PCURVEs, IGES 142 curves on a surface whose preferred or only
//! representation is the 141/142 model-space one).
//!
//! The curve is sampled and each sample inverted on the surface (closed forms for the
//! elementary surfaces, Newton point inversion from a sampled start for B-splines, as
//! [`crate::geom::nurbs::inversion`] does); the polyline through the parameters is refined
//! by halving every piece whose chord, mapped back onto the surface, strays from the
//! projected curve by more than the tolerance. Periodic parameters are unwrapped to the
//! previous sample, so a curve crossing a seam stays continuous; at a pole or apex, where
//! the angle of a point means nothing, a sample takes its neighbour's angle.

use glam::{DVec2, DVec3};

use crate::geom::nurbs::NurbsSurface;
use crate::geom::nurbs::inversion::Inverter;

/// Segments a projected curve starts with before refinement (enough that a curve bending
/// back on itself cannot hide between the first samples).
const MIN_SEGMENTS: usize = 4;
/// Halvings of a projected segment at most: 4 · 2^10 = 4096 samples per curve.
const MAX_REFINE: usize = 10;

/// A surface as the projection needs it.
pub trait ParamSurface {
    /// The point at parameters `uv`.
    fn point(&self, uv: DVec2) -> DVec3;
    /// The parameters of the surface's point closest to `p` (any period of a periodic
    /// parameter); `None` where it cannot be found.
    fn parameters(&self, p: DVec3) -> Option<DVec2>;
    /// The periods of (u, v), where a parameter is periodic.
    fn periods(&self) -> [Option<f64>; 2];
}

/// `x` moved by whole periods to lie nearest `near`.
pub fn unwrap(x: f64, near: f64, period: Option<f64>) -> f64 {
    match period {
        Some(p) => x - ((x - near) / p).round() * p,
        None => x,
    }
}

/// The parameters of `p` on `s`, unwrapped to lie nearest `near`.
pub fn parameters_near(s: &impl ParamSurface, p: DVec3, near: Option<DVec2>) -> Option<DVec2> {
    let uv = s.parameters(p)?;
    let periods = s.periods();
    Some(match near {
        Some(n) => DVec2::new(unwrap(uv.x, n.x, periods[0]), unwrap(uv.y, n.y, periods[1])),
        None => uv,
    })
}

/// Whether the periodic parameter `axis` (0 for u, 1 for v) collapses at `uv` (a sphere's
/// pole, a cone's apex, the degenerate edge of a closed B-spline): a quarter period along
/// it moves the point by at most `tol`.
pub fn collapsed(s: &impl ParamSurface, uv: DVec2, axis: usize, tol: f64) -> bool {
    quarter_turn(s, uv, axis).is_some_and(|d| d <= tol)
}

/// How far a quarter period along the periodic parameter `axis` moves the point at `uv`
/// (√2 times its distance from the axis of a surface of revolution); `None` where `axis`
/// is not periodic.
fn quarter_turn(s: &impl ParamSurface, uv: DVec2, axis: usize) -> Option<f64> {
    s.periods()[axis].map(|p| {
        let mut step = DVec2::ZERO;
        step[axis] = 0.25 * p;
        s.point(uv).distance(s.point(uv + step))
    })
}

/// Gives the samples at a pole or apex, where the periodic parameter `axis` means nothing
/// (its inversion there is rounding), the value of their neighbours along the curve. A
/// run of such samples between two neighbours is split at the sample nearest the pole:
/// those before it take the value the curve arrives with, those after the value it
/// leaves with. Where the two differ the curve passes through the pole (a meridian run
/// over it onto the opposite one), and the sample nearest the pole is doubled, so the
/// polyline runs along the pole's line in the parameter plane from the one value to the
/// other, as a pcurve through a pole does (ISO 10303-42 pcurve; a degenerate edge of a
/// B-rep): a chord cutting across instead leaves the face a corner short and a spur
/// doubling back along the far meridian, which readers of the faces we write reject.
fn through_poles(
    s: &impl ParamSurface,
    ts: &mut Vec<f64>,
    uvs: &mut Vec<DVec2>,
    axis: usize,
    tol: f64,
) {
    let mut k = 0;
    while k < uvs.len() {
        if !collapsed(s, uvs[k], axis, tol) {
            k += 1;
            continue;
        }
        let start = k;
        while k < uvs.len() && collapsed(s, uvs[k], axis, tol) {
            k += 1;
        }
        let (before, after) = (start.checked_sub(1), (k < uvs.len()).then_some(k));
        let (arrive, leave) = match (before, after) {
            (Some(b), Some(a)) => (uvs[b][axis], uvs[a][axis]),
            (Some(j), None) | (None, Some(j)) => (uvs[j][axis], uvs[j][axis]),
            (None, None) => continue,
        };
        let nearest = (start..k)
            .min_by(|&a, &b| {
                let d = |j: usize| quarter_turn(s, uvs[j], axis).unwrap_or(0.0);
                d(a).total_cmp(&d(b))
            })
            .unwrap_or(start);
        for j in start..k {
            uvs[j][axis] = if j <= nearest { arrive } else { leave };
        }
        if leave != arrive {
            let mut turn = uvs[nearest];
            turn[axis] = leave;
            uvs.insert(nearest + 1, turn);
            ts.insert(nearest + 1, ts[nearest]);
            k += 1;
        }
    }
}

/// How closely a projection follows its curve, in model units.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tolerance {
    /// Largest distance between a chord's image on the surface and the projected curve.
    pub chord: f64,
    /// Two surface points this close are one point: a periodic parameter that moves the
    /// point less than this over a quarter period has collapsed (a pole, an apex).
    pub point: f64,
}

/// A curve projected into a surface's parameters.
#[derive(Clone, Debug, PartialEq)]
pub struct Projected {
    /// The polyline in parameter space, from the curve's start to its end.
    pub points: Vec<DVec2>,
    /// The largest distance met between a curve sample and its image on the surface: how
    /// far the curve itself lies from the surface (the file's own gap, where the curve is
    /// an edge of a face on it).
    pub gap: f64,
    /// The largest distance between a chord's image on the surface and the projected
    /// curve: how far the polyline strays from the projection (this reader's own error).
    pub chord: f64,
}

/// The projection of `curve` over `[ta, tb]` onto `s` as a polyline refined until every
/// chord's midpoint maps within `tol.chord` of the projected curve (at most 4096 pieces);
/// `Err(p)` names a curve point that could not be inverted.
pub fn project(
    s: &impl ParamSurface,
    curve: impl Fn(f64) -> DVec3,
    ta: f64,
    tb: f64,
    tol: Tolerance,
) -> Result<Projected, DVec3> {
    let mut worst: f64 = 0.0;
    let mut measure = |t: f64, near: Option<DVec2>| -> Result<DVec2, DVec3> {
        let p = curve(t);
        let uv = parameters_near(s, p, near).ok_or(p)?;
        worst = worst.max(s.point(uv).distance(p));
        Ok(uv)
    };
    // Start samples, split until unwrapping each through the midpoint of its step agrees
    // with unwrapping it directly: unwrapping to the nearest period is only right for
    // steps below half a period (a helix sampled four times over three turns would
    // otherwise run backwards).
    let periods = s.periods();
    let mut ts = vec![ta];
    let mut uvs = vec![measure(ta, None)?];
    let mut pending: Vec<(f64, usize)> = (1..=MIN_SEGMENTS)
        .rev()
        .map(|k| (ta + (tb - ta) * k as f64 / MIN_SEGMENTS as f64, 0))
        .collect();
    while let Some((t, depth)) = pending.pop() {
        let (t0, a) = (ts[ts.len() - 1], uvs[uvs.len() - 1]);
        let uv = measure(t, Some(a))?;
        let mid = measure(0.5 * (t0 + t), Some(a))?;
        let jumps = (0..2).any(|k| {
            periods[k].is_some_and(|p| (unwrap(uv[k], mid[k], Some(p)) - uv[k]).abs() > 0.5 * p)
        });
        if jumps && depth < MAX_REFINE {
            pending.push((t, depth + 1));
            pending.push((0.5 * (t0 + t), depth + 1));
            continue;
        }
        ts.push(t);
        uvs.push(uv);
    }
    for axis in 0..2 {
        through_poles(s, &mut ts, &mut uvs, axis, tol.point);
    }
    // Refine: a stack of segments, left to right.
    let mut out = vec![uvs[0]];
    let mut stack: Vec<(f64, DVec2, f64, DVec2, usize)> = (0..ts.len() - 1)
        .rev()
        .map(|k| (ts[k], uvs[k], ts[k + 1], uvs[k + 1], 0))
        .collect();
    let mut chord_worst: f64 = 0.0;
    while let Some((t0, a, t1, b, depth)) = stack.pop() {
        if t0 == t1 {
            // Along a pole's line (`through_poles`): one point of the curve.
            out.push(b);
            continue;
        }
        let tm = 0.5 * (t0 + t1);
        let mut m = measure(tm, Some(a))?;
        for axis in 0..2 {
            if collapsed(s, m, axis, tol.point) {
                m[axis] = 0.5 * (a[axis] + b[axis]);
            }
        }
        // The chord's distance from the projected curve at `m`: to the chord's point
        // nearest `m` in the parameter plane, an upper bound of the distance to the
        // chord's image that does not count where the projection runs faster along the
        // chord than the curve (an edge running past the surface's end, its projection
        // stopped there). The curve's own distance from the surface is `gap`.
        let ab = b - a;
        let along = if ab.length_squared() > 0.0 {
            ((m - a).dot(ab) / ab.length_squared()).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let err = s.point(a + along * ab).distance(s.point(m));
        if err > tol.chord && depth < MAX_REFINE {
            stack.push((tm, m, t1, b, depth + 1));
            stack.push((t0, a, tm, m, depth + 1));
        } else {
            chord_worst = chord_worst.max(err);
            out.push(b);
        }
    }
    Ok(Projected {
        points: out,
        gap: worst,
        chord: chord_worst,
    })
}

/// A NURBS surface prepared for projection (its own, non-periodic, parameters).
pub struct NurbsTarget<'s> {
    pub surface: &'s NurbsSurface,
    inverter: Inverter,
}

impl<'s> NurbsTarget<'s> {
    pub fn new(surface: &'s NurbsSurface) -> NurbsTarget<'s> {
        NurbsTarget {
            surface,
            inverter: Inverter::new(surface),
        }
    }
}

impl ParamSurface for NurbsTarget<'_> {
    fn point(&self, uv: DVec2) -> DVec3 {
        self.surface.eval(uv.x, uv.y)
    }

    fn parameters(&self, p: DVec3) -> Option<DVec2> {
        let hit = self.inverter.project(p)?;
        Some(DVec2::new(hit.u, hit.v))
    }

    fn periods(&self) -> [Option<f64>; 2] {
        [None, None]
    }
}

#[cfg(test)]
mod tests;
