//! STEP geometry outside B-rep solids: surfaces in a GEOMETRIC_SET (a
//! RECTANGULAR_TRIMMED_SURFACE of a cylinder in degrees, a CURVE_BOUNDED_SURFACE annulus
//! on a plane), bare B-spline surfaces (occt_bug28366_fuselage.stp) and AP242 tessellated
//! geometry (occt_bug33638.stp, CATIA's tessellated cube). Hits are checked against the
//! closed forms, the fuselage's corners against its own control points (a clamped
//! B-spline passes through its corner points), the cube's triangles against the area and
//! normals its coordinates give.

use crate::common;
use crate::step_support;

use std::path::Path;

use glam::DVec3;
use patchtrace::formats::cad::scene::Shape;
use patchtrace::formats::cad::step::read_step;
use patchtrace::scene::model::SurfaceGeometry;
use step_support::{StepWriter, real};

const RADIUS: f64 = 2.0;
const HEIGHT: f64 = 3.0;
const CENTRE: DVec3 = DVec3::new(10.0, 0.0, -5.0);
const OUTER: f64 = 3.0;
const INNER: f64 = 1.0;

/// A quarter of a cylinder (u from 0° to 90°, v from 0 to 3) and an annulus on the plane
/// z = −5, both in one GEOMETRIC_SET; the annulus's boundaries are circles without
/// pcurves (projected onto the plane).
fn set_file() -> String {
    set_writer().0.finish()
}

/// The writer of `set_file` before it is finished, and the curve-bounded annulus's id.
fn set_writer() -> (StepWriter, u64) {
    let mut w = StepWriter {
        degrees: true,
        ..Default::default()
    };
    let axis = w.axis(DVec3::ZERO, DVec3::Z, DVec3::X);
    let cyl = w.add(format!("CYLINDRICAL_SURFACE('',#{axis},{})", real(RADIUS)));
    let rts = w.add(format!(
        "RECTANGULAR_TRIMMED_SURFACE('',#{cyl},0.,90.,0.,{},.T.,.T.)",
        real(HEIGHT)
    ));
    let paxis = w.axis(CENTRE, DVec3::Z, DVec3::X);
    let plane = w.add(format!("PLANE('',#{paxis})"));
    let boundary = |w: &mut StepWriter, r: f64, name: &str| {
        let c = w.circle(paxis, r);
        let seg = w.add(format!("COMPOSITE_CURVE_SEGMENT(.CONTINUOUS.,.T.,#{c})"));
        w.add(format!("{name}('',(#{seg}),.F.)"))
    };
    let outer = boundary(&mut w, OUTER, "OUTER_BOUNDARY_CURVE");
    let inner = boundary(&mut w, INNER, "BOUNDARY_CURVE");
    let cbs = w.add(format!(
        "CURVE_BOUNDED_SURFACE('',#{plane},(#{outer},#{inner}),.F.)"
    ));
    let set = w.add(format!("GEOMETRIC_SET('',(#{rts},#{cbs}))"));
    w.items.push(set);
    (w, cbs)
}

/// The set's surfaces, one of them also the representation of a shape aspect of the
/// product (as AutoCAD writes each surface of its set again): each drawn once.
#[test]
fn a_set_s_surface_named_again_by_a_shape_aspect_is_drawn_once() {
    let (mut w, cbs) = set_writer();
    let ctx = w.add("(GEOMETRIC_REPRESENTATION_CONTEXT(3) REPRESENTATION_CONTEXT('',''))");
    let mut text = w.finish();
    // The product: its definition shape holds the finished model (the last entity).
    let main = text.matches("\n#").count() as u64;
    let mut extra = step_support::StepWriter {
        next: main,
        ..Default::default()
    };
    let pd = extra.add("PRODUCT_DEFINITION('part','',$,$)");
    let pds = extra.add(format!("PRODUCT_DEFINITION_SHAPE('','',#{pd})"));
    extra.add(format!("SHAPE_DEFINITION_REPRESENTATION(#{pds},#{main})"));
    let aspect = extra.add(format!(
        "SHAPE_ASPECT('','solid associated with shape',#{pds},.F.)"
    ));
    let property = extra.add(format!("PROPERTY_DEFINITION('','',#{aspect})"));
    let aspect_rep = extra.add(format!("SHAPE_REPRESENTATION('',(#{cbs}),#{ctx})"));
    extra.add(format!(
        "SHAPE_DEFINITION_REPRESENTATION(#{property},#{aspect_rep})"
    ));
    text = text.replace(
        "\nENDSEC;\nEND-ISO-10303-21;",
        &format!("\n{}\nENDSEC;\nEND-ISO-10303-21;", extra.lines.join("\n")),
    );
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("aspect.step");
    std::fs::write(&path, &text).unwrap();
    let surfaces = read_step(&path)
        .unwrap()
        .parts
        .iter()
        .flat_map(|p| &p.pieces)
        .filter(|p| matches!(p.shape, Shape::Surface(_)))
        .count();
    assert_eq!(surfaces, 2, "{text}");
}

#[test]
fn surfaces_in_a_geometric_set_are_hit_where_their_bounds_keep_them() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("set.step");
    std::fs::write(&path, set_file()).unwrap();
    let s = 0.5f64.sqrt();
    let diag = DVec3::new(s, s, 0.0);
    let rays = [
        // Inside the quarter (45°, v = 1.5): on the cylinder.
        (
            DVec3::new(0.0, 0.0, 1.5),
            diag,
            Some(RADIUS * diag + 1.5 * DVec3::Z),
        ),
        // 180° and above v = 3: trimmed away.
        (DVec3::new(0.0, 0.0, 1.5), -DVec3::X, None),
        (DVec3::new(0.0, 0.0, 4.0), diag, None),
        // The annulus: 2 from its centre kept, the hole (0.5) and beyond 3 (3.5) not.
        (
            CENTRE + DVec3::new(2.0, 0.0, 10.0),
            -DVec3::Z,
            Some(CENTRE + DVec3::new(2.0, 0.0, 0.0)),
        ),
        (CENTRE + DVec3::new(0.0, 0.5, 10.0), -DVec3::Z, None),
        (CENTRE + DVec3::new(0.0, 3.5, 10.0), -DVec3::Z, None),
    ];
    let hits = common::trace_hits(
        &path,
        &rays.iter().map(|&(o, d, _)| (o, d)).collect::<Vec<_>>(),
    );
    for (k, ((_, _, want), got)) in rays.iter().zip(&hits).enumerate() {
        match (want, got) {
            (Some(p), Some((q, _))) => assert!(p.distance(*q) < 1e-5, "ray {k}: {q} != {p}"),
            (None, None) => {}
            _ => panic!("ray {k}: expected {want:?}, traced {got:?}"),
        }
    }
    let info = common::stdout(&common::run(&["info", path.to_str().unwrap()]));
    assert!(
        info.contains("surfaces outside faces: 2 converted"),
        "{info}"
    );
}

fn testdata(name: &str) -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("testdata/cad")
        .join(name)
}

/// Every CARTESIAN_POINT of a file, by its text.
fn file_points(text: &str) -> Vec<DVec3> {
    text.lines()
        .filter_map(|l| {
            let body = l.split("CARTESIAN_POINT(").nth(1)?;
            let inner = body.split('(').nth(1)?.split(')').next()?;
            let c: Vec<f64> = inner
                .split(',')
                .map(|x| x.trim().parse().unwrap())
                .collect();
            (c.len() == 3).then(|| DVec3::new(c[0], c[1], c[2]))
        })
        .collect()
}

#[test]
fn the_fuselage_surfaces_pass_through_their_corner_points() {
    let path = testdata("occt_bug28366_fuselage.stp");
    let model = read_step(&path).unwrap();
    assert!(model.failures.is_empty(), "{:?}", model.failures);
    assert!(model.skipped.is_empty(), "{:?}", model.skipped);
    let points = file_points(&std::fs::read_to_string(&path).unwrap());
    let surfaces: Vec<_> = model
        .parts
        .iter()
        .flat_map(|p| &p.pieces)
        .filter_map(|p| match &p.shape {
            Shape::Surface(s) => Some(s),
            _ => None,
        })
        .collect();
    assert_eq!(surfaces.len(), 8);
    for s in surfaces {
        let SurfaceGeometry::Nurbs(n) = &s.geometry else {
            panic!("expected a NURBS surface");
        };
        assert!(s.trims.is_empty());
        let d = n.domain();
        for (u, v) in [(d.u0, d.v0), (d.u1, d.v0), (d.u0, d.v1), (d.u1, d.v1)] {
            let p = n.eval(u, v);
            let near = points
                .iter()
                .map(|q| q.distance(p))
                .fold(f64::INFINITY, f64::min);
            assert!(
                near < 1e-9 * (1.0 + p.length()),
                "corner {p} is {near} from every point"
            );
        }
    }
}

#[test]
fn the_tessellated_cube_has_its_twelve_triangles_and_area() {
    let model = read_step(&testdata("occt_bug33638.stp")).unwrap();
    let meshes: Vec<_> = model
        .parts
        .iter()
        .flat_map(|p| &p.pieces)
        .filter_map(|p| match &p.shape {
            Shape::Triangles(m) => Some(m),
            _ => None,
        })
        .collect();
    assert_eq!(meshes.len(), 1);
    let m = meshes[0];
    assert_eq!(m.indices.len(), 12);
    // The box of its COORDINATES_LIST: 101.43797 x 76.14538 x 100.
    let (a, b, c) = (101.43797, 76.14538, 100.0);
    let mut area = 0.0;
    for t in &m.indices {
        let [p, q, r] = t.map(|i| m.positions[i as usize]);
        let n = (q - p).cross(r - p);
        area += 0.5 * n.length();
        // Each triangle turns the way the face's normal (given by CATIA) points.
        assert!(n.normalize().dot(m.normals[t[0] as usize]) > 1.0 - 1e-12);
    }
    let want = 2.0 * (a * b + b * c + c * a);
    assert!((area - want).abs() < 1e-9 * want, "{area} != {want}");
}
