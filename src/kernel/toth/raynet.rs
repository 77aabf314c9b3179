//! The patch in ray coordinates. Lischinski & Gonczarowski (§4.1, after Toth) write the
//! intersection as `f(u, v) = 0`; representing the ray as the intersection of two planes
//! `n₁·x = c₁`, `n₂·x = c₂` turns it into two equations in (u, v) alone. Applied to the
//! homogeneous point `H = (w x, w y, w z, w)` each plane gives the polynomial
//! `g_k = n_k·H.xyz − c_k H.w`, whose zero set is the plane (weights are positive), so the
//! system is a Bézier patch with two scalar components, rational patches included. A third
//! linear form `τ = (d·H.xyz − (d·o) H.w) / (d·d)` gives the ray parameter `t = τ / w` of a
//! surface point's projection onto the ray.
//!
//! The plane coefficients are computed in interval arithmetic from the exact `f32` ray, so
//! the projected net encloses the exact one and every bound derived from it is rigorous.

use glam::Vec3;

use crate::geom::Ray;
use crate::geom::interval::{IPoint, Interval, IntervalNet};

/// Component of a projected net: the two plane equations, the ray parameter numerator and
/// the weight.
pub const G1: usize = 0;
pub const G2: usize = 1;
pub const TAU: usize = 2;
pub const W: usize = 3;

/// The linear forms that take a homogeneous point to ray coordinates `(g₁, g₂, τ, w)`.
#[derive(Clone, Copy, Debug)]
pub struct RayFrame {
    rows: [IPoint; 3],
    /// `|n₁|`, `|n₂|`, `|d|` (approximate): scales from `g₁`, `g₂`, `t` to lengths.
    lengths: [f64; 3],
}

/// Bounds of a sub-patch in ray coordinates: the Euclidean `g₁`, `g₂` (signed distances
/// from the planes times `|n_k|`) and the ray parameter `t`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RayBox {
    pub g1: Interval,
    pub g2: Interval,
    pub t: Interval,
}

impl RayBox {
    /// The ray-box test in ray coordinates: the ray (`g₁ = g₂ = 0`) passes through the box
    /// within `[tmin, tmax]`.
    pub fn is_hit(&self, tmin: f64, tmax: f64) -> bool {
        self.g1.contains(0.0) && self.g2.contains(0.0) && self.t.hi() >= tmin && self.t.lo() <= tmax
    }
}

impl RayFrame {
    /// The frame of `ray`: `n₁ = d × e_k` for the axis `k` where `|d|` is smallest (exact:
    /// a permutation of `d`'s components), `n₂ = d × n₁`, both planes through the origin.
    pub fn new(ray: &Ray) -> RayFrame {
        let d = ray.dir.as_dvec3().to_array().map(Interval::point);
        let o = ray.origin.as_dvec3().to_array().map(Interval::point);
        let a = ray.dir.abs();
        let axis = if a.x <= a.y && a.x <= a.z {
            Vec3::X
        } else if a.y <= a.z {
            Vec3::Y
        } else {
            Vec3::Z
        };
        let e = axis.as_dvec3().to_array().map(Interval::point);
        let n1 = cross(d, e);
        let n2 = cross(d, n1);
        let dd = dot(d, d);
        let row = |n: [Interval; 3]| [n[0], n[1], n[2], -dot(n, o)];
        let t_row = {
            let r = row(d);
            r.map(|c| c.checked_div(dd).unwrap_or(Interval::ENTIRE))
        };
        let len = |n: [Interval; 3]| n.iter().map(|c| c.mid() * c.mid()).sum::<f64>().sqrt();
        RayFrame {
            rows: [row(n1), row(n2), t_row],
            lengths: [len(n1), len(n2), len(d)],
        }
    }

    /// Writes the projected net `(g₁, g₂, τ, w)` of a homogeneous net into `out`.
    pub fn project(&self, net: &[glam::DVec4], nu: usize, nv: usize, out: &mut IntervalNet) {
        out.assign(
            nu,
            nv,
            net.iter().map(|p| {
                let h = p.to_array().map(Interval::point);
                let f = |r: &IPoint| r[0] * h[0] + r[1] * h[1] + r[2] * h[2] + r[3] * h[3];
                [f(&self.rows[0]), f(&self.rows[1]), f(&self.rows[2]), h[3]]
            }),
        );
    }

    /// Bounds of the sub-patch whose projected net is `net`: the hull of `x / w` over the
    /// control points (positive weights make every point a convex combination of them).
    pub fn ray_box(&self, net: &IntervalNet) -> RayBox {
        let mut acc: Option<[Interval; 3]> = None;
        for p in net.points() {
            let e = [G1, G2, TAU].map(|c| p[c].checked_div(p[W]).unwrap_or(Interval::ENTIRE));
            acc = Some(match acc {
                None => e,
                Some(a) => std::array::from_fn(|c| a[c].hull(e[c])),
            });
        }
        let [g1, g2, t] = acc.unwrap_or([Interval::ENTIRE; 3]);
        RayBox { g1, g2, t }
    }

    /// The largest extent of a ray box as a length: across the two planes and along the ray.
    pub fn extent(&self, b: &RayBox) -> f64 {
        let w = [b.g1.width(), b.g2.width(), b.t.width()];
        (w[0] / self.lengths[0])
            .max(w[1] / self.lengths[1])
            .max(w[2] * self.lengths[2])
    }
}

fn cross(a: [Interval; 3], b: [Interval; 3]) -> [Interval; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn dot(a: [Interval; 3], b: [Interval; 3]) -> Interval {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
