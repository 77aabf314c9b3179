//! Point inversion: the point of a NURBS surface closest to a point in space (Piegl &
//! Tiller, *The NURBS Book*, §6.1). CAD readers use it to bring trim curves given only in
//! model space (IGES 142 without a parameter-space curve, STEP edges without pcurves) into
//! the surface's domain, and report the distance as the projection's error.
//!
//! As §6.1 advises, the start comes from sampling: the surface is cut into its exact
//! Bézier patches and each is sampled on a grid, its steps shared between the two
//! directions in proportion to the patch's extent along them; from the few nearest
//! samples, Gauss–Newton on `S(u, v) − P` (quadratic where the point lies on the surface,
//! which is the case the readers care about; linear otherwise) runs over the whole
//! surface, clamped to its domain, with step halving so the distance never grows. The
//! best of these is the answer.
//!
//! Both choices come from long thin patches (a lofted tube a hundred times longer than
//! its patches are wide around it). A square grid on such a patch leaves rings of samples
//! far apart along the tube, and the nearest sample to a point between two rings can lie
//! across the tube from it; a descent confined to the patch of its start then stops at
//! that patch's edge, a patch corner far from the point, which was kept as the answer.

use glam::DVec3;

use super::surface::NurbsSurface;
use crate::geom::bezier::BezierPatch;

/// Grid steps per patch direction of the start samples on a patch as long as wide; a
/// patch k times longer than wide gets √k times more steps along its length and √k
/// times fewer across (at least one), so the samples of a long thin patch (a tube of a
/// hundred such around its circumference) are as far apart along it as across the tube,
/// and the nearest sample is near the nearest point.
const SAMPLES: usize = 8;
/// Most grid steps along one patch direction.
const MAX_SAMPLES: usize = SAMPLES * SAMPLES;
/// How many of the nearest samples start a descent: more than one, because the nearest
/// sample can sit across a fold from the nearest point.
const STARTS: usize = 4;
/// Gauss–Newton steps per start; quadratic convergence needs about 5 from a grid sample.
const MAX_STEPS: usize = 40;
/// Step halvings before a descent gives up on a direction.
const MAX_HALVINGS: usize = 30;
/// The normal equations count as singular when det(JᵀJ) is below this fraction of the
/// product of its diagonal: S_u and S_v within about 1e-6 rad of parallel, or one of them
/// vanishing, where the 2 × 2 solve would only amplify rounding.
const DEGENERATE: f64 = 1e-12;
/// Near the minimum the distance is flat (it changes with the square of the parameter
/// error), so a step that leaves it the same up to a few ulps of the coordinates is still
/// progress: the step comes from the gradient, which keeps resolving the foot point.
const FLAT_ULPS: f64 = 4.0;

/// The closest point found: NURBS parameters and the distance to the query point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Projection {
    pub u: f64,
    pub v: f64,
    pub distance: f64,
}

/// A surface prepared for many inversions: its Bézier patches, where each lies in the
/// parameter plane, and start samples.
pub struct Inverter {
    /// The patches in span order, u spans fastest
    /// ([`NurbsSurface::to_bezier_patches`]).
    patches: Vec<BezierPatch>,
    /// The patches' span ends in u and in v, increasing: patch (a, b) covers
    /// `[breaks_u[a], breaks_u[a + 1]] × [breaks_v[b], breaks_v[b + 1]]`.
    breaks_u: Vec<f64>,
    breaks_v: Vec<f64>,
    /// (u, v, point).
    samples: Vec<(f64, f64, DVec3)>,
}

impl Inverter {
    pub fn new(surface: &NurbsSurface) -> Inverter {
        let patches = surface.to_bezier_patches();
        let mut samples = Vec::new();
        let (mut breaks_u, mut breaks_v) = (Vec::new(), Vec::new());
        for patch in &patches {
            let d = patch.domain();
            // The first row of patches gives the u spans, the first column the v spans.
            if breaks_v.is_empty() || d.v0 == breaks_v[0] {
                breaks_u.push(d.u0);
            }
            if breaks_u.is_empty() || d.u0 == breaks_u[0] {
                breaks_v.push(d.v0);
            }
            let (steps_u, steps_v) = sample_steps(patch);
            for i in 0..=steps_u {
                for j in 0..=steps_v {
                    let (s, t) = (i as f64 / steps_u as f64, j as f64 / steps_v as f64);
                    let (u, v) = d.to_parent(s, t);
                    samples.push((u, v, patch.eval(s, t)));
                }
            }
        }
        if let Some(last) = patches.last() {
            breaks_u.push(last.domain().u1);
            breaks_v.push(last.domain().v1);
        }
        Inverter {
            patches,
            breaks_u,
            breaks_v,
            samples,
        }
    }

    /// The closest point of the surface to `p`; `None` for a surface without patches or a
    /// non-finite `p`.
    ///
    /// # Examples
    /// ```
    /// use glam::DVec3;
    /// use patchtrace::geom::nurbs::{inversion::Inverter, shapes};
    /// let sphere = shapes::sphere(2.0)?;
    /// let hit = Inverter::new(&sphere).project(DVec3::new(0.0, 3.0, 0.0)).unwrap();
    /// assert!((hit.distance - 1.0).abs() < 1e-12);
    /// assert!((sphere.eval(hit.u, hit.v) - DVec3::new(0.0, 2.0, 0.0)).length() < 1e-12);
    /// # Ok::<(), patchtrace::geom::GeomError>(())
    /// ```
    pub fn project(&self, p: DVec3) -> Option<Projection> {
        if !p.is_finite() {
            return None;
        }
        let mut near: Vec<(f64, usize)> = self
            .samples
            .iter()
            .enumerate()
            .map(|(i, s)| (s.2.distance_squared(p), i))
            .collect();
        let starts = STARTS.min(near.len());
        if starts == 0 {
            return None;
        }
        near.select_nth_unstable_by(starts - 1, |a, b| a.0.total_cmp(&b.0));
        near[..starts]
            .iter()
            .map(|&(_, i)| {
                let (u, v, _) = self.samples[i];
                self.descend(p, u, v)
            })
            .min_by(|a, b| a.distance.total_cmp(&b.distance))
    }

    /// The patch under (u, v), a point of the domain, and its local parameters there.
    fn locate(&self, u: f64, v: f64) -> (&BezierPatch, f64, f64) {
        let span = |breaks: &[f64], x: f64| {
            let k = breaks
                .partition_point(|&b| b <= x)
                .clamp(1, breaks.len() - 1)
                - 1;
            let (lo, hi) = (breaks[k], breaks[k + 1]);
            (k, lo, hi - lo)
        };
        let (a, u0, du) = span(&self.breaks_u, u);
        let (b, v0, dv) = span(&self.breaks_v, v);
        let patch = &self.patches[b * (self.breaks_u.len() - 1) + a];
        (patch, (u - u0) / du, (v - v0) / dv)
    }

    /// The point and first partial derivatives in the surface's own parameters.
    fn derivatives(&self, u: f64, v: f64) -> (DVec3, DVec3, DVec3) {
        let (patch, s, t) = self.locate(u, v);
        let d = patch.domain();
        let (point, ss, st) = patch.derivatives(s, t);
        (point, ss / (d.u1 - d.u0), st / (d.v1 - d.v0))
    }

    fn eval(&self, u: f64, v: f64) -> DVec3 {
        let (patch, s, t) = self.locate(u, v);
        patch.eval(s, t)
    }

    /// Gauss–Newton for min |S(u, v) − p| from (u, v): each step solves the 2 × 2 normal
    /// equations JᵀJ δ = −Jᵀr (r = S − p, J = [S_u S_v]), clamps to the domain, and is
    /// halved until the distance does not grow (beyond rounding).
    fn descend(&self, p: DVec3, mut u: f64, mut v: f64) -> Projection {
        let (u_lo, u_hi) = (self.breaks_u[0], self.breaks_u[self.breaks_u.len() - 1]);
        let (v_lo, v_hi) = (self.breaks_v[0], self.breaks_v[self.breaks_v.len() - 1]);
        let mut dist = (self.eval(u, v) - p).length();
        let slack = FLAT_ULPS * f64::EPSILON * (p.abs().max_element() + dist);
        for _ in 0..MAX_STEPS {
            let (point, su, sv) = self.derivatives(u, v);
            let r = point - p;
            let (a, b, c) = (su.dot(su), su.dot(sv), sv.dot(sv));
            let (g0, g1) = (su.dot(r), sv.dot(r));
            let det = a * c - b * b;
            let (mut du, mut dv) = if det > DEGENERATE * a * c && det.is_finite() {
                (-(c * g0 - b * g1) / det, -(a * g1 - b * g0) / det)
            } else if a >= c && a > 0.0 {
                // A degenerate Jacobian: S_v vanishes (a collapsed boundary, a pole, where
                // every v is one point) or S_u ∥ S_v. Newton along the direction that
                // still moves the point leaves the degenerate point; the full step
                // follows from there.
                (-g0 / a, 0.0)
            } else if c > 0.0 {
                (0.0, -g1 / c)
            } else {
                break;
            };
            let mut improved = false;
            for _ in 0..MAX_HALVINGS {
                let (nu, nv) = ((u + du).clamp(u_lo, u_hi), (v + dv).clamp(v_lo, v_hi));
                let nd = (self.eval(nu, nv) - p).length();
                if nd <= dist + slack {
                    improved = (nu, nv) != (u, v);
                    (u, v, dist) = (nu, nv, nd);
                    break;
                }
                du *= 0.5;
                dv *= 0.5;
            }
            if !improved {
                break;
            }
        }
        Projection {
            u,
            v,
            distance: dist,
        }
    }
}

/// Grid steps along u and v of `patch`'s start samples ([`SAMPLES`]). The extent along a
/// direction is the longest control polygon line that way: for a polynomial patch it
/// bounds the length of every iso-line along it (a Bézier curve is no longer than its
/// control polygon, and an iso-line's polygon is a convex combination of those lines).
fn sample_steps(patch: &BezierPatch) -> (usize, usize) {
    let (du, dv) = (patch.degree_u(), patch.degree_v());
    let polygon = |points: &mut dyn Iterator<Item = DVec3>| {
        let first = points.next().unwrap_or(DVec3::ZERO);
        points
            .fold((0.0, first), |(l, a), b| (l + a.distance(b), b))
            .0
    };
    let along_u = (0..=dv)
        .map(|j| polygon(&mut (0..=du).map(|i| patch.point(i, j))))
        .fold(0.0, f64::max);
    let along_v = (0..=du)
        .map(|i| polygon(&mut (0..=dv).map(|j| patch.point(i, j))))
        .fold(0.0, f64::max);
    let ratio = (along_u / along_v).sqrt();
    if !(ratio.is_finite() && ratio > 0.0) {
        // A collapsed direction (or both): its samples would all be the same point.
        return match (along_u > 0.0, along_v > 0.0) {
            (true, false) => (MAX_SAMPLES, 1),
            (false, true) => (1, MAX_SAMPLES),
            _ => (SAMPLES, SAMPLES),
        };
    }
    let steps = |k: f64| ((SAMPLES as f64 * k).round() as usize).clamp(1, MAX_SAMPLES);
    (steps(ratio), steps(1.0 / ratio))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::nurbs::shapes;

    #[test]
    fn points_off_a_sphere_project_radially() {
        // The closest point of a sphere to q is the centre-to-q ray's crossing: closed form.
        let r = 1.5;
        let s = shapes::sphere(r).unwrap();
        let inv = Inverter::new(&s);
        for (k, dir) in [
            DVec3::new(1.0, 2.0, 0.5),
            DVec3::new(-0.3, 0.1, -0.9),
            DVec3::new(0.0, -1.0, 0.2),
            DVec3::new(0.7, -0.7, 0.1),
        ]
        .iter()
        .enumerate()
        {
            let n = dir.normalize();
            for offset in [0.0, 0.25, -0.5] {
                let q = n * (r + offset);
                let hit = inv.project(q).unwrap();
                assert!((hit.distance - offset.abs()).abs() < 1e-12, "{k}, {offset}");
                let foot = s.eval(hit.u, hit.v);
                assert!((foot - n * r).length() < 1e-10 * r, "{k}, {offset}: {foot}");
            }
        }
    }

    #[test]
    fn points_beside_a_pole_leave_it() {
        // At the NURBS sphere's poles one parameter moves nothing (its Jacobian is
        // singular), and every start sample of the pole row is the pole itself: the
        // nearest point of a point beside the pole is still radial (closed form).
        let r = 2.0;
        let s = shapes::sphere(r).unwrap();
        let inv = Inverter::new(&s);
        for pole in [DVec3::Z, -DVec3::Z] {
            for (angle, around) in [(1e-3, 0.3), (2e-2, 2.0), (0.1, -1.0)] {
                let side = DVec3::new(f64::cos(around), f64::sin(around), 0.0);
                let n = (pole * f64::cos(angle) + side * f64::sin(angle)).normalize();
                let q = n * (r + 0.01);
                let hit = inv.project(q).unwrap();
                assert!((hit.distance - 0.01).abs() < 1e-12, "{n}: {}", hit.distance);
            }
        }
    }

    #[test]
    fn points_on_a_torus_come_back_to_their_parameters() {
        let s = shapes::torus(2.0, 0.5).unwrap();
        let inv = Inverter::new(&s);
        for (u, v) in [(0.1, 0.2), (0.37, 0.91), (0.75, 0.5), (0.999, 0.001)] {
            let hit = inv.project(s.eval(u, v)).unwrap();
            assert!(hit.distance < 1e-12, "({u}, {v}): {}", hit.distance);
            assert!(
                (hit.u - u).abs() < 1e-9 && (hit.v - v).abs() < 1e-9,
                "({u}, {v})"
            );
        }
    }

    #[test]
    fn never_worse_than_a_dense_grid() {
        // An independent answer: the nearest of 200 × 200 surface points.
        let s = shapes::torus(2.0, 0.5).unwrap();
        let inv = Inverter::new(&s);
        for q in [
            DVec3::new(0.3, 0.1, 0.2),
            DVec3::new(3.0, 3.0, 3.0),
            DVec3::new(-2.2, 0.1, -0.9),
        ] {
            let grid = (0..=200)
                .flat_map(|i| (0..=200).map(move |j| (i as f64 / 200.0, j as f64 / 200.0)))
                .map(|(u, v)| (s.eval(u, v) - q).length())
                .fold(f64::INFINITY, f64::min);
            let hit = inv.project(q).unwrap();
            assert!(
                hit.distance <= grid + 1e-12,
                "{q}: {} > {grid}",
                hit.distance
            );
            assert!(((s.eval(hit.u, hit.v) - q).length() - hit.distance).abs() < 1e-12);
        }
        assert!(inv.project(DVec3::NAN).is_none());
    }
}
