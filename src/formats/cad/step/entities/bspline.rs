//! What B-spline curves and surfaces share: knots listed with their multiplicities or
//! implied by the entity's form (ISO 10303-42 §4.3.4), and control points weighted.

use glam::{DVec3, DVec4};

use super::{Rec, Resolver};
use crate::formats::cad::step::records::{Instance, Param};
use crate::formats::error::ParseError;

/// Premultiplied homogeneous points `(w x, w y, w z, w)`.
pub(super) fn homogeneous(points: &[DVec3], weights: &[f64]) -> Vec<DVec4> {
    points
        .iter()
        .zip(weights)
        .map(|(p, &w)| (*p * w).extend(w))
        .collect()
}

/// Expands B-spline knots given as distinct values and multiplicities.
pub(super) fn expand_knots(r: &Rec, mult: &Param, knots: &Param) -> Result<Vec<f64>, ParseError> {
    let m = r.list_of(mult, "knot multiplicities")?;
    let k = r.numbers(knots, "knots")?;
    if m.len() != k.len() {
        return Err(r.error_at(
            mult.line,
            mult.column,
            format!(
                "expected as many knot multiplicities as knots, found {} and {}",
                m.len(),
                k.len()
            ),
        ));
    }
    let mut out = Vec::new();
    for (p, &t) in m.iter().zip(&k) {
        let times = r.integer(p, "a knot multiplicity")?;
        if !(1..=64).contains(&times) {
            return Err(r.error_at(
                p.line,
                p.column,
                format!("expected a knot multiplicity in 1..=64, found {times}"),
            ));
        }
        out.extend(std::iter::repeat_n(t, times as usize));
    }
    Ok(out)
}

/// The curve entities whose knots are implied, in [`ImpliedKnots`] order.
pub(super) const CURVE_FORMS: [&str; 3] = ["BEZIER_CURVE", "UNIFORM_CURVE", "QUASI_UNIFORM_CURVE"];
/// The surface entities whose knots are implied, in [`ImpliedKnots`] order.
pub(super) const SURFACE_FORMS: [&str; 3] =
    ["BEZIER_SURFACE", "UNIFORM_SURFACE", "QUASI_UNIFORM_SURFACE"];

/// B-spline forms whose knots are implied rather than listed (ISO 10303-42 §4.3.4:
/// bezier_curve, uniform_curve, quasi_uniform_curve and their surface counterparts).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum ImpliedKnots {
    Bezier,
    Uniform,
    QuasiUniform,
}

impl ImpliedKnots {
    /// The form an instance declares by one of its records (the simple entity's name or a
    /// partial record of a complex instance), if any; `names` are the entity names of
    /// the three forms, [`CURVE_FORMS`] or [`SURFACE_FORMS`].
    pub(super) fn of(inst: &Instance, names: [&str; 3]) -> Option<ImpliedKnots> {
        let forms = [
            ImpliedKnots::Bezier,
            ImpliedKnots::Uniform,
            ImpliedKnots::QuasiUniform,
        ];
        names
            .iter()
            .zip(forms)
            .find(|(name, _)| inst.record(name).is_some())
            .map(|(_, k)| k)
    }

    /// The knots for `count` control points of degree `degree`; `None` when the count
    /// does not fit the form (a Bézier needs a multiple of the degree plus one).
    /// - bezier: 0 and the last breakpoint repeated `degree + 1` times, the integers
    ///   between `degree` times (a piecewise Bézier);
    /// - uniform: −degree, −degree + 1, …, count (every knot simple), so the domain is
    ///   [0, count − degree];
    /// - quasi-uniform: 0 and count − degree repeated `degree + 1` times, the integers
    ///   between once (clamped ends, uniform inside).
    pub(super) fn knots(self, degree: usize, count: usize) -> Option<Vec<f64>> {
        if degree == 0 || count < degree + 1 {
            return None;
        }
        match self {
            ImpliedKnots::Bezier => {
                if !(count - 1).is_multiple_of(degree) {
                    return None;
                }
                let pieces = (count - 1) / degree;
                let mut k = vec![0.0; degree + 1];
                for s in 1..pieces {
                    k.extend(std::iter::repeat_n(s as f64, degree));
                }
                k.extend(std::iter::repeat_n(pieces as f64, degree + 1));
                Some(k)
            }
            ImpliedKnots::Uniform => Some(
                (0..count + degree + 1)
                    .map(|i| i as f64 - degree as f64)
                    .collect(),
            ),
            ImpliedKnots::QuasiUniform => {
                let last = (count - degree) as f64;
                let mut k = vec![0.0; degree + 1];
                k.extend((1..count - degree).map(|i| i as f64));
                k.extend(std::iter::repeat_n(last, degree + 1));
                Some(k)
            }
        }
    }
}

impl<'e, 'a> Resolver<'e, 'a> {
    /// Weights of a rational complex instance (`RATIONAL_B_SPLINE_CURVE((w…))` or the
    /// surface form, a list of lists), if present.
    pub(super) fn weights<'r>(&'r self, inst: &'r Instance<'a>, name: &str) -> Option<Rec<'r, 'a>> {
        self.named(inst, name)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn implied_knots_follow_iso_42() {
        let bezier = |d, n| ImpliedKnots::Bezier.knots(d, n);
        assert_eq!(bezier(3, 4).unwrap(), [0., 0., 0., 0., 1., 1., 1., 1.]);
        assert_eq!(bezier(2, 5).unwrap(), [0., 0., 0., 1., 1., 2., 2., 2.]);
        assert!(bezier(2, 4).is_none());
        // ISO 10303-42 §4.3.4: uniform knots run from −degree by 1, quasi-uniform ones are
        // clamped (degree + 1 at each end) with unit steps between.
        assert_eq!(
            ImpliedKnots::Uniform.knots(2, 4).unwrap(),
            [-2., -1., 0., 1., 2., 3., 4.]
        );
        assert_eq!(
            ImpliedKnots::QuasiUniform.knots(2, 5).unwrap(),
            [0., 0., 0., 1., 2., 3., 3., 3.]
        );
        assert_eq!(
            ImpliedKnots::QuasiUniform.knots(3, 4).unwrap(),
            [0., 0., 0., 0., 1., 1., 1., 1.]
        );
        assert!(ImpliedKnots::Uniform.knots(3, 3).is_none());
    }
}
