//! Exact rational NURBS shapes built from the classic 9-point circle (Piegl & Tiller,
//! *The NURBS Book*, §7.5 and §8.5, surfaces of revolution): a degree-2 circle of four
//! 90° arcs, each a rational quadratic with middle weight cos 45° = √2/2. Useful as test
//! geometry with a closed form.

use glam::DVec3;
use std::f64::consts::FRAC_1_SQRT_2;

use super::surface::NurbsSurface;
use crate::geom::bezier::GeomError;

/// Knots of the 9-point circle: four quadrants, each a Bézier arc.
pub const CIRCLE_KNOTS: [f64; 12] = [0., 0., 0., 0.25, 0.25, 0.5, 0.5, 0.75, 0.75, 1., 1., 1.];

/// The 9-point unit circle around the z axis: Euclidean `(x, y)` and weight. The corner
/// points of the square carry weight √2/2, which makes each quadrant an exact circular arc.
pub fn circle() -> [(f64, f64, f64); 9] {
    let w = FRAC_1_SQRT_2;
    [
        (1., 0., 1.),
        (1., 1., w),
        (0., 1., 1.),
        (-1., 1., w),
        (-1., 0., 1.),
        (-1., -1., w),
        (0., -1., 1.),
        (1., -1., w),
        (1., 0., 1.),
    ]
}

/// The surface of revolution about the z axis of a degree-2 profile curve in the (ρ, z)
/// half-plane: `profile[j] = (ρ, z, weight)`. u runs once around the axis (the 9-point
/// circle, u = 0 on the +x axis, counter-clockwise), v along the profile. The tensor product
/// of the circle with the profile, weights multiplied, is exact because the rational basis
/// separates: x = cos θ(u) · ρ(v), y = sin θ(u) · ρ(v), z = z(v).
pub fn revolution(
    profile_knots: Vec<f64>,
    profile: &[(f64, f64, f64)],
) -> Result<NurbsSurface, GeomError> {
    let circle = circle();
    let points = profile
        .iter()
        .flat_map(|&(rho, z, wj)| {
            circle.iter().map(move |&(cx, cy, wi)| {
                let w = wi * wj;
                (DVec3::new(rho * cx, rho * cy, z) * w).extend(w)
            })
        })
        .collect();
    NurbsSurface::new(
        2,
        2,
        CIRCLE_KNOTS.to_vec(),
        profile_knots,
        circle.len(),
        profile.len(),
        points,
    )
}

/// A torus around the z axis, centred at the origin: tube centre circle of radius `major`
/// in the xy plane, tube radius `minor`. Degree 2 × 2, 9 × 9 control points, 16 Bézier
/// patches; every point satisfies `(√(x² + y²) − major)² + z² = minor²`.
///
/// # Examples
/// ```
/// let torus = patchtrace::geom::nurbs::shapes::torus(2.0, 0.5)?;
/// let p = torus.eval(0.0, 0.25); // on +x, at the top of the tube
/// assert!((p - glam::DVec3::new(2.0, 0.0, 0.5)).length() < 1e-15);
/// assert_eq!(torus.to_bezier_patches().len(), 16);
/// # Ok::<(), patchtrace::geom::GeomError>(())
/// ```
pub fn torus(major: f64, minor: f64) -> Result<NurbsSurface, GeomError> {
    let tube = circle().map(|(cx, cy, w)| (major + minor * cx, minor * cy, w));
    revolution(CIRCLE_KNOTS.to_vec(), &tube)
}

/// A sphere of `radius` centred at the origin: a half circle from the south pole (v = 0) to
/// the north pole (v = 1) revolved about z. Degree 2 × 2, 9 × 5 control points, 8 Bézier
/// patches, with collapsed edges at the poles.
pub fn sphere(radius: f64) -> Result<NurbsSurface, GeomError> {
    let w = FRAC_1_SQRT_2;
    let half = [
        (0., -radius, 1.),
        (radius, -radius, w),
        (radius, 0., 1.),
        (radius, radius, w),
        (0., radius, 1.),
    ];
    revolution(vec![0., 0., 0., 0.5, 0.5, 1., 1., 1.], &half)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Samples every patch on a grid of its own [0,1]² (edges included) and returns the
    /// largest relative error of the implicit equation `f(p)` against `target`.
    fn worst_relative_error(s: &NurbsSurface, f: impl Fn(DVec3) -> f64, target: f64) -> f64 {
        let steps = 16;
        let mut worst: f64 = 0.0;
        for patch in s.to_bezier_patches() {
            for i in 0..=steps {
                for j in 0..=steps {
                    let p = patch.eval(i as f64 / steps as f64, j as f64 / steps as f64);
                    worst = worst.max(((f(p) - target) / target).abs());
                }
            }
        }
        worst
    }

    #[test]
    fn torus_patches_lie_on_the_torus() {
        let (major, minor) = (2.0, 0.5);
        let s = torus(major, minor).unwrap();
        assert_eq!(s.to_bezier_patches().len(), 16);
        let implicit = |p: DVec3| (p.x.hypot(p.y) - major).powi(2) + p.z * p.z;
        let err = worst_relative_error(&s, implicit, minor * minor);
        assert!(err <= 1e-12, "relative error {err}");
    }

    #[test]
    fn sphere_patches_lie_on_the_sphere() {
        let s = sphere(1.5).unwrap();
        assert_eq!(s.to_bezier_patches().len(), 8);
        let err = worst_relative_error(&s, |p| p.length_squared(), 1.5 * 1.5);
        assert!(err <= 1e-12, "relative error {err}");
    }

    #[test]
    fn torus_parameterisation_is_the_circle_product() {
        // Quadrant boundaries are the exact axis points of both circles.
        let s = torus(3.0, 1.0).unwrap();
        assert!((s.eval(0.25, 0.0) - DVec3::new(0.0, 4.0, 0.0)).length() < 1e-15);
        assert!((s.eval(0.5, 0.5) - DVec3::new(-2.0, 0.0, 0.0)).length() < 1e-15);
        assert!((s.eval(0.75, 0.75) - DVec3::new(0.0, -3.0, -1.0)).length() < 1e-15);
    }
}
