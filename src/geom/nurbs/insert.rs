//! Boehm knot insertion (Piegl & Tiller, *The NURBS Book*, A5.1 CurveKnotIns; A5.3
//! SurfaceKnotIns is A5.1 on every row or column) and clamping of unclamped knot vectors
//! by inserting the domain ends.
//!
//! Every new control point is a convex combination of two old ones, with coefficients
//! `alpha` in [0, 1] because the inserted knot lies inside the span, so positive weights
//! stay positive and the surface does not move.

use glam::DVec4;

use super::curve::NurbsCurve;
use super::knots::{self, KnotError};
use super::surface::{NurbsSurface, knot_error};
use crate::geom::bezier::{GeomError, ParamRect};

impl NurbsCurve {
    /// Inserts `t` `times` times. `t` must lie in the domain and its multiplicity must
    /// not exceed the degree afterwards.
    pub fn insert_knot(&self, t: f64, times: usize) -> Result<NurbsCurve, KnotError> {
        knots::validate_insertion(self.degree, &self.knots, t, times)?;
        Ok(self.insert_unchecked(t, times))
    }

    /// A5.1 CurveKnotIns, for `t` in the domain with `multiplicity + times <= degree`.
    fn insert_unchecked(&self, t: f64, times: usize) -> NurbsCurve {
        if times == 0 {
            return self.clone();
        }
        let (p, u, pw, r) = (self.degree, &self.knots, &self.points, times);
        let s = knots::multiplicity(u, t);
        // The last knot <= t: the span A5.1 works on. Unlike FindSpan this also gives
        // the right span at an unclamped end of the domain, where t = knots[n].
        let k = u.partition_point(|&x| x <= t) - 1;
        let np = pw.len() - 1;

        let mut knots = Vec::with_capacity(u.len() + r);
        knots.extend_from_slice(&u[..=k]);
        knots.extend(std::iter::repeat_n(t, r));
        knots.extend_from_slice(&u[k + 1..]);

        let mut q = vec![DVec4::ZERO; pw.len() + r];
        q[..=k - p].copy_from_slice(&pw[..=k - p]);
        q[k - s + r..=np + r].copy_from_slice(&pw[k - s..=np]);
        let mut rw: Vec<DVec4> = pw[k - p..=k - s].to_vec();
        let mut l = k - p;
        for j in 1..=r {
            l = k - p + j;
            for i in 0..=p - j - s {
                let alpha = (t - u[l + i]) / (u[i + k + 1] - u[l + i]);
                rw[i] = rw[i + 1] * alpha + rw[i] * (1.0 - alpha);
            }
            q[l] = rw[0];
            q[k + r - j - s] = rw[p - j - s];
        }
        // The points between the two fronts of the triangle (none when s + r = p).
        if l + 1 < k - s {
            q[l + 1..k - s].copy_from_slice(&rw[1..k - s - l]);
        }
        NurbsCurve {
            degree: p,
            knots,
            points: q,
        }
    }

    /// The same curve on the same domain with clamped knots: each domain end is inserted
    /// until its multiplicity is the degree, which makes the curve pass through one control
    /// point there; the control points and knots beyond it no longer affect the domain and
    /// are dropped, and the outermost remaining knot is set to the end (the basis function
    /// left at each end does not depend on it, A2.2's recurrence).
    pub fn clamped(&self) -> NurbsCurve {
        let (start, end) = knots::domain(self.degree, &self.knots);
        self.clamped_to(start, end)
    }

    /// The curve restricted to `[start, end]` (inside its domain, `start < end`), with
    /// clamped knots: each end is inserted until its multiplicity is the degree, and the
    /// control points and knots beyond it are dropped, as [`NurbsCurve::clamped`] does at
    /// the domain's ends. The curve does not move on `[start, end]`.
    pub fn clamped_to(&self, start: f64, end: f64) -> NurbsCurve {
        let p = self.degree;
        let mut c = self.clone();
        if c.knots[0] != start {
            let s = knots::multiplicity(&c.knots, start);
            c = c.insert_unchecked(start, p.saturating_sub(s));
            let last = c.knots.partition_point(|&x| x <= start) - 1;
            let first = last - p;
            c.points.drain(..first);
            c.knots.drain(..first);
            c.knots[0] = start;
        }
        if c.knots[c.knots.len() - 1] != end {
            let s = knots::multiplicity(&c.knots, end);
            c = c.insert_unchecked(end, p.saturating_sub(s));
            let first = c.knots.partition_point(|&x| x < end);
            c.points.truncate(first);
            c.knots.truncate(first + p + 1);
            c.knots[first + p] = end;
        }
        c
    }
}

impl NurbsSurface {
    /// The same surface with the u knot `t` inserted `times` times (A5.3, u direction).
    pub fn insert_knot_u(&self, t: f64, times: usize) -> Result<NurbsSurface, GeomError> {
        knots::validate_insertion(self.degree_u, &self.knots_u, t, times)
            .map_err(knot_error("u"))?;
        Ok(self.map_rows_u(|row| row.insert_unchecked(t, times)))
    }

    /// The same surface with the v knot `t` inserted `times` times (A5.3, v direction).
    pub fn insert_knot_v(&self, t: f64, times: usize) -> Result<NurbsSurface, GeomError> {
        knots::validate_insertion(self.degree_v, &self.knots_v, t, times)
            .map_err(knot_error("v"))?;
        Ok(self
            .transposed()
            .map_rows_u(|row| row.insert_unchecked(t, times))
            .transposed())
    }

    /// The surface restricted to `rect` (inside its domain, non-empty), clamped: OBJ's
    /// `surf s0 s1 t0 t1` range. Exact: knot insertion does not move the surface.
    pub fn restricted(&self, rect: ParamRect) -> NurbsSurface {
        self.map_rows_u(|row| row.clamped_to(rect.u0, rect.u1))
            .transposed()
            .map_rows_u(|row| row.clamped_to(rect.v0, rect.v1))
            .transposed()
    }

    /// The same surface on the same domain with both knot vectors clamped.
    pub fn clamped(&self) -> NurbsSurface {
        self.map_rows_u(NurbsCurve::clamped)
            .transposed()
            .map_rows_u(NurbsCurve::clamped)
            .transposed()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::nurbs::testutil::surface;
    use proptest::prelude::*;

    /// Largest distance between two surfaces over a grid on the domain of `a`.
    fn max_deviation(a: &NurbsSurface, b: &NurbsSurface) -> f64 {
        let d = a.domain();
        let steps = 12;
        let mut worst: f64 = 0.0;
        for i in 0..=steps {
            for j in 0..=steps {
                let (u, v) = d.to_parent(i as f64 / steps as f64, j as f64 / steps as f64);
                worst = worst.max((a.eval(u, v) - b.eval(u, v)).length());
            }
        }
        worst
    }

    proptest! {
        #[test]
        fn insertion_does_not_move_the_surface(
            s in surface(),
            t in 0.0..=1.0f64,
            times in 1usize..=5,
            in_v in any::<bool>(),
        ) {
            let (p, knots) = if in_v { (s.degree_v, &s.knots_v) } else { (s.degree_u, &s.knots_u) };
            let times = times.min(p.saturating_sub(knots::multiplicity(knots, t)));
            prop_assume!(times > 0);
            let r = if in_v { s.insert_knot_v(t, times) } else { s.insert_knot_u(t, times) }.unwrap();
            prop_assert!(r.validate().is_ok());
            let new_knots = if in_v { &r.knots_v } else { &r.knots_u };
            prop_assert_eq!(new_knots.len(), knots.len() + times);
            prop_assert_eq!(r.domain(), s.domain());
            let dev = max_deviation(&s, &r);
            prop_assert!(dev <= 1e-12 * s.net_diagonal(), "deviation {}", dev);
        }

        #[test]
        fn restriction_keeps_the_surface_on_the_sub_rectangle(
            s in surface(),
            a in 0.0..1.0f64,
            b in 0.0..1.0f64,
            c in 0.0..1.0f64,
            e in 0.0..1.0f64,
        ) {
            let d = s.domain();
            let (u0, u1) = d.to_parent(a.min(b), a.max(b));
            let (v0, v1) = d.to_parent(c.min(e), c.max(e));
            prop_assume!(u1 - u0 > 1e-3 * (d.u1 - d.u0) && v1 - v0 > 1e-3 * (d.v1 - d.v0));
            let rect = ParamRect { u0, u1, v0, v1 };
            let r = s.restricted(rect);
            prop_assert!(r.validate().is_ok());
            prop_assert_eq!(r.domain(), rect);
            // Compared on the restricted domain: the same points as the original there.
            let dev = max_deviation(&r, &s);
            prop_assert!(dev <= 1e-12 * s.net_diagonal(), "deviation {}", dev);
        }

        #[test]
        fn clamping_does_not_move_the_surface(s in surface()) {
            let c = s.clamped();
            prop_assert!(c.validate().is_ok());
            prop_assert!(knots::is_clamped(c.degree_u, &c.knots_u));
            prop_assert!(knots::is_clamped(c.degree_v, &c.knots_v));
            prop_assert_eq!(c.domain(), s.domain());
            let dev = max_deviation(&s, &c);
            prop_assert!(dev <= 1e-12 * s.net_diagonal(), "deviation {}", dev);
        }
    }

    #[test]
    fn clamping_a_uniform_cubic_keeps_the_surface() {
        // Uniform knots 0..=10 for 7 × 6 points of degree 3 × 4, nothing clamped; points
        // from a smooth function so the surface is not degenerate.
        let (pu, pv, nu, nv) = (3, 4, 7, 6);
        let ku: Vec<f64> = (0..nu + pu + 1).map(|i| i as f64).collect();
        let kv: Vec<f64> = (0..nv + pv + 1).map(|i| 0.5 * i as f64).collect();
        let points = (0..nv)
            .flat_map(|j| {
                (0..nu).map(move |i| {
                    let w = 1.0 + 0.3 * ((i * 7 + j * 3) % 5) as f64;
                    let e = glam::DVec3::new(i as f64, j as f64, ((i * j) as f64).sin());
                    (e * w).extend(w)
                })
            })
            .collect();
        let s = NurbsSurface::new(pu, pv, ku, kv, nu, nv, points).unwrap();
        let c = s.clamped();
        assert_eq!(c.knots_u, vec![3., 3., 3., 3., 4., 5., 6., 7., 7., 7., 7.]);
        assert_eq!(
            c.knots_v,
            vec![2.0, 2.0, 2.0, 2.0, 2.0, 2.5, 3.0, 3.0, 3.0, 3.0, 3.0]
        );
        assert_eq!((c.count_u, c.count_v), (7, 6));
        assert!(max_deviation(&s, &c) <= 1e-12 * s.net_diagonal());
    }

    #[test]
    fn rejects_insertion_beyond_the_degree() {
        let s = crate::geom::nurbs::shapes::torus(2.0, 0.5).unwrap();
        let e = s.insert_knot_u(0.25, 1).unwrap_err();
        assert!(
            e.to_string()
                .starts_with("knots_u: inserting knot 0.25 1 times onto multiplicity 2"),
            "{e}"
        );
        let e = s.insert_knot_v(1.5, 1).unwrap_err();
        assert!(e.to_string().contains("outside the domain [0, 1]"), "{e}");
    }
}
