//! Tensor-product Bézier patches of any degree (1 to [`MAX_DEGREE`] in each direction),
//! rational or not, in `f64`.
//!
//! Control points are stored homogeneous and premultiplied, `(w x, w y, w z, w)`, with the
//! u index varying fastest (the `.bpt` and OBJ convention). Evaluation and splitting are
//! de Casteljau's algorithm on the homogeneous points, which is exact for rational patches
//! and numerically the most stable form (Farin, *Curves and Surfaces for CAGD*, §4).

use glam::{DVec3, DVec4};
use thiserror::Error;

use super::bbox::DAabb;
use super::real::{Real, lerp};

/// Highest degree per direction; higher-degree patches are rejected on input.
pub const MAX_DEGREE: usize = 15;

/// Why a patch or surface could not be built.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum GeomError {
    #[error("degree {0} is outside 1..={MAX_DEGREE}")]
    Degree(usize),
    #[error("expected {expected} control points, found {found}")]
    PointCount { expected: usize, found: usize },
    #[error("control point {index} has a non-finite coordinate")]
    NonFinite { index: usize },
    #[error("control point {index} has weight {weight}; weights must be positive")]
    Weight { index: usize, weight: f64 },
    #[error("{0}")]
    Knots(String),
}

/// The rectangle of a parent surface's parameter space that a patch covers, so (u, v) in
/// the patch's own [0,1]² maps back to the NURBS surface's parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ParamRect {
    pub u0: f64,
    pub u1: f64,
    pub v0: f64,
    pub v1: f64,
}

impl ParamRect {
    pub const UNIT: ParamRect = ParamRect {
        u0: 0.0,
        u1: 1.0,
        v0: 0.0,
        v1: 1.0,
    };

    /// Maps local (u, v) in [0,1]² to the parent's parameters.
    pub fn to_parent(&self, u: f64, v: f64) -> (f64, f64) {
        (lerp(self.u0, self.u1, u), lerp(self.v0, self.v1, v))
    }
}

/// A Bézier patch of degree (du, dv) with homogeneous control points.
#[derive(Clone, Debug, PartialEq)]
pub struct BezierPatch {
    degree_u: usize,
    degree_v: usize,
    points: Vec<DVec4>,
    domain: ParamRect,
}

impl BezierPatch {
    /// A patch from homogeneous premultiplied points `(w x, w y, w z, w)`, u fastest.
    pub fn new(degree_u: usize, degree_v: usize, points: Vec<DVec4>) -> Result<Self, GeomError> {
        for d in [degree_u, degree_v] {
            if !(1..=MAX_DEGREE).contains(&d) {
                return Err(GeomError::Degree(d));
            }
        }
        let expected = (degree_u + 1) * (degree_v + 1);
        if points.len() != expected {
            return Err(GeomError::PointCount {
                expected,
                found: points.len(),
            });
        }
        for (index, p) in points.iter().enumerate() {
            if !p.is_finite() {
                return Err(GeomError::NonFinite { index });
            }
            if p.w <= 0.0 {
                return Err(GeomError::Weight { index, weight: p.w });
            }
        }
        Ok(BezierPatch {
            degree_u,
            degree_v,
            points,
            domain: ParamRect::UNIT,
        })
    }

    /// A non-rational patch from Euclidean points, u fastest.
    pub fn from_points(
        degree_u: usize,
        degree_v: usize,
        points: &[DVec3],
    ) -> Result<Self, GeomError> {
        Self::new(
            degree_u,
            degree_v,
            points.iter().map(|p| p.extend(1.0)).collect(),
        )
    }

    /// A rational patch from Euclidean points and their weights, u fastest.
    pub fn from_weighted(
        degree_u: usize,
        degree_v: usize,
        points: &[DVec3],
        weights: &[f64],
    ) -> Result<Self, GeomError> {
        if weights.len() != points.len() {
            return Err(GeomError::PointCount {
                expected: points.len(),
                found: weights.len(),
            });
        }
        Self::new(
            degree_u,
            degree_v,
            points
                .iter()
                .zip(weights)
                .map(|(p, &w)| (*p * w).extend(w))
                .collect(),
        )
    }

    /// The same patch with u and v exchanged (its normal `S_u × S_v` turns around).
    pub fn transposed(&self) -> BezierPatch {
        let (nu, nv) = (self.degree_u + 1, self.degree_v + 1);
        let d = self.domain;
        BezierPatch {
            degree_u: self.degree_v,
            degree_v: self.degree_u,
            points: (0..nu)
                .flat_map(|i| (0..nv).map(move |j| self.points[j * nu + i]))
                .collect(),
            domain: ParamRect {
                u0: d.v0,
                u1: d.v1,
                v0: d.u0,
                v1: d.u1,
            },
        }
    }

    pub fn with_domain(mut self, domain: ParamRect) -> Self {
        self.domain = domain;
        self
    }

    pub fn degree_u(&self) -> usize {
        self.degree_u
    }

    pub fn degree_v(&self) -> usize {
        self.degree_v
    }

    pub fn domain(&self) -> ParamRect {
        self.domain
    }

    /// Homogeneous control points, u fastest.
    pub fn homogeneous_points(&self) -> &[DVec4] {
        &self.points
    }

    pub fn point_count(&self) -> usize {
        self.points.len()
    }

    /// Homogeneous control point (i along u, j along v).
    pub fn homogeneous(&self, i: usize, j: usize) -> DVec4 {
        self.points[j * (self.degree_u + 1) + i]
    }

    /// Euclidean control point (i along u, j along v).
    pub fn point(&self, i: usize, j: usize) -> DVec3 {
        dehomogenize(self.homogeneous(i, j))
    }

    /// All Euclidean control points, u fastest.
    pub fn euclidean_points(&self) -> impl Iterator<Item = DVec3> + '_ {
        self.points.iter().map(|&p| dehomogenize(p))
    }

    /// True when some weight differs from 1.
    pub fn is_rational(&self) -> bool {
        self.points.iter().any(|p| p.w != 1.0)
    }

    /// True when the surface is a curve or a point, so it has no area: every row of the net
    /// (fixed v) repeats one homogeneous point, or every column does, and the surface then
    /// does not depend on u (or v). Exact comparison: a nearly degenerate patch still has
    /// area and is left to the kernel.
    pub fn has_zero_area(&self) -> bool {
        let (nu, nv) = (self.degree_u + 1, self.degree_v + 1);
        let rows_repeat =
            (0..nv).all(|j| (1..nu).all(|i| self.homogeneous(i, j) == self.homogeneous(0, j)));
        let columns_repeat =
            (0..nu).all(|i| (1..nv).all(|j| self.homogeneous(i, j) == self.homogeneous(i, 0)));
        rows_repeat || columns_repeat
    }

    /// True for the common bicubic non-rational case that has a fixed-size fast path.
    pub fn is_plain_bicubic(&self) -> bool {
        self.degree_u == 3 && self.degree_v == 3 && !self.is_rational()
    }

    /// Applies an affine map to every control point. Affine maps commute with the
    /// (rational) Bézier basis, so the patch is transformed exactly.
    pub fn transform(&mut self, m: &glam::DAffine3) {
        for p in &mut self.points {
            let e = m.transform_point3(dehomogenize(*p));
            *p = (e * p.w).extend(p.w);
        }
    }

    /// Homogeneous point at (u, v), by de Casteljau.
    pub fn eval_homogeneous(&self, u: f64, v: f64) -> DVec4 {
        let mut row = [DVec4::ZERO; MAX_DEGREE + 1];
        let row = self.curve_in_u_at(v, &mut row);
        de_casteljau_in_place(row, u)
    }

    /// Surface point at (u, v) in `f64`.
    pub fn eval(&self, u: f64, v: f64) -> DVec3 {
        dehomogenize(self.eval_homogeneous(u, v))
    }

    /// Surface point at (u, v) computed entirely in `f32` arithmetic (the kernels'
    /// precision), for comparisons against the `f64` path.
    pub fn eval_f32(&self, u: f32, v: f32) -> glam::Vec3 {
        let pts: Vec<[f32; 4]> = self
            .points
            .iter()
            .map(|p| [p.x as f32, p.y as f32, p.z as f32, p.w as f32])
            .collect();
        let nu = self.degree_u + 1;
        let mut row = Vec::with_capacity(nu);
        let mut col = Vec::with_capacity(self.degree_v + 1);
        for i in 0..nu {
            col.clear();
            col.extend((0..=self.degree_v).map(|j| pts[j * nu + i]));
            row.push(de_casteljau_generic(&mut col, v));
        }
        let h = de_casteljau_generic(&mut row, u);
        glam::Vec3::new(h[0] / h[3], h[1] / h[3], h[2] / h[3])
    }

    /// Point and first partial derivatives `(S, ∂S/∂u, ∂S/∂v)` at (u, v), exact for
    /// rational patches (quotient rule on the homogeneous derivatives).
    ///
    /// Every hit's normal comes from here, so the rows and columns live on the stack: sized
    /// for bicubic patches where they fit (the heap vectors they replace were a tenth of
    /// the teapot render's time, BENCHMARKS.md, scenes at scale), for [`MAX_DEGREE`] otherwise.
    /// The arithmetic is the same either way.
    pub fn derivatives(&self, u: f64, v: f64) -> (DVec3, DVec3, DVec3) {
        if self.degree_u.max(self.degree_v) <= 3 {
            self.derivatives_in::<4>(u, v)
        } else {
            self.derivatives_in::<{ MAX_DEGREE + 1 }>(u, v)
        }
    }

    /// [`BezierPatch::derivatives`] with rows and columns of capacity `N`, at least the
    /// larger degree plus one.
    fn derivatives_in<const N: usize>(&self, u: f64, v: f64) -> (DVec3, DVec3, DVec3) {
        let (mut row, mut column) = ([DVec4::ZERO; N], [DVec4::ZERO; N]);
        let (a, au) = curve_point_and_tangent(self.curve_in_u_at(v, &mut row), u);
        let (_, av) = curve_point_and_tangent(self.curve_in_v_at(u, &mut column), v);
        let s = dehomogenize(a);
        let su = (au.truncate() - s * au.w) / a.w;
        let sv = (av.truncate() - s * av.w) / a.w;
        (s, su, sv)
    }

    /// Unit geometric normal `∂S/∂u × ∂S/∂v` at (u, v), finite and correct also where the
    /// cross product vanishes: at a collapsed edge (the teapot's lid and bottom, four
    /// coincident control points) the normal is the limit approached from the interior.
    pub fn normal(&self, u: f64, v: f64) -> DVec3 {
        let (_, su, sv) = self.derivatives(u, v);
        if let Some(n) = well_conditioned_normal(su, sv) {
            return n;
        }
        // The limit of the normal at a degenerate point is the normal a little way into the
        // patch. Approach along the line towards the centre, halving the step, and take the
        // first well-conditioned normal from the smallest step that gives one: the angular
        // error is O(step) and 2^-26 ≈ 1.5e-8 is the smallest step whose derivatives are
        // still accurate in f64 (√ε).
        let mut best = None;
        let mut step = 0.25;
        while step >= DEGENERATE_APPROACH_MIN_STEP {
            let (uu, vv) = (u + (0.5 - u) * step, v + (0.5 - v) * step);
            let (_, su, sv) = self.derivatives(uu, vv);
            match well_conditioned_normal(su, sv) {
                Some(n) => best = Some(n),
                None => break,
            }
            step *= 0.5;
        }
        best.unwrap_or(DVec3::Z)
    }

    /// Splits at u = 1/2 into the halves over [0, ½] and [½, 1].
    pub fn split_u(&self) -> (BezierPatch, BezierPatch) {
        let nu = self.degree_u + 1;
        let nv = self.degree_v + 1;
        let mut left = vec![DVec4::ZERO; nu * nv];
        let mut right = vec![DVec4::ZERO; nu * nv];
        let mut row = vec![DVec4::ZERO; nu];
        let (mut l, mut r) = (vec![DVec4::ZERO; nu], vec![DVec4::ZERO; nu]);
        for j in 0..nv {
            row.copy_from_slice(&self.points[j * nu..(j + 1) * nu]);
            split_curve_half(&row, &mut l, &mut r);
            left[j * nu..(j + 1) * nu].copy_from_slice(&l);
            right[j * nu..(j + 1) * nu].copy_from_slice(&r);
        }
        let d = self.domain;
        let mid = 0.5 * (d.u0 + d.u1);
        (
            self.child(left, ParamRect { u1: mid, ..d }),
            self.child(right, ParamRect { u0: mid, ..d }),
        )
    }

    /// Splits at v = 1/2 into the halves over [0, ½] and [½, 1].
    pub fn split_v(&self) -> (BezierPatch, BezierPatch) {
        let nu = self.degree_u + 1;
        let nv = self.degree_v + 1;
        let mut left = vec![DVec4::ZERO; nu * nv];
        let mut right = vec![DVec4::ZERO; nu * nv];
        let mut col = vec![DVec4::ZERO; nv];
        let (mut l, mut r) = (vec![DVec4::ZERO; nv], vec![DVec4::ZERO; nv]);
        for i in 0..nu {
            for j in 0..nv {
                col[j] = self.points[j * nu + i];
            }
            split_curve_half(&col, &mut l, &mut r);
            for j in 0..nv {
                left[j * nu + i] = l[j];
                right[j * nu + i] = r[j];
            }
        }
        let d = self.domain;
        let mid = 0.5 * (d.v0 + d.v1);
        (
            self.child(left, ParamRect { v1: mid, ..d }),
            self.child(right, ParamRect { v0: mid, ..d }),
        )
    }

    /// The box of the control points: contains the patch by the convex-hull property
    /// (positive weights).
    pub fn control_box(&self) -> DAabb {
        self.euclidean_points().collect()
    }

    /// The tighter box of LG90 §3.1 (Fig. 2): the union of the control boxes of the four
    /// sub-patches over the quarters of the parameter square.
    pub fn tight_box(&self) -> DAabb {
        let (a, b) = self.split_u();
        [a, b]
            .iter()
            .flat_map(|h| {
                let (c, d) = h.split_v();
                [c.control_box(), d.control_box()]
            })
            .fold(DAabb::EMPTY, |acc, b| acc.union(&b))
    }

    fn child(&self, points: Vec<DVec4>, domain: ParamRect) -> BezierPatch {
        BezierPatch {
            degree_u: self.degree_u,
            degree_v: self.degree_v,
            points,
            domain,
        }
    }

    /// The row of homogeneous points of the u-curve at parameter v, written to the start
    /// of `row` (at least `degree_u + 1` long).
    fn curve_in_u_at<'a, const N: usize>(
        &self,
        v: f64,
        row: &'a mut [DVec4; N],
    ) -> &'a mut [DVec4] {
        let (nu, nv) = (self.degree_u + 1, self.degree_v + 1);
        let mut work = [DVec4::ZERO; N];
        for (i, out) in row[..nu].iter_mut().enumerate() {
            for (j, w) in work[..nv].iter_mut().enumerate() {
                *w = self.points[j * nu + i];
            }
            *out = de_casteljau_in_place(&mut work[..nv], v);
        }
        &mut row[..nu]
    }

    /// The column of homogeneous points of the v-curve at parameter u, written to the
    /// start of `column` (at least `degree_v + 1` long).
    fn curve_in_v_at<'a, const N: usize>(
        &self,
        u: f64,
        column: &'a mut [DVec4; N],
    ) -> &'a mut [DVec4] {
        let (nu, nv) = (self.degree_u + 1, self.degree_v + 1);
        let mut work = [DVec4::ZERO; N];
        for (j, out) in column[..nv].iter_mut().enumerate() {
            work[..nu].copy_from_slice(&self.points[j * nu..(j + 1) * nu]);
            *out = de_casteljau_in_place(&mut work[..nu], u);
        }
        &mut column[..nv]
    }
}

/// Smallest step towards the patch centre used to find the limit normal at a degenerate
/// point: √ε of f64, below which derivative round-off dominates the direction.
const DEGENERATE_APPROACH_MIN_STEP: f64 = 1.0 / 67_108_864.0; // 2^-26

/// `|Su × Sv|` must exceed this fraction of `|Su| |Sv|` (the sine of the angle between the
/// tangents) for the cross product to be trusted: below it, the tangents are parallel to
/// within the f64 round-off of their own computation (≈ 1e3 ε).
const MIN_TANGENT_SINE: f64 = 1e3 * f64::EPSILON;

fn well_conditioned_normal(su: DVec3, sv: DVec3) -> Option<DVec3> {
    let n = su.cross(sv);
    let len = n.length();
    let scale = su.length() * sv.length();
    (len.is_finite() && scale > 0.0 && len > MIN_TANGENT_SINE * scale).then(|| n / len)
}

pub(crate) fn dehomogenize(p: DVec4) -> DVec3 {
    p.truncate() / p.w
}

/// De Casteljau evaluation of a homogeneous curve at t.
pub(crate) fn de_casteljau_point(points: &[DVec4], t: f64) -> DVec4 {
    de_casteljau_in_place(&mut points.to_vec(), t)
}

/// [`de_casteljau_point`] in place (`work` holds the
/// control points and is overwritten).
fn de_casteljau_in_place(work: &mut [DVec4], t: f64) -> DVec4 {
    let n = work.len();
    for k in 1..n {
        for i in 0..n - k {
            work[i] = work[i].lerp(work[i + 1], t);
        }
    }
    work[0]
}

/// De Casteljau in any [`Real`] type, in place, over `[x, y, z, w]` points.
pub(crate) fn de_casteljau_generic<T: Real>(work: &mut [[T; 4]], t: T) -> [T; 4] {
    let n = work.len();
    for k in 1..n {
        for i in 0..n - k {
            for c in 0..4 {
                work[i][c] = lerp(work[i][c], work[i + 1][c], t);
            }
        }
    }
    work[0]
}

/// Point and first derivative of a homogeneous Bézier curve at t: the last de Casteljau
/// step's two points give the tangent `n (b1 - b0)`. `work` holds the control points and
/// is overwritten.
fn curve_point_and_tangent(work: &mut [DVec4], t: f64) -> (DVec4, DVec4) {
    let n = work.len() - 1;
    for k in 1..n {
        for i in 0..=n - k {
            work[i] = work[i].lerp(work[i + 1], t);
        }
    }
    let (b0, b1) = (work[0], work[1]);
    (b0.lerp(b1, t), (b1 - b0) * n as f64)
}

/// Splits a homogeneous curve at t = 1/2 (de Casteljau's triangle: its left edge is the
/// left half's control polygon, its right edge the right half's). `right` doubles as the
/// work row: after level k its entry n-1-k is final and is never touched again.
pub(crate) fn split_curve_half(points: &[DVec4], left: &mut [DVec4], right: &mut [DVec4]) {
    let n = points.len();
    right.copy_from_slice(points);
    for k in 0..n {
        left[k] = right[0];
        for i in 0..n - 1 - k {
            right[i] = (right[i] + right[i + 1]) * 0.5;
        }
    }
}

#[cfg(test)]
#[path = "bezier_tests.rs"]
mod tests;
