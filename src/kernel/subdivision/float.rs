//! The scalar type the subdivision search runs in: `f32` for the kernel, `f64` for the
//! accuracy reference (Dammertz §2.3.4 compares against "the complete algorithm above
//! implemented using double precision arithmetic"). The trait adds to [`Real`] what the
//! search needs: neighbours of a float, ulp distances, and the robust ray–box slab test.

use glam::{DVec3, Vec3, Vec3A};

use crate::geom::bbox::slab;
use crate::geom::real::Real;
use crate::geom::ulp::ulp_distance;
use crate::geom::{Aabb, DAabb};

/// A floating-point type the subdivision search can run in.
pub trait KernelFloat: Real {
    const INFINITY: Self;
    /// How often a parameter interval may be halved per direction; see
    /// [`super::param::ParamCell`] for why this bounds the work without costing accuracy.
    const MAX_LEVEL: u8;
    fn min(self, other: Self) -> Self;
    fn max(self, other: Self) -> Self;
    fn next_up(self) -> Self;
    fn next_down(self) -> Self;
    /// Number of representable values between `a` and `b` (Dammertz's mantissa distance).
    fn ulp_distance(a: Self, b: Self) -> u64;
    /// The robust slab test of [`Aabb::intersect`] in this precision: the entry and exit
    /// parameters of `origin + t dir` in the box, clipped to `[tmin, tmax]`.
    fn slab(b: &GBox<Self>, ray: &GRay<Self>, tmax: Self) -> Option<(Self, Self)>;
}

impl KernelFloat for f32 {
    const INFINITY: Self = f32::INFINITY;
    /// 24 mantissa bits and 8 bits of headroom (see `ParamCell`).
    const MAX_LEVEL: u8 = 32;
    #[inline(always)]
    fn min(self, other: Self) -> Self {
        f32::min(self, other)
    }
    #[inline(always)]
    fn max(self, other: Self) -> Self {
        f32::max(self, other)
    }
    #[inline(always)]
    fn next_up(self) -> Self {
        f32::next_up(self)
    }
    #[inline(always)]
    fn next_down(self) -> Self {
        f32::next_down(self)
    }
    #[inline(always)]
    fn ulp_distance(a: Self, b: Self) -> u64 {
        ulp_distance(a, b) as u64
    }
    #[inline(always)]
    fn slab(b: &GBox<f32>, ray: &GRay<f32>, tmax: f32) -> Option<(f32, f32)> {
        slab(
            Vec3A::from_array(b.min),
            Vec3A::from_array(b.max),
            Vec3A::from_array(ray.origin),
            Vec3A::from_array(ray.inv_dir),
            ray.tmin,
            tmax,
        )
    }
}

impl KernelFloat for f64 {
    const INFINITY: Self = f64::INFINITY;
    /// 53 mantissa bits and 8 bits of headroom, the most a `u64` fixed-point cell holds.
    const MAX_LEVEL: u8 = 61;
    #[inline(always)]
    fn min(self, other: Self) -> Self {
        f64::min(self, other)
    }
    #[inline(always)]
    fn max(self, other: Self) -> Self {
        f64::max(self, other)
    }
    #[inline(always)]
    fn next_up(self) -> Self {
        f64::next_up(self)
    }
    #[inline(always)]
    fn next_down(self) -> Self {
        f64::next_down(self)
    }
    fn ulp_distance(a: Self, b: Self) -> u64 {
        fn ordered(x: f64) -> i128 {
            let bits = x.to_bits() as i64;
            (if bits < 0 {
                i64::MIN.wrapping_sub(bits)
            } else {
                bits
            }) as i128
        }
        (ordered(a) - ordered(b))
            .unsigned_abs()
            .min(u64::MAX as u128) as u64
    }
    fn slab(b: &GBox<f64>, ray: &GRay<f64>, tmax: f64) -> Option<(f64, f64)> {
        let b = DAabb {
            min: DVec3::from_array(b.min),
            max: DVec3::from_array(b.max),
        };
        let (o, inv) = (
            DVec3::from_array(ray.origin),
            DVec3::from_array(ray.inv_dir),
        );
        b.intersect(o, inv, ray.tmin, tmax)
    }
}

/// An axis-aligned box in either precision.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GBox<T> {
    pub min: [T; 3],
    pub max: [T; 3],
}

impl<T: KernelFloat> GBox<T> {
    /// Sum of the edge lengths, the diameter whose shrinking Dammertz watches (code 2.3.8).
    #[inline(always)]
    pub fn l1_diameter(&self) -> T {
        (self.max[0] - self.min[0]) + (self.max[1] - self.min[1]) + (self.max[2] - self.min[2])
    }

    /// True when every coordinate's bounds are fewer than `dist` ulps apart (§2.7.2,
    /// code 2.7.1; across a sign change the distance is large, as Dammertz requires).
    pub fn mantissa_close(&self, dist: u32) -> bool {
        (0..3).all(|i| T::ulp_distance(self.min[i], self.max[i]) < dist as u64)
    }
}

impl GBox<f32> {
    #[inline(always)]
    pub fn from_aabb(b: Aabb) -> Self {
        GBox {
            min: b.min.to_array(),
            max: b.max.to_array(),
        }
    }

    #[inline(always)]
    pub fn to_aabb(self) -> Aabb {
        Aabb::new(Vec3::from_array(self.min), Vec3::from_array(self.max))
    }
}

impl GBox<f64> {
    pub fn to_daabb(self) -> DAabb {
        DAabb {
            min: DVec3::from_array(self.min),
            max: DVec3::from_array(self.max),
        }
    }
}

/// A ray with its reciprocal direction, in either precision.
#[derive(Clone, Copy, Debug)]
pub struct GRay<T> {
    pub origin: [T; 3],
    pub dir: [T; 3],
    pub inv_dir: [T; 3],
    pub tmin: T,
    pub tmax: T,
}

impl<T: KernelFloat> GRay<T> {
    pub fn new(origin: [T; 3], dir: [T; 3], tmin: T, tmax: T) -> Self {
        GRay {
            origin,
            dir,
            inv_dir: dir.map(|d| T::ONE / d),
            tmin,
            tmax,
        }
    }
}
