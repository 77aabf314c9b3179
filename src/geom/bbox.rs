//! Axis-aligned bounding boxes in `f32` (for the kernels and accelerators) and `f64` (for
//! geometry processing), with a robust ray–box slab test.

use glam::{DVec3, Vec3, Vec3A};

/// Relative error bound of the slab test's `t` values: `(o - x) * inv` rounds twice and the
/// reciprocal once, so `t_far` is scaled by `1 + 2 γ(3)` with `γ(n) = n ε / (1 - n ε)`
/// (Ize, "Robust BVH Ray Traversal", JCGT 2013; pbrt-v3 §3.9.2). This keeps a ray that grazes
/// a box edge from slipping through between two adjacent boxes.
pub const SLAB_FAR_SCALE: f32 = 1.0 + 2.0 * gamma3_f32();

/// The same bound for `f64`.
const SLAB_FAR_SCALE_F64: f64 = 1.0 + 2.0 * gamma3_f64();

const fn gamma3_f64() -> f64 {
    let e = f64::EPSILON * 0.5;
    3.0 * e / (1.0 - 3.0 * e)
}

const fn gamma3_f32() -> f32 {
    let e = f32::EPSILON * 0.5;
    3.0 * e / (1.0 - 3.0 * e)
}

/// An axis-aligned box in `f32`. An empty box has `min > max`.
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
#[repr(C)]
pub struct Aabb {
    pub min: Vec3,
    pub max: Vec3,
}

impl Aabb {
    pub const EMPTY: Aabb = Aabb {
        min: Vec3::splat(f32::INFINITY),
        max: Vec3::splat(f32::NEG_INFINITY),
    };

    pub fn new(min: Vec3, max: Vec3) -> Self {
        Aabb { min, max }
    }

    pub fn is_empty(&self) -> bool {
        self.min.x > self.max.x || self.min.y > self.max.y || self.min.z > self.max.z
    }

    pub fn grow(&mut self, p: Vec3) {
        self.min = self.min.min(p);
        self.max = self.max.max(p);
    }

    pub fn union(&self, other: &Aabb) -> Aabb {
        Aabb {
            min: self.min.min(other.min),
            max: self.max.max(other.max),
        }
    }

    pub fn extent(&self) -> Vec3 {
        self.max - self.min
    }

    /// The same box in `f64` (exact: every `f32` is an `f64`).
    pub fn to_f64(&self) -> DAabb {
        DAabb {
            min: self.min.as_dvec3(),
            max: self.max.as_dvec3(),
        }
    }

    pub fn center(&self) -> Vec3 {
        (self.min + self.max) * 0.5
    }

    /// Sum of the edge lengths: the L1 diameter the subdivision kernel watches shrink
    /// (Dammertz §2.3.2).
    pub fn l1_diameter(&self) -> f32 {
        let e = self.extent();
        e.x + e.y + e.z
    }

    pub fn contains(&self, p: Vec3) -> bool {
        p.cmpge(self.min).all() && p.cmple(self.max).all()
    }

    /// Robust slab test: the parametric interval where `origin + t d` is inside the box,
    /// clipped to `[tmin, tmax]`, or `None`. `inv_dir` is `1 / d` per component (infinite
    /// for a zero component).
    #[inline(always)]
    pub fn intersect(
        &self,
        origin: Vec3,
        inv_dir: Vec3,
        tmin: f32,
        tmax: f32,
    ) -> Option<(f32, f32)> {
        slab(
            self.min.into(),
            self.max.into(),
            origin.into(),
            inv_dir.into(),
            tmin,
            tmax,
        )
    }
}

/// The slab test of [`Aabb::intersect`] on SIMD vectors (`Vec3A` is one SSE register), for
/// callers that keep their boxes and rays in that form (the subdivision kernel).
#[inline(always)]
pub fn slab(
    min: Vec3A,
    max: Vec3A,
    origin: Vec3A,
    inv_dir: Vec3A,
    tmin: f32,
    tmax: f32,
) -> Option<(f32, f32)> {
    let t0 = (min - origin) * inv_dir;
    let t1 = (max - origin) * inv_dir;
    // A zero direction component with the origin exactly on a slab plane gives
    // 0 * inf = NaN. The ray then lies in the plane, so that slab bounds nothing: NaN
    // must become -inf for the entry and +inf for the exit. (`min`/`max` alone would
    // pick the other, infinite operand and wrongly miss the box.)
    let nan = t0.is_nan_mask() | t1.is_nan_mask();
    let near = Vec3A::select(nan, Vec3A::NEG_INFINITY, t0.min(t1));
    let far = Vec3A::select(nan, Vec3A::INFINITY, t0.max(t1) * SLAB_FAR_SCALE);
    let t_enter = near.max_element().max(tmin);
    let t_exit = far.min_element().min(tmax);
    (t_enter <= t_exit).then_some((t_enter, t_exit))
}

/// An axis-aligned box in `f64`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DAabb {
    pub min: DVec3,
    pub max: DVec3,
}

/// Relative bound on the rounding of an affine map of a point in `f64`: 4 u for the three
/// products and the translation of each coordinate (Higham 2002 §3.1, γ₄ with u = 2⁻⁵³),
/// doubled so the sum of the magnitudes it multiplies, itself rounded, stays covered.
pub const AFFINE_ROUNDING: f64 = 8.0 * (f64::EPSILON / 2.0);

impl DAabb {
    pub const EMPTY: DAabb = DAabb {
        min: DVec3::splat(f64::INFINITY),
        max: DVec3::splat(f64::NEG_INFINITY),
    };

    pub fn is_empty(&self) -> bool {
        self.min.x > self.max.x || self.min.y > self.max.y || self.min.z > self.max.z
    }

    pub fn grow(&mut self, p: DVec3) {
        self.min = self.min.min(p);
        self.max = self.max.max(p);
    }

    pub fn union(&self, other: &DAabb) -> DAabb {
        DAabb {
            min: self.min.min(other.min),
            max: self.max.max(other.max),
        }
    }

    pub fn extent(&self) -> DVec3 {
        self.max - self.min
    }

    pub fn center(&self) -> DVec3 {
        (self.min + self.max) * 0.5
    }

    /// The slab test in `f64`, with the same treatment of rays lying in a slab plane and
    /// the same conservative exit scale as [`Aabb::intersect`]. The f64 kernel uses it.
    pub fn intersect(
        &self,
        origin: DVec3,
        inv_dir: DVec3,
        tmin: f64,
        tmax: f64,
    ) -> Option<(f64, f64)> {
        let t0 = (self.min - origin) * inv_dir;
        let t1 = (self.max - origin) * inv_dir;
        let nan = t0.is_nan_mask() | t1.is_nan_mask();
        let near = DVec3::select(nan, DVec3::NEG_INFINITY, t0.min(t1));
        let far = DVec3::select(nan, DVec3::INFINITY, t0.max(t1) * SLAB_FAR_SCALE_F64);
        let t_enter = near.max_element().max(tmin);
        let t_exit = far.min_element().min(tmax);
        (t_enter <= t_exit).then_some((t_enter, t_exit))
    }

    /// The box of this box's image under `m`: its eight corners mapped in `f64`, each
    /// grown by a bound on the rounding of that map ([`AFFINE_ROUNDING`] times the sum of
    /// the terms' magnitudes, Higham 2002 §3.1: a dot product of length 4 rounds by at
    /// most 4u of it), so the result holds the exact image of every point of the box.
    /// Empty stays empty.
    pub fn transformed(&self, m: &glam::DAffine3) -> DAabb {
        if self.is_empty() {
            return DAabb::EMPTY;
        }
        DAabb::of_mapped_points(
            (0..8).map(|k| {
                let pick = |bit: usize, lo: f64, hi: f64| if k & bit == 0 { lo } else { hi };
                DVec3::new(
                    pick(1, self.min.x, self.max.x),
                    pick(2, self.min.y, self.max.y),
                    pick(4, self.min.z, self.max.z),
                )
            }),
            m,
        )
    }

    /// The box of `points` mapped by `m` in `f64`, each grown by the bound on the map's
    /// rounding of [`DAabb::transformed`]: it holds their exact images.
    pub fn of_mapped_points(points: impl IntoIterator<Item = DVec3>, m: &glam::DAffine3) -> DAabb {
        let abs = glam::DMat3::from_cols(
            m.matrix3.x_axis.abs(),
            m.matrix3.y_axis.abs(),
            m.matrix3.z_axis.abs(),
        );
        let mut out = DAabb::EMPTY;
        for c in points {
            let p = m.transform_point3(c);
            let err = (abs * c.abs() + m.translation.abs()) * AFFINE_ROUNDING;
            out.grow(p - err);
            out.grow(p + err);
        }
        out
    }

    /// Length of the diagonal (0 for a point, NaN never: empty boxes give 0).
    pub fn diagonal(&self) -> f64 {
        if self.is_empty() {
            0.0
        } else {
            self.extent().length()
        }
    }

    /// The `f32` box that contains this one: each bound rounded outward, so that no point
    /// of the `f64` box falls outside it.
    pub fn to_f32_outward(&self) -> Aabb {
        fn down(x: f64) -> f32 {
            let y = x as f32;
            if (y as f64) > x { y.next_down() } else { y }
        }
        fn up(x: f64) -> f32 {
            let y = x as f32;
            if (y as f64) < x { y.next_up() } else { y }
        }
        Aabb {
            min: Vec3::new(down(self.min.x), down(self.min.y), down(self.min.z)),
            max: Vec3::new(up(self.max.x), up(self.max.y), up(self.max.z)),
        }
    }
}

impl FromIterator<DVec3> for DAabb {
    fn from_iter<I: IntoIterator<Item = DVec3>>(iter: I) -> Self {
        let mut b = DAabb::EMPTY;
        for p in iter {
            b.grow(p);
        }
        b
    }
}

impl FromIterator<Vec3> for Aabb {
    fn from_iter<I: IntoIterator<Item = Vec3>>(iter: I) -> Self {
        let mut b = Aabb::EMPTY;
        for p in iter {
            b.grow(p);
        }
        b
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn slab_test_hits_and_misses() {
        let b = Aabb::new(Vec3::splat(-1.0), Vec3::splat(1.0));
        let o = Vec3::new(0.0, 0.0, -5.0);
        let d = Vec3::new(0.0, 0.0, 1.0);
        let (t0, t1) = b.intersect(o, d.recip(), 0.0, f32::INFINITY).unwrap();
        assert_eq!(t0, 4.0);
        assert!((6.0..6.0001).contains(&t1));
        assert!(b.intersect(o, d.recip(), 0.0, 3.0).is_none());
        let off = Vec3::new(2.0, 0.0, -5.0);
        assert!(b.intersect(off, d.recip(), 0.0, f32::INFINITY).is_none());
    }

    #[test]
    fn ray_along_a_face_plane_counts_as_inside() {
        let b = Aabb::new(Vec3::splat(-1.0), Vec3::splat(1.0));
        let o = Vec3::new(1.0, 0.0, -5.0);
        let d = Vec3::new(0.0, 0.0, 1.0);
        assert!(b.intersect(o, d.recip(), 0.0, f32::INFINITY).is_some());
    }

    #[test]
    fn ray_in_a_face_plane_with_zero_direction_component_hits() {
        // Regression: origin.x == min.x and d.x == 0 gives 0 * inf = NaN in the x slab,
        // which min/max resolved to +inf, missing the box (a crack on shared edges).
        let b = Aabb::new(Vec3::new(0.0, -1.0, -1.0), Vec3::new(1.4, 1.0, 1.0));
        let o = Vec3::new(0.0, -8.0, 0.0);
        let d = Vec3::new(0.0, 1.0, 0.0);
        let (t0, _) = b.intersect(o, d.recip(), 0.0, f32::INFINITY).expect("hit");
        assert_eq!(t0, 7.0);
        let db = b.to_f64();
        let (t0, _) = db
            .intersect(o.as_dvec3(), d.as_dvec3().recip(), 0.0, f64::INFINITY)
            .expect("hit");
        assert_eq!(t0, 7.0);
    }

    #[test]
    fn outward_rounding_contains_the_f64_box() {
        let b = DAabb {
            min: DVec3::new(0.1, -0.3, 1e-9),
            max: DVec3::new(0.7, 1.0 / 3.0, 12345.678901),
        };
        let f = b.to_f32_outward();
        for i in 0..3 {
            assert!((f.min[i] as f64) <= b.min[i]);
            assert!((f.max[i] as f64) >= b.max[i]);
        }
    }
}
