//! The bicubic non-rational fast path: fixed-size arrays and the cubic Bernstein basis
//! written out, for the most common patch (all 32 teapot patches).

use glam::DVec3;

use super::bezier::BezierPatch;

/// A non-rational bicubic patch, 16 control points with u varying fastest.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BicubicPatch {
    pub points: [DVec3; 16],
}

impl BicubicPatch {
    /// The fast-path form of `patch`, if it is bicubic and non-rational.
    pub fn from_patch(patch: &BezierPatch) -> Option<Self> {
        if !patch.is_plain_bicubic() {
            return None;
        }
        let mut points = [DVec3::ZERO; 16];
        for (dst, src) in points.iter_mut().zip(patch.euclidean_points()) {
            *dst = src;
        }
        Some(BicubicPatch { points })
    }

    pub fn eval(&self, u: f64, v: f64) -> DVec3 {
        let (bu, bv) = (bernstein3(u), bernstein3(v));
        self.combine(&bu, &bv)
    }

    /// Point and first partial derivatives `(S, ∂S/∂u, ∂S/∂v)`.
    pub fn derivatives(&self, u: f64, v: f64) -> (DVec3, DVec3, DVec3) {
        let (bu, bv) = (bernstein3(u), bernstein3(v));
        let (du, dv) = (bernstein3_derivative(u), bernstein3_derivative(v));
        (
            self.combine(&bu, &bv),
            self.combine(&du, &bv),
            self.combine(&bu, &dv),
        )
    }

    fn combine(&self, bu: &[f64; 4], bv: &[f64; 4]) -> DVec3 {
        let mut s = DVec3::ZERO;
        for j in 0..4 {
            let mut row = DVec3::ZERO;
            for i in 0..4 {
                row += self.points[j * 4 + i] * bu[i];
            }
            s += row * bv[j];
        }
        s
    }
}

/// The four cubic Bernstein polynomials at t.
fn bernstein3(t: f64) -> [f64; 4] {
    let s = 1.0 - t;
    [s * s * s, 3.0 * t * s * s, 3.0 * t * t * s, t * t * t]
}

/// Their derivatives: 3 (B²_{i-1} − B²_i).
fn bernstein3_derivative(t: f64) -> [f64; 4] {
    let s = 1.0 - t;
    [
        -3.0 * s * s,
        3.0 * s * s - 6.0 * t * s,
        6.0 * t * s - 3.0 * t * t,
        3.0 * t * t,
    ]
}
