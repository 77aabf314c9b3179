//! Surface entities as exact rational NURBS (OpenCASCADE's `IGESToBRep_BasicSurface`),
//! each in the parameterisation the standard gives, so that parameter-space trim curves
//! land right: 128 rational B-spline surface, 114 parametric spline surface, 118 ruled
//! surface, 120 surface of revolution, 122 tabulated cylinder. Planes (108) have no parameterisation and are built around
//! their boundaries in `trimmed`.

use glam::{DVec3, DVec4};

use super::Model;
use super::curves::{self, Piece};
use super::entities::{Entity, SplineSurface};
use crate::geom::nurbs::analytic;
use crate::geom::nurbs::{NurbsCurve, NurbsSurface};
use crate::geom::trim::AxisMap;

/// A surface in model space, the maps of its parameters to the trim parameters, and the
/// 128's parameter range where it is narrower than the knot domain.
pub struct Converted {
    pub surface: NurbsSurface,
    pub maps: [AxisMap; 2],
    pub range: Option<[f64; 4]>,
    /// Per direction `(scale, offset)`: the trim parameter is `offset + scale · p` for the
    /// entity's parameter p (the 122's normalised u is the directrix parameter scaled).
    pub to_trim: [(f64, f64); 2],
}

const SAME: [(f64, f64); 2] = [(1.0, 0.0), (1.0, 0.0)];

fn err(e: impl std::fmt::Display) -> String {
    e.to_string()
}

/// The surface entity at `pointer`, in model space (its transform applied).
pub fn surface(model: &Model, pointer: usize) -> Result<Converted, String> {
    let (entry, entity) = model.get(pointer)?;
    let mut c = match entity {
        Entity::BSplineSurface(b) => {
            let points = b
                .points
                .iter()
                .zip(&b.weights)
                .map(|(p, &w)| (*p * w).extend(w))
                .collect();
            let s = NurbsSurface::new(
                b.degree[0],
                b.degree[1],
                b.knots[0].clone(),
                b.knots[1].clone(),
                b.counts[0],
                b.counts[1],
                points,
            )
            .map_err(err)?;
            let d = s.domain();
            let [u0, u1, v0, v1] = b.range;
            let narrower = u0 > d.u0 || u1 < d.u1 || v0 > d.v0 || v1 < d.v1;
            Converted {
                surface: s,
                maps: Default::default(),
                range: (narrower && u0 < u1 && v0 < v1).then_some(b.range),
                to_trim: SAME,
            }
        }
        Entity::SplineSurface(spline) => Converted {
            surface: bicubic(spline)?,
            maps: Default::default(),
            range: None,
            to_trim: SAME,
        },
        Entity::Ruled {
            curves: [a, b],
            reversed,
            ..
        } => {
            // §4.16: S(u, v) = (1 − v) C1(u) + v C2(u) on [0, 1]², both curves by their
            // normalised parameter (form 1; form 0, equal arc length, is the same for the
            // lines and arcs CAD systems write it with). DIRFLG 1 reverses C2.
            let c1 = single(curves::pieces(model, *a)?)?;
            let mut c2 = single(curves::pieces(model, *b)?)?;
            if *reversed {
                c2 = reverse(&c2);
            }
            if c1.map != AxisMap::Identity || c2.map != AxisMap::Identity {
                return Err("a ruled surface between arcs or ellipses is not supported yet (its normalised parameter has no exact map to the arc angle once the rails' breaks are merged)".into());
            }
            let (s, maps) = analytic::ruled(&c1.curve, &c2.curve).map_err(err)?;
            Converted {
                surface: s,
                maps,
                range: None,
                to_trim: SAME,
            }
        }
        Entity::Revolution {
            axis,
            generatrix,
            angles,
        } => revolution(model, *axis, *generatrix, *angles, 0.0)?,
        Entity::Offset { base, distance } => match model.get(*base)?.1 {
            Entity::Revolution {
                axis,
                generatrix,
                angles,
            } => {
                // The offset of a surface of revolution whose generatrix is a line in a
                // plane of the axis is the revolution of that line moved along its normal
                // (the normal is the same all along it): exact, and in the base's own
                // parameters, so the trims of the base apply unchanged.
                let mut c = revolution(model, *axis, *generatrix, *angles, *distance)?;
                c.surface
                    .transform(&model.transform(model.get(*base)?.0.transform)?);
                c
            }
            _ => {
                return Err(format!(
                    "the offset surface's base D {base} is entity {}; offsets are read of surfaces of revolution of lines, exactly",
                    model.get(*base)?.0.entity_type
                ));
            }
        },
        Entity::Tabulated { directrix, end } => {
            // §4.19: S(u, v) = C(t) + v (L − C(t0)), t = t0 + u (t1 − t0), u, v in [0, 1].
            // The NURBS u is the directrix's own parameter, so trims map to t.
            let c = single(curves::pieces(model, *directrix)?)?;
            let start = c.curve.eval(c.t0);
            let (s, [_, along]) =
                analytic::extrusion(&c.curve, *end - start, 0.0, 1.0).map_err(err)?;
            Converted {
                surface: s,
                maps: [c.map, along],
                range: None,
                to_trim: [(c.t1 - c.t0, c.t0), (1.0, 0.0)],
            }
        }
        _ => {
            return Err(format!(
                "the surface D {pointer} is entity {}, which is not a surface that is read",
                entry.entity_type
            ));
        }
    };
    c.surface.transform(&model.transform(entry.transform)?);
    Ok(c)
}

/// 114 (§4.15): each patch's bicubic polynomial in (s, t), measured from its lower
/// breakpoints, becomes its Bézier net exactly (s scaled to [0, 1] by powers of the patch
/// width, then the power-to-Bernstein change of basis b_k = Σ_{a ≤ k} C(k, a) / C(3, a) c_a
/// in each direction); the nets join into one bicubic B-spline with triple knots at the
/// breakpoints, so the NURBS parameters are the entity's. Neighbouring patches share
/// their boundary row of control points, which is taken from the later patch (the two
/// agree to the file's rounding on a valid surface).
fn bicubic(s: &SplineSurface) -> Result<NurbsSurface, String> {
    let (m, n) = (s.u.len() - 1, s.v.len() - 1);
    let increasing = |b: &[f64]| {
        b.windows(2)
            .all(|w| w[1].partial_cmp(&w[0]) == Some(std::cmp::Ordering::Greater))
    };
    if !increasing(&s.u) || !increasing(&s.v) {
        return Err("the breakpoints of a parametric spline surface must increase".into());
    }
    // C(k, a) / C(3, a) for a ≤ k ≤ 3.
    const TO_BERNSTEIN: [[f64; 4]; 4] = [
        [1.0, 0.0, 0.0, 0.0],
        [1.0, 1.0 / 3.0, 0.0, 0.0],
        [1.0, 2.0 / 3.0, 1.0 / 3.0, 0.0],
        [1.0, 1.0, 1.0, 1.0],
    ];
    let (count_u, count_v) = (3 * m + 1, 3 * n + 1);
    let mut points = vec![DVec4::ZERO; count_u * count_v];
    for i in 0..m {
        let hu = s.u[i + 1] - s.u[i];
        for j in 0..n {
            let hv = s.v[j + 1] - s.v[j];
            let patch = &s.patches[i * n + j];
            for k in 0..4 {
                for l in 0..4 {
                    let mut p = [0.0; 3];
                    for (d, c) in patch.iter().enumerate() {
                        for a in 0..=k {
                            for b in 0..=l {
                                p[d] += TO_BERNSTEIN[k][a]
                                    * TO_BERNSTEIN[l][b]
                                    * c[a + 4 * b]
                                    * hu.powi(a as i32)
                                    * hv.powi(b as i32);
                            }
                        }
                    }
                    points[(3 * j + l) * count_u + 3 * i + k] = DVec4::new(p[0], p[1], p[2], 1.0);
                }
            }
        }
    }
    let knots = |b: &[f64]| {
        let mut k = vec![b[0]; 4];
        for (x, &t) in b.iter().enumerate().skip(1) {
            k.extend(std::iter::repeat_n(t, if x + 1 == b.len() { 4 } else { 3 }));
        }
        k
    };
    NurbsSurface::new(3, 3, knots(&s.u), knots(&s.v), count_u, count_v, points).map_err(err)
}

/// §4.18 (120): S(t, θ), t the generatrix's parameter, θ from the start to the end angle:
/// the transpose of `analytic::revolution`, which puts the angle first. With `offset`
/// non-zero, the 140 offset surface of it (S + offset · n, n the unit normal of
/// S_t × S_θ), which is exact only for a line generatrix coplanar with the axis and not
/// crossing it: other generatrices are refused.
fn revolution(
    model: &Model,
    axis: usize,
    generatrix: usize,
    angles: [f64; 2],
    offset: f64,
) -> Result<Converted, String> {
    let Entity::Line { start, end } = model.get(axis)?.1 else {
        return Err(format!("the axis D {axis} is not a line (110)"));
    };
    let m = model.transform(model.get(axis)?.0.transform)?;
    let (p0, p1) = (m.transform_point3(*start), m.transform_point3(*end));
    let mut g = single(curves::pieces(model, generatrix)?)?;
    if offset != 0.0 {
        let shift = offset * line_normal(&g.curve, p0, p1 - p0)?;
        for q in &mut g.curve.points {
            *q += (shift * q.w).extend(0.0);
        }
    }
    let (s, [angle, _]) =
        analytic::revolution(&g.curve, p0, p1 - p0, angles[0], angles[1]).map_err(err)?;
    Ok(Converted {
        surface: s.transposed(),
        maps: [g.map, angle],
        range: None,
        to_trim: SAME,
    })
}

/// Relative size of a cross or triple product below which points count as on one line or
/// one plane: some thousands of `f64` ulps, the rounding of the file's 10-digit reals
/// and of a transform, far below any deliberate bend.
const FLAT: f64 = 1e-12;

/// The unit normal S_t × S_θ of the surface of revolution of the line `curve` about the
/// axis through `p` along `a`, at θ = 0 (the generatrix's own position): S_t is the line's
/// direction, S_θ = a × (G − p). It is one vector along the whole line when the line lies
/// in a plane of the axis on one side of it; anything else has no exact offset here.
fn line_normal(curve: &NurbsCurve, p: DVec3, a: DVec3) -> Result<DVec3, String> {
    let (d0, d1) = (curve.knots[0], curve.knots[curve.knots.len() - 1]);
    let (g0, g1) = (curve.eval(d0), curve.eval(d1));
    let along = g1 - g0;
    let straight = curve
        .points
        .iter()
        .all(|q| (q.truncate() / q.w - g0).cross(along).length() <= FLAT * along.length_squared());
    let (n0, n1) = (along.cross(a.cross(g0 - p)), along.cross(a.cross(g1 - p)));
    let coplanar = along.dot(a.cross(g0 - p)).abs()
        <= FLAT * along.length() * a.length() * (g0 - p).length().max(along.length());
    if !straight || !coplanar || n0.dot(n1) <= 0.0 {
        return Err("an offset of a surface of revolution is read only for a line generatrix in a plane of the axis, on one side of it (other offsets have no exact NURBS form)".into());
    }
    Ok(n0.normalize())
}

/// The one piece of a curve that must be a single NURBS curve (a generatrix, directrix or
/// rail).
fn single(mut pieces: Vec<Piece>) -> Result<Piece, String> {
    if pieces.len() != 1 {
        return Err(format!(
            "a composite curve of {} pieces as generatrix, directrix or rail is not supported yet",
            pieces.len()
        ));
    }
    Ok(pieces.remove(0))
}

/// The same curve run backwards: knots reflected, points reversed.
pub fn reverse(p: &Piece) -> Piece {
    let (a, b) = (p.curve.knots[0], p.curve.knots[p.curve.knots.len() - 1]);
    let mut points: Vec<DVec4> = p.curve.points.clone();
    points.reverse();
    Piece {
        curve: NurbsCurve {
            degree: p.curve.degree,
            knots: p.curve.knots.iter().rev().map(|k| a + b - k).collect(),
            points,
        },
        t0: a + b - p.t1,
        t1: a + b - p.t0,
        map: p.map.clone(),
    }
}
