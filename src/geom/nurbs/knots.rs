//! Knot vectors: validation, multiplicities, the parameter domain and its non-empty spans
//! (Piegl & Tiller, *The NURBS Book*, §2.2 and §3.2).
//!
//! A knot vector of a degree-`p` direction with `n` control points has `n + p + 1`
//! non-decreasing knots; the surface is defined on `[knots[p], knots[n]]`. It need not be
//! clamped (end knots repeated `p + 1` times): uniform and periodic vectors are accepted and
//! clamped by knot insertion before decomposition (see `insert.rs`).
//!
//! An interior knot may be repeated up to `p + 1` times. At multiplicity `p + 1` no basis
//! function spans the knot (The NURBS Book §2.2, property P2.2 and eq. 2.5): the curve
//! is two independent pieces there, which meet only if their end control points do. CAD
//! systems write such breaks (CATIA V4 IGES, piecewise Bézier data); the Bézier
//! decomposition cuts there as at any other breakpoint.

use thiserror::Error;

/// Why a knot vector (or a knot insertion into it) is invalid.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum KnotError {
    #[error("{count} control points are too few for degree {degree}: need at least {}", .degree + 1)]
    TooFewPoints { degree: usize, count: usize },
    #[error("expected {expected} knots (control points + degree + 1), found {found}")]
    Count { expected: usize, found: usize },
    #[error("knot {index} is not finite ({value})")]
    NonFinite { index: usize, value: f64 },
    #[error("knots decrease at index {index}: {value} follows {previous}")]
    Decreasing {
        index: usize,
        previous: f64,
        value: f64,
    },
    #[error(
        "interior knot {value} is repeated {multiplicity} times, more than degree + 1 = {}", .degree + 1
    )]
    InteriorMultiplicity {
        value: f64,
        multiplicity: usize,
        degree: usize,
    },
    #[error("end knot {value} is repeated {multiplicity} times, more than degree + 1 = {}", .degree + 1)]
    EndMultiplicity {
        value: f64,
        multiplicity: usize,
        degree: usize,
    },
    #[error("the parameter domain [knots[degree], knots[count]] = [{start}, {end}] is empty")]
    EmptyDomain { start: f64, end: f64 },
    #[error("cannot insert knot {t} outside the domain [{start}, {end}]")]
    OutsideDomain { t: f64, start: f64, end: f64 },
    #[error(
        "inserting knot {t} {times} times onto multiplicity {multiplicity} exceeds the degree {degree}"
    )]
    InsertMultiplicity {
        t: f64,
        times: usize,
        multiplicity: usize,
        degree: usize,
    },
}

/// Checks a knot vector for `count` control points of degree `degree` (already known to be
/// in `1..=MAX_DEGREE`).
pub fn validate(degree: usize, knots: &[f64], count: usize) -> Result<(), KnotError> {
    if count < degree + 1 {
        return Err(KnotError::TooFewPoints { degree, count });
    }
    let expected = count + degree + 1;
    if knots.len() != expected {
        return Err(KnotError::Count {
            expected,
            found: knots.len(),
        });
    }
    if let Some((index, &value)) = knots.iter().enumerate().find(|(_, k)| !k.is_finite()) {
        return Err(KnotError::NonFinite { index, value });
    }
    if let Some(index) = (1..knots.len()).find(|&i| knots[i] < knots[i - 1]) {
        return Err(KnotError::Decreasing {
            index,
            previous: knots[index - 1],
            value: knots[index],
        });
    }
    let (first, last) = (knots[0], knots[knots.len() - 1]);
    for run in knots.chunk_by(|a, b| a == b) {
        let (value, multiplicity) = (run[0], run.len());
        if value == first || value == last {
            if multiplicity > degree + 1 {
                return Err(KnotError::EndMultiplicity {
                    value,
                    multiplicity,
                    degree,
                });
            }
        } else if multiplicity > degree + 1 {
            return Err(KnotError::InteriorMultiplicity {
                value,
                multiplicity,
                degree,
            });
        }
    }
    let (start, end) = domain(degree, knots);
    if start >= end {
        return Err(KnotError::EmptyDomain { start, end });
    }
    Ok(())
}

/// Checks that `t` may be inserted `times` more times: inside the domain, and the resulting
/// multiplicity at most the degree (The NURBS Book, A5.1 precondition `s + r <= p`).
pub fn validate_insertion(
    degree: usize,
    knots: &[f64],
    t: f64,
    times: usize,
) -> Result<(), KnotError> {
    let (start, end) = domain(degree, knots);
    // Written so that NaN fails too.
    if !(t >= start && t <= end) {
        return Err(KnotError::OutsideDomain { t, start, end });
    }
    let multiplicity = multiplicity(knots, t);
    if multiplicity + times > degree {
        return Err(KnotError::InsertMultiplicity {
            t,
            times,
            multiplicity,
            degree,
        });
    }
    Ok(())
}

/// How many knots equal `t` exactly.
pub fn multiplicity(knots: &[f64], t: f64) -> usize {
    knots.iter().filter(|&&k| k == t).count()
}

/// The parameter domain `[knots[p], knots[n]]` on which the basis sums to one.
pub fn domain(degree: usize, knots: &[f64]) -> (f64, f64) {
    (knots[degree], knots[knots.len() - degree - 1])
}

/// True when both ends are repeated `degree + 1` times (the curve interpolates its end
/// control points).
pub fn is_clamped(degree: usize, knots: &[f64]) -> bool {
    let (start, end) = domain(degree, knots);
    knots[0] == start && knots[knots.len() - 1] == end
}

/// The clamped knot vector of a piecewise Bézier curve with the given breakpoints: the
/// end breakpoints repeated `degree + 1` times, interior ones `degree` times.
pub fn bezier_knots(breaks: &[f64], degree: usize) -> Vec<f64> {
    let last = breaks.len() - 1;
    breaks
        .iter()
        .enumerate()
        .flat_map(|(i, &b)| {
            let repeat = if i == 0 || i == last {
                degree + 1
            } else {
                degree
            };
            std::iter::repeat_n(b, repeat)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn accepts_clamped_uniform_and_interior_multiplicity() {
        assert!(validate(2, &[0., 0., 0., 0.5, 0.5, 1., 1., 1.], 5).is_ok());
        assert!(validate(3, &[0., 1., 2., 3., 4., 5., 6., 7.], 4).is_ok());
        // A break: interior multiplicity degree + 1.
        assert!(validate(1, &[0., 0., 1., 1., 2., 2.], 4).is_ok());
        assert!(matches!(
            validate(1, &[0., 0., 1., 1., 1., 2., 2.], 5),
            Err(KnotError::InteriorMultiplicity {
                multiplicity: 3,
                ..
            })
        ));
        assert!(is_clamped(2, &[0., 0., 0., 1., 1., 1.]));
        assert!(!is_clamped(3, &[0., 1., 2., 3., 4., 5., 6., 7.]));
        assert_eq!(domain(3, &[0., 1., 2., 3., 4., 5., 6., 7.]), (3.0, 4.0));
        assert_eq!(multiplicity(&[0., 0., 0., 0.5, 0.5, 1., 1., 1.], 0.5), 2);
    }

    #[test]
    fn rejects_empty_domain() {
        // Two equal knots are allowed inside for degree 2, but here they are the whole domain.
        let e = validate(2, &[0., 0.5, 1., 1., 2., 3.], 3).unwrap_err();
        assert_eq!(e, KnotError::EmptyDomain { start: 1., end: 1. });
    }

    #[test]
    fn insertion_limits() {
        let k = [0., 0., 0., 0.5, 1., 1., 1.];
        assert!(validate_insertion(2, &k, 0.5, 1).is_ok());
        assert!(matches!(
            validate_insertion(2, &k, 0.5, 2),
            Err(KnotError::InsertMultiplicity {
                multiplicity: 1,
                ..
            })
        ));
        assert!(matches!(
            validate_insertion(2, &k, 1.5, 1),
            Err(KnotError::OutsideDomain { .. })
        ));
        assert!(validate_insertion(2, &k, f64::NAN, 1).is_err());
    }
}
