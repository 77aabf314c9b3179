//! Point inversion: the point of a NURBS surface closest to a point in space (Piegl &
//! Tiller, *The NURBS Book*, §6.1). CAD readers use it to bring trim curves given only in
//! model space (IGES 142 without a parameter-space curve) into the surface's domain, and
//! report the distance as the projection's error.
//!
//! As §6.1 advises, the start comes from sampling: the surface is cut into its exact
//! Bézier patches and each is sampled on a grid; from the few nearest samples, Gauss–Newton
//! on `S(u, v) − P` (quadratic where the point lies on the surface, which is the case the
//! readers care about; linear otherwise) runs inside the patch, clamped to it, with step
//! halving so the distance never grows. The best of these is the answer.

use glam::DVec3;

use super::surface::NurbsSurface;
use crate::geom::bezier::BezierPatch;

/// Grid steps per patch direction of the start samples.
const SAMPLES: usize = 8;
/// How many of the nearest samples start a descent: more than one, because the nearest
/// sample can sit across a fold from the nearest point.
const STARTS: usize = 4;
/// Gauss–Newton steps per start; quadratic convergence needs about 5 from a grid sample.
const MAX_STEPS: usize = 40;
/// Step halvings before a descent gives up on a direction.
const MAX_HALVINGS: usize = 30;
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

/// A surface prepared for many inversions: its Bézier patches and start samples.
pub struct Inverter {
    patches: Vec<BezierPatch>,
    /// (patch, local u, local v, point).
    samples: Vec<(usize, f64, f64, DVec3)>,
}

impl Inverter {
    pub fn new(surface: &NurbsSurface) -> Inverter {
        let patches = surface.to_bezier_patches();
        let mut samples = Vec::with_capacity(patches.len() * (SAMPLES + 1) * (SAMPLES + 1));
        for (k, patch) in patches.iter().enumerate() {
            for i in 0..=SAMPLES {
                for j in 0..=SAMPLES {
                    let (s, t) = (i as f64 / SAMPLES as f64, j as f64 / SAMPLES as f64);
                    samples.push((k, s, t, patch.eval(s, t)));
                }
            }
        }
        Inverter { patches, samples }
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
            .map(|(i, s)| (s.3.distance_squared(p), i))
            .collect();
        let starts = STARTS.min(near.len());
        if starts == 0 {
            return None;
        }
        near.select_nth_unstable_by(starts - 1, |a, b| a.0.total_cmp(&b.0));
        near[..starts]
            .iter()
            .map(|&(_, i)| {
                let (k, s, t, _) = self.samples[i];
                let patch = &self.patches[k];
                let (s, t, d) = descend(patch, p, s, t);
                let (u, v) = patch.domain().to_parent(s, t);
                Projection { u, v, distance: d }
            })
            .min_by(|a, b| a.distance.total_cmp(&b.distance))
    }
}

/// Gauss–Newton for min |S(s, t) − p| on one patch's [0, 1]², from (s, t): each step solves
/// the 2 × 2 normal equations JᵀJ δ = −Jᵀr (r = S − p, J = [S_s S_t]), clamps to the
/// patch, and is halved until the distance does not grow (beyond rounding).
fn descend(patch: &BezierPatch, p: DVec3, mut s: f64, mut t: f64) -> (f64, f64, f64) {
    let mut dist = (patch.eval(s, t) - p).length();
    let slack = FLAT_ULPS * f64::EPSILON * (p.abs().max_element() + dist);
    for _ in 0..MAX_STEPS {
        let (point, ss, st) = patch.derivatives(s, t);
        let r = point - p;
        let (a, b, c) = (ss.dot(ss), ss.dot(st), st.dot(st));
        let (g0, g1) = (ss.dot(r), st.dot(r));
        let det = a * c - b * b;
        if !(det > 0.0 && det.is_finite()) {
            break;
        }
        let (mut ds, mut dt) = (-(c * g0 - b * g1) / det, -(a * g1 - b * g0) / det);
        let mut improved = false;
        for _ in 0..MAX_HALVINGS {
            let (ns, nt) = ((s + ds).clamp(0.0, 1.0), (t + dt).clamp(0.0, 1.0));
            let nd = (patch.eval(ns, nt) - p).length();
            if nd <= dist + slack {
                improved = (ns, nt) != (s, t);
                (s, t, dist) = (ns, nt, nd);
                break;
            }
            ds *= 0.5;
            dt *= 0.5;
        }
        if !improved {
            break;
        }
    }
    (s, t, dist)
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
