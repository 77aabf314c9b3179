//! Interval arithmetic in `f64`, rounded outward: every operation computes its end points
//! in round-to-nearest and then moves the lower end one representable value down
//! (`next_down`) and the upper end one up (`next_up`). A correctly rounded result is within
//! half an ulp of the exact one, so the widened interval always contains the exact result
//! of the operation on any reals inside the operands (inclusion monotonicity, Moore,
//! *Interval Analysis*, 1966). This is what Toth's method needs from interval analysis
//! (Toth 1985; Lischinski & Gonczarowski 1990, §4.1): rigorous bounds of a patch and of its
//! partial derivatives over a box of parameter space ([`bezier`]).
//!
//! Division by an interval that contains 0 is refused ([`Interval::checked_div`] returns
//! `None`) rather than answered with the whole line: every caller has a better fallback.

pub mod bezier;

pub use bezier::{
    IPoint, IntervalNet, ParamBox, enclose_derivatives, enclose_patch, euclidean_hull,
};

use std::ops::{Add, Mul, Neg, Sub};

/// A closed interval `[lo, hi]` of reals with `lo <= hi`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Interval {
    lo: f64,
    hi: f64,
}

impl Interval {
    /// The whole real line: the enclosure of a value nothing is known about.
    pub const ENTIRE: Interval = Interval {
        lo: f64::NEG_INFINITY,
        hi: f64::INFINITY,
    };

    /// `[0, 1]`, the parameter range of a Bézier patch.
    pub const UNIT: Interval = Interval { lo: 0.0, hi: 1.0 };

    /// The degenerate interval `[x, x]`: an exact `f64` value.
    pub const fn point(x: f64) -> Interval {
        Interval { lo: x, hi: x }
    }

    /// `[lo, hi]`, or `None` when `lo > hi` or either end is NaN.
    pub fn new(lo: f64, hi: f64) -> Option<Interval> {
        (lo <= hi).then_some(Interval { lo, hi })
    }

    /// The smallest interval holding both `a` and `b`, in either order.
    pub fn spanning(a: f64, b: f64) -> Interval {
        Interval {
            lo: a.min(b),
            hi: a.max(b),
        }
    }

    /// Widens a round-to-nearest result `[lo, hi]` by one ulp on each side.
    #[inline(always)]
    fn outward(lo: f64, hi: f64) -> Interval {
        Interval {
            lo: lo.next_down(),
            hi: hi.next_up(),
        }
    }

    pub fn lo(self) -> f64 {
        self.lo
    }

    pub fn hi(self) -> f64 {
        self.hi
    }

    /// The midpoint, an `f64` inside the interval (not an enclosure).
    pub fn mid(self) -> f64 {
        // max/min rather than clamp: clamp panics on NaN ends.
        (0.5 * self.lo + 0.5 * self.hi).max(self.lo).min(self.hi)
    }

    /// An upper bound of `hi - lo`.
    pub fn width(self) -> f64 {
        (self.hi - self.lo).next_up()
    }

    /// The largest absolute value in the interval (Moore's magnitude).
    pub fn mag(self) -> f64 {
        self.lo.abs().max(self.hi.abs())
    }

    pub fn contains(self, x: f64) -> bool {
        self.lo <= x && x <= self.hi
    }

    /// True when `self` lies inside `other`.
    pub fn is_subset_of(self, other: Interval) -> bool {
        other.lo <= self.lo && self.hi <= other.hi
    }

    /// True when `self` lies strictly inside `other` (both ends).
    pub fn is_interior_of(self, other: Interval) -> bool {
        other.lo < self.lo && self.hi < other.hi
    }

    pub fn is_finite(self) -> bool {
        self.lo.is_finite() && self.hi.is_finite()
    }

    /// The smallest interval holding both.
    pub fn hull(self, o: Interval) -> Interval {
        Interval {
            lo: self.lo.min(o.lo),
            hi: self.hi.max(o.hi),
        }
    }

    /// The common part, or `None` when the intervals are disjoint.
    pub fn intersect(self, o: Interval) -> Option<Interval> {
        Interval::new(self.lo.max(o.lo), self.hi.min(o.hi))
    }

    /// `x²`, which unlike `x * x` is never negative.
    pub fn square(self) -> Interval {
        let (a, b) = (self.lo * self.lo, self.hi * self.hi);
        if self.contains(0.0) {
            Interval {
                lo: 0.0,
                hi: a.max(b).next_up(),
            }
        } else {
            Interval::outward(a.min(b), a.max(b))
        }
    }

    /// `self / o`, or `None` when `o` contains 0 (the quotient would be unbounded).
    pub fn checked_div(self, o: Interval) -> Option<Interval> {
        if o.contains(0.0) {
            return None;
        }
        let q = [
            self.lo / o.lo,
            self.lo / o.hi,
            self.hi / o.lo,
            self.hi / o.hi,
        ];
        Some(Interval::outward(min4(q), max4(q)))
    }

    /// The linear interpolation `(1 - t) a + t b` of de Casteljau's algorithm.
    #[inline(always)]
    pub fn lerp(a: Interval, b: Interval, t: Interval) -> Interval {
        (Interval::point(1.0) - t) * a + t * b
    }
}

fn min4(q: [f64; 4]) -> f64 {
    q[0].min(q[1]).min(q[2].min(q[3]))
}

fn max4(q: [f64; 4]) -> f64 {
    q[0].max(q[1]).max(q[2].max(q[3]))
}

impl Add for Interval {
    type Output = Interval;
    #[inline(always)]
    fn add(self, o: Interval) -> Interval {
        Interval::outward(self.lo + o.lo, self.hi + o.hi)
    }
}

impl Sub for Interval {
    type Output = Interval;
    #[inline(always)]
    fn sub(self, o: Interval) -> Interval {
        Interval::outward(self.lo - o.hi, self.hi - o.lo)
    }
}

impl Neg for Interval {
    type Output = Interval;
    #[inline(always)]
    fn neg(self) -> Interval {
        Interval {
            lo: -self.hi,
            hi: -self.lo,
        }
    }
}

impl Mul for Interval {
    type Output = Interval;
    #[inline(always)]
    fn mul(self, o: Interval) -> Interval {
        let q = [
            self.lo * o.lo,
            self.lo * o.hi,
            self.hi * o.lo,
            self.hi * o.hi,
        ];
        Interval::outward(min4(q), max4(q))
    }
}

impl Add<f64> for Interval {
    type Output = Interval;
    fn add(self, x: f64) -> Interval {
        self + Interval::point(x)
    }
}

impl Sub<f64> for Interval {
    type Output = Interval;
    fn sub(self, x: f64) -> Interval {
        self - Interval::point(x)
    }
}

impl Mul<f64> for Interval {
    type Output = Interval;
    fn mul(self, x: f64) -> Interval {
        let (a, b) = (self.lo * x, self.hi * x);
        Interval::outward(a.min(b), a.max(b))
    }
}

#[cfg(test)]
mod tests;
