//! Krawczyk's test on one box of parameter space (Lischinski & Gonczarowski 1990, §4.1,
//! after Toth 1985): the building block of the Toth kernel and of any later search that
//! subdivides differently (LG90's cached surface trees use the same test with a quadtree).
//!
//! For the system `g(x) = 0`, `x = (u, v)`, a box `X`, its midpoint `y` and `Y ≈ g'(y)⁻¹`,
//! Krawczyk's operator is
//!
//! ```text
//! K(X, y, Y) = y − Y g(y) + (I − Y G'(X)) (X − y)
//! ```
//!
//! with `G'(X)` an interval enclosure of the Jacobian over `X`. Every root in `X` lies in
//! `K`, so `K ∩ X = ∅` excludes `X`. When `K ⊆ X`, `X` holds a root (Krawczyk, Moore 1977);
//! when also `r = ‖I − Y G'(X)‖∞ < 1` the root is unique and the simple Newton iteration
//! `x ← x − Y g(x)` is a contraction of `X` into itself with rate `r`: Toth's "safe region".

use crate::geom::interval::{Interval, IntervalNet, ParamBox};

use super::raynet::{G1, G2};

/// A 2×2 matrix, row-major.
pub type Mat2 = [[f64; 2]; 2];

/// What Krawczyk's test says about a box.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Classification {
    /// No root in the box.
    Excluded,
    /// Exactly one root in the box: a safe region.
    Safe(SafeRegion),
    /// Undecided: every root of the box lies in `region` (`K ∩ X`, or `X` itself when the
    /// operator could not be formed: a singular Jacobian at the midpoint, or a degenerate
    /// box).
    Undecided { region: ParamBox },
}

/// A box with exactly one root, which lies in `region` (`K`, inside the box). Simple Newton
/// with `inverse` converges to it from any point of the box, with rate at most
/// `contraction` (< 1). The test has evaluated the equations at the box's midpoint
/// `start`; `step` is simple Newton's first step `−Y g(start)` from there, so Newton does
/// not evaluate that point again.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SafeRegion {
    pub region: ParamBox,
    pub contraction: f64,
    pub inverse: Mat2,
    pub start: (f64, f64),
    pub step: [f64; 2],
}

/// Krawczyk's test of box `x` for the equations in components [`G1`], [`G2`] of `net`
/// (the whole patch's net, for the point evaluation at the midpoint) and `sub` (its
/// sub-net over `x`, from [`IntervalNet::subnet_into`], for the Jacobian enclosure).
pub fn classify(net: &IntervalNet, sub: &IntervalNet, x: &ParamBox) -> Classification {
    let undecided = Classification::Undecided { region: *x };
    let (yu, yv) = x.mid();
    let (g, gu, gv) = net.eval(yu, yv);
    let Some(inverse) = invert([[gu[G1].mid(), gv[G1].mid()], [gu[G2].mid(), gv[G2].mid()]]) else {
        return undecided;
    };
    let Some((du, dv)) = sub.derivative_hulls(x) else {
        return undecided;
    };
    let jac: [[Interval; 2]; 2] = [[du[G1], dv[G1]], [du[G2], dv[G2]]];
    let y = [Interval::point(yu), Interval::point(yv)];
    let dx = [x.u - y[0], x.v - y[1]];
    let gy = [g[G1], g[G2]];
    let mut k = [Interval::point(0.0); 2];
    let mut contraction = 0.0f64;
    for i in 0..2 {
        // Row i of I − Y G'(X).
        let a: [Interval; 2] = std::array::from_fn(|j| {
            let yg = jac[0][j] * inverse[i][0] + jac[1][j] * inverse[i][1];
            Interval::point(if i == j { 1.0 } else { 0.0 }) - yg
        });
        contraction = contraction.max((a[0].mag() + a[1].mag()).next_up());
        let newton = gy[0] * inverse[i][0] + gy[1] * inverse[i][1];
        k[i] = y[i] - newton + a[0] * dx[0] + a[1] * dx[1];
    }
    if !(k[0].is_finite() && k[1].is_finite()) {
        return undecided;
    }
    let kbox = ParamBox { u: k[0], v: k[1] };
    match kbox.intersect(x) {
        None => Classification::Excluded,
        Some(_) if kbox.is_subset_of(x) && contraction < 1.0 => Classification::Safe(SafeRegion {
            region: kbox,
            contraction,
            inverse,
            start: (yu, yv),
            step: newton_step(&inverse, [g[G1].mid(), g[G2].mid()]),
        }),
        Some(region) => Classification::Undecided { region },
    }
}

/// The inverse of a 2×2 matrix, `None` when it is singular or not finite.
pub fn invert(m: Mat2) -> Option<Mat2> {
    let det = m[0][0] * m[1][1] - m[0][1] * m[1][0];
    let inv = 1.0 / det;
    let r = [
        [m[1][1] * inv, -m[0][1] * inv],
        [-m[1][0] * inv, m[0][0] * inv],
    ];
    (det != 0.0 && r.iter().flatten().all(|x| x.is_finite())).then_some(r)
}

/// The simple Newton step `−Y g` at a point where the equations take the values `[a, b]`.
pub fn newton_step(inverse: &Mat2, [a, b]: [f64; 2]) -> [f64; 2] {
    [
        -(inverse[0][0] * a + inverse[0][1] * b),
        -(inverse[1][0] * a + inverse[1][1] * b),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::{BezierPatch, Ray};
    use crate::kernel::toth::raynet::RayFrame;
    use glam::{DVec3, Vec3};

    /// A planar parallelogram `p + u a + v b` and a ray through its point (0.3, 0.6): the
    /// root is known in closed form, and g is linear, so Krawczyk's operator is exact up
    /// to rounding.
    fn setup() -> (IntervalNet, Ray) {
        let (p, a, b) = (
            DVec3::new(1.0, 2.0, 0.5),
            DVec3::new(2.0, 0.5, 0.0),
            DVec3::new(-0.5, 3.0, 1.0),
        );
        let patch = BezierPatch::from_points(1, 1, &[p, p + a, p + b, p + a + b]).unwrap();
        let target = p + 0.3 * a + 0.6 * b;
        let ray = Ray::new(
            Vec3::new(0.0, 0.0, 9.0),
            (target - DVec3::new(0.0, 0.0, 9.0)).as_vec3(),
        );
        let mut net = IntervalNet::default();
        RayFrame::new(&ray).project(patch.homogeneous_points(), 2, 2, &mut net);
        (net, ray)
    }

    fn sub(net: &IntervalNet, x: &ParamBox) -> IntervalNet {
        let mut s = IntervalNet::default();
        net.subnet_into(x, &mut s);
        s
    }

    /// How far the root may move in (u, v): the ray is rounded to f32, which moves the root
    /// of this unit-sized plane by a few f32 ulps of 1 (2^-23 ≈ 1.2e-7 each).
    const F32_RAY_ROOT_SHIFT: f64 = 1e-6;
    /// What rounding alone leaves of a quantity that is exactly 0 for a linear system (the
    /// width of K, the contraction ‖I − Y G'(X)‖): a handful of outward-rounded operations
    /// on numbers of size 1 give a few f64 ulps (2.2e-16 each), far below this.
    const ROUNDING_ONLY: f64 = 1e-9;

    #[test]
    fn the_whole_domain_of_a_plane_is_a_safe_region_around_the_root() {
        let (net, _) = setup();
        let x = ParamBox::UNIT;
        match classify(&net, &sub(&net, &x), &x) {
            Classification::Safe(SafeRegion {
                region,
                contraction,
                ..
            }) => {
                // The ray is rounded to f32, so the root moves by f32 ulps of (0.3, 0.6).
                assert!(
                    (region.u.mid() - 0.3).abs() < F32_RAY_ROOT_SHIFT
                        && (region.v.mid() - 0.6).abs() < F32_RAY_ROOT_SHIFT
                );
                assert!(
                    region.width() < ROUNDING_ONLY,
                    "K of a linear system is a point: {region:?}"
                );
                assert!(contraction < ROUNDING_ONLY);
            }
            other => panic!("expected a safe region, got {other:?}"),
        }
    }

    #[test]
    fn a_box_away_from_the_root_is_excluded() {
        let (net, _) = setup();
        let x = ParamBox {
            u: Interval::new(0.5, 1.0).unwrap(),
            v: Interval::new(0.0, 0.5).unwrap(),
        };
        assert_eq!(classify(&net, &sub(&net, &x), &x), Classification::Excluded);
    }

    #[test]
    fn inverse_of_a_singular_matrix_is_refused() {
        assert!(invert([[1.0, 2.0], [2.0, 4.0]]).is_none());
        let m = invert([[2.0, 1.0], [1.0, 1.0]]).unwrap();
        assert_eq!(m, [[1.0, -1.0], [-1.0, 2.0]]);
    }
}
