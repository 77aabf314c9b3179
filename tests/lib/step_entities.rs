//! STEP entities, one small file each (written by `step_support`): every converted face's
//! NURBS, read through its `trim_space` maps, must agree with the entity's definition
//! evaluated here in f64 from the closed form of ISO 10303-42 (or an independent
//! Cox–de Boor), to 1e-12 relative; its trim loops must span the parameter rectangle the
//! face's edges bound.

use crate::step_support;

use std::f64::consts::{PI, TAU};
use std::path::Path;

use glam::{DQuat, DVec2, DVec3, DVec4};
use patchtrace::formats::cad::step::{StepModel, read_step_str};
use patchtrace::geom::nurbs::NurbsCurve;
use patchtrace::geom::trim::TrimLoop;
use patchtrace::scene::model::{Geometry, Surface, SurfaceGeometry};
use step_support::{StepWriter, basis, expand};

fn read(text: &str) -> StepModel {
    read_step_str(Path::new("test.step"), text).unwrap_or_else(|e| panic!("{e}\n{text}"))
}

/// The surfaces of the model, each of whose loops is checked to be a chain: every segment
/// starts (at t0) where the previous one ends (at t1), and the last ends at the first's
/// start, as `geom::trim` reads loops (a gap would be bridged by a straight piece there).
fn surfaces(m: &StepModel) -> Vec<Surface> {
    let out: Vec<Surface> = m
        .objects
        .iter()
        .flat_map(|o| match &o.geometry {
            Geometry::Surfaces(s) => s.clone(),
            _ => Vec::new(),
        })
        .collect();
    for s in &out {
        for l in &s.trims {
            let ends: Vec<(DVec2, DVec2)> = l
                .segments
                .iter()
                .map(|seg| {
                    let c = as_curve(&seg.curve);
                    (c.eval(seg.t0).truncate(), c.eval(seg.t1).truncate())
                })
                .collect();
            for k in 0..ends.len() {
                let next = ends[(k + 1) % ends.len()].0;
                let gap = (ends[k].1 - next).length();
                assert!(gap < 1e-9, "segment {k} ends {} from the next start", gap);
            }
        }
    }
    out
}

fn as_curve(c: &patchtrace::geom::trim::ParamCurve) -> NurbsCurve {
    NurbsCurve {
        degree: c.degree,
        knots: c.knots.clone(),
        points: c
            .points
            .iter()
            .map(|p| DVec4::new(p.x, p.y, 0.0, p.z))
            .collect(),
    }
}

fn only_surface(text: &str) -> Surface {
    let m = read(text);
    assert!(
        m.report.failed_faces.is_empty(),
        "{:?}",
        m.report.failed_faces
    );
    let s = surfaces(&m);
    assert_eq!(s.len(), 1);
    s.into_iter().next().unwrap()
}

/// Largest distance, relative to `scale`, between the NURBS at a 9 × 9 grid of its domain
/// and the definition at the mapped parameters.
fn worst_error(s: &Surface, def: impl Fn(f64, f64) -> DVec3, scale: f64) -> f64 {
    let SurfaceGeometry::Nurbs(n) = &s.geometry else {
        panic!("expected a NURBS surface")
    };
    let d = n.domain();
    let mut worst: f64 = 0.0;
    for i in 0..=8 {
        for j in 0..=8 {
            let su = d.u0 + (d.u1 - d.u0) * i as f64 / 8.0;
            let sv = d.v0 + (d.v1 - d.v0) * j as f64 / 8.0;
            let (u, v) = (s.trim_space[0].apply(su), s.trim_space[1].apply(sv));
            worst = worst.max(n.eval(su, sv).distance(def(u, v)) / scale);
        }
    }
    worst
}

/// The NURBS domain in trim (definition) parameters.
fn mapped_domain(s: &Surface) -> (DVec2, DVec2) {
    let SurfaceGeometry::Nurbs(n) = &s.geometry else {
        panic!("expected a NURBS surface")
    };
    let d = n.domain();
    (
        DVec2::new(s.trim_space[0].apply(d.u0), s.trim_space[1].apply(d.v0)),
        DVec2::new(s.trim_space[0].apply(d.u1), s.trim_space[1].apply(d.v1)),
    )
}

/// Points along a loop (each segment at 33 parameters), in trim space.
fn loop_points(l: &TrimLoop) -> Vec<DVec2> {
    let mut out = Vec::new();
    for seg in &l.segments {
        let c = as_curve(&seg.curve);
        for k in 0..=32 {
            out.push(
                c.eval(seg.t0 + (seg.t1 - seg.t0) * k as f64 / 32.0)
                    .truncate(),
            );
        }
    }
    out
}

fn assert_close(a: DVec2, b: DVec2, tol: f64, what: &str) {
    assert!((a - b).abs().max_element() <= tol, "{what}: {a} vs {b}");
}

/// Orthonormal frame as ISO 10303-42 builds it from axis and ref_direction.
fn frame(z: DVec3, x: DVec3) -> (DVec3, DVec3, DVec3) {
    let z = z.normalize();
    let x = (x - x.dot(z) * z).normalize();
    (x, z.cross(x), z)
}

/// A plane through (1, 2, 3) with normal (1, 1, 1) and x along (1, −1, 0): its origin,
/// axis, reference direction and its point at parameters (u, v) by ISO 10303-42.
fn tilted_plane() -> (DVec3, DVec3, DVec3, impl Fn(f64, f64) -> DVec3) {
    let (o, zd, xd) = (
        DVec3::new(1.0, 2.0, 3.0),
        DVec3::ONE,
        DVec3::new(1.0, -1.0, 0.0),
    );
    let (x, y, _) = frame(zd, xd);
    (o, zd, xd, move |u: f64, v: f64| o + u * x + v * y)
}

#[test]
fn plane_face_matches_the_definition() {
    let (o, zd, xd, at) = tilted_plane();
    let mut w = StepWriter::default();
    let ax = w.axis(o, zd, xd);
    let plane = w.add(format!("PLANE('',#{ax})"));
    let b = w.polygon_bound(
        &[at(-1.0, 0.5), at(2.0, 0.5), at(2.0, 1.5), at(-1.0, 1.5)],
        true,
    );
    w.face(&[b], plane);
    let s = only_surface(&w.finish());
    assert!(worst_error(&s, at, 4.0) <= 1e-12);
    let (lo, hi) = mapped_domain(&s);
    assert_close(lo, DVec2::new(-1.0, 0.5), 1e-12, "domain low");
    assert_close(hi, DVec2::new(2.0, 1.5), 1e-12, "domain high");
    assert_eq!(s.trims.len(), 1);
}

/// A plane's edges map exactly through its frame: a circular hole (no pcurve) in a tilted
/// plane becomes a rational loop whose every point lies at the circle's radius from its
/// centre in the plane's parameters, to 1e-12 (a projected polyline's chords would fall
/// inside by up to the chord tolerance).
#[test]
fn a_circle_on_a_plane_becomes_an_exact_rational_loop() {
    let (o, zd, xd, at) = tilted_plane();
    let (c, r) = (DVec2::new(0.5, 0.25), 0.75);
    let mut w = StepWriter::default();
    let ax = w.axis(o, zd, xd);
    let plane = w.add(format!("PLANE('',#{ax})"));
    let outer = w.polygon_bound(
        &[at(-2.0, -2.0), at(2.0, -2.0), at(2.0, 2.0), at(-2.0, 2.0)],
        true,
    );
    let hole = w.circle_bound(at(c.x, c.y), zd, DVec3::new(0.3, 0.7, -1.0), r, false);
    w.face(&[outer, hole], plane);
    let s = only_surface(&w.finish());
    let hole = s.trims.iter().find(|l| l.hole).expect("the hole loop");
    // Off the knots (a polyline's samples at its vertices would lie on the circle too).
    let points = hole.segments.iter().flat_map(|seg| {
        let c = as_curve(&seg.curve);
        (0..997).map(move |k| {
            c.eval(seg.t0 + (seg.t1 - seg.t0) * (k as f64 + 0.5) / 997.0)
                .truncate()
        })
    });
    for p in points {
        let off = ((p - c).length() - r).abs();
        assert!(off <= 1e-12, "a loop point {p} is {off} off the circle");
    }
}

#[test]
fn cylinder_face_with_arcs_and_lines() {
    let (o, r) = (DVec3::new(0.5, 0.0, -1.0), 2.0);
    let (zd, xd) = (DVec3::new(0.0, 0.6, 0.8), DVec3::X);
    let (x, y, z) = frame(zd, xd);
    let at = |u: f64, v: f64| o + r * (u.cos() * x + u.sin() * y) + v * z;
    let mut w = StepWriter::default();
    let ax = w.axis(o, zd, xd);
    let cyl = w.add(format!(
        "CYLINDRICAL_SURFACE('',#{ax},{})",
        step_support::real(r)
    ));
    let (u0, u1, v1) = (0.3, 2.0, 3.0);
    let bottom_ax = w.axis(o, zd, xd);
    let bottom = w.circle(bottom_ax, r);
    let top_ax = w.axis(o + v1 * z, zd, xd);
    let top = w.circle(top_ax, r);
    let l1 = w.line(at(u1, 0.0), z);
    let l0 = w.line(at(u0, 0.0), z);
    let corners = [at(u0, 0.0), at(u1, 0.0), at(u1, v1), at(u0, v1)];
    w.rect_face(cyl, corners, [bottom, l1, top, l0]);
    let s = only_surface(&w.finish());
    assert!(worst_error(&s, at, r) <= 1e-12);
    let (lo, hi) = mapped_domain(&s);
    assert_close(lo, DVec2::new(u0, 0.0), 1e-9, "domain low");
    assert_close(hi, DVec2::new(u1, v1), 1e-9, "domain high");
    for p in loop_points(&s.trims[0]) {
        assert!(p.x >= u0 - 1e-9 && p.x <= u1 + 1e-9 && p.y >= -1e-9 && p.y <= v1 + 1e-9);
    }
}

/// A face bounded by a full circle at each end and a seam line traversed both ways, with
/// SEAM_CURVE pcurves at u = 0 and u = 2π: the loop is the rectangle [0, 2π] × [0, h].
#[test]
fn cylinder_seam_face_with_pcurves_spans_the_whole_turn() {
    let (r, h) = (1.0, 2.0);
    let mut w = StepWriter::default();
    let ax = w.axis(DVec3::ZERO, DVec3::Z, DVec3::X);
    let cyl = w.add(format!(
        "CYLINDRICAL_SURFACE('',#{ax},{})",
        step_support::real(r)
    ));
    let (v0, v1) = (
        w.vertex(DVec3::new(r, 0.0, 0.0)),
        w.vertex(DVec3::new(r, 0.0, h)),
    );
    let bax = w.axis(DVec3::ZERO, DVec3::Z, DVec3::X);
    let bottom = w.circle(bax, r);
    let tax = w.axis(DVec3::new(0.0, 0.0, h), DVec3::Z, DVec3::X);
    let top = w.circle(tax, r);
    let seam3 = w.line(DVec3::new(r, 0.0, 0.0), DVec3::Z);
    let pcurve = |w: &mut StepWriter, u: f64| {
        let l = w.line2(DVec2::new(u, 0.0), DVec2::Y);
        let rep = w.add(format!("DEFINITIONAL_REPRESENTATION('',(#{l}),#{l})"));
        w.add(format!("PCURVE('',#{cyl},#{rep})"))
    };
    let (p0, p1) = (pcurve(&mut w, 0.0), pcurve(&mut w, TAU));
    let seam = w.add(format!("SEAM_CURVE('',#{seam3},(#{p0},#{p1}),.PCURVE_S1.)"));
    let eb = w.edge(v0, v0, bottom, true);
    let et = w.edge(v1, v1, top, true);
    let es = w.edge(v0, v1, seam, true);
    let b = w.quad_bound(eb, es, et, es);
    w.face(&[b], cyl);
    let m = read(&w.finish());
    assert_eq!(m.report.projected_edges, 2, "the circles have no pcurves");
    let s = surfaces(&m).remove(0);
    let (lo, hi) = mapped_domain(&s);
    assert_close(lo, DVec2::new(0.0, 0.0), 1e-12, "domain low");
    assert_close(hi, DVec2::new(TAU, h), 1e-12, "domain high");
    let pts = loop_points(&s.trims[0]);
    let on_u = |u: f64| pts.iter().filter(|p| (p.x - u).abs() < 1e-12).count();
    assert!(on_u(0.0) >= 33 && on_u(TAU) >= 33, "both sides of the seam");
    assert!(worst_error(&s, |u, v| DVec3::new(r * u.cos(), r * u.sin(), v), r) <= 1e-12);
}

/// A periodic face bounded by two full circles without a seam edge (some writers do this):
/// two loops that each wind once, closed beyond the v range.
#[test]
fn cylinder_band_of_two_winding_loops() {
    let mut w = StepWriter::default();
    let ax = w.axis(DVec3::ZERO, DVec3::Z, DVec3::X);
    let cyl = w.add(format!(
        "CYLINDRICAL_SURFACE('',#{ax},{})",
        step_support::real(1.0)
    ));
    let b0 = w.circle_bound(DVec3::ZERO, DVec3::Z, DVec3::X, 1.0, true);
    let b1 = w.circle_bound(DVec3::new(0.0, 0.0, 1.5), DVec3::Z, DVec3::X, 1.0, false);
    w.face(&[b0, b1], cyl);
    let s = only_surface(&w.finish());
    let (lo, hi) = mapped_domain(&s);
    assert_close(lo, DVec2::new(0.0, 0.0), 1e-9, "domain low");
    assert_close(hi, DVec2::new(TAU, 1.5), 1e-9, "domain high");
    assert_eq!(s.trims.len(), 2);
    for l in &s.trims {
        let pts = loop_points(l);
        assert_close(pts[0], *pts.last().unwrap(), 1e-12, "closed loop");
        assert!(
            pts.iter().any(|p| p.y > 1.5 + 1.0),
            "closed beyond the range"
        );
    }
}

/// Iso-curves of the elementary surfaces of revolution as STEP curves: the circle of
/// constant v and the curve (circle or line) of constant u.
#[derive(Clone, Copy)]
enum Kind {
    Cone { r: f64, alpha: f64 },
    Sphere { r: f64 },
    Torus { big: f64, small: f64 },
}

#[test]
fn cone_sphere_and_torus_faces_match_their_definitions() {
    let (o, zd, xd) = (
        DVec3::new(0.0, 1.0, 2.0),
        DVec3::new(1.0, 0.0, 1.0),
        DVec3::Y,
    );
    let (x, y, z) = frame(zd, xd);
    let e = move |u: f64| u.cos() * x + u.sin() * y;
    let cases = [
        (Kind::Cone { r: 1.0, alpha: 0.3 }, [0.2, 1.9, 0.0, 2.0], 2.0),
        (Kind::Sphere { r: 1.5 }, [0.2, 1.4, -0.5, 0.7], 1.5),
        (
            Kind::Torus {
                big: 3.0,
                small: 1.0,
            },
            [0.1, 1.2, 0.5, 2.5],
            4.0,
        ),
    ];
    for (kind, [u0, u1, v0, v1], scale) in cases {
        // (height, radius) of the circle of constant v.
        let lat = move |v: f64| match kind {
            Kind::Cone { r, alpha } => (v, r + v * alpha.tan()),
            Kind::Sphere { r } => (r * v.sin(), r * v.cos()),
            Kind::Torus { big, small } => (small * v.sin(), big + small * v.cos()),
        };
        let def = move |u: f64, v: f64| {
            let (h, rho) = lat(v);
            o + rho * e(u) + h * z
        };
        let mut w = StepWriter::default();
        let ax = w.axis(o, zd, xd);
        let r = step_support::real;
        let (entity, name) = match kind {
            Kind::Cone { r: rc, alpha } => (
                format!("CONICAL_SURFACE('',#{ax},{},{})", r(rc), r(alpha)),
                "cone",
            ),
            Kind::Sphere { r: rs } => (format!("SPHERICAL_SURFACE('',#{ax},{})", r(rs)), "sphere"),
            Kind::Torus { big, small } => (
                format!("TOROIDAL_SURFACE('',#{ax},{},{})", r(big), r(small)),
                "torus",
            ),
        };
        let surf = w.add(entity);
        let iso_v = |w: &mut StepWriter, v: f64| {
            let (h, rho) = lat(v);
            let a = w.axis(o + h * z, zd, xd);
            w.circle(a, rho)
        };
        let iso_u = |w: &mut StepWriter, u: f64| match kind {
            Kind::Cone { .. } => w.line(def(u, 0.0), def(u, 1.0) - def(u, 0.0)),
            Kind::Sphere { r } => {
                let a = w.axis(o, e(u).cross(z), e(u));
                w.circle(a, r)
            }
            Kind::Torus { big, small } => {
                let a = w.axis(o + big * e(u), e(u).cross(z), e(u));
                w.circle(a, small)
            }
        };
        let curves = [
            iso_v(&mut w, v0),
            iso_u(&mut w, u1),
            iso_v(&mut w, v1),
            iso_u(&mut w, u0),
        ];
        w.rect_face(
            surf,
            [def(u0, v0), def(u1, v0), def(u1, v1), def(u0, v1)],
            curves,
        );
        let m = read(&w.finish());
        assert!(
            m.report.failed_faces.is_empty(),
            "{name}: {:?}",
            m.report.failed_faces
        );
        assert!(
            m.report.max_trim_error < 1e-12 * scale,
            "{name}: {}",
            m.report.max_trim_error
        );
        let s = surfaces(&m).remove(0);
        let err = worst_error(&s, def, scale);
        assert!(err <= 1e-12, "{name}: relative error {err}");
        let (lo, hi) = mapped_domain(&s);
        assert_close(lo, DVec2::new(u0, v0), 1e-9, name);
        assert_close(hi, DVec2::new(u1, v1), 1e-9, name);
    }
}

/// SURFACE_OF_REVOLUTION of a quadratic B-spline profile and SURFACE_OF_LINEAR_EXTRUSION
/// of an ELLIPSE, bounded by their iso-curves (B_SPLINE_CURVE_WITH_KNOTS, CIRCLE,
/// TRIMMED_CURVE of the ellipse by parameters or by points, LINE).
#[test]
fn revolution_and_extrusion_faces_match_their_definitions() {
    // Revolution: profile in the xz plane, axis z through the origin.
    let prof = [
        DVec3::new(1.0, 0.0, 0.0),
        DVec3::new(2.0, 0.0, 1.0),
        DVec3::new(1.5, 0.0, 2.0),
    ];
    let knots = [0.0, 0.0, 0.0, 1.0, 1.0, 1.0];
    let profile = move |t: f64| -> DVec3 { (0..3).map(|i| prof[i] * basis(i, 2, &knots, t)).sum() };
    let rev = move |u: f64, v: f64| DQuat::from_rotation_z(u) * profile(v);
    let mut w = StepWriter::default();
    let curve = |w: &mut StepWriter, pts: &[DVec3]| {
        let ids: Vec<String> = pts.iter().map(|&p| format!("#{}", w.point(p))).collect();
        w.add(format!(
            "B_SPLINE_CURVE_WITH_KNOTS('',2,({}),.UNSPECIFIED.,.F.,.F.,(3,3),(0.,1.),.UNSPECIFIED.)",
            ids.join(",")
        ))
    };
    let c0 = curve(&mut w, &prof);
    let u1 = 1.5f64;
    let rotated: Vec<DVec3> = prof
        .iter()
        .map(|&p| DQuat::from_rotation_z(u1) * p)
        .collect();
    let c1 = curve(&mut w, &rotated);
    let axis_p = w.point(DVec3::ZERO);
    let axis_d = w.dir(DVec3::Z);
    let a1 = w.add(format!("AXIS1_PLACEMENT('',#{axis_p},#{axis_d})"));
    let surf = w.add(format!("SURFACE_OF_REVOLUTION('',#{c0},#{a1})"));
    let corners = [rev(0.0, 0.0), rev(u1, 0.0), rev(u1, 1.0), rev(0.0, 1.0)];
    let low_ax = w.axis(DVec3::ZERO, DVec3::Z, DVec3::X);
    let low = w.circle(low_ax, 1.0);
    let high_ax = w.axis(DVec3::new(0.0, 0.0, 2.0), DVec3::Z, DVec3::X);
    let high = w.circle(high_ax, 1.5);
    w.rect_face(surf, corners, [low, c1, high, c0]);
    let s = only_surface(&w.finish());
    let err = worst_error(&s, rev, 2.0);
    assert!(err <= 1e-12, "revolution: relative error {err}");
    let (lo, hi) = mapped_domain(&s);
    assert_close(lo, DVec2::new(0.0, 0.0), 1e-9, "revolution low");
    assert_close(hi, DVec2::new(u1, 1.0), 1e-9, "revolution high");

    for by_point in [false, true] {
        // Extrusion of an ellipse arc along d.
        let (a, b_axis) = (2.0, 1.0);
        let d = DVec3::new(0.2, 0.0, 1.0) * 2.0;
        let ell = move |t: f64| DVec3::new(a * t.cos(), b_axis * t.sin(), 0.0);
        let ext = move |u: f64, v: f64| ell(u) + v * d;
        let mut w = StepWriter::default();
        let ax = w.axis(DVec3::ZERO, DVec3::Z, DVec3::X);
        let e = w.add(format!(
            "ELLIPSE('',#{ax},{},{})",
            step_support::real(a),
            step_support::real(b_axis)
        ));
        let dir = w.dir(d.normalize());
        let vec = w.add(format!(
            "VECTOR('',#{dir},{})",
            step_support::real(d.length())
        ));
        let surf = w.add(format!("SURFACE_OF_LINEAR_EXTRUSION('',#{e},#{vec})"));
        let (t0, t1) = (0.3, 2.0);
        // Trimmed by parameter values, or (as UG writes them) by the points alone.
        let trimmed = if by_point {
            let (p0, p1) = (w.point(ell(t0)), w.point(ell(t1)));
            w.add(format!(
                "TRIMMED_CURVE('',#{e},(#{p0}),(#{p1}),.T.,.CARTESIAN.)"
            ))
        } else {
            w.add(format!(
                "TRIMMED_CURVE('',#{e},(PARAMETER_VALUE({})),(PARAMETER_VALUE({})),.T.,.PARAMETER.)",
                step_support::real(t0),
                step_support::real(t1)
            ))
        };
        let ax_top = w.axis(d, DVec3::Z, DVec3::X);
        let e_top = w.add(format!(
            "ELLIPSE('',#{ax_top},{},{})",
            step_support::real(a),
            step_support::real(b_axis)
        ));
        let corners = [ext(t0, 0.0), ext(t1, 0.0), ext(t1, 1.0), ext(t0, 1.0)];
        let l1 = w.line(corners[1], d);
        let l0 = w.line(corners[0], d);
        w.rect_face(surf, corners, [trimmed, l1, e_top, l0]);
        let s = only_surface(&w.finish());
        let err = worst_error(&s, ext, 2.0);
        assert!(
            err <= 1e-12,
            "extrusion (by point {by_point}): relative error {err}"
        );
        let (lo, hi) = mapped_domain(&s);
        assert_close(lo, DVec2::new(t0, 0.0), 1e-9, "extrusion low");
        assert_close(hi, DVec2::new(t1, 1.0), 1e-9, "extrusion high");
    }
}

/// B_SPLINE_SURFACE_WITH_KNOTS (bicubic, non-uniform knots), its rational complex form,
/// and BEZIER_SURFACE, each bounded by its four boundary curves (B-spline curves, projected
/// by point inversion since no pcurves are given).
#[test]
fn bspline_rational_and_bezier_faces_match_cox_de_boor() {
    let net = |nu: usize, nv: usize| -> Vec<Vec<DVec3>> {
        (0..nu)
            .map(|i| {
                (0..nv)
                    .map(|j| {
                        let (x, y) = (i as f64, j as f64);
                        DVec3::new(x, y, 0.3 * (x * 1.3).sin() * (y * 0.7).cos())
                    })
                    .collect()
            })
            .collect()
    };
    let weights = |nu: usize, nv: usize| -> Vec<Vec<f64>> {
        (0..nu)
            .map(|i| {
                (0..nv)
                    .map(|j| 1.0 + 0.5 * ((i + 2 * j) % 3) as f64)
                    .collect()
            })
            .collect()
    };
    struct Case {
        degrees: (usize, usize),
        mu: Vec<usize>,
        ku: Vec<f64>,
        mv: Vec<usize>,
        kv: Vec<f64>,
        rational: bool,
        bezier: bool,
    }
    let cases = [
        Case {
            degrees: (3, 2),
            mu: vec![4, 1, 4],
            ku: vec![0.0, 0.3, 1.0],
            mv: vec![3, 2, 3],
            kv: vec![-1.0, 0.5, 2.0],
            rational: false,
            bezier: false,
        },
        Case {
            degrees: (2, 2),
            mu: vec![3, 1, 3],
            ku: vec![0.0, 0.6, 1.0],
            mv: vec![3, 3],
            kv: vec![0.0, 1.0],
            rational: true,
            bezier: false,
        },
        Case {
            degrees: (3, 2),
            mu: vec![4, 4],
            ku: vec![0.0, 1.0],
            mv: vec![3, 3],
            kv: vec![0.0, 1.0],
            rational: false,
            bezier: true,
        },
    ];
    for c in cases {
        let ku = expand(&c.mu, &c.ku);
        let kv = expand(&c.mv, &c.kv);
        let (nu, nv) = (ku.len() - c.degrees.0 - 1, kv.len() - c.degrees.1 - 1);
        let pts = net(nu, nv);
        let ws = if c.rational {
            weights(nu, nv)
        } else {
            vec![vec![1.0; nv]; nu]
        };
        let (p, q) = c.degrees;
        let (ku2, kv2, pts2, ws2) = (ku.clone(), kv.clone(), pts.clone(), ws.clone());
        let def = move |u: f64, v: f64| -> DVec3 {
            let mut num = DVec3::ZERO;
            let mut den = 0.0;
            for i in 0..nu {
                for j in 0..nv {
                    let b = basis(i, p, &ku2, u) * basis(j, q, &kv2, v) * ws2[i][j];
                    num += pts2[i][j] * b;
                    den += b;
                }
            }
            num / den
        };
        let mut w = StepWriter::default();
        let surf = if c.bezier {
            let rows: Vec<String> = pts
                .iter()
                .map(|row| {
                    let ids: Vec<String> =
                        row.iter().map(|&p| format!("#{}", w.point(p))).collect();
                    format!("({})", ids.join(","))
                })
                .collect();
            w.add(format!(
                "BEZIER_SURFACE('',{p},{q},({}),.UNSPECIFIED.,.F.,.F.,.F.)",
                rows.join(",")
            ))
        } else {
            w.bspline_surface(
                c.degrees,
                &pts,
                (&c.mu, &c.ku),
                (&c.mv, &c.kv),
                c.rational.then_some(&ws[..]),
            )
        };
        // Boundary: many short lines through points of the boundary iso-curves.
        let (u0, u1, v0, v1) = (ku[p], ku[nu], kv[q], kv[nv]);
        let n = 12;
        let mut corners = Vec::new();
        for k in 0..n {
            corners.push(def(u0 + (u1 - u0) * k as f64 / n as f64, v0));
        }
        for k in 0..n {
            corners.push(def(u1, v0 + (v1 - v0) * k as f64 / n as f64));
        }
        for k in 0..n {
            corners.push(def(u1 - (u1 - u0) * k as f64 / n as f64, v1));
        }
        for k in 0..n {
            corners.push(def(u0, v1 - (v1 - v0) * k as f64 / n as f64));
        }
        let b = w.polygon_bound(&corners, true);
        w.face(&[b], surf);
        let m = read(&w.finish());
        assert!(
            m.report.failed_faces.is_empty(),
            "{:?}",
            m.report.failed_faces
        );
        let s = surfaces(&m).remove(0);
        let err = worst_error(&s, &def, (nu.max(nv)) as f64);
        assert!(
            err <= 1e-12,
            "relative error {err} (rational {}, bezier {})",
            c.rational,
            c.bezier
        );
        // The projected corners land on the domain's corners.
        let pts = loop_points(&s.trims[0]);
        for corner in [
            DVec2::new(u0, v0),
            DVec2::new(u1, v0),
            DVec2::new(u1, v1),
            DVec2::new(u0, v1),
        ] {
            let nearest = pts
                .iter()
                .map(|p| p.distance(corner))
                .fold(f64::INFINITY, f64::min);
            assert!(nearest < 1e-7, "corner {corner} missed by {nearest}");
        }
    }
}

#[test]
fn inch_and_degree_units_are_applied() {
    let mut w = StepWriter {
        unit: Some(("INCH".into(), 25.4)),
        degrees: true,
        ..Default::default()
    };
    let ax = w.axis(DVec3::ZERO, DVec3::Z, DVec3::X);
    let cyl = w.add(format!(
        "CYLINDRICAL_SURFACE('',#{ax},{})",
        step_support::real(1.0)
    ));
    // A cone with a semi-angle of 30 (degrees) too.
    let ax2 = w.axis(DVec3::new(5.0, 0.0, 0.0), DVec3::Z, DVec3::X);
    let cone = w.add(format!(
        "CONICAL_SURFACE('',#{ax2},{},{})",
        step_support::real(1.0),
        step_support::real(30.0)
    ));
    let b0 = w.circle_bound(DVec3::ZERO, DVec3::Z, DVec3::X, 1.0, true);
    let b1 = w.circle_bound(DVec3::new(0.0, 0.0, 1.0), DVec3::Z, DVec3::X, 1.0, false);
    w.face(&[b0, b1], cyl);
    let r1 = 1.0 + 1.0 * (30f64.to_radians()).tan();
    let b2 = w.circle_bound(DVec3::new(5.0, 0.0, 0.0), DVec3::Z, DVec3::X, 1.0, true);
    let b3 = w.circle_bound(DVec3::new(5.0, 0.0, 1.0), DVec3::Z, DVec3::X, r1, false);
    w.face(&[b2, b3], cone);
    let m = read(&w.finish());
    assert_eq!(m.report.units.length.factor, 25.4);
    assert!((m.report.units.angle.factor - PI / 180.0).abs() < 1e-18);
    assert!(
        m.report.failed_faces.is_empty(),
        "{:?}",
        m.report.failed_faces
    );
    let s = surfaces(&m);
    let SurfaceGeometry::Nurbs(n) = &s[0].geometry else {
        panic!()
    };
    let d = n.domain();
    let p = n.eval(d.u0, d.v1);
    assert!(
        (p - DVec3::new(25.4, 0.0, 25.4)).length() < 1e-12 * 25.4,
        "{p}"
    );
    let SurfaceGeometry::Nurbs(n) = &s[1].geometry else {
        panic!()
    };
    let d = n.domain();
    let p = n.eval(d.u0, d.v1);
    assert!(
        (p - DVec3::new(5.0 + r1, 0.0, 1.0) * 25.4).length() < 1e-12 * 200.0,
        "{p}"
    );
}

#[test]
fn styled_item_colours_become_materials() {
    let mut w = StepWriter::default();
    let ax = w.axis(DVec3::ZERO, DVec3::Z, DVec3::X);
    let plane = w.add(format!("PLANE('',#{ax})"));
    let sq = |x0: f64| {
        [
            DVec3::new(x0, 0.0, 0.0),
            DVec3::new(x0 + 1.0, 0.0, 0.0),
            DVec3::new(x0 + 1.0, 1.0, 0.0),
            DVec3::new(x0, 1.0, 0.0),
        ]
    };
    let b0 = w.polygon_bound(&sq(0.0), true);
    let f0 = w.face(&[b0], plane);
    let b1 = w.polygon_bound(&sq(2.0), true);
    w.face(&[b1], plane);
    let rgb = w.add("COLOUR_RGB('',0.2,0.4,0.6)");
    let fasc = w.add(format!("FILL_AREA_STYLE_COLOUR('',#{rgb})"));
    let fas = w.add(format!("FILL_AREA_STYLE('',(#{fasc}))"));
    let ssfa = w.add(format!("SURFACE_STYLE_FILL_AREA(#{fas})"));
    let sss = w.add(format!("SURFACE_SIDE_STYLE('',(#{ssfa}))"));
    let ssu = w.add(format!("SURFACE_STYLE_USAGE(.BOTH.,#{sss})"));
    let psa = w.add(format!("PRESENTATION_STYLE_ASSIGNMENT((#{ssu}))"));
    w.add(format!("STYLED_ITEM('color',(#{psa}),#{f0})"));
    let m = read(&w.finish());
    assert_eq!(m.report.colours, 1);
    assert_eq!(m.materials.len(), 2);
    assert_eq!(m.materials[1].diffuse, glam::Vec3::new(0.2, 0.4, 0.6));
    assert_eq!(m.objects.len(), 2);
    let coloured: Vec<_> = m.objects.iter().filter(|o| o.material == 1).collect();
    assert_eq!(coloured.len(), 1);
    let b = coloured[0].bounds();
    assert!(
        b.max.x <= 1.0 + 1e-12,
        "the coloured face is the first square"
    );
}

/// Two occurrences of one part in an assembly (NEXT_ASSEMBLY_USAGE_OCCURRENCE,
/// CONTEXT_DEPENDENT_SHAPE_REPRESENTATION, ITEM_DEFINED_TRANSFORMATION): two instances of
/// one shared geometry, each with its placement.
#[test]
fn assembly_occurrences_are_instances_of_one_part_with_their_placements() {
    let mut w = StepWriter::default();
    let model = w.unit_square_model();
    let mm = w.add("(LENGTH_UNIT() NAMED_UNIT(*) SI_UNIT(.MILLI.,.METRE.))");
    let ctx = w.add(format!(
        "(GEOMETRIC_REPRESENTATION_CONTEXT(3) GLOBAL_UNIT_ASSIGNED_CONTEXT((#{mm})) REPRESENTATION_CONTEXT('',''))"
    ));
    let part_origin = w.axis(DVec3::ZERO, DVec3::Z, DVec3::X);
    let part = w.add(format!(
        "MANIFOLD_SURFACE_SHAPE_REPRESENTATION('part',(#{part_origin},#{model}),#{ctx})"
    ));
    let asm_origin = w.axis(DVec3::ZERO, DVec3::Z, DVec3::X);
    let p1 = w.axis(DVec3::new(10.0, 0.0, 0.0), DVec3::Z, DVec3::X);
    let p2 = w.axis(DVec3::new(0.0, 5.0, 0.0), DVec3::Z, DVec3::Y);
    let asm = w.add(format!(
        "SHAPE_REPRESENTATION('asm',(#{asm_origin},#{p1},#{p2}),#{ctx})"
    ));
    let pd_asm = w.add("PRODUCT_DEFINITION('asm','',#0,#0)");
    let pd_part = w.add("PRODUCT_DEFINITION('part','',#0,#0)");
    for (k, p) in [p1, p2].into_iter().enumerate() {
        let idt = w.add(format!(
            "ITEM_DEFINED_TRANSFORMATION('','',#{part_origin},#{p})"
        ));
        let rr = w.add(format!(
            "(REPRESENTATION_RELATIONSHIP('','',#{part},#{asm}) REPRESENTATION_RELATIONSHIP_WITH_TRANSFORMATION(#{idt}) SHAPE_REPRESENTATION_RELATIONSHIP())"
        ));
        let nauo = w.add(format!(
            "NEXT_ASSEMBLY_USAGE_OCCURRENCE('{k}','','',#{pd_asm},#{pd_part},$)"
        ));
        let pds = w.add(format!("PRODUCT_DEFINITION_SHAPE('','',#{nauo})"));
        w.add(format!(
            "CONTEXT_DEPENDENT_SHAPE_REPRESENTATION(#{rr},#{pds})"
        ));
    }
    let m = read(&w.text());
    assert_eq!(m.report.occurrences, 2);
    assert_eq!(m.objects.len(), 2);
    let parts: Vec<_> = m
        .objects
        .iter()
        .map(|o| match &o.geometry {
            Geometry::Instance(i) => i.geometry.clone(),
            other => panic!("an occurrence of a shared part is an instance, found {other:?}"),
        })
        .collect();
    assert!(
        std::sync::Arc::ptr_eq(&parts[0], &parts[1]),
        "both occurrences share one part"
    );
    // The shared part is the square in its own frame, in millimetres as written.
    let own = parts[0].bounds();
    assert!(
        own.min.abs().max_element() < 1e-12
            && (own.max - DVec3::new(1.0, 1.0, 0.0)).length() < 1e-12,
        "{own:?}"
    );
    let boxes: Vec<_> = m
        .objects
        .iter()
        .map(|o| o.geometry.resolved().bounds())
        .collect();
    let near = |a: DVec3, b: DVec3| (a - b).length() < 1e-12;
    assert!(
        near(boxes[0].min, DVec3::new(10.0, 0.0, 0.0))
            && near(boxes[0].max, DVec3::new(11.0, 1.0, 0.0)),
        "{:?}",
        boxes[0]
    );
    // The second placement turns x onto y: the square [0,1]² becomes [-1,0] × [0,1].
    assert!(
        near(boxes[1].min, DVec3::new(-1.0, 5.0, 0.0))
            && near(boxes[1].max, DVec3::new(0.0, 6.0, 0.0)),
        "{:?}",
        boxes[1]
    );
}
