//! IGES reading. Small files are written here by a minimal IGES writer, one
//! per entity kind, and the converted surfaces and trims are checked at sample points
//! against the entity's definition evaluated independently in f64 (a recursive Cox–de Boor,
//! rotation by quaternion, the polynomials of a 112) to 1e-12 of the model's size. The
//! hammer read from IGES is compared with the same geometry read from OBJ.

use std::f64::consts::PI;
use std::path::Path;

use glam::{DQuat, DVec2, DVec3};
use patchtrace::formats::cad::iges::{Iges, parse_iges};
use patchtrace::geom::nurbs::NurbsSurface;
use patchtrace::geom::trim::{ParamCurve, TrimLoop};
use patchtrace::scene::model::{Surface, SurfaceGeometry};

use crate::iges_support;
use iges_support::{Entry, fixed_format};

const REL: f64 = 1e-12;

// ---------------------------------------------------------------------------------------
// Entities for the writer in `iges_support`.

#[derive(Clone)]
struct Ent {
    ty: i32,
    form: i32,
    params: Vec<String>,
    transform: usize,
    colour: i64,
    /// Status digits 3–4: 0 independent, 1 physically dependent.
    subordinate: u8,
    /// Status digits 1–2: 01, blanked.
    blank: bool,
}

fn ent(ty: i32, params: &[f64]) -> Ent {
    Ent {
        ty,
        form: 0,
        params: params.iter().map(|&p| number(p)).collect(),
        transform: 0,
        colour: 0,
        subordinate: 1,
        blank: false,
    }
}

/// Integral values as IGES integers (readers take them for reals too), others as reals
/// with an exponent.
fn number(p: f64) -> String {
    if p.fract() == 0.0 && p.abs() < 1e9 {
        format!("{}", p as i64)
    } else {
        format!("{p:e}").replace('e', "E")
    }
}

/// A pointer to the k-th entity (0-based).
fn de(k: usize) -> f64 {
    (2 * k + 1) as f64
}

/// The Global section of the test files: millimetres.
const GLOBAL: &str = ",,4Htest,8Htest.igs,2Hpt,2Hpt,32,38,6,308,15,4Htest,1.,2,2HMM,1,0.1,\
                      13H260101.000000,1.E-6,100.,2Hme,2Hus,11,0;";

fn write_iges(ents: &[Ent]) -> String {
    write_iges_global(GLOBAL, ents)
}

fn write_iges_global(global: &str, ents: &[Ent]) -> String {
    let entries: Vec<Entry> = ents
        .iter()
        .map(|e| Entry {
            ty: e.ty,
            form: e.form,
            fields: e.params.clone(),
            transform: e.transform,
            colour: e.colour,
            status: format!("{:02}{:02}0000", u8::from(e.blank), e.subordinate),
        })
        .collect();
    fixed_format(global, &entries)
}

fn read(ents: &[Ent]) -> Iges {
    let text = write_iges(ents);
    parse_iges(Path::new("test.igs"), &text).unwrap_or_else(|e| panic!("{e}\n{text}"))
}

/// The one drawn surface, with no conversion failures.
fn only(read: &Iges) -> (&NurbsSurface, &Surface) {
    assert!(read.report.failed.is_empty(), "{:?}", read.report.failed);
    assert_eq!(read.surfaces.len(), 1);
    let s = &read.surfaces[0].surface;
    let SurfaceGeometry::Nurbs(n) = &s.geometry else {
        panic!("a NURBS surface")
    };
    (n, s)
}

fn close(a: DVec3, b: DVec3, scale: f64, what: &str) {
    let e = (a - b).length();
    assert!(e <= REL * scale, "{what}: {a} vs {b} ({e:e})");
}

// ---------------------------------------------------------------------------------------
// Independent evaluation: the Cox–de Boor recursion as written in The NURBS Book eq. 2.5.

fn basis(i: usize, p: usize, knots: &[f64], t: f64) -> f64 {
    if p == 0 {
        let last = knots[knots.len() - 1];
        let inside = knots[i] <= t && t < knots[i + 1];
        // The closed right end belongs to the last non-empty span.
        let end = t == last && knots[i] < knots[i + 1] && knots[i + 1] == last;
        return if inside || end { 1.0 } else { 0.0 };
    }
    let mut v = 0.0;
    let d1 = knots[i + p] - knots[i];
    if d1 > 0.0 {
        v += (t - knots[i]) / d1 * basis(i, p - 1, knots, t);
    }
    let d2 = knots[i + p + 1] - knots[i + 1];
    if d2 > 0.0 {
        v += (knots[i + p + 1] - t) / d2 * basis(i + 1, p - 1, knots, t);
    }
    v
}

/// A rational B-spline curve point from Euclidean points and weights.
fn curve_point(p: usize, knots: &[f64], points: &[DVec3], weights: &[f64], t: f64) -> DVec3 {
    let (mut num, mut den) = (DVec3::ZERO, 0.0);
    for (i, (q, w)) in points.iter().zip(weights).enumerate() {
        let b = basis(i, p, knots, t) * w;
        num += *q * b;
        den += b;
    }
    num / den
}

/// A trim curve's point at t, from its homogeneous (w u, w v, w) points.
fn trim_point(c: &ParamCurve, t: f64) -> DVec2 {
    let pts: Vec<DVec3> = c
        .points
        .iter()
        .map(|q| DVec3::new(q.x / q.z, q.y / q.z, 0.0))
        .collect();
    let w: Vec<f64> = c.points.iter().map(|q| q.z).collect();
    curve_point(c.degree, &c.knots, &pts, &w, t).truncate()
}

/// Entity 126 parameters for a curve (planar flag 0, V range = the knot domain).
fn b126(p: usize, knots: &[f64], points: &[DVec3], weights: &[f64]) -> Vec<f64> {
    let k = points.len() - 1;
    let mut v = vec![k as f64, p as f64, 0.0, 0.0, 0.0, 0.0];
    v.extend(knots);
    v.extend(weights);
    for q in points {
        v.extend([q.x, q.y, q.z]);
    }
    v.extend([knots[p], knots[knots.len() - p - 1], 0.0, 0.0, 1.0]);
    v
}

/// A 128: degree (2, 1), a rational net with an interior u knot.
struct Net {
    ku: Vec<f64>,
    kv: Vec<f64>,
    pts: Vec<DVec3>,
    w: Vec<f64>,
}

fn net() -> Net {
    let mut pts = Vec::new();
    let mut w = Vec::new();
    for j in 0..2 {
        for i in 0..4 {
            pts.push(DVec3::new(
                i as f64,
                2.0 * j as f64,
                (i * j) as f64 * 0.3 + 0.1 * i as f64,
            ));
            w.push(1.0 + 0.25 * ((i + 2 * j) % 3) as f64);
        }
    }
    Net {
        ku: vec![0., 0., 0., 0.5, 1., 1., 1.],
        kv: vec![0., 0., 1., 1.],
        pts,
        w,
    }
}

fn b128(n: &Net, range: [f64; 4]) -> Vec<f64> {
    let mut v = vec![3.0, 1.0, 2.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0];
    v.extend(&n.ku);
    v.extend(&n.kv);
    v.extend(&n.w);
    for q in &n.pts {
        v.extend([q.x, q.y, q.z]);
    }
    v.extend(range);
    v
}

fn net_point(n: &Net, u: f64, v: f64) -> DVec3 {
    let (mut num, mut den) = (DVec3::ZERO, 0.0);
    for j in 0..2 {
        for i in 0..4 {
            let b = basis(i, 2, &n.ku, u) * basis(j, 1, &n.kv, v) * n.w[j * 4 + i];
            num += n.pts[j * 4 + i] * b;
            den += b;
        }
    }
    num / den
}

fn grid() -> impl Iterator<Item = (f64, f64)> {
    (0..=10).flat_map(|i| (0..=10).map(move |j| (i as f64 / 10.0, j as f64 / 10.0)))
}

#[test]
fn b_spline_surface_with_transform_colour_and_parameter_space_trims() {
    let n = net();
    // 0: 128; 1: 124 (rotation about z by 30° and a translation); 2: 314;
    // 3–6: 110 lines of the outer square in (u, v); 7: 102; 8: 142 outer;
    // 9: 100 circle hole; 10: 142 hole; 11: 144.
    let (c, s) = (30f64.to_radians().cos(), 30f64.to_radians().sin());
    let mut surf = ent(128, &b128(&n, [0.0, 1.0, 0.0, 1.0]));
    surf.transform = 3;
    // Marked independent, as some writers do: still drawn only through the 144.
    surf.subordinate = 0;
    let square = [(0.1, 0.1), (0.9, 0.1), (0.9, 0.9), (0.1, 0.9), (0.1, 0.1)];
    let mut ents = vec![
        surf,
        ent(124, &[c, -s, 0.0, 1.0, s, c, 0.0, -2.0, 0.0, 0.0, 1.0, 0.5]),
        ent(314, &[20.0, 40.0, 80.0]),
    ];
    for w in square.windows(2) {
        ents.push(ent(110, &[w[0].0, w[0].1, 0.0, w[1].0, w[1].1, 0.0]));
    }
    ents.push(ent(102, &[4.0, de(3), de(4), de(5), de(6)]));
    ents.push(ent(142, &[0.0, de(0), de(7), 0.0, 1.0]));
    ents.push(ent(100, &[0.0, 0.5, 0.5, 0.7, 0.5, 0.7, 0.5]));
    ents.push(ent(142, &[0.0, de(0), de(9), 0.0, 1.0]));
    let mut top = ent(144, &[de(0), 1.0, 1.0, de(8), de(10)]);
    top.subordinate = 0;
    top.colour = -(de(2) as i64);
    ents.push(top);
    let read = read(&ents);
    let (nurbs, surface) = only(&read);
    let m = glam::DAffine3::from_mat3_translation(
        glam::DMat3::from_cols(DVec3::new(c, s, 0.0), DVec3::new(-s, c, 0.0), DVec3::Z),
        DVec3::new(1.0, -2.0, 0.5),
    );
    for (u, v) in grid() {
        close(
            nurbs.eval(u, v),
            m.transform_point3(net_point(&n, u, v)),
            8.0,
            "128",
        );
    }
    let colour = read.surfaces[0].colour.unwrap();
    assert!((colour - DVec3::new(0.2, 0.4, 0.8)).length() < 1e-15);
    let [outer, hole]: &[TrimLoop; 2] = surface.trims.as_slice().try_into().unwrap();
    assert!(!outer.hole && hole.hole);
    assert_eq!(outer.segments.len(), 4);
    for (k, seg) in outer.segments.iter().enumerate() {
        let (a, b) = (DVec2::from(square[k]), DVec2::from(square[k + 1]));
        for i in 0..=4 {
            let t = seg.t0 + (seg.t1 - seg.t0) * i as f64 / 4.0;
            let want = a.lerp(b, (t - seg.t0) / (seg.t1 - seg.t0));
            assert!((trim_point(&seg.curve, t) - want).length() < REL);
        }
    }
    let circle = &hole.segments[0];
    assert!(
        (circle.t1 - circle.t0 - 2.0 * PI).abs() < 1e-15,
        "a full turn"
    );
    for i in 0..=16 {
        let t = circle.t0 + (circle.t1 - circle.t0) * i as f64 / 16.0;
        let r = (trim_point(&circle.curve, t) - DVec2::splat(0.5)).length();
        assert!((r - 0.2).abs() < REL, "radius {r}");
    }
}

/// The square-trimmed 128 of `b_spline_surface_with_transform_colour_and_parameter_space_trims`
/// without transform and hole: 0: 128, 1–4: 110 lines of the square (0.1..0.9)² in (u, v),
/// 5: 102, 6: 142 (parameter-space curve only), 7: 144.
fn square_trimmed(n: &Net) -> Vec<Ent> {
    let square = [(0.1, 0.1), (0.9, 0.1), (0.9, 0.9), (0.1, 0.9), (0.1, 0.1)];
    let mut ents = vec![ent(128, &b128(n, [0.0, 1.0, 0.0, 1.0]))];
    for w in square.windows(2) {
        ents.push(ent(110, &[w[0].0, w[0].1, 0.0, w[1].0, w[1].1, 0.0]));
    }
    ents.push(ent(102, &[4.0, de(1), de(2), de(3), de(4)]));
    ents.push(ent(142, &[0.0, de(0), de(5), 0.0, 1.0]));
    let mut top = ent(144, &[de(0), 1.0, 0.0, de(6)]);
    top.subordinate = 0;
    ents.push(top);
    ents
}

/// The surface and its outer loop's corners against the closed forms: the net, and the
/// square (0.1..0.9)² in (u, v).
fn assert_square_trimmed(n: &Net, read: &Iges) {
    let (nurbs, surface) = only(read);
    for (u, v) in grid() {
        close(nurbs.eval(u, v), net_point(n, u, v), 8.0, "128");
    }
    let [outer]: &[TrimLoop; 1] = surface.trims.as_slice().try_into().unwrap();
    let corners: Vec<DVec2> = outer
        .segments
        .iter()
        .map(|seg| trim_point(&seg.curve, seg.t0))
        .collect();
    let want = [(0.1, 0.1), (0.9, 0.1), (0.9, 0.9), (0.1, 0.9)].map(DVec2::from);
    assert_eq!(corners.len(), 4, "{corners:?}");
    for (c, w) in corners.iter().zip(want) {
        assert!((*c - w).length() < REL, "{c} against {w}");
    }
}

#[test]
fn miscounted_parameter_lines_and_blanked_surfaces_read_as_opencascade_reads_them() {
    // Rhino 98 writes directory parameter line counts that are not the entity's (20 for
    // a 128 on 7 records); CATIA V4 blanks every surface of some files. Each parameter
    // record names its entity (columns 65–72), and OpenCASCADE draws blanked entities.
    let n = net();
    let mut ents = square_trimmed(&n);
    ents[7].blank = true;
    let text = write_iges(&ents);
    // The second directory record of each entity: its parameter line count in columns
    // 25–32. The 128's made too large, the first 110's too small.
    let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
    let mut patched = 0;
    for l in lines.iter_mut() {
        let seq: usize = l[73..].trim().parse().unwrap_or(0);
        if l.as_bytes()[72] == b'D' && (seq == 2 || seq == 4) {
            let count = if seq == 2 { 20 } else { 0 };
            l.replace_range(24..32, &format!("{count:>8}"));
            patched += 1;
        }
    }
    assert_eq!(patched, 2);
    let text = lines.join("\n") + "\n";
    let read = parse_iges(Path::new("test.igs"), &text).unwrap_or_else(|e| panic!("{e}"));
    assert_square_trimmed(&n, &read);
    assert_eq!(read.report.blanked, 1);
    assert!(
        read.report
            .warnings
            .iter()
            .any(|w| w.contains("2 entities whose directory parameter line count disagrees")),
        "{:?}",
        read.report.warnings
    );
}

#[test]
fn a_model_space_curve_off_its_surface_leaves_the_parameter_space_curve() {
    // Both curves given, disagreeing; the model-space one (the square 100 above the
    // surface) does not lie on the surface, so it cannot stand for the boundary.
    let n = net();
    let mut ents = square_trimmed(&n);
    let lifted = [(0.1, 0.1), (0.9, 0.1), (0.9, 0.9), (0.1, 0.9), (0.1, 0.1)];
    for w in lifted.windows(2) {
        ents.push(ent(110, &[w[0].0, w[0].1, 100.0, w[1].0, w[1].1, 100.0]));
    }
    ents.push(ent(102, &[4.0, de(8), de(9), de(10), de(11)]));
    ents[6] = ent(142, &[0.0, de(0), de(5), de(12), 1.0]);
    let read = read(&ents);
    assert_square_trimmed(&n, &read);
    assert_eq!(read.report.off_surface, [25], "the 102 at D 25 is named");
    assert_eq!(read.report.projected, 0);
}

#[test]
fn narrower_parameter_range_becomes_an_outer_loop_and_units_are_read() {
    let n = net();
    let mut surf = ent(128, &b128(&n, [0.25, 0.75, 0.0, 1.0]));
    surf.subordinate = 0;
    let read = read(&[surf]);
    let (_, s) = only(&read);
    assert_eq!(s.trims.len(), 1);
    let seg = &s.trims[0].segments[0];
    let corners: Vec<DVec2> = (0..5).map(|i| trim_point(&seg.curve, i as f64)).collect();
    assert_eq!(corners[0], DVec2::new(0.25, 0.0));
    assert_eq!(corners[2], DVec2::new(0.75, 1.0));
    assert_eq!(read.report.unit.name, "MM");
    assert!(read.report.lines()[0].contains("MM"));
}

/// Rotation of `p` about the line through `a` along `d` by `angle` (quaternion, f64).
fn rotate(p: DVec3, a: DVec3, d: DVec3, angle: f64) -> DVec3 {
    a + DQuat::from_axis_angle(d.normalize(), angle) * (p - a)
}

#[test]
fn surface_of_revolution_of_a_line_and_of_an_arc() {
    let (a0, a1) = (DVec3::new(0.0, 0.0, -1.0), DVec3::new(0.2, 0.1, 3.0));
    let (l0, l1) = (DVec3::new(1.0, 0.0, 0.0), DVec3::new(2.0, 0.5, 2.0));
    let (sa, ta) = (0.3, 2.0 * PI - 0.2);
    let mut rev = ent(120, &[de(0), de(1), sa, ta]);
    rev.subordinate = 0;
    let read_line = read(&[
        ent(110, &[a0.x, a0.y, a0.z, a1.x, a1.y, a1.z]),
        ent(110, &[l0.x, l0.y, l0.z, l1.x, l1.y, l1.z]),
        rev,
    ]);
    let (s, surface) = only(&read_line);
    for (u, v) in grid() {
        let d = s.domain();
        let (u, v) = d.to_parent(u, v);
        let (t, theta) = (
            surface.trim_space[0].apply(u),
            surface.trim_space[1].apply(v),
        );
        let want = rotate(l0.lerp(l1, t), a0, a1 - a0, theta);
        close(s.eval(u, v), want, 4.0, "120 line");
    }
    // Generatrix: the arc of radius 0.5 about (1.5, 0) in the xz plane from angle 0 to
    // 180°, made by a 124 that maps the arc's xy plane to xz.
    let mut arc = ent(100, &[0.0, 1.5, 0.0, 2.0, 0.0, 1.0, 0.0]);
    arc.transform = 7;
    let mut rev = ent(120, &[de(0), de(1), 0.0, PI]);
    rev.subordinate = 0;
    let read_arc = read(&[
        ent(110, &[0.0, 0.0, 0.0, 0.0, 0.0, 1.0]),
        arc,
        rev,
        ent(
            124,
            &[1.0, 0.0, 0.0, 0.0, 0.0, 0.0, -1.0, 0.0, 0.0, 1.0, 0.0, 0.0],
        ),
    ]);
    let (s, surface) = only(&read_arc);
    for (u, v) in grid() {
        let (u, v) = s.domain().to_parent(u, v);
        let (t, theta) = (
            surface.trim_space[0].apply(u),
            surface.trim_space[1].apply(v),
        );
        let p = DVec3::new(1.5 + 0.5 * t.cos(), 0.0, 0.5 * t.sin());
        close(
            s.eval(u, v),
            rotate(p, DVec3::ZERO, DVec3::Z, theta),
            2.0,
            "120 arc",
        );
    }
}

/// §4.41 (140): S(t, θ) + d N, N the unit normal S_t × S_θ of the base 120 (a cone
/// frustum about z), computed here from the derivatives of the rotated line.
#[test]
fn offset_of_a_surface_of_revolution_of_a_line() {
    let (l0, l1) = (DVec3::new(1.0, 0.0, 0.0), DVec3::new(2.0, 0.0, 2.0));
    let (axis_0, axis_1) = (DVec3::new(0.0, 0.0, -1.0), DVec3::new(0.0, 0.0, 4.0));
    let d = 0.25;
    // The 140 over a 120 of the line from `g0` to `g1` about the axis, through `sweep`.
    let offset_file = |g0: DVec3, g1: DVec3, sweep: f64| {
        let mut offset = ent(140, &[0.0, 0.0, 0.0, d, de(3)]);
        offset.subordinate = 0;
        read(&[
            ent(
                110,
                &[axis_0.x, axis_0.y, axis_0.z, axis_1.x, axis_1.y, axis_1.z],
            ),
            ent(110, &[g0.x, g0.y, g0.z, g1.x, g1.y, g1.z]),
            offset,
            ent(120, &[de(0), de(1), 0.0, sweep]),
        ])
    };
    let read_offset = offset_file(l0, l1, 1.5 * PI);
    assert!(
        read_offset.report.failed.is_empty(),
        "{:?}",
        read_offset.report.failed
    );
    let (s, surface) = only(&read_offset);
    for (u, v) in grid() {
        let (u, v) = s.domain().to_parent(u, v);
        let (t, theta) = (
            surface.trim_space[0].apply(u),
            surface.trim_space[1].apply(v),
        );
        let p = rotate(l0.lerp(l1, t), DVec3::ZERO, DVec3::Z, theta);
        let along = rotate(l1 - l0, DVec3::ZERO, DVec3::Z, theta);
        let around = DVec3::Z.cross(p);
        let want = p + d * along.cross(around).normalize();
        close(s.eval(u, v), want, 4.0, "140 over 120");
    }
    // A line skew to the axis sweeps a hyperboloid, whose offset is no NURBS: refused,
    // and the refusal says so.
    let refused = offset_file(DVec3::new(1.0, 0.0, 0.0), DVec3::new(1.0, 1.0, 2.0), PI);
    let why: Vec<String> = refused
        .report
        .failed
        .iter()
        .map(|f| f.why.clone())
        .collect();
    assert!(
        why.len() == 1 && why[0].starts_with("entity 140: an offset"),
        "{why:?}"
    );
}

/// A 142 whose parameter-space curve follows another parameterisation than §4.3's (the
/// 100 arc generatrix measured from its start, as SolidWorks writes it) lies far from its
/// model-space curve: the model-space curve is drawn, projected through the sphere's pole.
/// The sphere: radius 2 about the origin, revolved about z from the arc from the north
/// pole (angle π/2) through (−2, 0, 0) to the south pole (3π/2). The boundary: the half
/// equator through (0, −2, 0) and the meridian half circle through the south pole in the
/// xz plane, so the face is the quarter sphere below the equator and y < 0, which in the
/// standard's parameters is t in [π, 3π/2], θ in [0, π].
#[test]
fn parameter_curve_far_from_its_model_curve_gives_way_to_it() {
    let xy_to_xz = [1.0, 0.0, 0.0, 0.0, 0.0, 0.0, -1.0, 0.0, 0.0, 1.0, 0.0, 0.0];
    let xy_to_x_minus_z = [1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, -1.0, 0.0, 0.0];
    let arc = |centre: [f64; 2], start: [f64; 2], end: [f64; 2], transform: usize| {
        let mut e = ent(
            100,
            &[
                0.0, centre[0], centre[1], start[0], start[1], end[0], end[1],
            ],
        );
        e.transform = transform;
        e
    };
    // B, one degree-1 126 through (t, θ) as measured from the arc's start (t − π/2).
    let h = 0.5 * PI;
    let corners =
        [(h, 0.0), (h, PI), (PI, PI), (PI, 0.0), (h, 0.0)].map(|(t, a)| DVec3::new(t, a, 0.0));
    let param_loop = b126(1, &[0.0, 0.0, 1.0, 2.0, 3.0, 4.0, 4.0], &corners, &[1.0; 5]);
    let mut face = ent(144, &[de(0), 1.0, 0.0, de(8)]);
    face.subordinate = 0;
    let ents = [
        ent(120, &[de(1), de(2), 0.0, 2.0 * PI]),
        ent(110, &[0.0, 0.0, 0.0, 0.0, 0.0, 1.0]),
        arc([0.0, 0.0], [0.0, 2.0], [0.0, -2.0], de(10) as usize),
        arc([0.0, 0.0], [-2.0, 0.0], [2.0, 0.0], 0),
        arc([0.0, 0.0], [2.0, 0.0], [0.0, 2.0], de(11) as usize),
        arc([0.0, 0.0], [0.0, 2.0], [-2.0, 0.0], de(11) as usize),
        ent(102, &[3.0, de(3), de(4), de(5)]),
        ent(126, &param_loop),
        ent(142, &[1.0, de(0), de(7), de(6), 1.0]),
        face,
        ent(124, &xy_to_xz),
        ent(124, &xy_to_x_minus_z),
    ];
    let read = read(&ents);
    assert_eq!(read.report.strayed, [1], "the 120 at D 1 is named");
    let (s, surface) = only(&read);
    let [outer]: &[TrimLoop; 1] = surface.trims.as_slice().try_into().unwrap();
    // The loop's points, in the standard's (t, θ), bound the quarter sphere.
    let points: Vec<DVec2> = outer
        .segments
        .iter()
        .flat_map(|seg| {
            (0..=8)
                .map(move |k| trim_point(&seg.curve, seg.t0 + (seg.t1 - seg.t0) * k as f64 / 8.0))
        })
        .collect();
    let lo = points.iter().fold(DVec2::INFINITY, |a, &p| a.min(p));
    let hi = points.iter().fold(DVec2::NEG_INFINITY, |a, &p| a.max(p));
    let near = |a: f64, b: f64| (a - b).abs() < 1e-6;
    assert!(
        near(lo.x, PI) && near(hi.x, 1.5 * PI) && near(lo.y, 0.0) && near(hi.y, PI),
        "loop box {lo} .. {hi}"
    );
    // And each lies on the sphere's boundary curves: on the equator or in the xz plane.
    for p in points {
        let (u, v) = (
            surface.trim_space[0].invert(p.x),
            surface.trim_space[1].invert(p.y),
        );
        let q = s.eval(u, v);
        assert!((q.length() - 2.0).abs() < 1e-9, "{q} off the sphere");
        assert!(q.z.abs() < 1e-6 || q.y.abs() < 1e-6, "{q} off the boundary");
    }
}

#[test]
fn tabulated_cylinder_of_a_b_spline_and_its_trims() {
    let pts = [
        DVec3::new(0., 0., 0.),
        DVec3::new(1., 2., 0.),
        DVec3::new(3., -1., 0.5),
        DVec3::new(4., 0., 0.),
    ];
    let w = [1.0, 0.5, 2.0, 1.0];
    let knots = [1.0, 1.0, 1.0, 2.0, 3.0, 3.0, 3.0];
    let end = DVec3::new(0.5, 0.5, 3.0);
    // 0: 126 directrix on t in [1, 3]; 1: 122; 2: 110 trim line in (u, v); 3: 142; 4: 144.
    let mut top = ent(144, &[de(1), 1.0, 0.0, de(3)]);
    top.subordinate = 0;
    let read = read(&[
        ent(126, &b126(2, &knots, &pts, &w)),
        ent(122, &[de(0), end.x, end.y, end.z]),
        ent(110, &[0.0, 0.0, 0.0, 1.0, 0.5, 0.0]),
        ent(142, &[0.0, de(1), de(2), 0.0, 1.0]),
        top,
    ]);
    let (s, surface) = only(&read);
    let c = |t: f64| curve_point(2, &knots, &pts, &w, t);
    for (u, v) in grid() {
        let (u, v) = s.domain().to_parent(u, v);
        let t = surface.trim_space[0].apply(u);
        close(s.eval(u, v), c(t) + (end - c(1.0)) * v, 5.0, "122");
    }
    // The trim (u, v) = (0, 0) → (1, 0.5) in the 122's normalised u lands at t = 1 → 3.
    let seg = &surface.trims[0].segments[0];
    assert!((trim_point(&seg.curve, seg.t0) - DVec2::new(1.0, 0.0)).length() < REL);
    assert!((trim_point(&seg.curve, seg.t1) - DVec2::new(3.0, 0.5)).length() < REL);
}

#[test]
fn ruled_surface_between_a_line_and_a_cubic() {
    let pts = [
        DVec3::new(0., 1., 0.),
        DVec3::new(1., 2., 1.),
        DVec3::new(2., 1., 0.),
        DVec3::new(3., 2., 1.),
    ];
    let knots = [0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0];
    let mut ruled = ent(118, &[de(0), de(1), 0.0, 0.0]);
    ruled.form = 1;
    ruled.subordinate = 0;
    let read = read(&[
        ent(110, &[0.0, 0.0, 0.0, 3.0, 0.0, 0.0]),
        ent(126, &b126(3, &knots, &pts, &[1.0; 4])),
        ruled,
    ]);
    let (s, _) = only(&read);
    for (u, v) in grid() {
        let line = DVec3::new(3.0 * u, 0.0, 0.0);
        let cubic = curve_point(3, &knots, &pts, &[1.0; 4], u);
        close(s.eval(u, v), line * (1.0 - v) + cubic * v, 3.0, "118");
    }
}

#[test]
fn bounded_plane_and_copious_data() {
    // 108 form 1 (A, B, C, D) bounded by a closed 106 form 63 polygon in the plane.
    let (nrm, d) = (DVec3::new(1.0, 2.0, 2.0), 3.0);
    let poly = [
        DVec3::new(3.0, 0.0, 0.0),
        DVec3::new(1.0, 1.0, 0.0),
        DVec3::new(-1.0, 0.0, 2.0),
        DVec3::new(3.0, 0.0, 0.0),
    ];
    let mut copious = vec![2.0, poly.len() as f64];
    for p in &poly {
        assert_eq!(p.dot(nrm), d);
        copious.extend([p.x, p.y, p.z]);
    }
    let mut cop = ent(106, &copious);
    cop.form = 63;
    let mut plane = ent(108, &[nrm.x, nrm.y, nrm.z, d, de(0), 0.0, 0.0, 0.0, 1.0]);
    plane.form = 1;
    plane.subordinate = 0;
    let read = read(&[cop, plane]);
    let (s, surface) = only(&read);
    for (u, v) in grid() {
        let (u, v) = s.domain().to_parent(u, v);
        assert!((s.eval(u, v).dot(nrm) - d).abs() < REL * 9.0);
    }
    // The loop's vertices are the polygon's, in the plane patch's own (u, v).
    let seg = &surface.trims[0].segments[0];
    for (i, p) in poly.iter().enumerate() {
        let uv = trim_point(&seg.curve, i as f64);
        close(s.eval(uv.x, uv.y), *p, 3.0, "106 vertex");
    }
}

#[test]
fn parametric_spline_and_ellipse_as_trims_and_a_projected_model_space_curve() {
    let n = net();
    // 1: 112 of two cubic segments as the outer loop's parameter curve; 3: 104 ellipse
    // (x − 0.5)²/0.04 + (y − 0.5)²/0.01 = 1 in general form, as a hole; 5: 110 model-space
    // line on the surface, only in model space (projected).
    let seg = |a: [f64; 4], b: [f64; 4]| [a, b, [0.0; 4]].concat();
    let s0 = seg([0.1, 0.8, 0.0, 0.0], [0.1, 0.0, 2.0, -2.0]);
    let s1 = seg([0.9, -0.8, 0.0, 0.0], [0.1, 0.4, 0.0, 0.0]);
    let mut p112 = vec![3.0, 2.0, 2.0, 2.0, 0.0, 1.0, 3.0];
    p112.extend(&s0);
    p112.extend(&s1);
    p112.extend([0.0; 12]);
    let (a, c, dd, e, f) = (25.0, 100.0, -25.0, -100.0, 25.0 * 0.25 + 100.0 * 0.25 - 1.0);
    let mut top = ent(144, &[de(0), 1.0, 2.0, de(2), de(4), de(7)]);
    top.subordinate = 0;
    let read = read(&[
        ent(128, &b128(&n, [0.0, 1.0, 0.0, 1.0])),
        ent(112, &p112),
        ent(142, &[0.0, de(0), de(1), 0.0, 1.0]),
        ent(104, &[a, 0.0, c, dd, e, f, 0.0, 0.7, 0.5, 0.7, 0.5]),
        ent(142, &[0.0, de(0), de(3), 0.0, 1.0]),
        // The u = 0 edge is the straight segment P00 → P01 (degree 1 in v).
        ent(
            110,
            &[
                n.pts[0].x, n.pts[0].y, n.pts[0].z, n.pts[4].x, n.pts[4].y, n.pts[4].z,
            ],
        ),
        // A null entity (type 0), physically dependent: neither drawn nor counted.
        ent(0, &[]),
        ent(142, &[0.0, de(0), 0.0, de(5), 2.0]),
        top,
    ]);
    let (_, surface) = only(&read);
    let [outer, ellipse, projected]: &[TrimLoop; 3] = surface.trims.as_slice().try_into().unwrap();
    assert!(!outer.hole && ellipse.hole && projected.hole);
    let poly = |k: [f64; 4], s: f64| k[0] + k[1] * s + k[2] * s * s + k[3] * s * s * s;
    let seg112 = &outer.segments[0];
    for i in 0..=20 {
        let t = 3.0 * i as f64 / 20.0;
        let (k, s) = if t <= 1.0 { (&s0, t) } else { (&s1, t - 1.0) };
        let want = DVec2::new(
            poly(k[0..4].try_into().unwrap(), s),
            poly(k[4..8].try_into().unwrap(), s),
        );
        assert!(
            (trim_point(&seg112.curve, t) - want).length() < REL,
            "t = {t}"
        );
    }
    let es = &ellipse.segments[0];
    for i in 0..=16 {
        let t = es.t0 + (es.t1 - es.t0) * i as f64 / 16.0;
        let p = trim_point(&es.curve, t);
        let q = a * p.x * p.x + c * p.y * p.y + dd * p.x + e * p.y + f;
        assert!(q.abs() < 1e-11, "conic residual {q}");
    }
    // The projected u = 0 edge: every point at u = 0, v from 0 to 1.
    // Within the projection's chord tolerance, 1e-6 of the surface's net diagonal; the
    // curve lies on the surface.
    let (lo, hi) = n
        .pts
        .iter()
        .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(a, b), &p| {
            (a.min(p), b.max(p))
        });
    assert_eq!(read.report.projected, 1);
    assert!(read.report.max_trim_error <= 1e-6 * (hi - lo).length());
    assert!(read.report.max_curve_gap <= 1e-12 * (hi - lo).length());
    let ps = &projected.segments[0];
    for i in 0..=8 {
        let t = ps.t0 + (ps.t1 - ps.t0) * i as f64 / 8.0;
        let p = trim_point(&ps.curve, t);
        assert!(
            p.x.abs() < 1e-9 && (-1e-9..=1.0 + 1e-9).contains(&p.y),
            "{p}"
        );
    }
}

#[test]
fn unsupported_entities_are_counted_and_bad_surfaces_named() {
    let mut offset_curve = ent(130, &[0.0]);
    offset_curve.subordinate = 0;
    let mut bad = ent(120, &[de(0), de(0), 0.0, 1.0]);
    bad.subordinate = 0;
    let read = read(&[offset_curve, bad]);
    assert_eq!(
        read.report.skipped().into_iter().collect::<Vec<_>>(),
        [("130 (offset curve)".to_string(), 1)]
    );
    assert_eq!(read.report.failed.len(), 1);
    let f = &read.report.failed[0];
    assert!(
        f.entity == "D 3" && f.why.starts_with("entity 120: "),
        "{f:?}"
    );
}

#[test]
fn syntax_errors_are_located() {
    let text = write_iges(&[ent(110, &[0.0, 0.0, 0.0, 1.0, 1.0, 1.0])]);
    let text = text.replacen("1,1,1;", "1,x,1;", 1);
    let line = 1 + text.lines().position(|l| l.starts_with("110,")).unwrap();
    let e = parse_iges(Path::new("bad.igs"), &text).err().unwrap();
    assert_eq!((e.line, e.column), (line, 13), "{e}");
    assert!(e.to_string().contains("expected a number"), "{e}");
    let text = write_iges(&[ent(110, &[0.0, 0.0, 0.0, 1.0, 1.0])]);
    let e = parse_iges(Path::new("short.igs"), &text).err().unwrap();
    assert_eq!(
        e.message,
        "parameter 6 of entity 110 (D 1): expected a real, found the end of its parameters"
    );
}

fn external(name: &str) -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("testdata/gismo")
        .join(name)
}

#[test]
fn torus_igs_loads_one_closed_bicubic() {
    let read = patchtrace::formats::cad::iges::read_iges(&external("torus.igs")).unwrap();
    let (n, s) = only(&read);
    assert_eq!(
        (n.degree_u, n.degree_v, n.count_u, n.count_v),
        (3, 3, 7, 11)
    );
    assert!(s.trims.is_empty());
    assert!(read.surfaces[0].colour.is_some());
}

#[test]
fn hammer_from_iges_is_the_hammer_from_obj() {
    let iges = patchtrace::formats::load_geometry(&external("hammer.iges")).unwrap();
    let obj = patchtrace::formats::load_geometry(&external("hammer.from_iges.obj")).unwrap();
    let (patchtrace::scene::Geometry::Surfaces(a), patchtrace::scene::Geometry::Surfaces(b)) =
        (iges, obj)
    else {
        panic!("surfaces")
    };
    assert_eq!(a.len(), 45);
    assert_eq!(a.len(), b.len());
    // The OBJ holds 10 significant digits.
    let rel = 1e-9;
    let near = |x: f64, y: f64, scale: f64| (x - y).abs() <= rel * scale.max(x.abs());
    let mut redrawn = Vec::new();
    for (k, (x, y)) in a.iter().zip(&b).enumerate() {
        let (SurfaceGeometry::Nurbs(p), SurfaceGeometry::Nurbs(q)) = (&x.geometry, &y.geometry)
        else {
            panic!("NURBS")
        };
        // The OBJ restricts a surface to its `surf` range (knot insertion, exact), where
        // the IGES reader keeps the whole 128 and makes a narrower parameter range an outer
        // loop: compare the IGES surface restricted the same way.
        let restricted;
        let p = if (p.domain().u0 - q.domain().u0).abs() > rel * p.domain().u0.abs().max(1.0)
            || (p.domain().u1 - q.domain().u1).abs() > rel * p.domain().u1.abs().max(1.0)
            || (p.domain().v0 - q.domain().v0).abs() > rel * p.domain().v0.abs().max(1.0)
            || (p.domain().v1 - q.domain().v1).abs() > rel * p.domain().v1.abs().max(1.0)
        {
            restricted = p.restricted(q.domain());
            &restricted
        } else {
            p
        };
        assert_eq!(
            (p.degree_u, p.degree_v, p.count_u, p.count_v),
            (q.degree_u, q.degree_v, q.count_u, q.count_v),
            "surface {k}"
        );
        for (s, t) in p
            .knots_u
            .iter()
            .chain(&p.knots_v)
            .zip(q.knots_u.iter().chain(&q.knots_v))
        {
            assert!(near(*s, *t, 10.0), "surface {k}: knot {s} vs {t}");
        }
        for (s, t) in p.points.iter().zip(&q.points) {
            let (e, f) = (s.truncate() / s.w, t.truncate() / t.w);
            assert!(
                (e - f).length() <= rel * e.length().max(1.0) * 2.0,
                "surface {k}: {e} vs {f}"
            );
            assert!(near(s.w, t.w, 1.0), "surface {k}: weight");
        }
        let same_trims = x.trims.len() == y.trims.len()
            && x.trims.iter().zip(&y.trims).all(|(l, m)| {
                (l.hole, l.segments.len()) == (m.hole, m.segments.len())
                    && l.segments.iter().zip(&m.segments).all(|(s, t)| {
                        near(s.t0, t.t0, 1.0)
                            && near(s.t1, t.t1, 1.0)
                            && s.curve.points.len() == t.curve.points.len()
                            && s.curve
                                .points
                                .iter()
                                .zip(&t.curve.points)
                                .all(|(g, h)| (*g / g.z - *h / h.z).length() <= rel * 10.0)
                    })
            });
        if !same_trims {
            redrawn.push(k);
        }
    }
    // The OBJ keeps every parameter-space curve; the reader draws a boundary from its
    // model-space curve where the parameter-space one lies far from it, and says where:
    // exactly those surfaces may differ in their trims.
    let report = parse_iges(
        &external("hammer.iges"),
        &std::fs::read_to_string(external("hammer.iges")).unwrap(),
    )
    .unwrap()
    .report;
    assert_eq!(redrawn.len(), report.strayed.len(), "{redrawn:?}");
}

// ---------------------------------------------------------------------------------------
// 114, 190–198, 141/143, hyperbolic 104.

/// A global bicubic polynomial surface, coefficients g[d][a + 4 b] of u^a v^b.
fn poly_surface() -> [[f64; 16]; 3] {
    let mut g = [[0.0; 16]; 3];
    g[0][1] = 1.0; // x = u + 0.1 u v²
    g[0][1 + 8] = 0.1;
    g[1][4] = 1.0; // y = v + 0.2 u³ − 0.05 u² v³
    g[1][3] = 0.2;
    g[1][2 + 12] = -0.05;
    g[2][0] = 0.2; // z = 0.2 − 0.5 u v + 0.3 u² v³ + 0.1 u³ v
    g[2][1 + 4] = -0.5;
    g[2][2 + 12] = 0.3;
    g[2][3 + 4] = 0.1;
    g
}

fn poly_eval(g: &[[f64; 16]; 3], u: f64, v: f64) -> DVec3 {
    let c = |d: usize| {
        (0..16)
            .map(|k| g[d][k] * u.powi((k % 4) as i32) * v.powi((k / 4) as i32))
            .sum::<f64>()
    };
    DVec3::new(c(0), c(1), c(2))
}

fn binomial(n: usize, k: usize) -> f64 {
    (0..k).fold(1.0, |acc, i| acc * (n - i) as f64 / (i + 1) as f64)
}

/// The polynomial re-expanded about (u0, v0) (Taylor shift), as a 114 patch stores it.
fn shifted(g: &[[f64; 16]; 3], u0: f64, v0: f64) -> Vec<f64> {
    let mut out = Vec::new();
    for gd in g {
        for k in 0..16 {
            let (a, b) = (k % 4, k / 4);
            let mut c = 0.0;
            for a2 in a..4 {
                for b2 in b..4 {
                    c += gd[a2 + 4 * b2]
                        * binomial(a2, a)
                        * binomial(b2, b)
                        * u0.powi((a2 - a) as i32)
                        * v0.powi((b2 - b) as i32);
                }
            }
            out.push(c);
        }
    }
    out
}

#[test]
fn parametric_spline_surface_of_two_by_two_patches() {
    let g = poly_surface();
    let (tu, tv) = ([0.0, 0.4, 1.0], [-1.0, 0.0, 0.5]);
    let mut p = vec![3.0, 0.0, 2.0, 2.0];
    p.extend(tu);
    p.extend(tv);
    for &u0 in &tu[..2] {
        for &v0 in &tv[..2] {
            p.extend(shifted(&g, u0, v0));
        }
        p.extend([0.0; 48]); // the arbitrary values after each row
    }
    p.extend([0.0; 48 * 3]);
    let mut s114 = ent(114, &p);
    s114.subordinate = 0;
    let read = read(&[s114]);
    let (s, surface) = only(&read);
    assert!(surface.trims.is_empty());
    assert_eq!((s.degree_u, s.degree_v, s.count_u, s.count_v), (3, 3, 7, 7));
    for (a, b) in grid() {
        let (u, v) = (a, -1.0 + 1.5 * b);
        close(s.eval(u, v), poly_eval(&g, u, v), 2.0, "114");
    }
}

/// An entity that is a 116 point or a 123 direction.
fn vector(ty: i32, v: DVec3) -> Ent {
    ent(ty, &[v.x, v.y, v.z])
}

/// The frame of a parameterised 190–198: X the reference made orthogonal to the axis.
fn frame(axis: DVec3, reference: DVec3) -> [DVec3; 3] {
    let z = axis.normalize();
    let x = (reference - z * reference.dot(z)).normalize();
    [x, z.cross(x), z]
}

#[test]
fn analytic_surfaces_in_their_standard_parameterisation_with_parameter_space_trims() {
    let centre = DVec3::new(1.0, -2.0, 0.5);
    let (axis, reference) = (DVec3::new(0.2, 0.3, 1.0), DVec3::new(1.0, 0.5, 0.0));
    let [x, y, z] = frame(axis, reference);
    let (r, big, alpha) = (1.5, 3.0, 20f64.to_radians());
    // (type, parameters after the three pointers' slots, the definition, the trim box)
    type Def = Box<dyn Fn(f64, f64) -> DVec3>;
    let ring = move |u: f64| x * u.cos() + y * u.sin();
    let cases: Vec<(i32, Vec<f64>, Def, [f64; 4])> = vec![
        (
            190,
            vec![de(0), de(1), de(2)],
            Box::new(move |u, v| centre + x * u + y * v),
            [-1.0, 2.0, -0.5, 1.5],
        ),
        (
            192,
            vec![de(0), de(1), r, de(2)],
            Box::new(move |u, v| centre + ring(u) * r + z * v),
            [0.3, 2.5, -1.0, 2.0],
        ),
        (
            194,
            vec![de(0), de(1), r, alpha.to_degrees(), de(2)],
            Box::new(move |u, v| centre + ring(u) * (r + v * alpha.tan()) + z * v),
            [-2.0, 3.0, -1.0, 2.0],
        ),
        (
            196,
            vec![de(0), r, de(1), de(2)],
            Box::new(move |u, v| centre + ring(u) * (r * v.cos()) + z * (r * v.sin())),
            [0.5, 5.5, -1.2, 0.9],
        ),
        (
            198,
            vec![de(0), de(1), big, r, de(2)],
            Box::new(move |u, v| centre + ring(u) * (big + r * v.cos()) + z * (r * v.sin())),
            [-1.0, 1.5, 0.2, 6.0],
        ),
    ];
    for (ty, params, def, [u0, u1, v0, v1]) in cases {
        let mut surface = ent(ty, &params);
        surface.form = 1;
        // 0: 116; 1: 123 axis; 2: 123 reference; 3: surface; 4: 106 loop in (u, v);
        // 5: 142; 6: 144.
        let corners = [(u0, v0), (u1, v0), (u1, v1), (u0, v1), (u0, v0)];
        let mut loop_points = vec![1.0, 5.0, 0.0];
        for (u, v) in corners {
            loop_points.extend([u, v]);
        }
        let mut polygon = ent(106, &loop_points);
        polygon.form = 63;
        let mut top = ent(144, &[de(3), 1.0, 0.0, de(5)]);
        top.subordinate = 0;
        let read = read(&[
            vector(116, centre),
            vector(123, axis),
            vector(123, reference),
            surface,
            polygon,
            ent(142, &[0.0, de(3), de(4), 0.0, 1.0]),
            top,
        ]);
        let (s, trimmed) = only(&read);
        let d = s.domain();
        let maps = &trimmed.trim_space;
        // The patch covers the trim box, and its points are the definition's at the
        // mapped parameters.
        let (a0, a1) = (maps[0].apply(d.u0), maps[0].apply(d.u1));
        let (b0, b1) = (maps[1].apply(d.v0), maps[1].apply(d.v1));
        assert!(
            (a0 - u0).abs() < 1e-12 && (a1 - u1).abs() < 1e-12,
            "{ty}: u {a0} {a1}"
        );
        assert!(
            (b0 - v0).abs() < 1e-12 && (b1 - v1).abs() < 1e-12,
            "{ty}: v {b0} {b1}"
        );
        for (a, b) in grid() {
            let (u, v) = d.to_parent(a, b);
            let want = def(maps[0].apply(u), maps[1].apply(v));
            close(s.eval(u, v), want, 6.0, &format!("{ty}"));
        }
        let seg = &trimmed.trims[0].segments[0];
        for (k, (u, v)) in corners.iter().enumerate() {
            assert!((trim_point(&seg.curve, k as f64) - DVec2::new(*u, *v)).length() < REL);
        }
    }
}

#[test]
fn closed_analytic_surfaces_draw_whole_and_unbounded_ones_are_named() {
    let centre = DVec3::new(0.5, 0.0, -1.0);
    let mut sphere = ent(196, &[de(0), 2.0]);
    sphere.subordinate = 0;
    let mut torus = ent(198, &[de(0), de(1), 3.0, 1.0]);
    torus.subordinate = 0;
    let mut cylinder = ent(192, &[de(0), de(1), 1.0]);
    cylinder.subordinate = 0;
    let read = read(&[
        vector(116, centre),
        vector(123, DVec3::Z),
        sphere,
        torus,
        cylinder,
    ]);
    assert_eq!(read.surfaces.len(), 2, "{:?}", read.report.failed);
    assert_eq!(read.report.failed.len(), 1);
    let f = &read.report.failed[0];
    assert!(
        f.entity == "D 9" && f.why.starts_with("entity 192: "),
        "{f:?}"
    );
    for (k, drawn) in read.surfaces.iter().enumerate() {
        let SurfaceGeometry::Nurbs(s) = &drawn.surface.geometry else {
            panic!()
        };
        let maps = &drawn.surface.trim_space;
        let d = s.domain();
        for (a, b) in grid() {
            let (u, v) = d.to_parent(a, b);
            let l = s.eval(u, v) - centre;
            let residual = if k == 0 {
                l.length() - 2.0
            } else {
                (l.truncate().length() - 3.0).hypot(l.z) - 1.0
            };
            assert!(residual.abs() < 1e-12 * 4.0, "surface {k}: {residual:e}");
        }
        let turn = maps[0].apply(d.u1) - maps[0].apply(d.u0);
        assert!((turn - 2.0 * PI).abs() < 1e-12, "a full turn: {turn}");
    }
}

#[test]
fn unparameterised_cylinder_trimmed_by_a_model_space_curve() {
    // 192 form 0 about the z axis through the origin, radius 2; the boundary is a 106
    // form 12 polygon through points on it, given only in model space.
    let angles_heights = [(0.2, 0.0), (1.5, 0.0), (2.0, 1.0), (0.6, 1.5), (0.2, 0.0)];
    let mut poly = vec![2.0, angles_heights.len() as f64];
    for (a, h) in angles_heights {
        poly.extend([2.0 * f64::cos(a), 2.0 * f64::sin(a), h]);
    }
    let mut copious = ent(106, &poly);
    copious.form = 12;
    let mut top = ent(144, &[de(2), 1.0, 0.0, de(4)]);
    top.subordinate = 0;
    let read = read(&[
        vector(116, DVec3::ZERO),
        vector(123, DVec3::Z),
        ent(192, &[de(0), de(1), 2.0]),
        copious,
        ent(142, &[0.0, de(2), 0.0, de(3), 2.0]),
        top,
    ]);
    let (s, trimmed) = only(&read);
    let d = s.domain();
    for (a, b) in grid() {
        let (u, v) = d.to_parent(a, b);
        assert!((s.eval(u, v).truncate().length() - 2.0).abs() < 1e-12 * 4.0);
    }
    // Each polygon vertex, through the trim loop and the surface, is the vertex again.
    let seg = &trimmed.trims[0].segments[0];
    let maps = &trimmed.trim_space;
    for (k, (a, h)) in angles_heights.iter().enumerate() {
        let uv = trim_point(&seg.curve, (24 * k) as f64);
        let p = s.eval(maps[0].invert(uv.x), maps[1].invert(uv.y));
        close(
            p,
            DVec3::new(2.0 * a.cos(), 2.0 * a.sin(), *h),
            4.0,
            "vertex",
        );
    }
}

#[test]
fn bounded_surface_of_boundaries_with_reversed_and_model_space_curves() {
    let n = net();
    // 1–3: 110 lines in (u, v) (0.1, 0.1) → (0.9, 0.1) → (0.9, 0.9) and, written backwards,
    // (0.1, 0.1) → (0.9, 0.9) for the closing edge; 4: 141 of two edges (the second
    // SENSE 2); 5: 100 circle hole in (u, v); 6: 141 of it; 7: 143.
    let mut bounded = ent(143, &[1.0, de(0), 2.0, de(4), de(6)]);
    bounded.subordinate = 0;
    let read = read(&[
        ent(128, &b128(&n, [0.0, 1.0, 0.0, 1.0])),
        ent(110, &[0.1, 0.1, 0.0, 0.9, 0.1, 0.0]),
        ent(110, &[0.9, 0.1, 0.0, 0.9, 0.9, 0.0]),
        ent(110, &[0.1, 0.1, 0.0, 0.9, 0.9, 0.0]),
        ent(
            141,
            &[
                1.0,
                2.0,
                de(0),
                2.0,
                0.0,
                1.0,
                2.0,
                de(1),
                de(2),
                0.0,
                2.0,
                1.0,
                de(3),
            ],
        ),
        ent(100, &[0.0, 0.6, 0.3, 0.7, 0.3, 0.7, 0.3]),
        ent(141, &[1.0, 2.0, de(0), 1.0, 0.0, 1.0, 1.0, de(5)]),
        bounded,
    ]);
    let (_, surface) = only(&read);
    let [outer, hole]: &[TrimLoop; 2] = surface.trims.as_slice().try_into().unwrap();
    assert!(!outer.hole && hole.hole);
    // The loop runs (0.1, 0.1) → (0.9, 0.1) → (0.9, 0.9) → (0.1, 0.1), each segment
    // starting where the last ended.
    let vertices = [(0.1, 0.1), (0.9, 0.1), (0.9, 0.9), (0.1, 0.1)];
    assert_eq!(outer.segments.len(), 3);
    for (k, seg) in outer.segments.iter().enumerate() {
        let (a, b) = (DVec2::from(vertices[k]), DVec2::from(vertices[k + 1]));
        assert!((trim_point(&seg.curve, seg.t0) - a).length() < REL, "{k}");
        assert!((trim_point(&seg.curve, seg.t1) - b).length() < REL, "{k}");
    }
    let c = &hole.segments[0];
    let mid = trim_point(&c.curve, 0.5 * (c.t0 + c.t1));
    assert!(((mid - DVec2::new(0.6, 0.3)).length() - 0.1).abs() < REL);
}

#[test]
fn hyperbolic_conic_arc_in_general_position() {
    let n = net();
    let (a, b, phi, c) = (0.1, 0.05, 0.4f64, DVec2::new(0.4, 0.5));
    let (cp, sp) = (phi.cos(), phi.sin());
    let ka = cp * cp / (a * a) - sp * sp / (b * b);
    let kb = 2.0 * cp * sp * (1.0 / (a * a) + 1.0 / (b * b));
    let kc = sp * sp / (a * a) - cp * cp / (b * b);
    let kd = -2.0 * ka * c.x - kb * c.y;
    let ke = -kb * c.x - 2.0 * kc * c.y;
    let kf = ka * c.x * c.x + kb * c.x * c.y + kc * c.y * c.y - 1.0;
    let on = |t: f64| {
        let q = DVec2::new(a * t.cosh(), b * t.sinh());
        c + DVec2::new(cp * q.x - sp * q.y, sp * q.x + cp * q.y)
    };
    // Written from t = 0.8 to t = −0.5: the reader orients the arc itself.
    let (s, e) = (on(0.8), on(-0.5));
    let mut top = ent(144, &[de(0), 1.0, 1.0, 0.0, de(2)]);
    top.subordinate = 0;
    let read = read(&[
        ent(128, &b128(&n, [0.0, 1.0, 0.0, 1.0])),
        ent(104, &[ka, kb, kc, kd, ke, kf, 0.0, s.x, s.y, e.x, e.y]),
        ent(142, &[0.0, de(0), de(1), 0.0, 1.0]),
        top,
    ]);
    let (_, surface) = only(&read);
    let seg = &surface.trims[0].segments[0];
    let ends = [
        trim_point(&seg.curve, seg.t0),
        trim_point(&seg.curve, seg.t1),
    ];
    assert!(
        (ends[0] - s).length() < REL && (ends[1] - e).length() < REL
            || (ends[0] - e).length() < REL && (ends[1] - s).length() < REL,
        "{ends:?}"
    );
    for i in 0..=16 {
        let t = (seg.t0 + (seg.t1 - seg.t0) * i as f64 / 16.0).min(seg.t1);
        let p = trim_point(&seg.curve, t);
        let q = ka * p.x * p.x + kb * p.x * p.y + kc * p.y * p.y + kd * p.x + ke * p.y + kf;
        // The conic's gradient is about 2/b² · b = 40 here: residual 1e-12 · 40 per unit.
        assert!(q.abs() < 1e-10, "conic residual {q:e}");
        // On the branch between the ends: its local x is positive.
        let l = p - c;
        assert!(cp * l.x + sp * l.y > 0.0);
    }
}

#[test]
fn manifold_solid_b_rep_faces_with_edge_lists_and_loops() {
    let n = net();
    let (c, r) = (DVec3::new(0.0, 0.0, 5.0), 1.5);
    // 0: 128; 1–3: 110 model-space curves (unused: parameter curves are given), the
    // third written backwards; 4–6: 110 parameter curves along the loop; 7: 504; 8: 508
    // (the third edge OF 0: its model-space curve runs against the loop); 9: 510 on the
    // 128; 10: 116; 11: 196; 12: 510 on the sphere, no loops; 13: 514; 14: 186 (colour 3,
    // translated by 15: 124).
    let uv = [(0.1, 0.1), (0.9, 0.1), (0.9, 0.9)];
    let model = |(u, v): (f64, f64)| net_point(&n, u, v);
    let mut ents = vec![ent(128, &b128(&n, [0.0, 1.0, 0.0, 1.0]))];
    for k in 0..3 {
        let (a, b) = if k == 2 {
            (model(uv[0]), model(uv[2]))
        } else {
            (model(uv[k]), model(uv[k + 1]))
        };
        ents.push(ent(110, &[a.x, a.y, a.z, b.x, b.y, b.z]));
    }
    for k in 0..3 {
        let (a, b) = (uv[k], uv[(k + 1) % 3]);
        ents.push(ent(110, &[a.0, a.1, 0.0, b.0, b.1, 0.0]));
    }
    let mut edges = vec![3.0];
    for k in 0..3 {
        edges.extend([de(1 + k), 0.0, 0.0, 0.0, 0.0]);
    }
    ents.push(ent(504, &edges));
    let mut lp = vec![3.0];
    for k in 0..3 {
        let of = if k == 2 { 0.0 } else { 1.0 };
        lp.extend([0.0, de(7), (k + 1) as f64, of, 1.0, 0.0, de(4 + k)]);
    }
    ents.push(ent(508, &lp));
    ents.push(ent(510, &[de(0), 1.0, 1.0, de(8)]));
    ents.push(vector(116, c));
    let mut sphere = ent(196, &[de(10), r]);
    sphere.subordinate = 0; // marked independent: still drawn only as the face
    ents.push(sphere);
    let mut red = ent(510, &[de(11), 0.0, 0.0]);
    red.colour = 2;
    ents.push(red);
    ents.push(ent(514, &[2.0, de(9), 1.0, de(12), 1.0]));
    let mut solid = ent(186, &[de(13), 1.0, 0.0]);
    solid.subordinate = 0;
    solid.colour = 3;
    solid.transform = 31;
    ents.push(solid);
    let shift = DVec3::new(1.0, 2.0, -3.0);
    ents.push(ent(
        124,
        &[
            1.0, 0.0, 0.0, shift.x, 0.0, 1.0, 0.0, shift.y, 0.0, 0.0, 1.0, shift.z,
        ],
    ));
    // The same faces drawn on their own: the shell without its solid, and one face
    // without a shell, each marked independent (as some writers leave them); and the
    // solid's faces and shell marked independent too are still drawn once.
    let drawn = |ents: &[Ent]| {
        let r = read(ents);
        assert!(r.report.failed.is_empty(), "{:?}", r.report.failed);
        r.surfaces.len()
    };
    let independent = |mut e: Ent| {
        e.subordinate = 0;
        e
    };
    let mut lone_shell = ents[..13].to_vec();
    lone_shell.push(independent(ents[13].clone()));
    assert_eq!(drawn(&lone_shell), 2, "a lone 514");
    let mut lone_face = ents[..9].to_vec();
    lone_face.push(independent(ents[9].clone()));
    assert_eq!(drawn(&lone_face), 1, "a lone 510");
    // Marked as part of another entity that no shell or solid holds (as OpenCASCADE
    // writes a lone face): drawn, as OpenCASCADE reads it.
    assert_eq!(drawn(&ents[..10]), 1, "a lone dependent 510");
    let all_independent: Vec<Ent> = ents.iter().cloned().map(independent).collect();
    assert_eq!(
        drawn(&all_independent),
        2,
        "faces and shell of a solid, all independent"
    );
    let read = read(&ents);
    assert!(read.report.failed.is_empty(), "{:?}", read.report.failed);
    assert!(read.report.ignored.is_empty(), "{:?}", read.report.ignored);
    assert_eq!(read.surfaces.len(), 2);
    let (patch, ball) = (&read.surfaces[0], &read.surfaces[1]);
    assert_eq!(patch.colour, Some(DVec3::Y));
    assert_eq!(ball.colour, Some(DVec3::X));
    let SurfaceGeometry::Nurbs(s) = &patch.surface.geometry else {
        panic!()
    };
    for (u, v) in grid() {
        close(s.eval(u, v), net_point(&n, u, v) + shift, 8.0, "186 face");
    }
    let [outer]: &[TrimLoop; 1] = patch.surface.trims.as_slice().try_into().unwrap();
    assert!(!outer.hole);
    for (k, seg) in outer.segments.iter().enumerate() {
        let (a, b) = (DVec2::from(uv[k]), DVec2::from(uv[(k + 1) % 3]));
        assert!((trim_point(&seg.curve, seg.t0) - a).length() < REL, "{k}");
        assert!((trim_point(&seg.curve, seg.t1) - b).length() < REL, "{k}");
    }
    let SurfaceGeometry::Nurbs(b) = &ball.surface.geometry else {
        panic!()
    };
    assert!(ball.surface.trims.is_empty());
    for (u, v) in grid() {
        let (u, v) = b.domain().to_parent(u, v);
        let d = (b.eval(u, v) - c - shift).length();
        assert!((d - r).abs() < 1e-12 * 8.0, "{d}");
    }
}

#[test]
fn subfigure_instances_become_transformed_copies() {
    let (c, r) = (DVec3::new(0.5, -0.5, 1.0), 0.75);
    // 0: 116; 1: 123; 2: 196 sphere; 3: 198 torus; 4: 308 {torus}; 5: 408 of 4 at
    // (5, 0, 0); 6: 308 {sphere, 5}; 7: 408 of 6 at (1, 2, 3) scale 2; 8: 408 of 6
    // at the origin.
    let mut member = ent(196, &[de(0), r]);
    member.subordinate = 0; // a member marked independent is still drawn only per instance
    let mut outer = ent(408, &[de(6), 1.0, 2.0, 3.0, 2.0]);
    outer.subordinate = 0;
    let mut plain = ent(408, &[de(6)]);
    plain.subordinate = 0;
    let read = read(&[
        vector(116, c),
        vector(123, DVec3::Z),
        member,
        ent(198, &[de(0), de(1), 2.0, 0.5]),
        ent(308, &[0.0, 0.0, 1.0, de(3)]),
        ent(408, &[de(4), 5.0, 0.0, 0.0, 1.0]),
        ent(308, &[1.0, 0.0, 2.0, de(2), de(5)]),
        outer,
        plain,
    ]);
    assert!(read.report.failed.is_empty(), "{:?}", read.report.failed);
    assert_eq!(read.surfaces.len(), 4);
    let place = |scale: f64, shift: DVec3, p: DVec3| shift + p * scale;
    let t = DVec3::new(1.0, 2.0, 3.0);
    let want: [(DVec3, f64, bool); 4] = [
        (place(2.0, t, c), 2.0 * r, true),
        (place(2.0, t, c + DVec3::X * 5.0), 2.0, false),
        (c, r, true),
        (c + DVec3::X * 5.0, 1.0, false),
    ];
    for (k, (drawn, (centre, scale, is_sphere))) in read.surfaces.iter().zip(want).enumerate() {
        let SurfaceGeometry::Nurbs(s) = &drawn.surface.geometry else {
            panic!()
        };
        for (u, v) in grid() {
            let (u, v) = s.domain().to_parent(u, v);
            let l = s.eval(u, v) - centre;
            let residual = if is_sphere {
                l.length() - scale
            } else {
                (l.truncate().length() - 2.0 * scale).hypot(l.z) - 0.5 * scale
            };
            assert!(residual.abs() < 1e-12 * 16.0, "copy {k}: {residual:e}");
        }
    }
}

#[test]
fn subfigure_cycles_and_blow_ups_are_refused_by_name() {
    // 0: 308 holding 1 twice; 1: 408 of 0 (a cycle); 2: 408 of 0, drawn.
    let mut top = ent(408, &[de(0)]);
    top.subordinate = 0;
    let cyclic = read(&[
        ent(308, &[0.0, 0.0, 2.0, de(1), de(1)]),
        ent(408, &[de(0)]),
        top,
    ]);
    assert!(cyclic.surfaces.is_empty());
    assert!(
        cyclic.report.failed.iter().all(|f| f
            .why
            .ends_with("the definition D 1 contains an instance of itself")),
        "{:?}",
        cyclic.report.failed
    );
    // Ten definitions each instancing the next four times: 4^10 copies, cut off.
    let mut ents = Vec::new();
    for k in 0..10 {
        ents.push(ent(
            308,
            &[
                0.0,
                0.0,
                4.0,
                de(2 * k + 1),
                de(2 * k + 1),
                de(2 * k + 1),
                de(2 * k + 1),
            ],
        ));
        ents.push(ent(408, &[de(2 * k + 2)]));
    }
    ents.push(ent(308, &[0.0, 0.0, 0.0]));
    let mut top = ent(408, &[de(0)]);
    top.subordinate = 0;
    ents.push(top);
    let blown = read(&ents);
    assert!(
        blown.report.failed.iter().any(|f| f
            .why
            .contains("more than 65536 entities drawn through instances")),
        "{:?}",
        blown.report.failed.len()
    );
}

#[test]
fn parabolic_conic_arc_in_general_position() {
    let n = net();
    // 2 x''² − y'' = 0 in axes turned by φ about c.
    let (phi, c) = (0.7f64, DVec2::new(0.5, 0.4));
    let (cp, sp) = (phi.cos(), phi.sin());
    let (ka, kb, kc) = (2.0 * cp * cp, 4.0 * cp * sp, 2.0 * sp * sp);
    let kd = -2.0 * ka * c.x - kb * c.y + sp;
    let ke = -kb * c.x - 2.0 * kc * c.y - cp;
    let kf = ka * c.x * c.x + kb * c.x * c.y + kc * c.y * c.y - sp * c.x + cp * c.y;
    let on = |t: f64| c + DVec2::new(cp * t - sp * 2.0 * t * t, sp * t + cp * 2.0 * t * t);
    let (s, e) = (on(0.2), on(-0.15));
    let mut top = ent(144, &[de(0), 1.0, 1.0, 0.0, de(2)]);
    top.subordinate = 0;
    let read = read(&[
        ent(128, &b128(&n, [0.0, 1.0, 0.0, 1.0])),
        ent(104, &[ka, kb, kc, kd, ke, kf, 0.0, s.x, s.y, e.x, e.y]),
        ent(142, &[0.0, de(0), de(1), 0.0, 1.0]),
        top,
    ]);
    let (_, surface) = only(&read);
    let seg = &surface.trims[0].segments[0];
    let ends = [
        trim_point(&seg.curve, seg.t0),
        trim_point(&seg.curve, seg.t1),
    ];
    assert!(
        (ends[0] - s).length() < REL && (ends[1] - e).length() < REL
            || (ends[0] - e).length() < REL && (ends[1] - s).length() < REL,
        "{ends:?}"
    );
    for i in 0..=16 {
        let t = (seg.t0 + (seg.t1 - seg.t0) * i as f64 / 16.0).min(seg.t1);
        let p = trim_point(&seg.curve, t);
        let q = ka * p.x * p.x + kb * p.x * p.y + kc * p.y * p.y + kd * p.x + ke * p.y + kf;
        assert!(q.abs() < 1e-12, "conic residual {q:e}");
    }
}

#[test]
fn angles_beyond_a_turn_are_named_not_clamped() {
    // A cylinder trimmed by a loop from 10 to 80 in u: degrees, not radians.
    let mut cylinder = ent(192, &[de(0), de(1), 1.0, de(2)]);
    cylinder.form = 1;
    let mut polygon = ent(
        106,
        &[
            1.0, 5.0, 0.0, 10.0, 0.0, 80.0, 0.0, 80.0, 1.0, 10.0, 1.0, 10.0, 0.0,
        ],
    );
    polygon.form = 63;
    let mut top = ent(144, &[de(3), 1.0, 0.0, de(5)]);
    top.subordinate = 0;
    let read = read(&[
        vector(116, DVec3::ZERO),
        vector(123, DVec3::Z),
        vector(123, DVec3::X),
        cylinder,
        polygon,
        ent(142, &[0.0, de(3), de(4), 0.0, 1.0]),
        top,
    ]);
    assert!(read.surfaces.is_empty());
    assert_eq!(read.report.failed.len(), 1);
    assert!(
        read.report.failed[0].entity == "D 13"
            && read.report.failed[0]
                .why
                .starts_with("entity 144: the trim loops span 70 in the angle u"),
        "{:?}",
        read.report.failed
    );
}

/// A rational tensor-product point from Euclidean points and weights (u fastest), by the
/// recursion above.
#[allow(clippy::too_many_arguments)]
fn rational_point(
    [pu, pv]: [usize; 2],
    [ku, kv]: [&[f64]; 2],
    nu: usize,
    pts: &[DVec3],
    w: &[f64],
    u: f64,
    v: f64,
) -> DVec3 {
    let (mut num, mut den) = (DVec3::ZERO, 0.0);
    for (k, (q, wk)) in pts.iter().zip(w).enumerate() {
        let b = basis(k % nu, pu, ku, u) * basis(k / nu, pv, kv, v) * wk;
        num += *q * b;
        den += b;
    }
    num / den
}

#[test]
fn knot_of_multiplicity_degree_plus_one_is_a_break() {
    // Degree 2 × 1 with the u knot 1 repeated three times (degree + 1), as CATIA V4
    // writes piecewise surfaces: two pieces of three columns each, and here the second
    // is lifted by 5 so they do not meet. The surface is read whole, both pieces exact.
    let ku = [0., 0., 0., 1., 1., 1., 2., 2., 2.];
    let kv = [0., 0., 1., 1.];
    let (mut pts, mut w) = (Vec::new(), Vec::new());
    for j in 0..2 {
        for i in 0..6 {
            let lift = if i >= 3 { 5.0 } else { 0.0 };
            pts.push(DVec3::new(
                i as f64,
                2.0 * j as f64,
                lift + 0.3 * (i * j) as f64,
            ));
            w.push(1.0 + 0.25 * ((i + 2 * j) % 3) as f64);
        }
    }
    let mut params = vec![5.0, 1.0, 2.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0];
    params.extend(ku);
    params.extend(kv);
    params.extend(&w);
    for q in &pts {
        params.extend([q.x, q.y, q.z]);
    }
    params.extend([0.0, 2.0, 0.0, 1.0]);
    let mut surf = ent(128, &params);
    surf.subordinate = 0;
    let read = read(&[surf]);
    let (n, _) = only(&read);
    for (u, v) in grid() {
        let u = 2.0 * u;
        let expected = rational_point([2, 1], [&ku, &kv], 6, &pts, &w, u, v);
        close(n.eval(u, v), expected, 10.0, &format!("({u}, {v})"));
    }
    // Two patches, one per piece, and the jump between them kept.
    let patches = n.to_bezier_patches();
    assert_eq!(patches.len(), 2);
    // The ends of the two pieces are their corner control points.
    close(
        patches[0].eval(1.0, 0.0),
        pts[2],
        10.0,
        "end of the first piece",
    );
    close(
        patches[1].eval(0.0, 0.0),
        pts[3],
        10.0,
        "start of the second piece",
    );
}

#[test]
fn inch_file_is_read_into_millimetres() {
    let n = net();
    let mut surf = ent(128, &b128(&n, [0.0, 1.0, 0.0, 1.0]));
    surf.subordinate = 0;
    // Unit flag 1 (inches, §2.2.4.3.14): 25.4 mm each.
    let global = GLOBAL.replacen(",2,2HMM,", ",1,4HINCH,", 1);
    let text = write_iges_global(&global, &[surf]);
    let read = parse_iges(Path::new("inch.igs"), &text).unwrap();
    assert_eq!(read.report.unit.name, "INCH");
    assert!(read.report.lines()[0].starts_with("IGES units: INCH (25.4 mm)"));
    // Through the CAD front door, as every command reads the file.
    let built =
        patchtrace::formats::cad::scene::build_scene(Path::new("inch.igs"), read.into_model())
            .unwrap();
    assert_eq!(
        built
            .scene
            .unit
            .as_ref()
            .map(|u| (u.millimetres, u.words.as_str())),
        Some((
            1.0,
            "lengths in millimetres (the IGES file declares INCH, 25.4 mm)"
        ))
    );
    let surfaces = built.scene.objects[0].geometry.surfaces();
    assert_eq!(surfaces.len(), 1);
    let SurfaceGeometry::Nurbs(s) = &surfaces[0].geometry else {
        panic!("a NURBS surface")
    };
    for (u, v) in grid() {
        close(s.eval(u, v), net_point(&n, u, v) * 25.4, 100.0, "inch net");
    }
}
