//! The general path: patches of any degree up to 15 and rational patches (Dammertz §2.7),
//! in either precision. Control points are homogeneous `(w x, w y, w z, w)` so that a split
//! is the same de Casteljau step as for integral patches (§2.7.2); boxes are taken of the
//! projected points `x/w, y/w, z/w` (valid because the weights are positive) and rounded
//! outward with `next_down`/`next_up`, so a box contains the projection of its net in exact
//! arithmetic (the improvement Dammertz gets from directed rounding in code 2.7.3).
//!
//! Nets live in one reused scratch buffer of `2 · MAX_LEVEL + 2` slots: slot `k` holds
//! the net of stack entry `k`, the current net sits on top, and a split writes its children
//! into the top slot and the one above it.

use super::float::{GBox, GRay, KernelFloat};
use super::heuristics::Corners;
use super::param::Split;
use super::search::{NetStack, Node};

/// Shape of a control net: points per row (u) and per column (v), and whether it needs
/// the homogeneous division.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct NetShape {
    pub nu: usize,
    pub nv: usize,
    pub rational: bool,
}

impl NetShape {
    pub fn point_count(&self) -> usize {
        self.nu * self.nv
    }
}

/// Reusable buffers of one search: no allocation per ray once they have grown.
#[derive(Debug, Default)]
pub struct Scratch<T> {
    pub nets: Vec<[T; 4]>,
    pub nodes: Vec<Node<T>>,
}

/// The box of a homogeneous net: exact for integral nets, rounded outward after the
/// division for rational ones. The rational test is hoisted out of the point loop and the
/// bounds grow by plain comparisons (control points are finite, so the NaN handling of
/// `min`/`max` is not needed): this loop is most of a split of a low-degree patch.
pub fn net_box<T: KernelFloat>(net: &[[T; 4]], rational: bool) -> GBox<T> {
    let mut b = GBox {
        min: [T::INFINITY; 3],
        max: [-T::INFINITY; 3],
    };
    let mut grow = |c: usize, lo: T, hi: T| {
        if lo < b.min[c] {
            b.min[c] = lo;
        }
        if hi > b.max[c] {
            b.max[c] = hi;
        }
    };
    if rational {
        for p in net {
            for c in 0..3 {
                let x = p[c] / p[3];
                grow(c, x.next_down(), x.next_up());
            }
        }
    } else {
        for p in net {
            for c in 0..3 {
                grow(c, p[c], p[c]);
            }
        }
    }
    b
}

/// Splits the curve of `n` points at `stride` apart in `net` at 1/2: the lower half stays
/// in `net`, the upper half goes to `upper`. Same operations, in the same order, as
/// `geom::bezier::split_curve_half`, so the `f64` path splits bit-identically.
fn split_curve<T: KernelFloat>(
    net: &mut [[T; 4]],
    upper: &mut [[T; 4]],
    start: usize,
    stride: usize,
    n: usize,
) {
    let at = |i: usize| start + i * stride;
    for i in 0..n {
        upper[at(i)] = net[at(i)];
    }
    for k in 0..n {
        net[at(k)] = upper[at(0)];
        for i in 0..n - 1 - k {
            let (a, b) = (upper[at(i)], upper[at(i + 1)]);
            upper[at(i)] = [0, 1, 2, 3].map(|c| (a[c] + b[c]) * T::HALF);
        }
    }
}

/// Splits a net in place at 1/2: lower child in `net`, upper child in `upper`.
pub fn split_net<T: KernelFloat>(
    net: &mut [[T; 4]],
    upper: &mut [[T; 4]],
    shape: NetShape,
    dir: Split,
) {
    match dir {
        Split::U => {
            for j in 0..shape.nv {
                split_curve(net, upper, j * shape.nu, 1, shape.nu);
            }
        }
        Split::V => {
            for i in 0..shape.nu {
                split_curve(net, upper, i, shape.nu, shape.nv);
            }
        }
    }
}

fn distance2<T: KernelFloat>(a: [T; 3], b: [T; 3]) -> T {
    (0..3).fold(T::ZERO, |acc, c| acc + (a[c] - b[c]) * (a[c] - b[c]))
}

/// The nets of a general-path search in the slots of a scratch buffer.
pub struct GeneralStack<'a, T> {
    pub nets: &'a mut [[T; 4]],
    pub shape: NetShape,
    /// Slot of the current net.
    pub top: usize,
}

impl<'a, T: KernelFloat> GeneralStack<'a, T> {
    /// Prepares `scratch` for `net` (growing it only the first time) and puts `net` in
    /// slot 0.
    pub fn new(scratch: &'a mut Vec<[T; 4]>, net: &[[T; 4]], shape: NetShape) -> Self {
        let n = shape.point_count();
        let need = (2 * T::MAX_LEVEL as usize + 2) * n;
        if scratch.len() < need {
            scratch.resize(need, [T::ZERO; 4]);
        }
        scratch[..n].copy_from_slice(net);
        GeneralStack {
            nets: scratch,
            shape,
            top: 0,
        }
    }

    fn slot(&self, k: usize) -> &[[T; 4]] {
        let n = self.shape.point_count();
        &self.nets[k * n..(k + 1) * n]
    }

    fn euclidean(&self, p: [T; 4]) -> [T; 3] {
        if self.shape.rational {
            [p[0] / p[3], p[1] / p[3], p[2] / p[3]]
        } else {
            [p[0], p[1], p[2]]
        }
    }
}

impl<T: KernelFloat> NetStack<T> for GeneralStack<'_, T> {
    /// Along each boundary edge from b(0,0), the farther of the edge's middle and last
    /// control points: a boundary that closes on itself (a full circle as one polynomial
    /// patch, as IGES and STEP writers store periodic surfaces) has its last point on its
    /// first, and measured by the corners alone the heuristic would never split across it,
    /// halving the other direction until the split budget ran out with boxes as wide as
    /// the circle (Dammertz's corner heuristic, §2.3.2, assumes open edges).
    fn corners(&self) -> Corners<T> {
        let net = self.slot(self.top);
        let s = self.shape;
        let p00 = self.euclidean(net[0]);
        let farther = |mid: usize, end: usize| {
            let (m, e) = (self.euclidean(net[mid]), self.euclidean(net[end]));
            if distance2(m, p00) > distance2(e, p00) {
                m
            } else {
                e
            }
        };
        Corners {
            p00,
            pn0: farther(s.nu / 2, s.nu - 1),
            p0m: farther(s.nv / 2 * s.nu, (s.nv - 1) * s.nu),
        }
    }

    fn split_test(&mut self, dir: Split, ray: &GRay<T>, tmax: T) -> [(GBox<T>, Option<T>); 2] {
        let n = self.shape.point_count();
        let (lower, upper) = self.nets[self.top * n..(self.top + 2) * n].split_at_mut(n);
        split_net(lower, upper, self.shape, dir);
        [lower, upper].map(|net| {
            let b = net_box(net, self.shape.rational);
            (b, T::slab(&b, ray, tmax).map(|(t, _)| t))
        })
    }

    fn push_far(&mut self, far_is_lower: bool) {
        // The pushed net must stay in the current slot and the continued one go above it.
        if !far_is_lower {
            let n = self.shape.point_count();
            let (lower, upper) = self.nets[self.top * n..(self.top + 2) * n].split_at_mut(n);
            lower.swap_with_slice(upper);
        }
        self.top += 1;
    }

    fn keep(&mut self, lower: bool) {
        if !lower {
            let n = self.shape.point_count();
            let k = self.top * n;
            self.nets.copy_within(k + n..k + 2 * n, k);
        }
    }

    fn pop(&mut self) {
        self.top -= 1;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::BezierPatch;
    use glam::DVec3;

    fn rational_patch() -> BezierPatch {
        let (du, dv) = (3, 2);
        let pts: Vec<DVec3> = (0..(du + 1) * (dv + 1))
            .map(|k| {
                let (i, j) = ((k % (du + 1)) as f64, (k / (du + 1)) as f64);
                DVec3::new(i + 0.1 * j * j, j - 0.2 * i, (i * 0.7 + j * 1.3).sin())
            })
            .collect();
        let w: Vec<f64> = (0..pts.len())
            .map(|k| 0.3 + (k as f64 * 0.77).fract() * 3.0)
            .collect();
        BezierPatch::from_weighted(du, dv, &pts, &w).unwrap()
    }

    fn net_of(p: &BezierPatch) -> Vec<[f64; 4]> {
        p.homogeneous_points()
            .iter()
            .map(|q| q.to_array())
            .collect()
    }

    #[test]
    fn f64_split_is_bit_identical_to_bezier_split() {
        let p = rational_patch();
        let shape = NetShape {
            nu: 4,
            nv: 3,
            rational: true,
        };
        for (dir, (lo, hi)) in [(Split::U, p.split_u()), (Split::V, p.split_v())] {
            let mut net = net_of(&p);
            let mut upper = vec![[0.0; 4]; net.len()];
            split_net(&mut net, &mut upper, shape, dir);
            assert_eq!(net, net_of(&lo));
            assert_eq!(upper, net_of(&hi));
        }
    }

    #[test]
    fn f32_split_matches_f64_within_rounding() {
        let p = rational_patch();
        let shape = NetShape {
            nu: 4,
            nv: 3,
            rational: true,
        };
        for (dir, (lo, hi)) in [(Split::U, p.split_u()), (Split::V, p.split_v())] {
            let mut net: Vec<[f32; 4]> = net_of(&p).iter().map(|q| q.map(|c| c as f32)).collect();
            let mut upper = vec![[0.0f32; 4]; net.len()];
            split_net(&mut net, &mut upper, shape, dir);
            for (got, want) in net
                .iter()
                .chain(&upper)
                .zip(net_of(&lo).iter().chain(&net_of(&hi)))
            {
                for c in 0..4 {
                    // Input rounding (½ ulp) plus one rounding per de Casteljau level (3),
                    // each at most ½ ulp of the largest magnitude involved.
                    let tol = 4.0 * crate::geom::ulp::ulp_of(want[c].abs().max(8.0) as f32);
                    assert!(
                        (got[c] as f64 - want[c]).abs() <= tol,
                        "{got:?} vs {want:?}"
                    );
                }
            }
        }
    }

    /// Bernstein sum of a curve in the xz-plane, in `f64`.
    fn bezier_xz(points: &[(f64, f64)], u: f64) -> (f64, f64) {
        let n = points.len() - 1;
        let binomial = |k: usize| (0..k).fold(1.0, |c, i| c * (n - i) as f64 / (i + 1) as f64);
        points
            .iter()
            .enumerate()
            .fold((0.0, 0.0), |(x, z), (k, p)| {
                let b = binomial(k) * u.powi(k as i32) * (1.0 - u).powi((n - k) as i32);
                (x + b * p.0, z + b * p.1)
            })
    }

    #[test]
    fn patch_whose_rows_close_on_themselves_is_split_across_them() {
        // A closed degree-6 curve (first point = last) swept along y: every row of the net
        // closes, so the corners of a u edge coincide. The hit must be the nearest
        // crossing of the curve, found here by bisection on the Bernstein sum, within the
        // normal split count (no budget reached, no box as wide as the curve reported).
        let mut curve: Vec<(f64, f64)> = (0..6)
            .map(|k| {
                let a = k as f64 * std::f64::consts::FRAC_PI_3;
                (2.0 * a.cos(), 2.0 * a.sin())
            })
            .collect();
        curve.push(curve[0]);
        let pts: Vec<DVec3> = [0.0, 1.0]
            .iter()
            .flat_map(|&y| curve.iter().map(move |&(x, z)| DVec3::new(x, y, z)))
            .collect();
        let patch = crate::kernel::subdivision::PreparedPatch::new(
            &BezierPatch::from_points(6, 1, &pts).unwrap(),
        );
        // The ray's height as the ray holds it (f32), so the crossing is of that ray.
        let z0 = 0.3f32 as f64;
        let crossings: Vec<f64> = (0..1000)
            .filter_map(|k| {
                let (mut a, mut b) = (k as f64 / 1000.0, (k + 1) as f64 / 1000.0);
                let f = |u| bezier_xz(&curve, u).1 - z0;
                if f(a) * f(b) > 0.0 {
                    return None;
                }
                for _ in 0..60 {
                    let m = 0.5 * (a + b);
                    if f(a) * f(m) <= 0.0 { b = m } else { a = m }
                }
                Some(bezier_xz(&curve, a).0)
            })
            .collect();
        let nearest_x = crossings.iter().cloned().fold(f64::INFINITY, f64::min);
        let ray = crate::geom::Ray::new(
            glam::Vec3::new(-10.0, 0.5, 0.3),
            glam::Vec3::new(1.0, 0.0, 0.0),
        );
        let mut stats = crate::kernel::KernelStats::default();
        let cfg = crate::kernel::subdivision::SubdivisionConfig::default();
        let hit = crate::kernel::subdivision::intersect(&patch, None, &ray, &cfg, &mut stats)
            .expect("the ray crosses the closed curve");
        // The exact crossing must lie in the final box, which the kernel widens outward by
        // a few ulps: allow those ulps and no more.
        let exact = DVec3::new(nearest_x, 0.5, z0);
        let (lo, hi) = (hit.hit_box.min.as_dvec3(), hit.hit_box.max.as_dvec3());
        let ulps = |c: f64| 4.0 * f32::EPSILON as f64 * c.abs().max(1.0);
        assert!(
            (0..3).all(|i| lo[i] - ulps(lo[i]) <= exact[i] && exact[i] <= hi[i] + ulps(hi[i])),
            "crossing {exact} outside the hit box {lo}..{hi}"
        );
        assert!(
            stats.splits < 1000,
            "{} splits: the closed direction was not split",
            stats.splits
        );
    }

    #[test]
    fn outward_box_contains_the_exact_projections() {
        let p = rational_patch();
        let net: Vec<[f32; 4]> = net_of(&p).iter().map(|q| q.map(|c| c as f32)).collect();
        let b = net_box(&net, true);
        for q in &net {
            for c in 0..3 {
                let exact = q[c] as f64 / q[3] as f64;
                assert!(b.min[c] as f64 <= exact && exact <= b.max[c] as f64);
            }
        }
    }
}
