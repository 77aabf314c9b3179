//! Outward rounding checked against exact dyadic arithmetic: every `f64` is `m · 2^e` with
//! an integer `m`, so sums and products of `f64`s are exact in `i128` when the exponents
//! stay close, and an enclosure is correct exactly when its ends bracket that value.

use super::*;
use proptest::prelude::*;
use std::cmp::Ordering;

/// An exact dyadic rational `m · 2^e`.
#[derive(Clone, Copy, Debug)]
struct Dyadic {
    m: i128,
    e: i32,
}

impl Dyadic {
    fn of(x: f64) -> Dyadic {
        assert!(x.is_finite());
        let bits = x.to_bits();
        let sign = if bits >> 63 == 1 { -1 } else { 1 };
        let exp = ((bits >> 52) & 0x7ff) as i32;
        let frac = (bits & ((1u64 << 52) - 1)) as i128;
        let (m, e) = if exp == 0 {
            (frac, -1074)
        } else {
            (frac | (1i128 << 52), exp - 1075)
        };
        Dyadic { m: sign * m, e }
    }

    /// Both numbers over the common denominator `2^min(e)`.
    fn aligned(a: Dyadic, b: Dyadic) -> (i128, i128, i32) {
        // Zero has any exponent: take the other number's.
        if a.m == 0 || b.m == 0 {
            let e = if a.m == 0 { b.e } else { a.e };
            return (a.m, b.m, e);
        }
        let e = a.e.min(b.e);
        let shift = |d: Dyadic| {
            let s = (d.e - e) as u32;
            assert!(
                s < 127 && d.m.unsigned_abs().leading_zeros() > s + 1,
                "shift overflows"
            );
            d.m << s
        };
        (shift(a), shift(b), e)
    }

    fn add(a: Dyadic, b: Dyadic) -> Dyadic {
        let (x, y, e) = Dyadic::aligned(a, b);
        Dyadic { m: x + y, e }
    }

    fn neg(self) -> Dyadic {
        Dyadic {
            m: -self.m,
            e: self.e,
        }
    }

    fn mul(a: Dyadic, b: Dyadic) -> Dyadic {
        Dyadic {
            m: a.m.checked_mul(b.m).expect("product fits"),
            e: a.e + b.e,
        }
    }

    /// Position of the leading bit of `|m| · 2^e` (`None` for zero).
    fn top_bit(self) -> Option<i32> {
        (self.m != 0).then(|| 128 - self.m.unsigned_abs().leading_zeros() as i32 + self.e)
    }

    /// Exact order. Numbers of one sign whose leading bits differ are ordered by those
    /// bits alone, so only numbers of similar magnitude are aligned (a product's 106-bit
    /// mantissa beside a far smaller bound would overflow `i128` when shifted).
    fn cmp(a: Dyadic, b: Dyadic) -> Ordering {
        let sign = a.m.signum().cmp(&b.m.signum());
        if sign != Ordering::Equal || a.m == 0 {
            return sign;
        }
        match a.top_bit().cmp(&b.top_bit()) {
            Ordering::Equal => {
                let (x, y, _) = Dyadic::aligned(a, b);
                x.cmp(&y)
            }
            by_magnitude if a.m > 0 => by_magnitude,
            by_magnitude => by_magnitude.reverse(),
        }
    }
}

/// True when `iv` contains the exact value `x`.
fn brackets(iv: Interval, x: Dyadic) -> bool {
    Dyadic::cmp(Dyadic::of(iv.lo()), x) != Ordering::Greater
        && Dyadic::cmp(x, Dyadic::of(iv.hi())) != Ordering::Greater
}

/// `f64`s with full 53-bit mantissas and exponents in [-4, 4], so that exact sums and
/// products of two of them fit the `i128` alignment above.
fn dyadic_f64() -> impl Strategy<Value = f64> {
    (any::<bool>(), 0u64..(1 << 52), -4i32..=4).prop_map(|(neg, frac, exp)| {
        let x = f64::from_bits(((exp + 1023) as u64) << 52 | frac);
        if neg { -x } else { x }
    })
}

fn interval() -> impl Strategy<Value = Interval> {
    (dyadic_f64(), dyadic_f64()).prop_map(|(a, b)| Interval::spanning(a, b))
}

/// The four corner combinations of two intervals' ends.
fn corners(a: Interval, b: Interval) -> [(f64, f64); 4] {
    [
        (a.lo(), b.lo()),
        (a.lo(), b.hi()),
        (a.hi(), b.lo()),
        (a.hi(), b.hi()),
    ]
}

proptest! {
    #[test]
    fn sum_and_difference_enclose_the_exact_values(a in interval(), b in interval()) {
        let (s, d) = (a + b, a - b);
        for (x, y) in corners(a, b) {
            let (dx, dy) = (Dyadic::of(x), Dyadic::of(y));
            prop_assert!(brackets(s, Dyadic::add(dx, dy)), "{x} + {y} outside {s:?}");
            prop_assert!(brackets(d, Dyadic::add(dx, dy.neg())), "{x} - {y} outside {d:?}");
        }
    }

    #[test]
    fn product_and_square_enclose_the_exact_values(a in interval(), b in interval()) {
        let p = a * b;
        for (x, y) in corners(a, b) {
            let exact = Dyadic::mul(Dyadic::of(x), Dyadic::of(y));
            prop_assert!(brackets(p, exact), "{x} * {y} outside {p:?}");
        }
        let sq = a.square();
        for x in [a.lo(), a.hi(), a.mid()] {
            prop_assert!(brackets(sq, Dyadic::mul(Dyadic::of(x), Dyadic::of(x))));
        }
        prop_assert!(sq.lo() >= 0.0);
        let scaled = a * b.lo();
        for x in [a.lo(), a.hi()] {
            prop_assert!(brackets(scaled, Dyadic::mul(Dyadic::of(x), Dyadic::of(b.lo()))));
        }
    }

    /// `q` encloses `x / y` (y > 0) exactly when `q.lo · y <= x <= q.hi · y`.
    #[test]
    fn quotient_encloses_the_exact_value(a in interval(), b in interval()) {
        let b = Interval::new(b.lo().abs().min(b.hi().abs()), b.mag()).unwrap();
        let q = a.checked_div(b).expect("divisor excludes 0");
        for (x, y) in corners(a, b) {
            let (dx, dy) = (Dyadic::of(x), Dyadic::of(y));
            let lo = Dyadic::mul(Dyadic::of(q.lo()), dy);
            let hi = Dyadic::mul(Dyadic::of(q.hi()), dy);
            prop_assert!(Dyadic::cmp(lo, dx) != Ordering::Greater, "{x} / {y} below {q:?}");
            prop_assert!(Dyadic::cmp(dx, hi) != Ordering::Greater, "{x} / {y} above {q:?}");
        }
    }

    /// The lerp of de Casteljau holds the exact `(1 - t) a + t b` for `t` at the ends of
    /// its interval.
    #[test]
    fn lerp_encloses_the_exact_value(a in dyadic_f64(), b in dyadic_f64(), k in 0u32..=16) {
        let t = k as f64 / 16.0;
        let r = Interval::lerp(Interval::point(a), Interval::point(b), Interval::point(t));
        let one_minus_t = Dyadic::of(1.0 - t); // exact: t is a multiple of 1/16
        let exact = Dyadic::add(
            Dyadic::mul(one_minus_t, Dyadic::of(a)),
            Dyadic::mul(Dyadic::of(t), Dyadic::of(b)),
        );
        prop_assert!(brackets(r, exact));
    }
}

#[test]
fn inexact_sum_is_widened_on_both_sides() {
    // 1 + 2^-60 is not representable: round-to-nearest gives 1, and the enclosure must
    // reach above 1 to hold the exact sum.
    let s = Interval::point(1.0) + Interval::point(2f64.powi(-60));
    assert!(s.lo() < 1.0 && s.hi() > 1.0);
}

#[test]
fn division_by_an_interval_holding_zero_is_refused() {
    let a = Interval::point(1.0);
    assert!(a.checked_div(Interval::new(-1.0, 2.0).unwrap()).is_none());
    assert!(a.checked_div(Interval::point(0.0)).is_none());
}

#[test]
fn hull_intersection_and_subsets() {
    let a = Interval::new(0.0, 2.0).unwrap();
    let b = Interval::new(1.0, 3.0).unwrap();
    assert_eq!(a.hull(b), Interval::new(0.0, 3.0).unwrap());
    assert_eq!(a.intersect(b), Interval::new(1.0, 2.0));
    assert_eq!(a.intersect(Interval::point(5.0)), None);
    assert!(Interval::new(0.5, 1.5).unwrap().is_interior_of(a));
    assert!(!a.is_interior_of(a) && a.is_subset_of(a));
    assert!(Interval::new(2.0, 1.0).is_none() && Interval::new(f64::NAN, 1.0).is_none());
    assert_eq!(a.mid(), 1.0);
    assert!(a.width() >= 2.0);
}
