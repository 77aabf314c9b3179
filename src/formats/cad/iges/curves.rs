//! Curve entities as exact NURBS (OpenCASCADE's `IGESToBRep_BasicCurve`): 100 circular
//! arc, 102 composite, 104 conic arc, 106 copious data, 110 line, 112 parametric spline,
//! 126 rational B-spline. Each becomes one or more pieces, each a NURBS curve with the
//! parameter range it is used on, in model space (the entity's transform applied).

use glam::{DVec2, DVec3, DVec4};
use std::f64::consts::TAU;

use super::Model;
use super::entities::Entity;
use crate::geom::nurbs::NurbsCurve;
use crate::geom::nurbs::analytic::{self, Frame};
use crate::geom::trim::AxisMap;

/// One piece of a curve: a NURBS curve used on `[t0, t1]`, and the map from its NURBS
/// parameter to the entity's own (the angle, for arcs).
#[derive(Clone, Debug, PartialEq)]
pub struct Piece {
    pub curve: NurbsCurve,
    pub t0: f64,
    pub t1: f64,
    pub map: AxisMap,
}

impl Piece {
    fn whole(curve: NurbsCurve) -> Piece {
        Piece::mapped((curve, AxisMap::Identity))
    }

    fn mapped((curve, map): (NurbsCurve, AxisMap)) -> Piece {
        let (t0, t1) = crate::geom::nurbs::knots::domain(curve.degree, &curve.knots);
        Piece { curve, t0, t1, map }
    }
}

/// Nesting limit for composites of composites, against cycles.
const MAX_DEPTH: usize = 16;

/// The pieces of the curve entity at directory pointer `pointer`, in model space.
pub fn pieces(model: &Model, pointer: usize) -> Result<Vec<Piece>, String> {
    pieces_at(model, pointer, 0)
}

fn pieces_at(model: &Model, pointer: usize, depth: usize) -> Result<Vec<Piece>, String> {
    if depth > MAX_DEPTH {
        return Err(format!(
            "curves nest deeper than {MAX_DEPTH} (a cycle?) at D {pointer}"
        ));
    }
    let (entry, entity) = model.get(pointer)?;
    let mut out = match entity {
        Entity::Composite(parts) => {
            let mut all = Vec::new();
            for &p in parts {
                all.extend(pieces_at(model, p, depth + 1)?);
            }
            // The composite's own transform applies on top of its parts'.
            for piece in &mut all {
                transform(&mut piece.curve, &model.transform(entry.transform)?);
            }
            return Ok(all);
        }
        Entity::Arc {
            z,
            centre,
            start,
            end,
        } => vec![arc(*z, *centre, *start, *end)?],
        Entity::Conic {
            coefficients,
            z,
            start,
            end,
        } => vec![conic(coefficients, *z, *start, *end)?],
        Entity::Copious(points) => vec![polyline(points)?],
        Entity::Line { start, end } => vec![Piece::whole(
            analytic::line_segment(*start, *end, 0.0, 1.0).map_err(|e| e.to_string())?,
        )],
        Entity::Spline {
            breaks,
            coefficients,
        } => vec![spline(breaks, coefficients)?],
        Entity::BSplineCurve(c) => {
            let curve = NurbsCurve {
                degree: c.degree,
                knots: c.knots.clone(),
                points: c
                    .points
                    .iter()
                    .zip(&c.weights)
                    .map(|(p, &w)| (*p * w).extend(w))
                    .collect(),
            };
            if c.degree == 0 {
                return Err("degree 0 is outside 1..=15".into());
            }
            crate::geom::nurbs::knots::validate(c.degree, &curve.knots, curve.points.len())
                .map_err(|e| e.to_string())?;
            if c.weights
                .iter()
                .any(|w| w.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater))
            {
                return Err("a weight is not positive".into());
            }
            let (d0, d1) = crate::geom::nurbs::knots::domain(c.degree, &curve.knots);
            // §4.23 (126): V(0) and V(1) bound the curve's use. Solid Edge writes
            // V(0) = V(1) = 0 on lines whose knots run over [-1, 0]: a range that holds
            // no curve at all, where the knots say which curve is meant, as OpenCASCADE
            // reads it (the edge spans the knot domain); a range that merely reaches
            // beyond the knots is clamped to them.
            let (t0, t1) = if c.range[0] == c.range[1] {
                (d0, d1)
            } else {
                (c.range[0].max(d0), c.range[1].min(d1))
            };
            if t0.partial_cmp(&t1) != Some(std::cmp::Ordering::Less) {
                return Err(format!(
                    "the parameter range [{}, {}] is empty",
                    c.range[0], c.range[1]
                ));
            }
            vec![Piece {
                curve,
                t0,
                t1,
                map: AxisMap::Identity,
            }]
        }
        other => {
            return Err(format!(
                "entity {} (D {pointer}) is not a curve{}",
                entry.entity_type,
                if matches!(other, Entity::Unsupported) {
                    " type that is read"
                } else {
                    ""
                }
            ));
        }
    };
    let m = model.transform(entry.transform)?;
    for piece in &mut out {
        transform(&mut piece.curve, &m);
    }
    Ok(out)
}

fn transform(c: &mut NurbsCurve, m: &glam::DAffine3) {
    for p in &mut c.points {
        let e = m.transform_point3(p.truncate() / p.w);
        *p = (e * p.w).extend(p.w);
    }
}

/// The definition space's axes about `origin`.
fn plane_frame(origin: DVec3) -> Frame {
    Frame {
        origin,
        x: DVec3::X,
        y: DVec3::Y,
        z: DVec3::Z,
    }
}

/// 100 (§4.3): counter-clockwise from start to end about the centre; equal start and end
/// make a full circle. The parameter is the angle (the knots are angles at the pieces'
/// ends; the arc's own parameterisation in §4.3 is by angle too).
fn arc(z: f64, centre: DVec2, start: DVec2, end: DVec2) -> Result<Piece, String> {
    let radius = (start - centre).length();
    let a0 = (start - centre).to_angle();
    let mut a1 = (end - centre).to_angle();
    while a1 <= a0 {
        a1 += TAU;
    }
    Ok(Piece::mapped(
        analytic::circle_arc(&plane_frame(centre.extend(z)), radius, a0, a1)
            .map_err(|e| e.to_string())?,
    ))
}

/// B² − 4AC of a parabola written in decimal rounds to the file's precision of its terms
/// rather than to zero (B = 4 cos φ sin φ, AC = 4 cos² φ sin² φ for a turned one). The
/// ratio |B² − 4AC| / (B² + 4|AC|) is the ratio of the quadratic form's eigenvalues, so
/// below this a conic would be an ellipse or hyperbola with axes more than 3·10⁴ : 1,
/// which no CAD system writes; it is taken as the parabola the writer meant (9 significant
/// digits or more suffice to land here).
const PARABOLIC: f64 = 1e-9;

/// 104 (§4.5): ellipses and hyperbolas (B² ≠ 4AC) are brought to their centre and axes,
/// parabolas to their vertex and axis, and converted exactly, in any position.
fn conic(k: &[f64; 6], z: f64, start: DVec2, end: DVec2) -> Result<Piece, String> {
    let [a, b, c, d, e, f] = *k;
    let disc = b * b - 4.0 * a * c;
    let err = |x: analytic::ShapeError| x.to_string();
    if disc.abs() > PARABOLIC * (b * b + (4.0 * a * c).abs()) {
        // Centre: the gradient vanishes. Axes: rotate by θ with tan 2θ = B / (A − C); in
        // the axes the conic is A' x'² + C' y'² + F' = 0.
        let det = 4.0 * a * c - b * b;
        let centre = DVec2::new((b * e - 2.0 * c * d) / det, (b * d - 2.0 * a * e) / det);
        let f0 = a * centre.x * centre.x
            + b * centre.x * centre.y
            + c * centre.y * centre.y
            + d * centre.x
            + e * centre.y
            + f;
        let theta = 0.5 * b.atan2(a - c);
        let (s, co) = theta.sin_cos();
        let a2 = a * co * co + b * co * s + c * s * s;
        let c2 = a * s * s - b * co * s + c * co * co;
        let (e1, e2) = (DVec2::new(co, s), DVec2::new(-s, co));
        if disc > 0.0 {
            return hyperbola(centre, z, [(e1, a2), (e2, c2)], f0, start, end);
        }
        let (ra, rb) = ((-f0 / a2).sqrt(), (-f0 / c2).sqrt());
        let x = e1.extend(0.0);
        let frame = Frame {
            origin: centre.extend(z),
            x,
            y: DVec3::Z.cross(x),
            z: DVec3::Z,
        };
        let local = |p: DVec2| {
            let q = p - centre;
            (q.dot(e2) / rb).atan2(q.dot(e1) / ra)
        };
        let t0 = local(start);
        let mut t1 = local(end);
        while t1 <= t0 {
            t1 += TAU;
        }
        return Ok(Piece::mapped(
            analytic::ellipse_arc(&frame, ra, rb, [t0, t1]).map_err(err)?,
        ));
    }
    parabola(k, z, start, end)
}

/// The parabolic arc of a 104 (B² = 4AC). In the axes rotated by θ (tan 2θ = B / (A − C))
/// the quadratic part is one square, A' x'² (the other coefficient is zero up to
/// rounding, and the smaller one is taken as zero); completing the square,
/// y' = −(A' X² + F') / E' with X = x' + D' / 2A', a parabola with its vertex at
/// X = 0: `analytic::parabola_arc` in the frame (axis along y', parameter along x'), whose
/// parameter is X.
fn parabola(k: &[f64; 6], z: f64, start: DVec2, end: DVec2) -> Result<Piece, String> {
    let [a, b, c, d, e, f] = *k;
    let theta = 0.5 * b.atan2(a - c);
    let (s, co) = theta.sin_cos();
    let a2 = a * co * co + b * co * s + c * s * s;
    let c2 = a * s * s - b * co * s + c * co * co;
    let (e1, e2) = (DVec2::new(co, s), DVec2::new(-s, co));
    // The square is in whichever rotated coordinate has the larger coefficient.
    let (sq, lin, k2) = if a2.abs() >= c2.abs() {
        (e1, e2, a2)
    } else {
        (e2, -e1, c2)
    };
    let d2 = d * sq.x + e * sq.y;
    let e2c = d * lin.x + e * lin.y;
    if k2 == 0.0 || e2c == 0.0 || !(k2 / e2c).is_finite() {
        return Err("a degenerate parabola (a line or a pair of lines) is not a conic arc".into());
    }
    let shift = d2 / (2.0 * k2);
    let f2 = f - d2 * d2 / (4.0 * k2);
    let vertex = sq * -shift + lin * (-f2 / e2c);
    let frame = Frame {
        origin: vertex.extend(z),
        x: lin.extend(0.0),
        y: sq.extend(0.0),
        z: lin.extend(0.0).cross(sq.extend(0.0)),
    };
    let (ts, te) = (start.dot(sq) + shift, end.dot(sq) + shift);
    Ok(Piece::whole(
        analytic::parabola_arc(&frame, -k2 / e2c, ts.min(te), ts.max(te))
            .map_err(|x| x.to_string())?,
    ))
}

/// The hyperbolic arc of a 104 in its axes `[(e1, A'), (e2, C')]` about `centre`, where
/// A' x'² + C' y'² + F' = 0: the transverse axis is the one whose coefficient has the
/// sign opposite to F'. In the frame (transverse axis towards the start's branch, the
/// other axis oriented so the parameter increases from start to end) the arc is
/// (a cosh t, b sinh t) with t = asinh(y / b), converted by `analytic::hyperbola_arc`.
fn hyperbola(
    centre: DVec2,
    z: f64,
    axes: [(DVec2, f64); 2],
    f0: f64,
    start: DVec2,
    end: DVec2,
) -> Result<Piece, String> {
    let [(main, ka), (other, kb)] = if -f0 / axes[0].1 > 0.0 {
        axes
    } else {
        [axes[1], axes[0]]
    };
    let (ra, rb) = ((-f0 / ka).sqrt(), (f0 / kb).sqrt());
    if !(ra > 0.0 && rb > 0.0) {
        return Err("a degenerate hyperbola (a pair of lines) is not a conic arc".into());
    }
    let (qs, qe) = (start - centre, end - centre);
    let side = qs.dot(main).signum();
    if qe.dot(main).signum() != side {
        return Err("the start and end of a hyperbolic arc are on different branches".into());
    }
    let t = |q: DVec2| (q.dot(other) / rb).asinh();
    let turn = if t(qs) <= t(qe) { 1.0 } else { -1.0 };
    let (x, y) = ((main * side).extend(0.0), (other * turn).extend(0.0));
    let frame = Frame {
        origin: centre.extend(z),
        x,
        y,
        z: x.cross(y),
    };
    let (t0, t1) = (turn * t(qs), turn * t(qe));
    Ok(Piece::whole(
        analytic::hyperbola_arc(&frame, ra, rb, [t0, t1]).map_err(|e| e.to_string())?,
    ))
}

/// 106: the points joined in order, parameter i at point i.
fn polyline(points: &[DVec3]) -> Result<Piece, String> {
    if points.len() < 2 {
        return Err("a copious data curve needs at least two points".into());
    }
    let n = points.len();
    let mut knots = vec![0.0];
    knots.extend((0..n).map(|i| i as f64));
    knots.push((n - 1) as f64);
    Ok(Piece::whole(NurbsCurve {
        degree: 1,
        knots,
        points: points.iter().map(|p| p.extend(1.0)).collect(),
    }))
}

/// 112 (§4.14): each cubic segment `a + b s + c s² + d s³`, s in [0, h], becomes its
/// Bézier form on [0, 1] (coefficients scaled by powers of h, then the power-to-Bernstein
/// conversion), joined with triple knots at the breaks: the same curve exactly.
fn spline(breaks: &[f64], coefficients: &[[[f64; 4]; 3]]) -> Result<Piece, String> {
    if coefficients.is_empty()
        || breaks
            .windows(2)
            .any(|w| w[1].partial_cmp(&w[0]) != Some(std::cmp::Ordering::Greater))
    {
        return Err("the breakpoints of a parametric spline must increase".into());
    }
    let mut knots = vec![breaks[0]; 4];
    let mut points = Vec::new();
    for (k, seg) in coefficients.iter().enumerate() {
        let h = breaks[k + 1] - breaks[k];
        let bez = |[a, b, c, d]: [f64; 4]| {
            let (b, c, d) = (b * h, c * h * h, d * h * h * h);
            [a, a + b / 3.0, a + 2.0 * b / 3.0 + c / 3.0, a + b + c + d]
        };
        let (x, y, z) = (bez(seg[0]), bez(seg[1]), bez(seg[2]));
        let first = if k == 0 { 0 } else { 1 };
        for i in first..4 {
            points.push(DVec4::new(x[i], y[i], z[i], 1.0));
        }
        let times = if k + 1 == coefficients.len() { 4 } else { 3 };
        knots.extend(std::iter::repeat_n(breaks[k + 1], times));
    }
    Ok(Piece::whole(NurbsCurve {
        degree: 3,
        knots,
        points,
    }))
}
