//! OBJ free-form reader and writer: the test data files, the writer round trip, and one
//! test per error path checking the line, column and wording.

use std::path::Path;

use glam::{DVec3, DVec4};
use patchtrace::geom::BezierPatch;
use patchtrace::geom::bezier::ParamRect;
use patchtrace::geom::nurbs::NurbsSurface;
use patchtrace::scene::obj::{is_freeform, parse_obj_freeform, write_obj_freeform};
use patchtrace::scene::{ParseError, Surface, SurfaceGeometry};
use proptest::prelude::*;

fn read(name: &str) -> Vec<Surface> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("testdata")
        .join(name);
    let src = std::fs::read_to_string(&path).unwrap();
    assert!(is_freeform(&src));
    parse_obj_freeform(&path, &src).unwrap_or_else(|e| panic!("{e}"))
}

fn nurbs(s: &Surface) -> &NurbsSurface {
    match &s.geometry {
        SurfaceGeometry::Nurbs(n) => n,
        other => panic!("expected a NURBS surface, found {other:?}"),
    }
}

fn bezier(s: &Surface) -> &BezierPatch {
    match &s.geometry {
        SurfaceGeometry::Bezier(p) => p,
        other => panic!("expected a Bézier patch, found {other:?}"),
    }
}

/// The classic 9-point quadratic NURBS circle: (x, y, weight).
fn circle() -> Vec<(f64, f64, f64)> {
    let s = 2f64.sqrt() / 2.0;
    vec![
        (1.0, 0.0, 1.0),
        (1.0, 1.0, s),
        (0.0, 1.0, 1.0),
        (-1.0, 1.0, s),
        (-1.0, 0.0, 1.0),
        (-1.0, -1.0, s),
        (0.0, -1.0, 1.0),
        (1.0, -1.0, s),
        (1.0, 0.0, 1.0),
    ]
}

const CIRCLE_KNOTS: [f64; 12] = [
    0.0, 0.0, 0.0, 0.25, 0.25, 0.5, 0.5, 0.75, 0.75, 1.0, 1.0, 1.0,
];

#[test]
fn torus_is_the_tensor_product_of_two_rational_circles() {
    let surfaces = read("torus.obj");
    assert_eq!(surfaces.len(), 1);
    let n = nurbs(&surfaces[0]);
    assert_eq!((n.degree_u, n.degree_v), (2, 2));
    assert_eq!((n.count_u, n.count_v), (9, 9));
    assert_eq!(n.knots_u, CIRCLE_KNOTS);
    assert_eq!(n.knots_v, CIRCLE_KNOTS);
    let (big_r, small_r) = (2.0, 0.5);
    let c = circle();
    for (j, &(cx, cz, wv)) in c.iter().enumerate() {
        for (i, &(ax, ay, wu)) in c.iter().enumerate() {
            let rho = big_r + small_r * cx;
            let w = wu * wv;
            let expected = (DVec3::new(rho * ax, rho * ay, small_r * cz) * w).extend(w);
            assert_eq!(n.points[j * 9 + i], expected, "control point ({i}, {j})");
        }
    }
    assert!(surfaces[0].trims.is_empty());
}

#[test]
fn multiknot_surface_keeps_knots_trim_loop_and_hole() {
    let surfaces = read("bspline_multiknot.obj");
    assert_eq!(surfaces.len(), 1);
    let n = nurbs(&surfaces[0]);
    assert_eq!((n.degree_u, n.degree_v), (3, 2));
    assert_eq!(
        n.knots_u,
        [0.0, 0.0, 0.0, 0.0, 0.5, 0.5, 1.0, 1.0, 1.0, 1.0]
    );
    assert_eq!(n.knots_v, [0.0, 0.0, 0.0, 1.0, 1.0, 2.0, 2.0, 2.0]);
    assert_eq!((n.count_u, n.count_v), (6, 5));
    for j in 0..5 {
        for i in 0..6 {
            let (x, y) = (i as f64, j as f64);
            let expected = DVec4::new(x, y, 0.1 * x * y, 1.0);
            assert_eq!(n.points[j * 6 + i], expected, "control point ({i}, {j})");
        }
    }
    let trims = &surfaces[0].trims;
    assert_eq!(trims.len(), 2);
    let outer = &trims[0];
    assert!(!outer.hole);
    assert_eq!(outer.segments.len(), 1);
    assert_eq!((outer.segments[0].t0, outer.segments[0].t1), (0.0, 4.0));
    let polyline = &outer.segments[0].curve;
    assert_eq!(polyline.degree, 1);
    assert_eq!(polyline.knots, [0.0, 0.0, 1.0, 2.0, 3.0, 4.0, 4.0]);
    assert_eq!(polyline.points.first(), Some(&DVec3::new(0.1, 0.1, 1.0)));
    assert_eq!(polyline.points.get(2), Some(&DVec3::new(0.9, 1.9, 1.0)));
    let hole = &trims[1];
    assert!(hole.hole);
    let c = &hole.segments[0].curve;
    assert_eq!(c.degree, 2);
    assert_eq!(c.knots, CIRCLE_KNOTS);
    for (p, &(cx, cy, w)) in c.points.iter().zip(&circle()) {
        let expected = DVec3::new((0.5 + 0.2 * cx) * w, (1.0 + 0.2 * cy) * w, w);
        assert_eq!(*p, expected);
    }
}

#[test]
fn piecewise_bezier_surface_splits_into_patches_in_span_order() {
    let surfaces = read("bezier_pieces.obj");
    assert_eq!(surfaces.len(), 4);
    let breaks_u = [0.0, 1.0, 2.0];
    let breaks_v = [0.0, 0.5, 1.0];
    for (k, s) in surfaces.iter().enumerate() {
        let (su, sv) = (k % 2, k / 2);
        let p = bezier(s);
        assert_eq!((p.degree_u(), p.degree_v()), (3, 2));
        assert_eq!(
            p.domain(),
            ParamRect {
                u0: breaks_u[su],
                u1: breaks_u[su + 1],
                v0: breaks_v[sv],
                v1: breaks_v[sv + 1],
            }
        );
        for b in 0..=2 {
            for a in 0..=3 {
                let (i, j) = ((3 * su + a) as f64, (2 * sv + b) as f64);
                let z = (i - 3.0).powi(2) / 9.0 + 0.25 * j;
                assert_eq!(
                    p.point(a, b),
                    DVec3::new(i, j, z),
                    "patch {k} point ({a}, {b})"
                );
            }
        }
    }
}

fn write_and_read(patches: &[BezierPatch]) -> Vec<BezierPatch> {
    let mut out = Vec::new();
    write_obj_freeform(&mut out, patches).unwrap();
    let text = String::from_utf8(out).unwrap();
    parse_obj_freeform(Path::new("written.obj"), &text)
        .unwrap_or_else(|e| panic!("{e}\n{text}"))
        .iter()
        .map(|s| bezier(s).clone())
        .collect()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn non_rational_patches_round_trip_bit_for_bit(
        du in 1usize..=4,
        dv in 1usize..=4,
        coords in proptest::collection::vec(-1e6f64..1e6, 75),
    ) {
        let n = (du + 1) * (dv + 1);
        let points: Vec<DVec3> = (0..n)
            .map(|k| DVec3::new(coords[3 * k], coords[3 * k + 1], coords[3 * k + 2]))
            .collect();
        let patches = vec![
            BezierPatch::from_points(du, dv, &points).unwrap(),
            BezierPatch::from_points(1, 1, &points[..4]).unwrap(),
        ];
        prop_assert_eq!(write_and_read(&patches), patches);
    }
}

#[test]
fn rational_patches_round_trip_to_within_an_ulp() {
    let points: Vec<DVec3> = (0..9)
        .map(|k| DVec3::new(k as f64 / 3.0, (k * k) as f64 / 7.0, 1.0 / (k as f64 + 1.0)))
        .collect();
    let weights: Vec<f64> = (0..9).map(|k| 0.3 + k as f64 / 11.0).collect();
    let patch = BezierPatch::from_weighted(2, 2, &points, &weights).unwrap();
    let back = write_and_read(std::slice::from_ref(&patch));
    assert_eq!(back.len(), 1);
    assert_eq!((back[0].degree_u(), back[0].degree_v()), (2, 2));
    for (a, b) in back[0]
        .homogeneous_points()
        .iter()
        .zip(patch.homogeneous_points())
    {
        assert_eq!(a.w, b.w, "weights are written exactly");
        let err = (*a - *b).abs().max_element();
        let scale = b.abs().max_element();
        assert!(err <= 2.0 * f64::EPSILON * scale, "{a} vs {b}");
    }
}

// ---- error paths ---------------------------------------------------------------------

/// A valid bilinear B-spline patch; the error tests change one line of it.
const GOOD: &str = "v 0 0 0
v 1 0 0
v 0 1 0
v 1 1 0
cstype bspline
deg 1 1
surf 0 1 0 1 1 2 3 4
parm u 0 0 1 1
parm v 0 0 1 1
end
";

fn with_line(line: usize, text: &str) -> String {
    let mut lines: Vec<&str> = GOOD.lines().collect();
    lines[line - 1] = text;
    lines.join("\n") + "\n"
}

fn error(src: &str) -> ParseError {
    match parse_obj_freeform(Path::new("bad.obj"), src) {
        Ok(s) => panic!(
            "expected an error, parsed {} surface(s) from\n{src}",
            s.len()
        ),
        Err(e) => e,
    }
}

fn assert_error(src: &str, line: usize, column: usize, message: &str) {
    let e = error(src);
    assert_eq!((e.line, e.column), (line, column), "{e}");
    assert!(
        e.message.starts_with(message),
        "{e}\nexpected message: {message}"
    );
    assert!(
        e.to_string()
            .starts_with(&format!("bad.obj:{line}:{column}: "))
    );
}

#[test]
fn the_good_base_file_parses() {
    let s = parse_obj_freeform(Path::new("good.obj"), GOOD).unwrap();
    assert_eq!(s.len(), 1);
    assert_eq!(nurbs(&s[0]).points[3], DVec4::new(1.0, 1.0, 0.0, 1.0));
}

#[test]
fn nan_coordinate_is_refused_at_its_token() {
    assert_error(
        &with_line(2, "v 1 nan 0"),
        2,
        5,
        "expected y coordinate as a finite number, found `nan`",
    );
}

#[test]
fn bad_number_is_refused_at_its_token() {
    assert_error(
        &with_line(3, "v 0 1 abc"),
        3,
        7,
        "expected z coordinate, found `abc`",
    );
}

#[test]
fn zero_and_negative_weights_are_refused_at_the_weight() {
    let rational = with_line(5, "cstype rat bspline");
    let zero = rational.replacen("v 1 0 0\n", "v 1 0 0 0\n", 1);
    assert_error(&zero, 2, 9, "expected a positive weight, found `0`");
    let negative = rational.replacen("v 1 1 0\n", "v 1 1 0   -2.5\n", 1);
    assert_error(&negative, 4, 11, "expected a positive weight, found `-2.5`");
    // Non-rational surfaces ignore weights.
    let plain = GOOD.replacen("v 1 0 0\n", "v 1 0 0 0\n", 1);
    assert!(parse_obj_freeform(Path::new("ok.obj"), &plain).is_ok());
}

#[test]
fn wrong_point_count_is_refused_at_surf() {
    assert_error(
        &with_line(7, "surf 0 1 0 1 1 2 3"),
        7,
        1,
        "expected 2 × 2 = 4 control points (from `deg` and the knot counts",
    );
    let bezier = with_line(5, "cstype bezier")
        .replace("parm u 0 0 1 1", "parm u 0 1 2")
        .replace("parm v 0 0 1 1", "parm v 0 1");
    assert_error(
        &bezier,
        7,
        1,
        "expected 3 × 2 = 6 control points (from `deg` and the breakpoints",
    );
}

#[test]
fn decreasing_knots_are_refused_at_the_knot() {
    assert_error(
        &with_line(9, "parm v 0 0.5 0.25 1"),
        9,
        14,
        "expected parameter values in non-decreasing order, found `0.25` after `0.5`",
    );
}

#[test]
fn too_few_knots_are_refused_at_parm() {
    assert_error(
        &with_line(8, "parm u 0 0 1"),
        8,
        1,
        "expected at least 4 values in `parm u` for degree 1, found 3",
    );
}

#[test]
fn degree_above_fifteen_is_refused_at_the_degree() {
    assert_error(
        &with_line(6, "deg 2 16"),
        6,
        7,
        "expected a degree from 1 to 15, found `16`",
    );
    assert_error(
        &with_line(6, "deg 0 1"),
        6,
        5,
        "expected a degree from 1 to 15, found `0`",
    );
}

#[test]
fn dangling_and_zero_indices_are_refused_at_the_index() {
    assert_error(
        &with_line(7, "surf 0 1 0 1 1 2 3 5"),
        7,
        20,
        "dangling vertex index `5`: expected 1 to 4 or -4 to -1",
    );
    assert_error(
        &with_line(7, "surf 0 1 0 1 -5 2 3 4"),
        7,
        14,
        "dangling vertex index `-5`",
    );
    assert_error(
        &with_line(7, "surf 0 1 0 1 0/1 2 3 4"),
        7,
        14,
        "expected a vertex index (1-based, or negative to count back), found `0`",
    );
    // Relative and v/vt/vn forms resolve to the same points.
    let relative = with_line(7, "surf 0 1 0 1 -4 2/1 3//2 -1");
    let a = parse_obj_freeform(Path::new("a.obj"), &relative).unwrap();
    let b = parse_obj_freeform(Path::new("b.obj"), GOOD).unwrap();
    assert_eq!(a, b);
}

#[test]
fn unsupported_curve_types_are_named() {
    for ty in ["bmatrix", "cardinal", "taylor"] {
        assert_error(
            &with_line(5, &format!("cstype rat {ty}")),
            5,
            12,
            &format!("unsupported curve/surface type `{ty}`: expected `bezier` or `bspline`"),
        );
    }
    assert_error(
        &with_line(5, "cstype nurbs"),
        5,
        8,
        "expected `bezier` or `bspline`, found `nurbs`",
    );
}

#[test]
fn missing_end_is_reported_at_end_of_file_or_the_next_element() {
    let no_end = GOOD.replace("end\n", "");
    assert_error(
        &no_end,
        9,
        15,
        "expected `end` to close the `surf` from line 7, found end of file",
    );
    let twice = no_end + "surf 0 1 0 1 1 2 3 4\n";
    assert_error(
        &twice,
        10,
        1,
        "expected `end` to close the `surf` from line 7, found `surf`",
    );
}

#[test]
fn missing_deg_parm_and_cstype_are_named() {
    let no_deg = with_line(6, "");
    assert_error(&no_deg, 7, 1, "expected `deg` before `surf`");
    let no_cstype = with_line(5, "");
    assert_error(&no_cstype, 7, 1, "expected `cstype` before `surf`");
    let no_parm_v = with_line(9, "");
    assert_error(
        &no_parm_v,
        10,
        1,
        "expected `parm v` for the `surf` from line 7 before `end`",
    );
    assert_error(
        &with_line(6, "deg 1"),
        7,
        1,
        "expected two degrees (`deg du dv`) before `surf`",
    );
}

#[test]
fn trailing_garbage_is_refused() {
    assert_error(
        &with_line(6, "deg 1 1 1"),
        6,
        9,
        "expected end of line, found `1`",
    );
    assert_error(
        &with_line(10, "end now"),
        10,
        5,
        "expected end of line, found `now`",
    );
    assert_error(
        &with_line(1, "v 0 0 0 1 7"),
        1,
        11,
        "expected end of line, found `7`",
    );
}

#[test]
fn continued_lines_report_the_physical_position() {
    let src = with_line(7, "surf 0 1 0 1 1 2 \\\n    3 x");
    assert_error(&src, 8, 7, "expected a vertex index, found `x`");
    let ok = with_line(7, "surf 0 1 \\\n 0 1 1 2 \\\n 3 4");
    let a = parse_obj_freeform(Path::new("a.obj"), &ok).unwrap();
    assert_eq!(a, parse_obj_freeform(Path::new("b.obj"), GOOD).unwrap());
}

#[test]
fn trims_need_defined_curves() {
    let src = with_line(10, "trim 0 1 1\nend");
    assert_error(
        &src,
        10,
        10,
        "dangling curv2 index `1`: no curv2 is defined before this line",
    );
}

#[test]
fn curve_point_counts_must_match_the_knots() {
    let src = "vp 0 0\nvp 1 0\nvp 1 1\ncstype bspline\ndeg 1\ncurv2 1 2 3\nparm u 0 0 1 1\nend\n";
    assert_error(
        src,
        7,
        1,
        "expected 5 values in `parm u` (3 control points + degree 1 + 1), found 4",
    );
    let one_d = "vp 0\nvp 1 0\ncstype bspline\ndeg 1\ncurv2 1 2\nparm u 0 0 1 1\nend\n";
    assert_error(
        one_d,
        5,
        7,
        "expected a parameter vertex with u and v, `vp` 1 has only u",
    );
}

#[test]
fn surf_range_restricts_the_surface_exactly() {
    // A bilinear B-spline plane x = u over [0, 4] × [0, 2], restricted by `surf 1 3 0 2.5`
    // (t1 past the domain, as exporters round, is clipped to it); a Bézier surface of two
    // spans restricted to [0.5, 1.5] keeps parts of both.
    let src = "v 0 0 0\nv 4 0 0\nv 0 2 0\nv 4 2 1\ncstype bspline\ndeg 1 1\nsurf 1 3 0 2.5 1 2 3 4\nparm u 0 0 4 4\nparm v 0 0 2 2\nend\n\
        v 0 0 5\nv 1 0 5\nv 2 0 5\nv 0 1 5\nv 1 1 5\nv 2 1 6\ncstype bezier\ndeg 1 1\nsurf 0.5 1.5 0 1 5 6 7 8 9 10\nparm u 0 1 2\nparm v 0 1\nend\n";
    let surfaces =
        patchtrace::scene::obj::parse_obj_freeform(std::path::Path::new("range.obj"), src)
            .expect("parses");
    let patchtrace::scene::SurfaceGeometry::Nurbs(n) = &surfaces[0].geometry else {
        panic!("a B-spline surface");
    };
    let d = n.domain();
    assert_eq!((d.u0, d.u1, d.v0, d.v1), (1.0, 3.0, 0.0, 2.0));
    // The plane's height is u v / 8 (bilinear through the corners): check it on the range.
    for (u, v) in [(1.0, 0.0), (3.0, 2.0), (2.2, 0.7)] {
        let p = n.eval(u, v);
        assert!(
            (p - glam::DVec3::new(u, v, u * v / 8.0)).length() < 1e-14,
            "{p}"
        );
    }
    let beziers: Vec<_> = surfaces[1..]
        .iter()
        .map(|s| match &s.geometry {
            patchtrace::scene::SurfaceGeometry::Bezier(p) => p.clone(),
            _ => panic!("Bézier patches"),
        })
        .collect();
    assert_eq!(beziers.len(), 2);
    assert_eq!((beziers[0].domain().u0, beziers[0].domain().u1), (0.5, 1.0));
    assert_eq!((beziers[1].domain().u0, beziers[1].domain().u1), (1.0, 1.5));
    // Local (0, 0) of the first piece is global u = 0.5: x = 0.5 on the first span.
    assert!((beziers[0].eval(0.0, 0.0) - glam::DVec3::new(0.5, 0.0, 5.0)).length() < 1e-14);
    assert!((beziers[1].eval(1.0, 1.0) - glam::DVec3::new(1.5, 1.0, 5.5)).length() < 1e-14);
}
