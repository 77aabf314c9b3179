//! Every shape against its closed form in f64: points of the NURBS at sampled parameters,
//! mapped to the analytic parameters by the returned `AxisMap`s, must be the analytic
//! formula's points to 1e-12 of the shape's size.

use std::f64::consts::{FRAC_PI_2, PI, TAU};

use glam::{DQuat, DVec3, DVec4};

use super::*;

const REL: f64 = 1e-12;

fn tilted() -> Frame {
    Frame::new(
        DVec3::new(1.0, -2.0, 0.5),
        DVec3::new(0.3, 0.4, 1.0),
        Some(DVec3::new(1.0, 0.2, -0.1)),
    )
    .unwrap()
}

fn assert_close(a: DVec3, b: DVec3, scale: f64, what: &str) {
    let e = (a - b).length();
    assert!(e <= REL * scale, "{what}: {a} vs {b}, error {e:e}");
}

/// Samples the surface's domain on a grid including its edges and compares each point with
/// `exact(analytic u, analytic v)`.
fn check_surface((s, maps): &MappedSurface, exact: impl Fn(f64, f64) -> DVec3, scale: f64) {
    let d = s.domain();
    let n = 12;
    for i in 0..=n {
        for j in 0..=n {
            let (u, v) = d.to_parent(i as f64 / n as f64, j as f64 / n as f64);
            let want = exact(maps[0].apply(u), maps[1].apply(v));
            assert_close(s.eval(u, v), want, scale, &format!("at ({u}, {v})"));
        }
    }
}

fn check_curve(c: &NurbsCurve, map: &AxisMap, exact: impl Fn(f64) -> DVec3, scale: f64) {
    let (t0, t1) = crate::geom::nurbs::knots::domain(c.degree, &c.knots);
    for k in 0..=40 {
        let t = t0 + (t1 - t0) * k as f64 / 40.0;
        assert_close(c.eval(t), exact(map.apply(t)), scale, &format!("at {t}"));
    }
}

#[test]
fn frame_is_orthonormal_and_keeps_the_reference_plane() {
    let f = tilted();
    for (a, b) in [(f.x, f.y), (f.y, f.z), (f.z, f.x)] {
        assert!(a.dot(b).abs() < 1e-15);
    }
    assert!((f.x.cross(f.y) - f.z).length() < 1e-15);
    // x lies in the plane of the axis and the reference.
    let n = DVec3::new(0.3, 0.4, 1.0).cross(DVec3::new(1.0, 0.2, -0.1));
    assert!(f.x.dot(n).abs() < 1e-15);
    // A reference parallel to the axis falls back to a perpendicular one.
    let g = Frame::new(DVec3::ZERO, DVec3::Z, Some(DVec3::Z * 2.0)).unwrap();
    assert!(g.x.dot(DVec3::Z).abs() < 1e-15 && (g.x.length() - 1.0).abs() < 1e-15);
    assert!(Frame::new(DVec3::ZERO, DVec3::ZERO, None).is_err());
}

#[test]
fn circle_arcs_of_any_range_are_exact_and_split_at_most_90_degrees() {
    let f = tilted();
    for (a0, a1) in [
        (0.0, TAU),
        (0.3, 0.5),
        (-1.0, 2.5),
        (PI, PI + FRAC_PI_2),
        (-PI, PI),
    ] {
        let (c, map) = circle_arc(&f, 2.5, a0, a1).unwrap();
        let exact = |t: f64| f.point(2.5 * t.cos(), 2.5 * t.sin(), 0.0);
        check_curve(&c, &map, exact, 2.5);
        let AxisMap::Arcs { breaks, angles } = &map else {
            panic!("an arc maps by arcs")
        };
        assert_eq!(breaks, angles);
        assert_eq!((angles[0], *angles.last().unwrap()), (a0, a1));
        assert!(
            angles
                .windows(2)
                .all(|w| w[1] - w[0] <= FRAC_PI_2 * (1.0 + 1e-15))
        );
        // The NURBS parameter is the angle at the piece ends.
        for &a in angles {
            assert_close(c.eval(a), exact(a), 2.5, "break");
        }
    }
    assert!(circle_arc(&f, 1.0, 0.0, TAU + 1e-3).is_err());
    assert!(circle_arc(&f, 1.0, 1.0, 1.0).is_err());
    assert!(circle_arc(&f, -1.0, 0.0, 1.0).is_err());
}

#[test]
fn ellipse_arc_is_the_affine_circle() {
    let f = tilted();
    let (c, map) = ellipse_arc(&f, 3.0, 0.5, [-0.7, 4.0]).unwrap();
    check_curve(
        &c,
        &map,
        |t| f.point(3.0 * t.cos(), 0.5 * t.sin(), 0.0),
        3.0,
    );
}

#[test]
fn hyperbola_and_parabola_lie_on_their_conics() {
    let f = tilted();
    let h = hyperbola_arc(&f, 2.0, 0.5, [-1.2, 0.7]).unwrap();
    for k in 0..=20 {
        let p = h.eval(-1.2 + 1.9 * k as f64 / 20.0) - f.origin;
        let (x, y) = (p.dot(f.x) / 2.0, p.dot(f.y) / 0.5);
        assert!((x * x - y * y - 1.0).abs() < 1e-12, "k = {k}");
        assert!(p.dot(f.z).abs() < 1e-14 && x > 0.0);
    }
    assert_close(
        h.eval(-1.2),
        f.point(2.0 * 1.2f64.cosh(), -0.5 * 1.2f64.sinh(), 0.0),
        3.0,
        "end",
    );
    let p = parabola_arc(&f, 0.3, -2.0, 1.5).unwrap();
    check_curve(
        &p,
        &AxisMap::Identity,
        |t| f.point(0.3 * t * t, t, 0.0),
        2.0,
    );
}

#[test]
fn plane_and_line() {
    let f = tilted();
    let s = plane(&f, -1.0, 2.0, 0.5, 3.0).unwrap();
    check_surface(&s, |u, v| f.point(u, v, 0.0), 3.0);
    let l = line_segment(DVec3::X, DVec3::Y * 3.0, 2.0, 4.0).unwrap();
    check_curve(
        &l,
        &AxisMap::Identity,
        |t| DVec3::X.lerp(DVec3::Y * 3.0, (t - 2.0) / 2.0),
        3.0,
    );
}

#[test]
fn cylinder_cone_sphere_torus_match_iso_10303_42() {
    let f = tilted();
    let around = |rho: f64, u: f64, z: f64| f.point(rho * u.cos(), rho * u.sin(), z);
    let cyl = cylinder(&f, 1.5, [0.2, 5.0], [-1.0, 2.0]).unwrap();
    check_surface(&cyl, |u, v| around(1.5, u, v), 3.0);
    let alpha = 0.4f64;
    let con = cone(&f, 1.0, alpha, [-PI, PI], [-2.0, 1.0]).unwrap();
    check_surface(&con, |u, v| around(1.0 + v * alpha.tan(), u, v), 3.0);
    let sph = sphere(&f, 2.0, [0.0, TAU], [-FRAC_PI_2, FRAC_PI_2]).unwrap();
    check_surface(&sph, |u, v| around(2.0 * v.cos(), u, 2.0 * v.sin()), 2.0);
    let part = sphere(&f, 2.0, [1.0, 2.0], [-0.3, 1.2]).unwrap();
    check_surface(&part, |u, v| around(2.0 * v.cos(), u, 2.0 * v.sin()), 2.0);
    let tor = torus(&f, 3.0, 0.75, [0.0, TAU], [-PI, 2.0]).unwrap();
    check_surface(
        &tor,
        |u, v| around(3.0 + 0.75 * v.cos(), u, 0.75 * v.sin()),
        4.0,
    );
    // 16 patches for the full torus (four quadrants each way), as the 9-point circle.
    let full = torus(&f, 3.0, 0.75, [0.0, TAU], [0.0, TAU]).unwrap();
    assert_eq!(full.0.to_bezier_patches().len(), 16);
}

/// A rational cubic profile away from the axis.
fn profile() -> NurbsCurve {
    let pts = [
        (DVec3::new(1.0, 0.0, 0.0), 1.0),
        (DVec3::new(2.0, 0.5, 1.0), 0.5),
        (DVec3::new(1.5, -0.3, 2.0), 2.0),
        (DVec3::new(0.8, 0.2, 2.5), 1.0),
        (DVec3::new(1.2, 0.0, 3.5), 1.0),
    ];
    NurbsCurve {
        degree: 3,
        knots: vec![0.0, 0.0, 0.0, 0.0, 0.4, 1.0, 1.0, 1.0, 1.0],
        points: pts.iter().map(|&(p, w)| (p * w).extend(w)).collect(),
    }
}

#[test]
fn revolution_rotates_the_profile_by_the_angle() {
    let c = profile();
    let (axis_point, axis) = (DVec3::new(0.1, -0.2, 0.0), DVec3::new(0.1, 0.05, 1.0));
    let s = revolution(&c, axis_point, axis, -0.5, 4.0).unwrap();
    let q = |angle: f64| DQuat::from_axis_angle(axis.normalize(), angle);
    check_surface(&s, |u, v| axis_point + q(u) * (c.eval(v) - axis_point), 4.0);
}

#[test]
fn extrusion_translates_the_curve() {
    let c = profile();
    let d = DVec3::new(0.3, -1.0, 0.2);
    let s = extrusion(&c, d, 0.0, 2.0).unwrap();
    check_surface(&s, |u, v| c.eval(u) + d * v, 4.0);
}

#[test]
fn ruled_surface_joins_curves_of_different_degree_and_breaks() {
    // Polynomial curves: the correspondence is linear in both parameters.
    let a = NurbsCurve {
        points: profile()
            .points
            .iter()
            .map(|p| (p.truncate() / p.w).extend(1.0))
            .collect(),
        ..profile()
    };
    let b = NurbsCurve {
        degree: 2,
        knots: vec![2.0, 2.0, 2.0, 2.5, 3.0, 3.0, 3.0],
        points: [(0., 0., 5.), (1., 2., 5.), (3., 1., 6.), (4., 0., 5.)]
            .map(|(x, y, z)| DVec4::new(x, y, z, 1.0))
            .to_vec(),
    };
    let s = ruled(&a, &b).unwrap();
    check_surface(&s, |u, v| a.eval(u) * (1.0 - v) + b.eval(2.0 + u) * v, 6.0);
    // Rational rows: every point lies on the ruling between the curves' points.
    let (c, _) = circle_arc(&tilted(), 1.0, 0.0, 3.0).unwrap();
    let (r, _) = ruled(&c, &b).unwrap();
    for k in 0..=10 {
        let u = k as f64 / 10.0;
        let (p0, p1) = (c.eval(3.0 * u), b.eval(2.0 + u));
        let m = r.eval(u, 0.37);
        let off = (m - p0).cross(p1 - p0).length() / (p1 - p0).length();
        assert!(off < 1e-12 * 6.0, "u = {u}: {off:e} off the ruling");
        assert_close(r.eval(u, 0.0), p0, 6.0, "v = 0");
        assert_close(r.eval(u, 1.0), p1, 6.0, "v = 1");
    }
}
