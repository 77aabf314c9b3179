//! pbrt-v3 `Shape "nurbs"` reader: the test data file, transforms, and error positions.

use std::path::Path;

use glam::{DVec3, DVec4};
use patchtrace::geom::nurbs::NurbsSurface;
use patchtrace::scene::pbrt::parse_pbrt;
use patchtrace::scene::{ParseError, Surface, SurfaceGeometry};

fn nurbs(s: &Surface) -> &NurbsSurface {
    match &s.geometry {
        SurfaceGeometry::Nurbs(n) => n,
        other => panic!("expected a NURBS surface, found {other:?}"),
    }
}

fn euclidean(p: DVec4) -> DVec3 {
    p.truncate() / p.w
}

fn close(a: DVec3, b: DVec3) -> bool {
    (a - b).abs().max_element() <= 1e-12 * (1.0 + b.abs().max_element())
}

#[test]
fn nurbs_patch_with_pw_is_read_premultiplied_and_translated() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("testdata/nurbs_patch.pbrt");
    let src = std::fs::read_to_string(&path).unwrap();
    let surfaces = parse_pbrt(&path, &src).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(surfaces.len(), 1, "the sphere is ignored");
    let n = nurbs(&surfaces[0]);
    assert_eq!((n.degree_u, n.degree_v), (2, 1));
    assert_eq!((n.count_u, n.count_v), (4, 3));
    assert_eq!(n.knots_u, [0.0, 0.0, 0.0, 0.5, 1.0, 1.0, 1.0]);
    assert_eq!(n.knots_v, [0.0, 0.0, 0.5, 1.0, 1.0]);
    let translate = DVec3::new(1.0, 2.0, 3.0);
    for j in 0..3 {
        for i in 0..4 {
            let (x, y) = (i as f64, j as f64);
            let w = 1.0 + 0.5 * ((i + j) % 2) as f64;
            let p = n.points[j * 4 + i];
            assert_eq!(p.w, w, "weight of ({i}, {j})");
            let expected = DVec3::new(x, y, 0.25 * x * y) + translate;
            assert!(
                close(euclidean(p), expected),
                "({i}, {j}): {p} vs {expected}"
            );
        }
    }
}

/// A bilinear patch over the unit square given by "point P", with a bare single value.
const BILINEAR: &str = r#"Shape "nurbs" "integer nu" 2 "integer nv" [2] "integer uorder" [2]
  "integer vorder" 2 "float uknots" [0 0 1 1] "float vknots" [0 0 1 1]
  "point P" [1 0 0  2 0 0  1 1 0  2 1 0]
"#;

fn parse(src: &str) -> Result<Vec<Surface>, ParseError> {
    parse_pbrt(Path::new("s.pbrt"), src)
}

#[test]
fn transforms_apply_in_pbrt_order_and_attribute_blocks_restore_them() {
    let src = format!(
        "WorldBegin\nAttributeBegin\n Translate 0 0 5 # then rotate about z\n Rotate 90 0 0 1\n Scale 2 2 2\n{BILINEAR}AttributeEnd\n{BILINEAR}\
         TransformBegin\nConcatTransform [1 0 0 0  0 1 0 0  0 0 1 0  10 20 30 1]\n{BILINEAR}TransformEnd\n"
    );
    let surfaces = parse(&src).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(surfaces.len(), 3);
    let first = euclidean(nurbs(&surfaces[0]).points[0]);
    // p' = T · R · S · p for p = (1, 0, 0): scale to (2, 0, 0), rotate to (0, 2, 0), lift.
    assert!(close(first, DVec3::new(0.0, 2.0, 5.0)), "{first}");
    assert_eq!(
        euclidean(nurbs(&surfaces[1]).points[0]),
        DVec3::new(1.0, 0.0, 0.0)
    );
    assert_eq!(
        euclidean(nurbs(&surfaces[2]).points[3]),
        DVec3::new(12.0, 21.0, 30.0)
    );
}

/// The 1-based line and column of `needle` (first occurrence) plus `offset` characters.
fn at(src: &str, needle: &str, offset: usize) -> (usize, usize) {
    let start = src.find(needle).expect("needle in source") + offset;
    let line_start = src[..start].rfind('\n').map_or(0, |k| k + 1);
    (
        src[..start].matches('\n').count() + 1,
        src[line_start..start].chars().count() + 1,
    )
}

fn assert_error_at(src: &str, (line, column): (usize, usize), message: &str) {
    assert_error(src, line, column, message);
}

fn assert_error(src: &str, line: usize, column: usize, message: &str) {
    let e = parse(src).expect_err("expected an error");
    assert_eq!((e.line, e.column), (line, column), "{e}");
    assert!(
        e.message.starts_with(message),
        "{e}\nexpected message: {message}"
    );
}

#[test]
fn wrong_knot_count_is_refused_at_the_parameter() {
    let src = BILINEAR.replace("[0 0 1 1] \"float vknots\"", "[0 0 1] \"float vknots\"");
    assert_error_at(
        &src,
        at(&src, "\"float uknots\"", 0),
        "expected 4 values in \"float uknots\" (control points + order), found 3",
    );
}

#[test]
fn decreasing_knots_are_refused_at_the_knot() {
    let src = BILINEAR.replace("\"float vknots\" [0 0 1 1]", "\"float vknots\" [0 1 0 1]");
    assert_error_at(
        &src,
        at(&src, "[0 1 0 1]", 5),
        "expected knots in non-decreasing order, found `0` after `1`",
    );
}

#[test]
fn order_above_sixteen_is_refused_at_the_value() {
    let src = BILINEAR.replace("\"integer uorder\" [2]", "\"integer uorder\" [17]");
    assert_error_at(
        &src,
        at(&src, "17", 0),
        "expected an order from 2 to 16 (degree + 1), found `17`",
    );
}

#[test]
fn nonpositive_pw_weight_is_refused_at_the_weight() {
    let src = BILINEAR.replace(
        "\"point P\" [1 0 0  2 0 0  1 1 0  2 1 0]",
        "\"float Pw\" [1 0 0 1  2 0 0 1  1 1 0 0  2 1 0 1]",
    );
    assert_error_at(
        &src,
        at(&src, "1 1 0 0", 6),
        "expected a positive weight, found `0`",
    );
}

#[test]
fn missing_and_mistyped_parameters_are_named() {
    let src = BILINEAR.replace("\"integer nv\" [2] ", "");
    assert_error(
        &src,
        1,
        1,
        "expected parameter \"integer nv\" for Shape \"nurbs\"",
    );
    let src = BILINEAR.replace("\"integer nu\"", "\"float nu\"");
    assert_error_at(
        &src,
        at(&src, "\"float nu\"", 0),
        "expected \"integer nu\", found \"float nu\"",
    );
}

#[test]
fn syntax_errors_point_at_the_token() {
    assert_error(
        "Shape \"nurbs\n",
        1,
        7,
        "expected a closing `\"` on the same line",
    );
    assert_error("WorldBegin\n  ]\n", 2, 3, "expected a directive, found `]`");
    assert_error(
        "AttributeEnd\n",
        1,
        1,
        "expected a matching `AttributeBegin` before `AttributeEnd`",
    );
    assert_error(
        "Translate 1 nan 2\n",
        1,
        13,
        "expected three numbers after `Translate` as a finite number",
    );
    assert_error(
        "Include \"other.pbrt\"\n",
        1,
        1,
        "`Include` is not supported",
    );
}
