use std::f64::consts::TAU;

use super::*;
use crate::geom::nurbs::shapes;

/// A cylinder of radius `r` about z in closed form: `(r cos u, r sin u, v)`, u 2π-periodic.
struct Cylinder {
    r: f64,
}

impl ParamSurface for Cylinder {
    fn point(&self, uv: DVec2) -> DVec3 {
        DVec3::new(self.r * uv.x.cos(), self.r * uv.x.sin(), uv.y)
    }

    fn parameters(&self, p: DVec3) -> Option<DVec2> {
        Some(DVec2::new(p.y.atan2(p.x), p.z))
    }

    fn periods(&self) -> [Option<f64>; 2] {
        [Some(TAU), None]
    }
}

/// The same tolerance for chords and for collapsed parameters.
fn both(t: f64) -> Tolerance {
    Tolerance { chord: t, point: t }
}

#[test]
fn a_helix_crossing_the_seam_stays_continuous() {
    // The helix (r cos t, r sin t, c t) is u = t, v = c t on the cylinder: it crosses the
    // seam (u = ±π) three times, and must come out as one increasing line, not jumps.
    let (r, c) = (2.0, 0.3);
    let s = Cylinder { r };
    let helix = |t: f64| DVec3::new(r * t.cos(), r * t.sin(), c * t);
    let p = project(&s, helix, 0.5, 0.5 + 3.0 * TAU, both(1e-9)).unwrap();
    assert!(p.gap.max(p.chord) < 1e-12, "{p:?}");
    assert!((p.points[0] - DVec2::new(0.5, 0.5 * c)).length() < 1e-12);
    for w in p.points.windows(2) {
        assert!(
            w[1].x > w[0].x,
            "u runs on across the seam: {} {}",
            w[0],
            w[1]
        );
        // Every vertex on the line v = c u (closed form).
        assert!((w[1].y - c * w[1].x).abs() < 1e-12, "{}", w[1]);
    }
    let end = *p.points.last().unwrap();
    assert!((end.x - (0.5 + 3.0 * TAU)).abs() < 1e-12, "{end}");
}

#[test]
fn a_tilted_circle_on_a_nurbs_sphere_lands_on_it() {
    // The circle cut from the sphere of radius r by the plane n · q = h, tilted so that it
    // follows no iso-line: its projection's chords, mapped back onto the NURBS, must stay
    // within the tolerance of that plane (closed form; every surface point is on the
    // sphere, so the plane alone places it on the circle).
    let (r, h) = (1.5, 0.6);
    let n = DVec3::new(0.3, -0.2, 1.0).normalize();
    let e1 = n.cross(DVec3::X).normalize();
    let e2 = n.cross(e1);
    let sphere = shapes::sphere(r).unwrap();
    let target = NurbsTarget::new(&sphere);
    let rho = (r * r - h * h).sqrt();
    let circle = |t: f64| h * n + rho * (t.cos() * e1 + t.sin() * e2);
    let tol = 1e-6;
    let p = project(&target, circle, 0.2, 0.2 + 1.5, both(tol)).unwrap();
    assert!(p.gap.max(p.chord) <= tol, "{p:?}");
    assert!(p.points.len() > 5, "refined: {} points", p.points.len());
    for w in p.points.windows(2) {
        for k in 0..=4 {
            let uv = w[0].lerp(w[1], k as f64 / 4.0);
            let q = sphere.eval(uv.x, uv.y);
            let off = (n.dot(q) - h).abs();
            assert!(off <= 2.0 * tol, "{q} is {off} off the circle");
        }
    }
}

#[test]
fn a_curve_off_the_surface_is_told_apart_from_the_chords_error() {
    // A circle of radius r + d about the cylinder's axis lies d from the cylinder of
    // radius r everywhere (closed form); its projection is the line v = h, whose chords
    // are exact. The gap must be d, the chord error below the tolerance.
    let (r, d, h) = (2.0, 3e-3, 0.7);
    let s = Cylinder { r };
    let circle = |t: f64| DVec3::new((r + d) * t.cos(), (r + d) * t.sin(), h);
    let p = project(&s, circle, 0.0, 2.0, both(1e-9)).unwrap();
    assert!((p.gap - d).abs() < 1e-12, "{p:?}");
    assert!(p.chord <= 1e-9, "{p:?}");
}

/// The unit sphere in closed form: `(cos v cos u, cos v sin u, sin v)`, u 2π-periodic,
/// the poles at v = ±π/2.
struct Sphere;

impl ParamSurface for Sphere {
    fn point(&self, uv: DVec2) -> DVec3 {
        DVec3::new(uv.y.cos() * uv.x.cos(), uv.y.cos() * uv.x.sin(), uv.y.sin())
    }

    fn parameters(&self, p: DVec3) -> Option<DVec2> {
        Some(DVec2::new(p.y.atan2(p.x), p.z.atan2(p.x.hypot(p.y))))
    }

    fn periods(&self) -> [Option<f64>; 2] {
        [Some(TAU), None]
    }
}

#[test]
fn a_meridian_from_the_pole_keeps_its_longitude() {
    // The meridian u = 1 from the north pole to the equator: at the pole any u is the
    // same point, and the projection must take the meridian's (closed form: u = 1,
    // v = π/2 − t), not whatever atan2(0, 0) gives, or its first chord would cut across.
    let u = 1.0_f64;
    let meridian = |t: f64| Sphere.point(DVec2::new(u, std::f64::consts::FRAC_PI_2 - t));
    let p = project(&Sphere, meridian, 0.0, 1.5, both(1e-9)).unwrap();
    assert!(p.gap.max(p.chord) < 1e-12, "{p:?}");
    for q in &p.points {
        assert!((q.x - u).abs() < 1e-12, "{q}");
    }
    assert!(
        p.points.len() < 100,
        "no refinement at the pole: {}",
        p.points.len()
    );
}

#[test]
fn a_half_circle_through_the_pole_turns_along_the_pole_line() {
    // The great half circle from the equator at u = π over the south pole to the equator
    // at u = 0: in closed form its pcurve is the meridian u = π down to v = −π/2, the pole
    // line from u = π to u = 0 (mod 2π), and the meridian u = 0 back up. Samples near the
    // pole have no meaningful u; they must not give the polyline a chord cutting across
    // the corner and a spur down the far meridian.
    use std::f64::consts::{FRAC_PI_2, PI};
    let half = |t: f64| DVec3::new(-t.cos(), 0.0, -t.sin());
    for tol in [1e-9, 1e-4, 1e-3] {
        let p = project(&Sphere, half, 0.0, PI, both(tol)).unwrap();
        let turn = p
            .points
            .windows(2)
            .position(|w| (w[1].x - w[0].x).abs() > 1.0)
            .expect("the polyline crosses to the other meridian");
        let (before, after) = p.points.split_at(turn + 1);
        let on = |q: &DVec2, u: f64| (q.x - u).rem_euclid(TAU).min((u - q.x).rem_euclid(TAU));
        for q in before {
            assert!(on(q, PI) < 1e-12, "tol {tol}: {q} arrives off u = π");
        }
        for q in after {
            assert!(on(q, 0.0) < 1e-12, "tol {tol}: {q} leaves off u = 0");
        }
        // The crossing runs along the pole's line, within the point tolerance of it.
        let (a, b) = (before[before.len() - 1], after[0]);
        assert_eq!(a.y, b.y, "tol {tol}: the crossing {a} -> {b} cuts across");
        assert!(
            Sphere.point(a).distance(DVec3::NEG_Z) <= tol.max(1e-12),
            "tol {tol}: {a}"
        );
        // Latitude falls to the pole and rises after it: no spur doubling back.
        assert!(
            before.windows(2).all(|w| w[1].y < w[0].y),
            "tol {tol}: {before:?}"
        );
        assert!(
            after.windows(2).all(|w| w[1].y > w[0].y),
            "tol {tol}: {after:?}"
        );
        assert!((a.y + FRAC_PI_2).abs() < 1e-3, "tol {tol}: {a}");
    }
}

/// A long, thin, tapering tube whose rings are tilted against its axis, as CAD systems
/// write a lofted rod: degree 1 along its length (u, clamped), and around it (v) an
/// unclamped uniform closed cubic B-spline over `N` control points on a circle, domain
/// [0, 1] inside knots from −3/N to 1 + 3/N. Its patches are about a hundred times
/// longer than wide, and a sample ring of the inverter's start grid passes a point
/// between rings on the wrong side of the tube.
fn tilted_tube() -> (NurbsSurface, impl Fn(usize) -> [DVec3; 2]) {
    const N: usize = 32;
    let (length, radius, tilt, taper) = (100.0, 1.5, 20.0, 0.5);
    let ring = |m: usize| {
        let a = TAU * m as f64 / N as f64;
        DVec3::new(0.0, radius * a.cos(), radius * a.sin())
    };
    let far = move |q: DVec3| DVec3::new(length + tilt * taper * q.y, taper * q.y, taper * q.z);
    let points = (0..N + 3)
        .flat_map(|m| [ring(m).extend(1.0), far(ring(m)).extend(1.0)])
        .collect();
    let knots_v = (0..N + 7).map(|i| (i as f64 - 3.0) / N as f64).collect();
    let s = NurbsSurface::new(1, 3, vec![0.0, 0.0, 1.0, 1.0], knots_v, 2, N + 3, points).unwrap();
    // The ends of the iso-line v = c / N, in closed form: at a knot a uniform cubic
    // B-spline is (Q_c + 4 Q_{c+1} + Q_{c+2}) / 6, on the circle of radius
    // r (2 + cos(2π/N)) / 3 at angle 2π (c + 1) / N, and the surface is affine in u.
    let iso = move |c: usize| {
        let a = TAU * (c + 1) as f64 / N as f64;
        let rho = radius * (2.0 + (TAU / N as f64).cos()) / 3.0;
        let near = DVec3::new(0.0, rho * a.cos(), rho * a.sin());
        [near, far(near)]
    };
    (s, iso)
}

#[test]
fn iso_lines_of_a_thin_unclamped_closed_tube_project_onto_themselves() {
    // The straight line between the ends of the iso-line v = c / N is that iso-line, with
    // u its own parameter: every projected vertex must have v = c / N, and points along
    // it must invert to (t, c / N).
    let (s, iso) = tilted_tube();
    let target = NurbsTarget::new(&s);
    let n = 32;
    for c in 1..n {
        let v = c as f64 / n as f64;
        let [a, b] = iso(c);
        let line = |t: f64| a.lerp(b, t);
        for k in 0..=16 {
            let t = k as f64 / 16.0;
            let uv = target.parameters(line(t)).unwrap();
            assert!(
                (uv - DVec2::new(t, v)).length() < 1e-9,
                "v = {v}, t = {t}: {uv}"
            );
        }
        let p = project(&target, line, 0.0, 1.0, both(1e-6)).unwrap();
        assert!(p.gap.max(p.chord) < 1e-9, "v = {v}: {p:?}");
        assert!(
            (p.points[0] - DVec2::new(0.0, v)).length() < 1e-9,
            "v = {v}"
        );
        let end = *p.points.last().unwrap();
        assert!((end - DVec2::new(1.0, v)).length() < 1e-9, "v = {v}: {end}");
        for q in &p.points {
            assert!((q.y - v).abs() < 1e-9, "v = {v}: {q}");
        }
    }
}
