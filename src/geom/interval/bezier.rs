//! Enclosures of Bézier patches and of their partial derivatives over boxes of parameter
//! space, for Toth's method (Toth 1985; Lischinski & Gonczarowski 1990, §4.1).
//!
//! Method: the control net of the sub-patch over `[u0,u1]×[v0,v1]` is computed by de
//! Casteljau subdivision in interval arithmetic (split at `u0`, then split the right part
//! at `(u1 - u0) / (1 - u0)`, the same in v), and the box of that net encloses the sub-patch
//! by the convex-hull property; the differences of neighbouring control points, scaled by
//! `degree / (u1 - u0)`, enclose the partial derivatives. This is chosen over interval
//! Horner or de Casteljau evaluation with an interval parameter because the natural
//! interval extension of the Bernstein sum overestimates by O(width) (the dependency
//! problem: every term sees the whole parameter interval independently), while the
//! sub-patch hull's overestimation is O(width²) and it is exact at the corners. The split
//! parameters are exact `f64` values or (for the second split) an interval a few ulps
//! wide, and every lerp rounds outward, so each computed control point contains the exact
//! one: the enclosures are rigorous.
//!
//! Points are homogeneous and premultiplied, `(w x, w y, w z, w)`, so rational patches
//! subdivide exactly; the Euclidean enclosure is the hull of `x/w` over the control points
//! (positive weights make every surface point a convex combination of them).

use super::Interval;
use crate::geom::{BezierPatch, MAX_DEGREE};

/// A homogeneous point (or any four coordinates) with interval components.
pub type IPoint = [Interval; 4];

/// A box `u × v` of parameter space.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ParamBox {
    pub u: Interval,
    pub v: Interval,
}

impl ParamBox {
    /// The whole domain `[0,1]²` of a patch.
    pub const UNIT: ParamBox = ParamBox {
        u: Interval::UNIT,
        v: Interval::UNIT,
    };

    /// The centre `(u, v)`, inside the box.
    pub fn mid(&self) -> (f64, f64) {
        (self.u.mid(), self.v.mid())
    }

    /// The larger of the two side lengths (LG90's "width" of a safe region, §7.1).
    pub fn width(&self) -> f64 {
        self.u.width().max(self.v.width())
    }

    pub fn contains(&self, u: f64, v: f64) -> bool {
        self.u.contains(u) && self.v.contains(v)
    }

    pub fn is_subset_of(&self, o: &ParamBox) -> bool {
        self.u.is_subset_of(o.u) && self.v.is_subset_of(o.v)
    }

    /// The common part, or `None` when the boxes are disjoint.
    pub fn intersect(&self, o: &ParamBox) -> Option<ParamBox> {
        Some(ParamBox {
            u: self.u.intersect(o.u)?,
            v: self.v.intersect(o.v)?,
        })
    }

    /// Halves the box across its wider parameter (Toth's bisection), or `None` when that
    /// side is too narrow for its midpoint to differ from both ends in `f64`.
    pub fn bisect(&self) -> Option<(ParamBox, ParamBox)> {
        let along_u = self.u.width() >= self.v.width();
        let side = if along_u { self.u } else { self.v };
        let m = side.mid();
        if m <= side.lo() || m >= side.hi() {
            return None;
        }
        let (a, b) = (Interval::new(side.lo(), m)?, Interval::new(m, side.hi())?);
        Some(if along_u {
            (ParamBox { u: a, ..*self }, ParamBox { u: b, ..*self })
        } else {
            (ParamBox { v: a, ..*self }, ParamBox { v: b, ..*self })
        })
    }
}

/// A tensor-product Bézier net of interval points, u index fastest.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct IntervalNet {
    nu: usize,
    nv: usize,
    points: Vec<IPoint>,
}

impl IntervalNet {
    /// The exact net of a patch: its homogeneous control points as degenerate intervals.
    pub fn from_patch(patch: &BezierPatch) -> IntervalNet {
        let mut net = IntervalNet::default();
        net.assign(
            patch.degree_u() + 1,
            patch.degree_v() + 1,
            patch
                .homogeneous_points()
                .iter()
                .map(|p| p.to_array().map(Interval::point)),
        );
        net
    }

    /// Replaces the net by `nu × nv` points (u fastest), reusing the storage.
    pub fn assign(&mut self, nu: usize, nv: usize, points: impl IntoIterator<Item = IPoint>) {
        self.nu = nu;
        self.nv = nv;
        self.points.clear();
        self.points.extend(points);
        debug_assert_eq!(self.points.len(), nu * nv);
    }

    pub fn degree_u(&self) -> usize {
        self.nu - 1
    }

    pub fn degree_v(&self) -> usize {
        self.nv - 1
    }

    /// Control points, u fastest.
    pub fn points(&self) -> &[IPoint] {
        &self.points
    }

    /// Writes into `out` a net that encloses the control net of the sub-patch over `b`
    /// (re-parameterized to `[0,1]²`). `b` must lie inside `[0,1]²`.
    pub fn subnet_into(&self, b: &ParamBox, out: &mut IntervalNet) {
        out.nu = self.nu;
        out.nv = self.nv;
        out.points.clear();
        out.points.extend_from_slice(&self.points);
        let mut buf = [[Interval::point(0.0); 4]; MAX_DEGREE + 1];
        let (nu, nv) = (self.nu, self.nv);
        for j in 0..nv {
            let row = &mut out.points[j * nu..(j + 1) * nu];
            sub_curve(row, b.u.lo(), b.u.hi());
        }
        for i in 0..nu {
            let col = &mut buf[..nv];
            for (j, c) in col.iter_mut().enumerate() {
                *c = out.points[j * nu + i];
            }
            sub_curve(col, b.v.lo(), b.v.hi());
            for (j, c) in col.iter().enumerate() {
                out.points[j * nu + i] = *c;
            }
        }
    }

    /// The box of the control points: encloses every point of the patch the net defines.
    pub fn hull(&self) -> IPoint {
        hull_of(self.points.iter().copied())
    }

    /// Boxes of the control points of the partial derivatives `∂/∂s`, `∂/∂t` of the net in
    /// its own parameters: they enclose the derivatives over the net's whole domain.
    pub fn local_derivative_hulls(&self) -> (IPoint, IPoint) {
        let (nu, nv) = (self.nu, self.nv);
        let du = Interval::point(self.degree_u() as f64);
        let dv = Interval::point(self.degree_v() as f64);
        let p = &self.points;
        let su = (0..nv).flat_map(|j| {
            (0..nu - 1).map(move |i| sub4(p[j * nu + i + 1], p[j * nu + i]).map(|c| c * du))
        });
        let sv = (0..nv - 1).flat_map(|j| {
            (0..nu).map(move |i| sub4(p[(j + 1) * nu + i], p[j * nu + i]).map(|c| c * dv))
        });
        (hull_of(su), hull_of(sv))
    }

    /// Enclosures of the partial derivatives `∂/∂u`, `∂/∂v` over `b`, when `self` is the
    /// sub-net over `b` (from [`IntervalNet::subnet_into`]): the local derivatives divided
    /// by the side lengths. `None` when a side has zero length.
    pub fn derivative_hulls(&self, b: &ParamBox) -> Option<(IPoint, IPoint)> {
        let (su, sv) = self.local_derivative_hulls();
        let wu = Interval::point(b.u.hi()) - Interval::point(b.u.lo());
        let wv = Interval::point(b.v.hi()) - Interval::point(b.v.lo());
        let scale = |p: IPoint, w: Interval| -> Option<IPoint> {
            Some([
                p[0].checked_div(w)?,
                p[1].checked_div(w)?,
                p[2].checked_div(w)?,
                p[3].checked_div(w)?,
            ])
        };
        Some((scale(su, wu)?, scale(sv, wv)?))
    }

    /// Enclosures of the point and of its partial derivatives `∂/∂u`, `∂/∂v` at one
    /// parameter `(u, v)` of the net, by interval de Casteljau.
    pub fn eval(&self, u: f64, v: f64) -> (IPoint, IPoint, IPoint) {
        let (nu, nv) = (self.nu, self.nv);
        let mut pts = [[Interval::point(0.0); 4]; MAX_DEGREE + 1];
        let mut tans = pts;
        let mut col = pts;
        let v = Interval::point(v);
        for i in 0..nu {
            for (j, c) in col[..nv].iter_mut().enumerate() {
                *c = self.points[j * nu + i];
            }
            (pts[i], tans[i]) = point_and_tangent(&mut col[..nv], v);
        }
        let u = Interval::point(u);
        let (p, pu) = point_and_tangent(&mut pts[..nu], u);
        let pv = de_casteljau(&mut tans[..nu], u);
        (p, pu, pv)
    }
}

/// The Euclidean box of the patch over `b` (in `[0,1]²`), rounded outward.
pub fn enclose_patch(patch: &BezierPatch, b: &ParamBox) -> [Interval; 3] {
    let mut sub = IntervalNet::default();
    IntervalNet::from_patch(patch).subnet_into(b, &mut sub);
    euclidean_hull(&sub)
}

/// Enclosures of the Euclidean partial derivatives `(∂S/∂u, ∂S/∂v)` over `b`, by the
/// quotient rule `S_u = (H_u.xyz − S H_u.w) / H.w` applied to the enclosures of the
/// homogeneous point `H`, of `S`, and of `H_u`, `H_v`: every factor holds its value at
/// each point of `b`, so the result holds the derivative there. The whole line for a
/// degenerate box.
pub fn enclose_derivatives(patch: &BezierPatch, b: &ParamBox) -> ([Interval; 3], [Interval; 3]) {
    let mut sub = IntervalNet::default();
    IntervalNet::from_patch(patch).subnet_into(b, &mut sub);
    let Some((hu, hv)) = sub.derivative_hulls(b) else {
        return ([Interval::ENTIRE; 3], [Interval::ENTIRE; 3]);
    };
    let h = sub.hull();
    let s = euclidean_hull(&sub);
    let quotient = |d: IPoint| -> [Interval; 3] {
        std::array::from_fn(|c| {
            (d[c] - s[c] * d[3])
                .checked_div(h[3])
                .unwrap_or(Interval::ENTIRE)
        })
    };
    (quotient(hu), quotient(hv))
}

/// The box of the Euclidean control points `x / w` of a homogeneous net.
pub fn euclidean_hull(net: &IntervalNet) -> [Interval; 3] {
    let mut acc: Option<[Interval; 3]> = None;
    for p in net.points() {
        let e: [Interval; 3] =
            std::array::from_fn(|c| p[c].checked_div(p[3]).unwrap_or(Interval::ENTIRE));
        acc = Some(match acc {
            None => e,
            Some(a) => std::array::from_fn(|c| a[c].hull(e[c])),
        });
    }
    acc.unwrap_or([Interval::ENTIRE; 3])
}

fn sub4(a: IPoint, b: IPoint) -> IPoint {
    std::array::from_fn(|c| a[c] - b[c])
}

fn hull_of(points: impl Iterator<Item = IPoint>) -> IPoint {
    points
        .reduce(|a, b| std::array::from_fn(|c| a[c].hull(b[c])))
        .unwrap_or([Interval::ENTIRE; 4])
}

#[inline(always)]
fn lerp4(a: IPoint, b: IPoint, t: Interval) -> IPoint {
    std::array::from_fn(|c| Interval::lerp(a[c], b[c], t))
}

/// Replaces a curve's control points over `[0,1]` by enclosures of those of its piece over
/// `[a, b]`: the right part of a split at `a`, then the left part of a split of that at
/// `(b - a) / (1 - a)`.
fn sub_curve(p: &mut [IPoint], a: f64, b: f64) {
    let n = p.len();
    if a > 0.0 {
        // In place, level k overwrites entry i with b_i^(k); entry i is last written at
        // level n-1-i, which is the right part's control point i.
        let t = Interval::point(a);
        for k in 1..n {
            for i in 0..n - k {
                p[i] = lerp4(p[i], p[i + 1], t);
            }
        }
    }
    if b < 1.0 {
        let s = if a > 0.0 {
            (Interval::point(b) - Interval::point(a))
                .checked_div(Interval::point(1.0) - Interval::point(a))
                .unwrap_or(Interval::UNIT)
        } else {
            Interval::point(b)
        };
        // Backwards, entry i ends as b_0^(i), the left part's control point i.
        for k in 1..n {
            for i in (k..n).rev() {
                p[i] = lerp4(p[i - 1], p[i], s);
            }
        }
    }
}

/// De Casteljau evaluation in place.
fn de_casteljau(p: &mut [IPoint], t: Interval) -> IPoint {
    let n = p.len();
    for k in 1..n {
        for i in 0..n - k {
            p[i] = lerp4(p[i], p[i + 1], t);
        }
    }
    p[0]
}

/// Point and derivative of a curve: the last de Casteljau level's two points `b0`, `b1`
/// give the point `lerp(b0, b1, t)` and the tangent `degree · (b1 − b0)`.
fn point_and_tangent(p: &mut [IPoint], t: Interval) -> (IPoint, IPoint) {
    let n = p.len();
    if n == 1 {
        return (p[0], [Interval::point(0.0); 4]);
    }
    for k in 1..n - 1 {
        for i in 0..n - k {
            p[i] = lerp4(p[i], p[i + 1], t);
        }
    }
    let deg = Interval::point((n - 1) as f64);
    (lerp4(p[0], p[1], t), sub4(p[1], p[0]).map(|c| c * deg))
}

#[cfg(test)]
#[path = "bezier_tests.rs"]
mod tests;
