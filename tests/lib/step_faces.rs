//! STEP faces CAD systems write that are not a plain outer loop of edges with pcurves:
//! faces without bounds (whole spheres, B-spline surfaces), a sphere cap bounded by one
//! circle, a cylinder bounded by two circles and no seam, B-splines whose knots are
//! implied (ISO 10303-42 §4.3.4), and an edge whose LINE lies beside its vertices. Each
//! is checked against the closed form or an independent Cox–de Boor evaluation.

use crate::step_support;

use std::f64::consts::{FRAC_PI_2, TAU};
use std::path::Path;

use glam::{DVec2, DVec3};
use patchtrace::formats::cad::step::{StepModel, read_step_str};
use patchtrace::scene::model::{Geometry, Surface, SurfaceGeometry};
use step_support::{StepWriter, basis};

fn read(text: &str) -> StepModel {
    read_step_str(Path::new("test.step"), text).unwrap_or_else(|e| panic!("{e}\n{text}"))
}

/// The model's only surface; no face may have failed.
fn only_surface(m: &StepModel) -> Surface {
    assert!(
        m.report.failed_faces.is_empty(),
        "{:?}",
        m.report.failed_faces
    );
    let mut all: Vec<Surface> = m
        .objects
        .iter()
        .flat_map(|o| match &o.geometry {
            Geometry::Surfaces(s) => s.clone(),
            _ => Vec::new(),
        })
        .collect();
    assert_eq!(all.len(), 1);
    all.remove(0)
}

/// The NURBS domain in the definition's parameters (through `trim_space`).
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

fn assert_close(a: DVec2, b: DVec2, tol: f64, what: &str) {
    assert!((a - b).abs().max_element() <= tol, "{what}: {a} vs {b}");
}

/// Points of the NURBS over a 9 × 9 grid of its domain.
fn grid_points(s: &Surface) -> Vec<DVec3> {
    let SurfaceGeometry::Nurbs(n) = &s.geometry else {
        panic!("expected a NURBS surface")
    };
    let d = n.domain();
    (0..=8)
        .flat_map(|i| (0..=8).map(move |j| (i as f64 / 8.0, j as f64 / 8.0)))
        .map(|(a, b)| n.eval(d.u0 + (d.u1 - d.u0) * a, d.v0 + (d.v1 - d.v0) * b))
        .collect()
}

/// SPHERICAL_SURFACE at `centre` with radius `r` and axis −z (as a BGA's balls are
/// written).
fn sphere(w: &mut StepWriter, centre: DVec3, r: f64) -> u64 {
    let ax = w.axis(centre, -DVec3::Z, -DVec3::X);
    w.add(format!(
        "SPHERICAL_SURFACE('',#{ax},{})",
        step_support::real(r)
    ))
}

#[test]
fn a_face_without_bounds_is_the_whole_sphere() {
    let (centre, r) = (DVec3::new(-4.225, 4.225, 0.178), 0.1778);
    let mut w = StepWriter::default();
    let s = sphere(&mut w, centre, r);
    w.face(&[], s);
    let s = only_surface(&read(&w.finish()));
    assert!(s.trims.is_empty(), "no trims: the whole surface");
    let (lo, hi) = mapped_domain(&s);
    assert_close(lo, DVec2::new(0.0, -FRAC_PI_2), 1e-12, "domain low");
    assert_close(hi, DVec2::new(TAU, FRAC_PI_2), 1e-12, "domain high");
    for p in grid_points(&s) {
        let off = (p.distance(centre) - r).abs();
        assert!(off <= 1e-12 * r, "{p} is {off} off the sphere");
    }
}

/// A sphere face bounded by one circle of latitude v = 0.4: by ISO 10303-42 the face lies
/// to the left of its bound seen from outside, so the circle run counter-clockwise about
/// the sphere's axis bounds the cap over it, and the same bound with orientation FALSE
/// the rest of the sphere below it.
#[test]
fn one_circle_bounds_a_sphere_cap_on_its_left() {
    let (centre, r, v) = (DVec3::new(1.0, 2.0, 3.0), 2.0, 0.4);
    for (orientation, v_lo, v_hi) in [(true, v, FRAC_PI_2), (false, -FRAC_PI_2, v)] {
        let mut w = StepWriter::default();
        let ax = w.axis(centre, DVec3::Z, DVec3::X);
        let s = w.add(format!(
            "SPHERICAL_SURFACE('',#{ax},{})",
            step_support::real(r)
        ));
        let h = centre + DVec3::Z * r * v.sin();
        let cax = w.axis(h, DVec3::Z, DVec3::X);
        let c = w.circle(cax, r * v.cos());
        let vx = w.vertex(h + DVec3::X * r * v.cos());
        let e = w.edge(vx, vx, c, true);
        let oe = w.oriented(e, true);
        let l = w.add(format!("EDGE_LOOP('',(#{oe}))"));
        let sense = if orientation { ".T." } else { ".F." };
        let b = w.add(format!("FACE_OUTER_BOUND('',#{l},{sense})"));
        w.face(&[b], s);
        let m = read(&w.finish());
        let s = only_surface(&m);
        let (lo, hi) = mapped_domain(&s);
        assert_close(
            DVec2::new(lo.y, hi.y),
            DVec2::new(v_lo, v_hi),
            1e-9,
            &format!("latitudes of the cap, orientation {orientation}"),
        );
        assert!(m.report.max_trim_error <= 1e-12 * r);
    }
}

/// A cylinder between two closed circle edges, both FACE_BOUND and neither outer, the
/// second used backwards, off the origin (how NX writes a drilled hole; the geometry of
/// face #494 of occt_bug27453_165-174_piattello.stp).
#[test]
fn a_cylinder_between_two_circles_without_a_seam() {
    let (axis_at, r) = (DVec3::new(38.0069894887767, 38.0069894887771, 80.0), 3.2501);
    let mut w = StepWriter::default();
    let ax = w.axis(axis_at, DVec3::Z, DVec3::X);
    let cyl = w.add(format!(
        "CYLINDRICAL_SURFACE('',#{ax},{})",
        step_support::real(r)
    ));
    let mut bounds = Vec::new();
    for (z, orientation) in [(86.0, true), (68.0, false)] {
        let c0 = DVec3::new(axis_at.x, axis_at.y, z);
        let cax = w.axis(c0, DVec3::Z, DVec3::X);
        let c = w.circle(cax, r);
        let vx = w.vertex(c0 + DVec3::X * r);
        let e = w.edge(vx, vx, c, true);
        bounds.push(w.bound(&[(e, orientation)], false));
    }
    w.face_with_sense(&bounds, cyl, false);
    // A point far from the B-rep (the file this face comes from holds one half a
    // kilometre away), which must not widen the tolerances.
    w.point(DVec3::new(-494999.984246378, 0.0, 0.0));
    let s = only_surface(&read(&w.finish()));
    // The face's normal is against the surface's, which the scene writes by exchanging
    // the parameters: (v, u).
    let (lo, hi) = mapped_domain(&s);
    let (lo, hi) = (DVec2::new(lo.y, lo.x), DVec2::new(hi.y, hi.x));
    assert!((hi.x - lo.x - TAU).abs() <= 1e-9, "a whole turn: {lo} {hi}");
    assert_close(
        DVec2::new(lo.y, hi.y),
        DVec2::new(-12.0, 6.0),
        1e-9,
        "heights",
    );
    assert_eq!(s.trims.len(), 2);
    for p in grid_points(&s) {
        let radial = (p - axis_at).truncate().length();
        assert!((radial - r).abs() <= 1e-12 * r, "{p} is off the cylinder");
    }
}

/// A cylinder of radius r between two circle edges of radius r + d, lying d off it (a
/// file whose edges miss their face), in a file declaring an uncertainty: the edges are
/// named, with their distance d (closed form), exactly when d exceeds the declared
/// uncertainty; the trims keep within 1e-6 of the model of the edges' projections.
#[test]
fn edges_off_their_face_beyond_the_declared_uncertainty_are_named() {
    let r = 5.0;
    for (d, uncertainty, named) in [(0.02, 1e-3, true), (0.02, 0.05, false)] {
        let mut w = StepWriter {
            uncertainty: Some(uncertainty),
            ..StepWriter::default()
        };
        let ax = w.axis(DVec3::ZERO, DVec3::Z, DVec3::X);
        let cyl = w.add(format!(
            "CYLINDRICAL_SURFACE('',#{ax},{})",
            step_support::real(r)
        ));
        let bounds: Vec<u64> = [(0.0, true), (10.0, false)]
            .into_iter()
            .map(|(z, orientation)| {
                let c0 = DVec3::new(0.0, 0.0, z);
                let cax = w.axis(c0, DVec3::Z, DVec3::X);
                let c = w.circle(cax, r + d);
                let vx = w.vertex(c0 + DVec3::X * (r + d));
                let e = w.edge(vx, vx, c, true);
                w.bound(&[(e, orientation)], false)
            })
            .collect();
        w.face(&bounds, cyl);
        let m = read(&w.finish());
        assert_eq!(m.report.units.uncertainty, Some(uncertainty));
        assert!(
            m.report.failed_faces.is_empty(),
            "{:?}",
            m.report.failed_faces
        );
        assert_eq!(m.report.projected_edges, 2);
        assert!(
            m.report.max_trim_error <= 1e-6 * m.report.model_size,
            "{} of {}",
            m.report.max_trim_error,
            m.report.model_size
        );
        if named {
            assert_eq!(m.report.far_edges.len(), 2, "{:?}", m.report.far_edges);
            for &(_, _, gap) in &m.report.far_edges {
                assert!((gap - d).abs() <= 1e-9 * r, "{gap} against {d}");
            }
            let line = m.report.lines().join("\n");
            assert!(
                line.contains("edges farther from their face than the file's tolerance"),
                "{line}"
            );
        } else {
            assert!(m.report.far_edges.is_empty(), "{:?}", m.report.far_edges);
        }
    }
}

/// Cox–de Boor over knots written out here from ISO 10303-42 §4.3.4.
fn cox_de_boor(
    net: &[Vec<DVec3>],
    p: (usize, usize),
    k: (&[f64], &[f64]),
    u: f64,
    v: f64,
) -> DVec3 {
    let mut s = DVec3::ZERO;
    for (i, row) in net.iter().enumerate() {
        for (j, q) in row.iter().enumerate() {
            s += *q * basis(i, p.0, k.0, u) * basis(j, p.1, k.1, v);
        }
    }
    s
}

#[test]
fn uniform_and_quasi_uniform_surfaces_take_their_implied_knots() {
    let net: Vec<Vec<DVec3>> = (0..5)
        .map(|i| {
            (0..4)
                .map(|j| {
                    let (x, y) = (i as f64, j as f64);
                    DVec3::new(x, y, 0.3 * (x * 1.3).sin() * (y * 0.7).cos())
                })
                .collect()
        })
        .collect();
    // Degrees (2, 3) over 5 × 4 points: quasi-uniform knots are clamped with unit steps,
    // uniform ones run from −degree by 1 (domain [0, count − degree]).
    let cases = [
        (
            "QUASI_UNIFORM_SURFACE",
            vec![0., 0., 0., 1., 2., 3., 3., 3.],
            vec![0., 0., 0., 0., 1., 1., 1., 1.],
            (0.0, 3.0, 0.0, 1.0),
        ),
        (
            "UNIFORM_SURFACE",
            vec![-2., -1., 0., 1., 2., 3., 4., 5.],
            vec![-3., -2., -1., 0., 1., 2., 3., 4.],
            (0.0, 3.0, 0.0, 1.0),
        ),
    ];
    for (entity, ku, kv, (u0, u1, v0, v1)) in cases {
        let mut w = StepWriter::default();
        let rows: Vec<String> = net
            .iter()
            .map(|row| {
                let ids: Vec<String> = row.iter().map(|&p| format!("#{}", w.point(p))).collect();
                format!("({})", ids.join(","))
            })
            .collect();
        let s = w.add(format!(
            "{entity}('',2,3,({}),.UNSPECIFIED.,.F.,.F.,.F.)",
            rows.join(",")
        ));
        w.face(&[], s);
        let surface = only_surface(&read(&w.finish()));
        let SurfaceGeometry::Nurbs(n) = &surface.geometry else {
            panic!("expected a NURBS surface")
        };
        let d = n.domain();
        assert_eq!(
            (d.u0, d.u1, d.v0, d.v1),
            (u0, u1, v0, v1),
            "{entity} domain"
        );
        for i in 0..=6 {
            for j in 0..=6 {
                let u = u0 + (u1 - u0) * i as f64 / 6.0;
                let v = v0 + (v1 - v0) * j as f64 / 6.0;
                let want = cox_de_boor(&net, (2, 3), (&ku, &kv), u, v);
                let got = n.eval(u, v);
                assert!(
                    got.distance(want) <= 1e-12 * 5.0,
                    "{entity} at ({u}, {v}): {got} vs {want}"
                );
            }
        }
    }
}

/// A square face on the plane z = 0 whose left edge's LINE is written 0.3 beside its
/// vertices, parallel to them (as some ECAD writers do): the line is taken through the
/// vertices, as OpenCASCADE does, so nothing is projected with an error and the loop is
/// the square.
#[test]
fn a_line_beside_its_vertices_is_moved_onto_them() {
    let mut w = StepWriter::default();
    let ax = w.axis(DVec3::ZERO, DVec3::Z, DVec3::X);
    let plane = w.add(format!("PLANE('',#{ax})"));
    let corners = [
        DVec3::new(0.0, 0.0, 0.0),
        DVec3::new(1.0, 0.0, 0.0),
        DVec3::new(1.0, 1.0, 0.0),
        DVec3::new(0.0, 1.0, 0.0),
    ];
    let vs: Vec<u64> = corners.iter().map(|&c| w.vertex(c)).collect();
    let mut edges = Vec::new();
    for k in 0..4 {
        let (a, b) = (corners[k], corners[(k + 1) % 4]);
        // The last edge's line lies 0.3 off the plane and 0.2 aside, parallel to its edge.
        let shift = if k == 3 {
            DVec3::new(-0.2, 0.0, 0.3)
        } else {
            DVec3::ZERO
        };
        let l = w.line(a + shift + 5.0 * (b - a), b - a);
        edges.push((w.edge(vs[k], vs[(k + 1) % 4], l, true), true));
    }
    let b = w.bound(&edges, true);
    w.face(&[b], plane);
    let m = read(&w.finish());
    let s = only_surface(&m);
    assert!(
        m.report.max_trim_error <= 1e-12,
        "{}",
        m.report.max_trim_error
    );
    let (lo, hi) = mapped_domain(&s);
    assert_close(lo, DVec2::ZERO, 1e-12, "domain low");
    assert_close(hi, DVec2::ONE, 1e-12, "domain high");
}

/// OFFSET_SURFACE of a sphere (a whole face) and of a cone (a band between two circles
/// on the offset): every point of the face is `d` from the basis, by the closed forms
/// (the sphere's radius; a cone's distance in its axial half-plane, |ρ − r − z tan α| cos α).
#[test]
fn offsets_of_a_sphere_and_a_cone_are_exact() {
    let r = step_support::real;
    let (centre, radius, d) = (DVec3::new(0.5, -1.0, 2.0), 1.2, 0.3);
    let mut w = StepWriter::default();
    let s = sphere(&mut w, centre, radius);
    let off = w.add(format!("OFFSET_SURFACE('',#{s},{},.F.)", r(d)));
    w.face(&[], off);
    let surface = only_surface(&read(&w.finish()));
    for p in grid_points(&surface) {
        let err = (p.distance(centre) - (radius + d)).abs();
        assert!(err <= 1e-12, "{p}: {err}");
    }

    let (rc, alpha, d) = (1.0, 0.4_f64, 0.25);
    let mut w = StepWriter::default();
    let ax = w.axis(DVec3::ZERO, DVec3::Z, DVec3::X);
    let cone = w.add(format!("CONICAL_SURFACE('',#{ax},{},{})", r(rc), r(alpha)));
    let off = w.add(format!("OFFSET_SURFACE('',#{cone},{},.F.)", r(d)));
    // The offset's circles at heights z: radius r + z tan α + d / cos α.
    let mut bounds = Vec::new();
    for (z, orientation) in [(0.2, false), (1.1, true)] {
        let rho = rc + z * alpha.tan() + d / alpha.cos();
        let cax = w.axis(DVec3::new(0.0, 0.0, z), DVec3::Z, DVec3::X);
        let c = w.circle(cax, rho);
        let vx = w.vertex(DVec3::new(rho, 0.0, z));
        let e = w.edge(vx, vx, c, true);
        bounds.push(w.bound(&[(e, orientation)], false));
    }
    w.face(&bounds, off);
    let m = read(&w.finish());
    let surface = only_surface(&m);
    assert!(m.report.max_trim_error <= 1e-12);
    for p in grid_points(&surface) {
        let rho = p.truncate().length();
        let err = ((rho - rc - p.z * alpha.tan()) * alpha.cos() - d).abs();
        assert!(err <= 1e-12, "{p}: {err}");
        assert!(
            p.z >= 0.2 - 1e-12 && p.z <= 1.1 + 1e-12,
            "{p} beyond the band"
        );
    }
}

/// B_SPLINE_CURVE_WITH_KNOTS of degree 2 through `points` (clamped, unit knot steps).
fn quadratic_curve(w: &mut StepWriter, points: &[DVec3]) -> (u64, Vec<f64>) {
    let n = points.len();
    let ids: Vec<String> = points.iter().map(|&p| format!("#{}", w.point(p))).collect();
    let inner = n - 3;
    let mut mults = vec!["3".to_string()];
    mults.extend((0..inner).map(|_| "1".to_string()));
    mults.push("3".into());
    let knots: Vec<String> = (0..=inner + 1).map(|k| format!("{k}.")).collect();
    let id = w.add(format!(
        "B_SPLINE_CURVE_WITH_KNOTS('',2,({}),.UNSPECIFIED.,.T.,.F.,({}),({}),.UNSPECIFIED.)",
        ids.join(","),
        mults.join(","),
        knots.join(",")
    ));
    let mut full = vec![0.0; 3];
    full.extend((1..=inner).map(|k| k as f64));
    full.extend([(inner + 1) as f64; 3]);
    (id, full)
}

/// A SURFACE_OF_LINEAR_EXTRUSION of a closed B-spline profile (CATIA's "tabulated
/// cylinder"), bounded by the profile and its copy one extrusion up: the profile's
/// parameter wraps like an angle, so each bound goes once around and the face is the
/// band between them; its points are the profile's (Cox–de Boor) plus v times the
/// extrusion.
#[test]
fn a_band_around_an_extruded_closed_profile() {
    let ring = [
        DVec3::new(1.0, 0.0, 0.0),
        DVec3::new(1.0, 1.0, 0.0),
        DVec3::new(-1.0, 1.0, 0.0),
        DVec3::new(-1.0, -1.0, 0.0),
        DVec3::new(1.0, -1.0, 0.0),
        DVec3::new(1.0, 0.0, 0.0),
    ];
    let up = DVec3::new(0.0, 0.2, 1.5);
    let mut w = StepWriter::default();
    let (profile, knots) = quadratic_curve(&mut w, &ring);
    let dir = w.dir(up.normalize());
    let vec = w.add(format!(
        "VECTOR('',#{dir},{})",
        step_support::real(up.length())
    ));
    let ext = w.add(format!("SURFACE_OF_LINEAR_EXTRUSION('',#{profile},#{vec})"));
    let top: Vec<DVec3> = ring.iter().map(|&p| p + up).collect();
    let (top_curve, _) = quadratic_curve(&mut w, &top);
    let mut bounds = Vec::new();
    for (curve, start, orientation) in [(profile, ring[0], true), (top_curve, top[0], false)] {
        let v = w.vertex(start);
        let e = w.edge(v, v, curve, true);
        bounds.push(w.bound(&[(e, orientation)], orientation));
    }
    w.face(&bounds, ext);
    let m = read(&w.finish());
    let s = only_surface(&m);
    assert!(
        m.report.max_trim_error <= 1e-9,
        "{}",
        m.report.max_trim_error
    );
    assert_eq!(s.trims.len(), 2);
    let (lo, hi) = mapped_domain(&s);
    assert_close(lo, DVec2::new(0.0, 0.0), 1e-9, "domain low");
    assert_close(hi, DVec2::new(4.0, 1.0), 1e-9, "domain high");
    let SurfaceGeometry::Nurbs(n) = &s.geometry else {
        panic!("expected a NURBS surface")
    };
    let d = n.domain();
    for i in 0..=16 {
        for j in 0..=4 {
            let su = d.u0 + (d.u1 - d.u0) * i as f64 / 16.0;
            let sv = d.v0 + (d.v1 - d.v0) * j as f64 / 4.0;
            let (u, v) = (s.trim_space[0].apply(su), s.trim_space[1].apply(sv));
            let c: DVec3 = (0..ring.len())
                .map(|k| ring[k] * basis(k, 2, &knots, u))
                .sum();
            let want = c + v * up;
            let got = n.eval(su, sv);
            assert!(got.distance(want) <= 1e-12, "({u}, {v}): {got} vs {want}");
        }
    }
}

/// A ball drilled along x: a sphere face whose only bounds are the two circles where the
/// hole leaves it, both FACE_BOUND and used clockwise seen from outside (the face on
/// their right: holes, ISO 10303-42 face_bound). The face is the sphere without the two
/// caps |x| > c: checked at the points of the NURBS against that closed form.
/// The unit sphere about the origin (axis z, longitude 0 at +x) with a circular hole
/// about each of `centres` (unit directions) at distance `c` from the centre, each bound
/// a one-edge loop whose vertex is the circle's point towards `start` from its centre,
/// as the face's only bounds; checked over a grid of the surface against the closed form
/// (a point is cut away when its component along a centre exceeds c).
fn check_sphere_with_holes(c: f64, holes: &[(DVec3, DVec3)], poles: bool) {
    let r = 1.0;
    let rho = (r * r - c * c).sqrt();
    let mut w = StepWriter::default();
    let ax = w.axis(DVec3::ZERO, DVec3::Z, DVec3::X);
    let s = w.add(format!(
        "SPHERICAL_SURFACE('',#{ax},{})",
        step_support::real(r)
    ));
    let mut bounds = Vec::new();
    for &(centre, start) in holes {
        // Counter-clockwise about the outward axis, used backwards: clockwise seen
        // from outside.
        let cax = w.axis(centre * c, centre, start);
        let circle = w.circle(cax, rho);
        let vx = w.vertex(centre * c + start * rho);
        let e = w.edge(vx, vx, circle, true);
        bounds.push(w.bound(&[(e, false)], false));
    }
    if poles {
        // A vertex loop at each pole, as Parasolid writes a sphere's degenerate ends.
        for z in [1.0, -1.0] {
            let v = w.vertex(DVec3::Z * z);
            let vl = w.add(format!("VERTEX_LOOP('',#{v})"));
            bounds.push(w.add(format!("FACE_BOUND('',#{vl},.T.)")));
        }
    }
    w.face(&bounds, s);
    let surface = only_surface(&read(&w.finish()));
    assert_region(&surface, |p| {
        let along: Vec<f64> = holes.iter().map(|(h, _)| p.dot(*h)).collect();
        (!along.iter().any(|a| (a - c).abs() < 0.05)).then(|| along.iter().all(|&a| a < c))
    });
}

/// Checks the face's trim region over a 39 × 39 grid inside its surface's domain (the
/// domain's edges, where a closed surface's seam and the loops' closing lines run, left
/// out) against `expect` (whether a surface point belongs to the face; `None` near a
/// boundary, not checked).
fn assert_region(surface: &Surface, expect: impl Fn(DVec3) -> Option<bool>) {
    let region = surface.trim_region().unwrap().expect("trimmed");
    let SurfaceGeometry::Nurbs(n) = &surface.geometry else {
        panic!("expected a NURBS surface")
    };
    let d = n.domain();
    let mut checked = 0;
    let mut wrong = Vec::new();
    for i in 1..40 {
        for j in 1..40 {
            let su = d.u0 + (d.u1 - d.u0) * i as f64 / 40.0;
            let sv = d.v0 + (d.v1 - d.v0) * j as f64 / 40.0;
            let p = n.eval(su, sv);
            let Some(inside) = expect(p) else { continue };
            checked += 1;
            if region.contains(su, sv) != inside {
                wrong.push((su, sv, p));
            }
        }
    }
    assert!(checked > 1000, "{checked}");
    assert!(
        wrong.is_empty(),
        "{} of {checked} wrong, e.g. {:?}; domain {d:?}, trims {:?}",
        wrong.len(),
        &wrong[..wrong.len().min(8)],
        mapped_domain(surface)
    );
}

#[test]
fn a_sphere_with_holes_only_is_the_sphere_without_them() {
    check_sphere_with_holes(0.6, &[(DVec3::X, DVec3::Y), (-DVec3::X, DVec3::Y)], false);
}

/// Three holes around the equator, one across the seam (longitude 0), and a vertex loop
/// at each pole, as Parasolid writes a drilled ball: every hole is cut, the one across
/// the seam on both sides of it, wherever the first loop or a pole's arbitrary longitude
/// puts the surface's range.
#[test]
fn holes_around_a_sphere_are_cut_across_its_seam() {
    check_sphere_with_holes(
        0.75,
        &[
            (-DVec3::X, DVec3::Z),
            (DVec3::X, -DVec3::Y),
            (DVec3::Y, DVec3::X),
        ],
        true,
    );
}

/// A band of a cylinder between a circle through the seam and an oblique ellipse whose
/// one vertex is a quarter turn from the seam (as Onshape writes a cut tube): the
/// ellipse's loop winds once around from that vertex, and bounds the band all around,
/// not only over the turn that starts there.
#[test]
fn a_band_under_an_ellipse_starting_off_the_seam() {
    let k = 0.3;
    let mut w = StepWriter::default();
    let ax = w.axis(DVec3::ZERO, DVec3::Z, DVec3::X);
    let cyl = w.add(format!(
        "CYLINDRICAL_SURFACE('',#{ax},{})",
        step_support::real(1.0)
    ));
    let circle = w.circle(ax, 1.0);
    let v0 = w.vertex(DVec3::X);
    let bottom = w.edge(v0, v0, circle, true);
    // The plane z = 1 + k x cuts the cylinder in the ellipse about (0, 0, 1) with
    // semi-axes √(1 + k²) along (1, 0, k) and 1 along y.
    let tilt = DVec3::new(1.0, 0.0, k).normalize();
    let eax = w.axis(DVec3::Z, DVec3::new(-k, 0.0, 1.0).normalize(), tilt);
    let ellipse = w.add(format!(
        "ELLIPSE('',#{eax},{},{})",
        step_support::real((1.0 + k * k).sqrt()),
        step_support::real(1.0)
    ));
    let v1 = w.vertex(DVec3::new(0.0, 1.0, 1.0));
    let top = w.edge(v1, v1, ellipse, true);
    let bounds = [
        w.bound(&[(bottom, true)], false),
        w.bound(&[(top, false)], false),
    ];
    w.face(&bounds, cyl);
    let surface = only_surface(&read(&w.finish()));
    assert_region(&surface, |p| {
        let top = 1.0 + k * p.x;
        (p.z.abs() > 0.05 && (p.z - top).abs() > 0.05).then_some(p.z > 0.0 && p.z < top)
    });
}

/// A sphere cap bounded by a circle and a seam run down to the pole and back, whose
/// bound says the cap is on the other side (the geometry of face #11034 of
/// occt_ec_turbine-A.stp, which Euclid wrote): the loop's extent decides, as
/// OpenCASCADE's healing does (it renders the cap the seam runs into). Checked: the face
/// spans the latitudes from the pole to the circle and keeps points inside them.
#[test]
fn a_cap_closed_through_its_seam_is_the_side_the_seam_runs_into() {
    let (r, c) = (11.5, -0.2094395_f64);
    let mut w = StepWriter::default();
    let ax = w.axis(DVec3::ZERO, DVec3::Z, DVec3::X);
    let s = w.add(format!(
        "SPHERICAL_SURFACE('',#{ax},{})",
        step_support::real(r)
    ));
    let cax = w.axis(DVec3::Z * r * c.sin(), DVec3::Z, DVec3::X);
    let circle = w.circle(cax, r * c.cos());
    let start = DVec3::new(r * c.cos(), 0.0, r * c.sin());
    let v0 = w.vertex(start);
    let ring = w.edge(v0, v0, circle, true);
    // The meridian through the circle's vertex, from it down to the south pole.
    let max = w.axis(DVec3::ZERO, DVec3::Y, DVec3::X);
    let meridian = w.circle(max, r);
    let pole = w.vertex(-DVec3::Z * r);
    let seam = w.edge(v0, pole, meridian, true);
    let oes: Vec<u64> = [(ring, false), (seam, true), (seam, false)]
        .iter()
        .map(|&(e, o)| w.oriented(e, o))
        .collect();
    let l = w.add(format!(
        "EDGE_LOOP('',({}))",
        oes.iter()
            .map(|i| format!("#{i}"))
            .collect::<Vec<_>>()
            .join(",")
    ));
    let b = w.add(format!("FACE_BOUND('',#{l},.F.)"));
    w.face(&[b], s);
    let surface = only_surface(&read(&w.finish()));
    let (lo, hi) = mapped_domain(&surface);
    assert_close(
        DVec2::new(lo.y, hi.y),
        DVec2::new(-FRAC_PI_2, c),
        1e-6,
        "latitudes",
    );
    let region = surface.trim_region().unwrap().expect("trimmed");
    let SurfaceGeometry::Nurbs(n) = &surface.geometry else {
        panic!("expected a NURBS surface")
    };
    let d = n.domain();
    let (su, sv) = (0.5 * (d.u0 + d.u1), 0.5 * (d.v0 + d.v1));
    assert!(region.contains(su, sv), "the middle of the cap is kept");
}

fn read_real(name: &str) -> StepModel {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("testdata/cad")
        .join(name);
    let text = std::fs::read_to_string(&path).unwrap();
    read_step_str(&path, &text).unwrap_or_else(|e| panic!("{e}"))
}

/// A BGA package whose 196 balls are ADVANCED_FACEs without bounds on a
/// SPHERICAL_SURFACE (testdata/cad/PROVENANCE.tsv): every face converts, and 196
/// surfaces lie on the balls the file places on a 0.65 mm pitch from (−4.225, 4.225,
/// 0.178) with radius 0.1778 (read off the file; the distance is the closed form).
#[test]
fn a_bga_s_balls_are_whole_spheres() {
    let m = read_real("sfe_BGA_10x10mm_blankhdr.step");
    assert!(
        m.report.failed_faces.is_empty(),
        "{:?}",
        m.report.failed_faces
    );
    let (pitch, r) = (0.65, 0.1778);
    let balls = m
        .objects
        .iter()
        .flat_map(|o| match &o.geometry {
            Geometry::Surfaces(s) => s.clone(),
            _ => Vec::new(),
        })
        .filter(|s| {
            let points = grid_points(s);
            let p = points[0];
            let snap = |x: f64, x0: f64| x0 + ((x - x0) / pitch).round() * pitch;
            let centre = DVec3::new(snap(p.x, -4.225), snap(p.y, 4.225), 0.178);
            points
                .iter()
                .all(|q| (q.distance(centre) - r).abs() <= 1e-9)
        })
        .count();
    assert_eq!(balls, 196);
}

/// CATIA V5's k1 key, every edge without a pcurve and a wireframe a kilometre wide in
/// the same file (testdata/cad/PROVENANCE.tsv): every face converts and the trims keep
/// within the chord tolerance of 1e-6 of the faces' extent (about 150 mm), where the
/// wireframe's points used to widen it to tens of millimetres; no edge lies off its face
/// by more than the file's declared uncertainty.
#[test]
fn catia_s_key_projects_its_edges_within_tolerance() {
    let m = read_real("occt_trj5_k1-ct-214.stp");
    assert!(
        m.report.failed_faces.is_empty(),
        "{:?}",
        m.report.failed_faces
    );
    assert!(
        m.report.projected_edges > 80,
        "{}",
        m.report.projected_edges
    );
    assert!(m.report.model_size < 200.0, "{} mm", m.report.model_size);
    assert!(
        m.report.max_trim_error <= 1e-6 * m.report.model_size,
        "{} mm",
        m.report.max_trim_error
    );
    assert!(m.report.far_edges.is_empty(), "{:?}", m.report.far_edges);
}

/// A sphere written as two faces, each bounded by the same two half circles from pole to
/// pole (CATIA V4's primitives): one loop runs down the +x meridian and up the −x one,
/// the other the same edges the other way round. By ISO 10303-42 face_bound each face lies
/// to the left of its loop seen from outside, so the first is the hemisphere y > 0 and the
/// second, whose `FACE_OUTER_BOUND` has the face on its right in the sphere's parameters,
/// the hemisphere y < 0, not the first one again.
#[test]
fn two_faces_between_the_same_half_circles_are_the_two_hemispheres() {
    for (first, side) in [(true, 1.0), (false, -1.0)] {
        let mut w = StepWriter::default();
        let ax = w.axis(DVec3::ZERO, DVec3::Z, DVec3::X);
        let s = w.add(format!(
            "SPHERICAL_SURFACE('',#{ax},{})",
            step_support::real(1.0)
        ));
        let (north, south) = (w.vertex(DVec3::Z), w.vertex(-DVec3::Z));
        // Both circles start at the north pole; the first passes +x, the second −x.
        let c_plus = w.axis(DVec3::ZERO, DVec3::Y, DVec3::Z);
        let c_plus = w.circle(c_plus, 1.0);
        let c_minus = w.axis(DVec3::ZERO, -DVec3::Y, DVec3::Z);
        let c_minus = w.circle(c_minus, 1.0);
        let plus = w.edge(north, south, c_plus, true);
        let minus = w.edge(north, south, c_minus, true);
        let bound = if first {
            w.bound(&[(plus, true), (minus, false)], true)
        } else {
            w.bound(&[(minus, true), (plus, false)], true)
        };
        w.face(&[bound], s);
        let surface = only_surface(&read(&w.finish()));
        assert_region(&surface, |p| (p.y.abs() > 0.05).then_some(p.y * side > 0.0));
    }
}
