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

use glam::{Vec3, Vec4};

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

    /// Writes into `out` an enclosure of the projected net of a homogeneous net known only
    /// to within `radius` of `centres` in each component (`|H_k − c_k| ≤ r_k`): each plane's
    /// value at the centre, widened by `Σ_k |row_k| r_k`.
    pub fn project_enclosed(
        &self,
        centres: &[Vec4],
        radius: Vec4,
        nu: usize,
        nv: usize,
        out: &mut IntervalNet,
    ) {
        let r = radius.as_dvec4().to_array();
        // Upper bounds of the widening, every product and sum rounded up (all terms ≥ 0).
        let spread = self.rows.map(|row| {
            let e = (0..4).fold(0.0, |acc: f64, k| {
                (acc + (row[k].mag() * r[k]).next_up()).next_up()
            });
            Interval::spanning(-e, e)
        });
        let w_spread = Interval::spanning(-r[W], r[W]);
        out.assign(
            nu,
            nv,
            centres.iter().map(|p| {
                let c = p.as_dvec4().to_array();
                let f = |row: &IPoint, e: Interval| {
                    row[0] * c[0] + row[1] * c[1] + row[2] * c[2] + row[3] * c[3] + e
                };
                [
                    f(&self.rows[0], spread[0]),
                    f(&self.rows[1], spread[1]),
                    f(&self.rows[2], spread[2]),
                    Interval::point(c[W]) + w_spread,
                ]
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

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec4;

    /// Every homogeneous point within the radius of a centre projects, by the exact-input
    /// [`RayFrame::project`], into the enclosure [`RayFrame::project_enclosed`] gives.
    #[test]
    fn enclosed_projection_holds_every_point_within_the_radius() {
        let ray = Ray::new(Vec3::new(0.3, -1.7, 2.5), Vec3::new(0.6, 0.2, -0.77));
        let frame = RayFrame::new(&ray);
        let centres: Vec<Vec4> = (0..4)
            .map(|i| {
                Vec4::new(
                    i as f32 - 1.5,
                    0.25 * i as f32,
                    2.0 - i as f32,
                    1.0 + 0.5 * i as f32,
                )
            })
            .collect();
        let radius = Vec4::new(0.5, 0.25, 0.125, 0.0625);
        let mut enclosed = IntervalNet::default();
        frame.project_enclosed(&centres, radius, 2, 2, &mut enclosed);
        // The corners of each point's box: the projection is linear, so they bound it.
        let mut exact = IntervalNet::default();
        for signs in 0..16 {
            let s = |k: usize| if signs >> k & 1 == 1 { 1.0 } else { -1.0 };
            let corners: Vec<DVec4> = centres
                .iter()
                .map(|c| (*c + radius * Vec4::new(s(0), s(1), s(2), s(3))).as_dvec4())
                .collect();
            frame.project(&corners, 2, 2, &mut exact);
            for (e, x) in enclosed.points().iter().zip(exact.points()) {
                for k in 0..4 {
                    assert!(x[k].is_subset_of(e[k]), "{:?} not in {:?}", x[k], e[k]);
                }
            }
        }
    }
}
