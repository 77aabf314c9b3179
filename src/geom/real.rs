//! A minimal scalar trait so that de Casteljau code is written once for `f32` and `f64`.

use std::ops::{Add, Div, Mul, Neg, Sub};

/// The floating-point operations the geometry code needs, for `f32` and `f64`.
pub trait Real:
    Copy
    + PartialOrd
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
    + std::fmt::Debug
{
    const ZERO: Self;
    const ONE: Self;
    const HALF: Self;
    fn from_f64(x: f64) -> Self;
    fn to_f64(self) -> f64;
}

impl Real for f32 {
    const ZERO: Self = 0.0;
    const ONE: Self = 1.0;
    const HALF: Self = 0.5;
    fn from_f64(x: f64) -> Self {
        x as f32
    }
    fn to_f64(self) -> f64 {
        self as f64
    }
}

impl Real for f64 {
    const ZERO: Self = 0.0;
    const ONE: Self = 1.0;
    const HALF: Self = 0.5;
    fn from_f64(x: f64) -> Self {
        x
    }
    fn to_f64(self) -> f64 {
        self
    }
}

/// Linear interpolation `a + t (b - a)` written as `(1 - t) a + t b`, which is exact at
/// both ends and symmetric, so a split at 1/2 gives bit-identical shared edges.
#[inline(always)]
pub fn lerp<T: Real>(a: T, b: T, t: T) -> T {
    (T::ONE - t) * a + t * b
}
