//! Damaged STEP files read as OpenCASCADE reads them: a malformed face (dangling
//! reference, zero direction or vector, missing parameter, `.U.` for a boolean, a reference
//! to the wrong type, an instance that does not parse) costs that face only, named with
//! its reason; an instance that does not parse is skipped and a duplicated instance name
//! keeps its first definition, each with one located warning; a malformed shell costs
//! what it holds. The face left is checked against its closed form: the plane z = 0 over
//! the unit square. Also the edge curves OpenCASCADE reads beyond SURFACE_CURVE and LINE:
//! INTERSECTION_CURVE, POLYLINE and COMPOSITE_CURVE.

use crate::step_support;

use std::path::Path;

use glam::{DVec2, DVec3, DVec4};
use patchtrace::formats::cad::step::{StepModel, read_model, read_step_str};
use patchtrace::geom::nurbs::NurbsCurve;
use patchtrace::scene::model::{Geometry, Surface, SurfaceGeometry};
use step_support::{StepWriter, real};

fn read(text: &str) -> StepModel {
    read_step_str(Path::new("test.step"), text).unwrap_or_else(|e| panic!("{e}\n{text}"))
}

fn surfaces(m: &StepModel) -> Vec<Surface> {
    m.objects
        .iter()
        .flat_map(|o| match &o.geometry {
            Geometry::Surfaces(s) => s.clone(),
            _ => Vec::new(),
        })
        .collect()
}

/// Points along every trim loop (each segment at 33 parameters), in the definition's
/// parameters.
fn loop_points(s: &Surface) -> Vec<DVec2> {
    let mut out = Vec::new();
    for seg in s.trims.iter().flat_map(|l| &l.segments) {
        let c = NurbsCurve {
            degree: seg.curve.degree,
            knots: seg.curve.knots.clone(),
            points: seg
                .curve
                .points
                .iter()
                .map(|p| DVec4::new(p.x, p.y, 0.0, p.z))
                .collect(),
        };
        for k in 0..=32 {
            out.push(
                c.eval(seg.t0 + (seg.t1 - seg.t0) * k as f64 / 32.0)
                    .truncate(),
            );
        }
    }
    out
}

/// Distance from `p` to the closed polygon `corners`.
fn to_polygon(p: DVec2, corners: &[DVec2]) -> f64 {
    (0..corners.len())
        .map(|k| {
            let (a, b) = (corners[k], corners[(k + 1) % corners.len()]);
            let t = ((p - a).dot(b - a) / (b - a).length_squared()).clamp(0.0, 1.0);
            p.distance(a + t * (b - a))
        })
        .fold(f64::INFINITY, f64::min)
}

/// `s` is the plane z = 0 (parameters x, y) trimmed to the polygon `corners`: its points
/// over a grid of its domain lie where the closed form puts them, its domain is the
/// polygon's bounding box, and its loops run along the polygon's sides enclosing its
/// area.
fn assert_plane_polygon(s: &Surface, corners: &[DVec2]) {
    let SurfaceGeometry::Nurbs(n) = &s.geometry else {
        panic!("expected a NURBS surface")
    };
    let d = n.domain();
    for i in 0..=8 {
        for j in 0..=8 {
            let su = d.u0 + (d.u1 - d.u0) * i as f64 / 8.0;
            let sv = d.v0 + (d.v1 - d.v0) * j as f64 / 8.0;
            let (u, v) = (s.trim_space[0].apply(su), s.trim_space[1].apply(sv));
            let off = n.eval(su, sv).distance(DVec3::new(u, v, 0.0));
            assert!(off <= 1e-12, "({u}, {v}) is {off} off the plane");
        }
    }
    let lo = corners.iter().fold(DVec2::INFINITY, |a, &c| a.min(c));
    let hi = corners.iter().fold(DVec2::NEG_INFINITY, |a, &c| a.max(c));
    let mapped = |u, v| DVec2::new(s.trim_space[0].apply(u), s.trim_space[1].apply(v));
    assert!((mapped(d.u0, d.v0) - lo).abs().max_element() <= 1e-12);
    assert!((mapped(d.u1, d.v1) - hi).abs().max_element() <= 1e-12);
    let points = loop_points(s);
    for &p in &points {
        let off = to_polygon(p, corners);
        assert!(off <= 1e-12, "loop point {p} is {off} off the polygon");
    }
    // Along the sides through every corner: the sampled loop encloses the polygon's area
    // (a corner cut by a chord would lose a triangle of it), to the samples' spacing.
    let area = |p: &[DVec2]| {
        (0..p.len())
            .map(|k| p[k].perp_dot(p[(k + 1) % p.len()]))
            .sum::<f64>()
            .abs()
            / 2.0
    };
    let (got, want) = (area(&points), area(corners));
    assert!(
        (got - want).abs() <= 0.01 * want,
        "loop area {got}, polygon {want}"
    );
}

const UNIT_SQUARE: [DVec2; 4] = [DVec2::ZERO, DVec2::X, DVec2::new(1.0, 1.0), DVec2::Y];

/// The good face, the plane z = 0 over the unit square.
fn good_face(w: &mut StepWriter) {
    let ax = w.axis(DVec3::ZERO, DVec3::Z, DVec3::X);
    let plane = w.add(format!("PLANE('',#{ax})"));
    let sq = UNIT_SQUARE.map(|c| c.extend(0.0));
    let b = w.polygon_bound(&sq, true);
    w.face(&[b], plane);
}

/// A face at z = 1 (its own plane, bound and edges), then `damage` applied to the first
/// of its lines that contains `key`, given the line and the id of the face's first
/// Cartesian point. Returns the file and the face's id.
fn with_bad_face(key: &str, damage: impl Fn(&str, u64) -> String) -> (String, u64) {
    let mut w = StepWriter::default();
    good_face(&mut w);
    let first = w.lines.len();
    let ax = w.axis(DVec3::Z, DVec3::Z, DVec3::X);
    let plane = w.add(format!("PLANE('',#{ax})"));
    let sq = UNIT_SQUARE.map(|c| c.extend(1.0));
    let b = w.polygon_bound(&sq, true);
    let bad = w.face(&[b], plane);
    let point = first as u64 + 1;
    let k = first
        + w.lines[first..]
            .iter()
            .position(|l| l.contains(key))
            .unwrap();
    w.lines[k] = damage(&w.lines[k], point);
    (w.finish(), bad)
}

/// Damage done to one line of a file, given the line and the id of a Cartesian point.
type Damage = dyn Fn(&str, u64) -> String;

#[test]
fn a_malformed_face_costs_that_face_only() {
    let one = real(1.0);
    let cases: Vec<(&str, &str, Box<Damage>, String)> = vec![
        (
            "bound to a missing loop",
            "FACE_OUTER_BOUND",
            Box::new(|l, _| l.replacen("('',#", "('',#999999", 1)),
            "which is not defined in the file".into(),
        ),
        (
            "zero axis direction",
            "DIRECTION",
            Box::new(|l, _| format!("{}=DIRECTION('',(0.,0.,0.));", l.split('=').next().unwrap())),
            "DIRECTION: expected a non-zero direction".into(),
        ),
        (
            "vector of magnitude 0",
            "VECTOR",
            Box::new(move |l, _| l.replacen(&format!(",{one})"), ",0.)", 1)),
            "VECTOR: expected a magnitude > 0, found 0".into(),
        ),
        (
            "same_sense missing",
            "ADVANCED_FACE",
            Box::new(|l, _| l.replacen(",.T.)", ")", 1)),
            "ADVANCED_FACE: expected same_sense as parameter 4, found only 3".into(),
        ),
        (
            "unknown logical for a boolean",
            "FACE_OUTER_BOUND",
            Box::new(|l, _| l.replacen(".T.)", ".U.)", 1)),
            "expected orientation (.T. or .F.), found an enumeration".into(),
        ),
        (
            "edge that is a point",
            "ORIENTED_EDGE",
            Box::new(|l, point| {
                let cut = l.find("*,*,#").unwrap() + 5;
                let end = cut + l[cut..].find(',').unwrap();
                format!("{}{point}{}", &l[..cut], &l[end..])
            }),
            "expected a reference to EDGE_CURVE, found #".into(),
        ),
        (
            "loop that does not parse",
            "EDGE_LOOP",
            Box::new(|l, _| l.replacen("))", "),)", 1)),
            "which is not defined in the file".into(),
        ),
    ];
    for (what, key, damage, reason) in cases {
        let (text, bad) = with_bad_face(key, damage);
        let m = read(&text);
        let s = surfaces(&m);
        assert_eq!(s.len(), 1, "{what}: {:?}", m.report.failed_faces);
        assert_plane_polygon(&s[0], &UNIT_SQUARE);
        let failed = &m.report.failed_faces;
        assert_eq!(failed.len(), 1, "{what}: {failed:?}");
        assert_eq!(failed[0].0, bad, "{what}: {failed:?}");
        // The reason is located (`LINE:COL: #id ENTITY: …`) at the damaged instance.
        let (at, message) = failed[0].1.split_once(": ").unwrap();
        let (line, _) = at.split_once(':').unwrap();
        let line: usize = line.parse().unwrap();
        let id = message.split(' ').next().unwrap();
        let src = text.lines().nth(line - 1).unwrap();
        assert!(
            src.starts_with(&format!("{id}=")),
            "{what}: {src} vs {message}"
        );
        assert!(message.contains(&reason), "{what}: {message}");
        // One warning line names the face.
        let (model, _) = read_model(Path::new("test.step"), &text).unwrap();
        let warnings = model.warning_lines(Path::new("test.step"));
        let named: Vec<&String> = warnings
            .iter()
            .filter(|w| w.contains(&format!("#{bad}")))
            .collect();
        assert_eq!(named.len(), 1, "{what}: {warnings:?}");
    }
}

/// A shell whose face list is malformed is lost with what it holds, named (as the
/// representation item it was reached from) with its located reason; the other items
/// are read.
#[test]
fn a_malformed_shell_costs_its_item_only() {
    let mut w = StepWriter::default();
    good_face(&mut w);
    let shell = w.add("OPEN_SHELL('',#999999)");
    let model = w.add(format!("SHELL_BASED_SURFACE_MODEL('',(#{shell}))"));
    w.items.push(model);
    let m = read(&w.finish());
    let s = surfaces(&m);
    assert_eq!(s.len(), 1);
    assert_plane_polygon(&s[0], &UNIT_SQUARE);
    let failed = &m.report.failed_faces;
    assert_eq!(failed.len(), 1, "{failed:?}");
    assert_eq!(failed[0].0, model);
    assert!(
        failed[0].1.contains(&format!(
            "#{shell} OPEN_SHELL: expected a list of items, found a reference"
        )),
        "{failed:?}"
    );
}

/// Where nothing renderable is left, the file is still refused, saying why each face
/// failed.
#[test]
fn a_file_of_malformed_faces_only_is_refused_with_the_reasons() {
    let mut w = StepWriter::default();
    let ax = w.axis(DVec3::ZERO, DVec3::Z, DVec3::X);
    let plane = w.add(format!("PLANE('',#{ax})"));
    let b = w.add("FACE_OUTER_BOUND('',#999999,.T.)");
    let bad = w.face(&[b], plane);
    let (model, _) = read_model(Path::new("bad.step"), &w.finish()).unwrap();
    let Err(e) = patchtrace::formats::cad::scene::build_scene(Path::new("bad.step"), model) else {
        panic!("a scene was built from no face");
    };
    let e = e.to_string();
    assert!(e.contains("nothing to render"), "{e}");
    assert!(
        e.contains(&format!("face #{bad}: ")) && e.contains("#999999, which is not defined"),
        "{e}"
    );
}

/// An instance that does not parse, not referenced by any face, is skipped with one
/// warning at its position; a second `#id` keeps the first definition.
#[test]
fn syntax_errors_and_duplicate_names_are_skipped_with_located_warnings() {
    let mut w = StepWriter::default();
    good_face(&mut w);
    w.add("DRAUGHTING_PRE_DEFINED_COLOUR('red',)");
    w.add("DRAUGHTING_PRE_DEFINED_COLOUR('a;b' 'c;')");
    // The plane's id again, as a point: the plane is kept.
    let plane = w.lines.iter().position(|l| l.contains("=PLANE(")).unwrap() + 1;
    w.lines
        .push(format!("#{plane}=CARTESIAN_POINT('',(5.,5.,5.));"));
    let text = w.finish();
    let m = read(&text);
    let s = surfaces(&m);
    assert_eq!(s.len(), 1);
    assert_plane_polygon(&s[0], &UNIT_SQUARE);
    let line_of = |needle: &str| text.lines().position(|l| l.contains(needle)).unwrap() + 1;
    let comma = line_of("'red',)");
    let col = text.lines().nth(comma - 1).unwrap().find(",)").unwrap() + 2;
    let dup = line_of(&format!("#{plane}=CARTESIAN_POINT"));
    let (model, _) = read_model(Path::new("test.step"), &text).unwrap();
    let warnings = model.warning_lines(Path::new("test.step"));
    assert_eq!(warnings.len(), 2, "{warnings:?}");
    assert!(
        warnings[0].starts_with(&format!("warning: test.step: {comma}:{col}: 2 instance(s)")),
        "{warnings:?}"
    );
    assert!(
        warnings[0].contains("expected a parameter, found `)`"),
        "{warnings:?}"
    );
    assert!(
        warnings[1].starts_with(&format!("warning: test.step: {dup}:1: 1 instance name(s)")),
        "{warnings:?}"
    );
}

/// The quadrilateral (0,0) (2,0) (1,1) (0,1) on the plane z = 0, its edges made by
/// `curve(w, from, to, plane)`.
fn quad_with(curve: impl Fn(&mut StepWriter, &[DVec3], u64) -> u64) -> Surface {
    let mut w = StepWriter::default();
    let ax = w.axis(DVec3::ZERO, DVec3::Z, DVec3::X);
    let plane = w.add(format!("PLANE('',#{ax})"));
    let corners = [
        DVec3::ZERO,
        2.0 * DVec3::X,
        DVec3::new(1.0, 1.0, 0.0),
        DVec3::Y,
    ];
    let vs: Vec<u64> = corners.iter().map(|&c| w.vertex(c)).collect();
    // Three edges: the bottom, the right side bent at (1, 1) as one edge, the left
    // side closing the loop through (0, 0).
    let runs: [&[usize]; 3] = [&[0, 1], &[1, 2, 3], &[3, 0]];
    let mut edges = Vec::new();
    for run in runs {
        let points: Vec<DVec3> = run.iter().map(|&k| corners[k]).collect();
        let c = curve(&mut w, &points, plane);
        let (a, b) = (vs[run[0]], vs[*run.last().unwrap()]);
        edges.push((w.edge(a, b, c, true), true));
    }
    let b = w.bound(&edges, true);
    w.face(&[b], plane);
    let m = read(&w.finish());
    assert!(
        m.report.failed_faces.is_empty(),
        "{:?}",
        m.report.failed_faces
    );
    let mut s = surfaces(&m);
    assert_eq!(s.len(), 1);
    s.remove(0)
}

fn polyline(w: &mut StepWriter, points: &[DVec3]) -> u64 {
    let ids: Vec<String> = points.iter().map(|&p| format!("#{}", w.point(p))).collect();
    w.add(format!("POLYLINE('',({}))", ids.join(",")))
}

const QUAD: [DVec2; 4] = [
    DVec2::ZERO,
    DVec2::new(2.0, 0.0),
    DVec2::new(1.0, 1.0),
    DVec2::Y,
];

/// POLYLINE edges (ISO 10303-42: straight segments through the points), one of them
/// through three points, trim the face along the polygon.
#[test]
fn polyline_edges_trim_their_face_along_the_polygon() {
    assert_plane_polygon(&quad_with(|w, points, _| polyline(w, points)), &QUAD);
}

/// INTERSECTION_CURVE edges (ISO 10303-42: a surface curve, here the intersection of the
/// face's plane with itself as written, curve_3d first) trim as their curve_3d does.
#[test]
fn intersection_curve_edges_trim_as_their_3d_curve() {
    let s = quad_with(|w, points, plane| {
        let c = polyline(w, points);
        w.add(format!(
            "INTERSECTION_CURVE('',#{c},(#{plane},#{plane}),.CURVE_3D.)"
        ))
    });
    assert_plane_polygon(&s, &QUAD);
}

/// COMPOSITE_CURVE edges (ISO 10303-42: segments in order, each along its parent curve or
/// against it) trim along their segments: the bent side as two segments, the second
/// written backwards (same_sense false), the others as a lone segment on an unbounded
/// LINE, which runs between the edge's vertices.
#[test]
fn composite_curve_edges_trim_along_their_segments() {
    let s = quad_with(|w, points, _| {
        let segments = if points.len() == 3 {
            let a = polyline(w, &points[..2]);
            let b = polyline(w, &[points[2], points[1]]);
            vec![
                format!("COMPOSITE_CURVE_SEGMENT(.CONTINUOUS.,.T.,#{a})"),
                format!("COMPOSITE_CURVE_SEGMENT(.CONTINUOUS.,.F.,#{b})"),
            ]
        } else {
            let l = w.line(points[0], points[1] - points[0]);
            vec![format!("COMPOSITE_CURVE_SEGMENT(.CONTINUOUS.,.T.,#{l})")]
        };
        let ids: Vec<String> = segments
            .into_iter()
            .map(|s| format!("#{}", w.add(s)))
            .collect();
        w.add(format!("COMPOSITE_CURVE('',({}),.F.)", ids.join(",")))
    });
    assert_plane_polygon(&s, &QUAD);
}
