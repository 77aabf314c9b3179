//! The tensor-product NURBS surface: validation, Cox–de Boor evaluation (The NURBS Book,
//! A4.3 on homogeneous points), and the row/column views through which the curve
//! algorithms act on it.

use glam::{DVec3, DVec4};

use super::basis::span_basis;
use super::curve::NurbsCurve;
use super::knots::{self, KnotError};
use crate::geom::MAX_DEGREE;
use crate::geom::bezier::{GeomError, ParamRect, dehomogenize};

/// A NURBS surface with homogeneous premultiplied control points `(w x, w y, w z, w)`,
/// u index fastest: `points[j * count_u + i]`.
///
/// The fields are public for reading; build surfaces with [`NurbsSurface::new`], which
/// validates them. The other methods expect a surface that passes
/// [`NurbsSurface::validate`].
#[derive(Clone, Debug, PartialEq)]
pub struct NurbsSurface {
    pub degree_u: usize,
    pub degree_v: usize,
    pub knots_u: Vec<f64>,
    pub knots_v: Vec<f64>,
    pub count_u: usize,
    pub count_v: usize,
    pub points: Vec<DVec4>,
}

/// Names the direction in a knot error, e.g. "knots_u: knots decrease at index 3 ...".
pub(super) fn knot_error(direction: &'static str) -> impl Fn(KnotError) -> GeomError {
    move |e| GeomError::Knots(format!("knots_{direction}: {e}"))
}

impl NurbsSurface {
    /// The diagonal of the box of the Euclidean control points: the surface's scale for
    /// tolerances (the surface lies in their convex hull).
    pub fn net_diagonal(&self) -> f64 {
        let (lo, hi) = self
            .points
            .iter()
            .map(|p| p.truncate() / p.w)
            .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), p| {
                (lo.min(p), hi.max(p))
            });
        (hi - lo).length()
    }

    /// Validates and builds a surface.
    ///
    /// # Examples
    /// ```
    /// use glam::DVec4;
    /// use patchtrace::geom::nurbs::NurbsSurface;
    /// // A bilinear patch: degree 1 × 1, Bézier knots.
    /// let points = vec![
    ///     DVec4::new(0., 0., 0., 1.), DVec4::new(1., 0., 0., 1.),
    ///     DVec4::new(0., 1., 0., 1.), DVec4::new(1., 1., 1., 1.),
    /// ];
    /// let s = NurbsSurface::new(1, 1, vec![0., 0., 1., 1.], vec![0., 0., 1., 1.], 2, 2, points)?;
    /// assert_eq!(s.eval(0.5, 0.5).z, 0.25);
    /// assert!(NurbsSurface::new(1, 1, vec![0., 1., 0., 1.], vec![0., 0., 1., 1.], 2, 2,
    ///     s.points.clone()).is_err());
    /// # Ok::<(), patchtrace::geom::GeomError>(())
    /// ```
    pub fn new(
        degree_u: usize,
        degree_v: usize,
        knots_u: Vec<f64>,
        knots_v: Vec<f64>,
        count_u: usize,
        count_v: usize,
        points: Vec<DVec4>,
    ) -> Result<Self, GeomError> {
        let surface = NurbsSurface {
            degree_u,
            degree_v,
            knots_u,
            knots_v,
            count_u,
            count_v,
            points,
        };
        surface.validate()?;
        Ok(surface)
    }

    /// Checks every invariant `new` promises: degrees in `1..=MAX_DEGREE`, valid knot
    /// vectors (see [`knots::validate`]), `count_u * count_v` finite control points with
    /// positive weights.
    pub fn validate(&self) -> Result<(), GeomError> {
        for d in [self.degree_u, self.degree_v] {
            if !(1..=MAX_DEGREE).contains(&d) {
                return Err(GeomError::Degree(d));
            }
        }
        knots::validate(self.degree_u, &self.knots_u, self.count_u).map_err(knot_error("u"))?;
        knots::validate(self.degree_v, &self.knots_v, self.count_v).map_err(knot_error("v"))?;
        let expected = self.count_u.saturating_mul(self.count_v);
        if self.points.len() != expected {
            return Err(GeomError::PointCount {
                expected,
                found: self.points.len(),
            });
        }
        for (index, p) in self.points.iter().enumerate() {
            if !p.is_finite() {
                return Err(GeomError::NonFinite { index });
            }
            if p.w <= 0.0 {
                return Err(GeomError::Weight { index, weight: p.w });
            }
        }
        Ok(())
    }

    /// The parameter domain `[knots_u[p], knots_u[n]] × [knots_v[q], knots_v[m]]`.
    pub fn domain(&self) -> ParamRect {
        let (u0, u1) = knots::domain(self.degree_u, &self.knots_u);
        let (v0, v1) = knots::domain(self.degree_v, &self.knots_v);
        ParamRect { u0, u1, v0, v1 }
    }

    /// Homogeneous surface point at (u, v), clamped into the domain.
    pub fn eval_homogeneous(&self, u: f64, v: f64) -> DVec4 {
        let (pu, pv) = (self.degree_u, self.degree_v);
        let (su, nu) = span_basis(pu, &self.knots_u, u);
        let (sv, nv) = span_basis(pv, &self.knots_v, v);
        (0..=pv)
            .map(|l| {
                let row = (sv - pv + l) * self.count_u + su - pu;
                let along_u: DVec4 = (0..=pu).map(|k| self.points[row + k] * nu[k]).sum();
                along_u * nv[l]
            })
            .sum()
    }

    /// Surface point at (u, v), Cox–de Boor in f64, rational.
    pub fn eval(&self, u: f64, v: f64) -> DVec3 {
        dehomogenize(self.eval_homogeneous(u, v))
    }

    /// Applies an affine map to every control point; affine maps commute with the rational
    /// basis, so the surface is transformed exactly.
    pub fn transform(&mut self, m: &glam::DAffine3) {
        for p in &mut self.points {
            let e = m.transform_point3(dehomogenize(*p));
            *p = (e * p.w).extend(p.w);
        }
    }

    /// The same surface with u and v exchanged, so that an operation written for the u
    /// direction serves for v too.
    pub fn transposed(&self) -> NurbsSurface {
        let points = (0..self.count_u)
            .flat_map(|i| (0..self.count_v).map(move |j| self.points[j * self.count_u + i]))
            .collect();
        NurbsSurface {
            degree_u: self.degree_v,
            degree_v: self.degree_u,
            knots_u: self.knots_v.clone(),
            knots_v: self.knots_u.clone(),
            count_u: self.count_v,
            count_v: self.count_u,
            points,
        }
    }

    /// Row `j` of the control net as a curve in u.
    pub(super) fn row_u(&self, j: usize) -> NurbsCurve {
        NurbsCurve {
            degree: self.degree_u,
            knots: self.knots_u.clone(),
            points: self.points[j * self.count_u..(j + 1) * self.count_u].to_vec(),
        }
    }

    /// Applies a curve operation that changes only the u knots and points to every row.
    pub(super) fn map_rows_u(&self, op: impl Fn(&NurbsCurve) -> NurbsCurve) -> NurbsSurface {
        let rows: Vec<NurbsCurve> = (0..self.count_v).map(|j| op(&self.row_u(j))).collect();
        let knots_u = rows[0].knots.clone();
        let count_u = rows[0].points.len();
        NurbsSurface {
            degree_u: self.degree_u,
            degree_v: self.degree_v,
            knots_u,
            knots_v: self.knots_v.clone(),
            count_u,
            count_v: self.count_v,
            points: rows.into_iter().flat_map(|r| r.points).collect(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A valid 3 × 2 surface of degree 2 × 1 with clamped knots, to be broken per test.
    fn args() -> (usize, usize, Vec<f64>, Vec<f64>, usize, usize, Vec<DVec4>) {
        let points = (0..6)
            .map(|k| DVec4::new(k as f64, 1.0, 0.0, 1.0))
            .collect();
        (
            2,
            1,
            vec![0., 0., 0., 1., 1., 1.],
            vec![0., 0., 1., 1.],
            3,
            2,
            points,
        )
    }

    fn build(
        a: (usize, usize, Vec<f64>, Vec<f64>, usize, usize, Vec<DVec4>),
    ) -> Result<NurbsSurface, GeomError> {
        NurbsSurface::new(a.0, a.1, a.2, a.3, a.4, a.5, a.6)
    }

    fn message(a: (usize, usize, Vec<f64>, Vec<f64>, usize, usize, Vec<DVec4>)) -> String {
        build(a).unwrap_err().to_string()
    }

    #[test]
    fn accepts_the_base_case() {
        assert!(build(args()).is_ok());
    }

    #[test]
    fn rejects_wrong_point_count() {
        let mut a = args();
        a.6.pop();
        assert_eq!(message(a), "expected 6 control points, found 5");
    }

    #[test]
    fn rejects_wrong_knot_count() {
        let mut a = args();
        a.3.push(1.0);
        assert_eq!(
            message(a),
            "knots_v: expected 4 knots (control points + degree + 1), found 5"
        );
    }

    #[test]
    fn rejects_too_few_points_for_the_degree() {
        let mut a = args();
        a.0 = 3;
        assert_eq!(
            message(a),
            "knots_u: 3 control points are too few for degree 3: need at least 4"
        );
    }

    #[test]
    fn rejects_decreasing_knot() {
        let mut a = args();
        a.2 = vec![0., 0., 0.5, 0.25, 1., 1.];
        assert_eq!(
            message(a),
            "knots_u: knots decrease at index 3: 0.25 follows 0.5"
        );
    }

    #[test]
    fn rejects_interior_multiplicity_above_degree_plus_one() {
        let mut a = args();
        a.2 = vec![0., 0., 0., 0.5, 0.5, 0.5, 0.5, 1., 1., 1.];
        a.4 = 7;
        a.6 = vec![DVec4::ONE; 14];
        assert_eq!(
            message(a),
            "knots_u: interior knot 0.5 is repeated 4 times, more than degree + 1 = 3"
        );
    }

    #[test]
    fn rejects_end_multiplicity_above_degree_plus_one() {
        let mut a = args();
        a.3 = vec![0., 0., 0., 1.];
        assert_eq!(
            message(a),
            "knots_v: end knot 0 is repeated 3 times, more than degree + 1 = 2"
        );
    }

    #[test]
    fn rejects_empty_domain() {
        let mut a = args();
        a.2 = vec![0., 0.5, 1., 1., 2., 3.];
        assert_eq!(
            message(a),
            "knots_u: the parameter domain [knots[degree], knots[count]] = [1, 1] is empty"
        );
    }

    #[test]
    fn rejects_degree_16() {
        let mut a = args();
        a.1 = 16;
        assert_eq!(message(a), "degree 16 is outside 1..=15");
        let mut a = args();
        a.0 = 0;
        assert_eq!(build(a).unwrap_err(), GeomError::Degree(0));
    }

    #[test]
    fn rejects_zero_weight() {
        let mut a = args();
        a.6[4].w = 0.0;
        assert_eq!(
            message(a),
            "control point 4 has weight 0; weights must be positive"
        );
    }

    #[test]
    fn rejects_nan() {
        let mut a = args();
        a.6[2].y = f64::NAN;
        assert_eq!(message(a), "control point 2 has a non-finite coordinate");
        let mut a = args();
        a.3[1] = f64::NAN;
        assert_eq!(message(a), "knots_v: knot 1 is not finite (NaN)");
    }

    #[test]
    fn transposed_swaps_parameters() {
        let s = crate::geom::nurbs::shapes::sphere(1.0).unwrap();
        let t = s.transposed();
        assert!(t.validate().is_ok());
        for (u, v) in [(0.1, 0.7), (0.6, 0.3), (1.0, 0.0)] {
            // Same terms summed in another order: equal up to rounding.
            assert!((s.eval(u, v) - t.eval(v, u)).length() < 1e-15);
        }
    }

    #[test]
    fn eval_clamps_outside_the_domain() {
        let s = crate::geom::nurbs::shapes::torus(2.0, 0.5).unwrap();
        assert_eq!(s.eval(-1.0, 2.0), s.eval(0.0, 1.0));
        assert!(s.eval(f64::NAN, 0.5).is_nan());
    }

    #[test]
    fn transform_is_exact_for_the_torus() {
        let mut s = crate::geom::nurbs::shapes::torus(2.0, 0.5).unwrap();
        let m = glam::DAffine3::from_translation(DVec3::new(1.0, -2.0, 3.0));
        let before = s.eval(0.3, 0.6);
        s.transform(&m);
        assert!((s.eval(0.3, 0.6) - (before + DVec3::new(1.0, -2.0, 3.0))).length() < 1e-14);
    }
}
