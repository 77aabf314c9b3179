//! B-spline basis functions by the Cox–de Boor recurrence (Piegl & Tiller, *The NURBS
//! Book*, A2.1 FindSpan and A2.2 BasisFuns), in `f64`.

use crate::geom::MAX_DEGREE;

/// The non-zero basis values of one span: entry `r` is `N[span - p + r, p]`.
pub type SpanBasis = [f64; MAX_DEGREE + 1];

/// A2.1 FindSpan: the span index `i` in `p..n` with `knots[i] <= t < knots[i + 1]`, found by
/// binary search. Parameters outside the domain use the first or last non-empty span, so
/// `t = knots[n]` gets the limit from the left; NaN gets the first span.
pub fn find_span(degree: usize, knots: &[f64], t: f64) -> usize {
    let count = knots.len() - degree - 1;
    let (start, end) = (knots[degree], knots[count]);
    if t >= end {
        // The last index whose knot is below the end: the last non-empty span.
        return knots.partition_point(|&k| k < end) - 1;
    }
    let t = if t > start { t } else { start };
    knots.partition_point(|&k| k <= t) - 1
}

/// A2.2 BasisFuns: the `p + 1` basis functions that are non-zero on `span`, at `t`.
/// The triangular scheme only divides by sums of knot differences of a non-empty span,
/// which are positive.
pub fn basis_funs(degree: usize, knots: &[f64], span: usize, t: f64) -> SpanBasis {
    let mut n = [0.0; MAX_DEGREE + 1];
    let mut left = [0.0; MAX_DEGREE + 1];
    let mut right = [0.0; MAX_DEGREE + 1];
    n[0] = 1.0;
    for j in 1..=degree {
        left[j] = t - knots[span + 1 - j];
        right[j] = knots[span + j] - t;
        let mut saved = 0.0;
        for r in 0..j {
            let temp = n[r] / (right[r + 1] + left[j - r]);
            n[r] = saved + right[r + 1] * temp;
            saved = left[j - r] * temp;
        }
        n[j] = saved;
    }
    n
}

/// The span of `t` and its basis values, with `t` clamped into the domain first (outside
/// it the basis no longer sums to one).
pub fn span_basis(degree: usize, knots: &[f64], t: f64) -> (usize, SpanBasis) {
    let (start, end) = super::knots::domain(degree, knots);
    let t = t.clamp(start, end);
    let span = find_span(degree, knots, t);
    (span, basis_funs(degree, knots, span, t))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::nurbs::testutil::knot_vector;
    use proptest::prelude::*;

    /// The degree-p Bernstein polynomials, the basis of the Bézier knot vector.
    fn bernstein(p: usize, t: f64) -> Vec<f64> {
        let binom =
            |n: usize, k: usize| (0..k).fold(1.0, |b, i| b * (n - i) as f64 / (i + 1) as f64);
        (0..=p)
            .map(|i| binom(p, i) * t.powi(i as i32) * (1.0 - t).powi((p - i) as i32))
            .collect()
    }

    #[test]
    fn find_span_at_knots_and_ends() {
        let k = [0., 0., 0., 0.5, 0.5, 1., 1., 1.];
        assert_eq!(find_span(2, &k, 0.0), 2);
        assert_eq!(find_span(2, &k, 0.25), 2);
        assert_eq!(find_span(2, &k, 0.5), 4);
        assert_eq!(find_span(2, &k, 1.0), 4);
        assert_eq!(find_span(2, &k, f64::NAN), 2);
    }

    proptest! {
        #[test]
        fn bezier_knots_give_bernstein(p in 1usize..=MAX_DEGREE, t in 0.0..=1.0f64) {
            let knots: Vec<f64> = [vec![0.0; p + 1], vec![1.0; p + 1]].concat();
            let (span, n) = span_basis(p, &knots, t);
            prop_assert_eq!(span, p);
            for (a, b) in n.iter().zip(bernstein(p, t)) {
                prop_assert!((a - b).abs() <= 1e-14, "{} vs {}", a, b);
            }
        }

        #[test]
        fn partition_of_unity(
            (p, knots) in (1usize..=5, any::<bool>()).prop_flat_map(|(p, c)| (Just(p), knot_vector(p, c))),
            t in 0.0..=1.0f64,
        ) {
            let (_, n) = span_basis(p, &knots, t);
            prop_assert!(n[..=p].iter().all(|&x| x >= 0.0));
            prop_assert!(n[p + 1..].iter().all(|&x| x == 0.0));
            prop_assert!((n.iter().sum::<f64>() - 1.0).abs() <= 1e-14);
        }
    }
}
