//! Trimmed surfaces (OpenCASCADE's `IGESToBRep_TopoSurface`): 144 (a surface, an optional
//! outer boundary and holes, each a 142 curve on the surface), and bare surfaces. A 142's
//! parameter-space curve is used where it is given and not marked second choice (PREF 2);
//! otherwise its model-space curve is projected into the domain by point inversion and the
//! largest distance reported. Planes (108) have no parameterisation in IGES: their patch is
//! laid in a frame of the plane around the boundary curves, projected onto it exactly
//! (an affine map of the control points).

use glam::{DVec2, DVec3, DVec4};

use super::curves::{self, Piece};
use super::entities::Entity;
use super::surfaces::{self, Converted};
use super::{Model, Report};
use crate::geom::nurbs::analytic::{self, Frame};
use crate::geom::nurbs::inversion::Inverter;
use crate::geom::trim::{ParamCurve, TrimLoop, TrimSegment};
use crate::scene::model::{Surface, SurfaceGeometry};

/// Points per Bézier segment of a model-space trim curve that are projected; the loop
/// through them is a polyline (the projection has no exact form).
const PROJECTED_PER_SEGMENT: usize = 24;

/// A bare surface entity (no trims but a narrower 128 range).
pub fn untrimmed(model: &Model, pointer: usize) -> Result<Surface, String> {
    let (entry, entity) = model.get(pointer)?;
    if let Entity::Plane { boundary, .. } = entity {
        if *boundary == 0 {
            return Err("an unbounded plane (108 form 0) has no extent to draw".into());
        }
        let m = model.transform(entry.transform)?;
        let mut pieces = curves::pieces(model, *boundary)?;
        for p in &mut pieces {
            transform(&mut p.curve.points, &m);
        }
        return plane(model, pointer, vec![(false, pieces)]);
    }
    Ok(finish(surfaces::surface(model, pointer)?, Vec::new()))
}

/// A 144 trimmed surface.
pub fn trimmed(model: &Model, pointer: usize, report: &mut Report) -> Result<Surface, String> {
    let (entry, entity) = model.get(pointer)?;
    let Entity::Trimmed {
        surface,
        outer,
        holes,
    } = entity
    else {
        return Err("not a 144".into());
    };
    let m = model.transform(entry.transform)?;
    let boundaries: Vec<(bool, usize)> = outer
        .iter()
        .map(|&o| (false, o))
        .chain(holes.iter().map(|&h| (true, h)))
        .collect();
    let mut s = if let Entity::Plane { .. } = model.get(*surface)?.1 {
        let loops = boundaries
            .iter()
            .map(|&(hole, b)| Ok((hole, model_curve(model, b)?)))
            .collect::<Result<Vec<_>, String>>()?;
        plane(model, *surface, loops)?
    } else {
        let c = surfaces::surface(model, *surface)?;
        let mut inverter = None;
        let mut loops = Vec::new();
        for &(hole, b) in &boundaries {
            let segments = boundary(model, b, &c, &mut inverter, report)?;
            loops.push(TrimLoop { hole, segments });
        }
        finish(c, loops)
    };
    s.transform(&m);
    Ok(s)
}

/// The surface with its loops; a 128 whose range is narrower than its knots and that has
/// no outer loop gets the range as one (its domain, §4.24, is the range).
fn finish(c: Converted, mut loops: Vec<TrimLoop>) -> Surface {
    if let Some([u0, u1, v0, v1]) = c.range
        && loops.iter().all(|l| l.hole)
    {
        loops.insert(0, rectangle(u0, u1, v0, v1));
    }
    Surface {
        geometry: SurfaceGeometry::Nurbs(c.surface),
        trims: loops,
        trim_space: c.maps,
    }
}

fn rectangle(u0: f64, u1: f64, v0: f64, v1: f64) -> TrimLoop {
    let corners = [(u0, v0), (u1, v0), (u1, v1), (u0, v1), (u0, v0)];
    TrimLoop {
        hole: false,
        segments: vec![TrimSegment::polyline(
            &corners.map(|(u, v)| DVec2::new(u, v)),
        )],
    }
}

/// The model-space curve of a 142.
fn model_curve(model: &Model, pointer: usize) -> Result<Vec<Piece>, String> {
    match model.get(pointer)?.1 {
        Entity::CurveOnSurface { model_curve, .. } if *model_curve != 0 => {
            curves::pieces(model, *model_curve)
        }
        Entity::CurveOnSurface { .. } => Err(format!(
            "the boundary D {pointer} of a plane has no model-space curve"
        )),
        _ => Err(format!(
            "the boundary D {pointer} is not a curve on a surface (142)"
        )),
    }
}

/// The loop segments of one 142 boundary of a parametric surface.
fn boundary(
    model: &Model,
    pointer: usize,
    c: &Converted,
    inverter: &mut Option<Inverter>,
    report: &mut Report,
) -> Result<Vec<TrimSegment>, String> {
    let Entity::CurveOnSurface {
        parameter_curve,
        model_curve,
        preferred,
        ..
    } = model.get(pointer)?.1
    else {
        return Err(format!(
            "the boundary D {pointer} is not a curve on a surface (142)"
        ));
    };
    if *parameter_curve != 0 && (*preferred != 2 || *model_curve == 0) {
        // Affine in (u, v), so exact on the homogeneous points.
        let [(su, ou), (sv, ov)] = c.to_trim;
        return Ok(curves::pieces(model, *parameter_curve)?
            .into_iter()
            .map(|p| TrimSegment {
                t0: p.t0,
                t1: p.t1,
                curve: ParamCurve {
                    degree: p.curve.degree,
                    knots: p.curve.knots,
                    points: p
                        .curve
                        .points
                        .iter()
                        .map(|q| DVec3::new(su * q.x + ou * q.w, sv * q.y + ov * q.w, q.w))
                        .collect(),
                },
            })
            .collect());
    }
    if *model_curve == 0 {
        return Err(format!(
            "the boundary D {pointer} has neither a parameter-space nor a model-space curve"
        ));
    }
    let inv = inverter.get_or_insert_with(|| Inverter::new(&c.surface));
    let mut segments = Vec::new();
    for piece in curves::pieces(model, *model_curve)? {
        let mut points = Vec::new();
        for seg in piece.curve.bezier_segments() {
            let (a, b) = (seg.t0.max(piece.t0), seg.t1.min(piece.t1));
            if a >= b || a.is_nan() || b.is_nan() {
                continue;
            }
            let first = if points.is_empty() { 0 } else { 1 };
            for k in first..=PROJECTED_PER_SEGMENT {
                let t = a + (b - a) * k as f64 / PROJECTED_PER_SEGMENT as f64;
                let q = piece.curve.eval(t);
                let hit = inv
                    .project(q)
                    .ok_or("a model-space trim point could not be projected")?;
                report.max_projection_error = report.max_projection_error.max(hit.distance);
                points.push(DVec2::new(c.maps[0].apply(hit.u), c.maps[1].apply(hit.v)));
            }
        }
        if points.len() >= 2 {
            segments.push(TrimSegment::polyline(&points));
        }
    }
    report.projected += 1;
    Ok(segments)
}

fn transform(points: &mut [DVec4], m: &glam::DAffine3) {
    for p in points {
        let e = m.transform_point3(p.truncate() / p.w);
        *p = (e * p.w).extend(p.w);
    }
}

/// A 108 plane (in model space, its transform applied) as a bilinear patch around the
/// given model-space loops, which become its trims. The frame: normal (A, B, C), origin the
/// plane's point nearest the definition origin.
fn plane(model: &Model, pointer: usize, loops: Vec<(bool, Vec<Piece>)>) -> Result<Surface, String> {
    let (entry, entity) = model.get(pointer)?;
    let Entity::Plane { coefficients, .. } = entity else {
        return Err(format!("D {pointer} is not a plane (108)"));
    };
    let [a, b, cc, d] = *coefficients;
    let n = DVec3::new(a, b, cc);
    let m = model.transform(entry.transform)?;
    let origin = m.transform_point3(n * (d / n.length_squared()));
    let frame = Frame::new(origin, m.transform_vector3(n), None).map_err(|e| e.to_string())?;
    let mut lo = DVec3::splat(f64::INFINITY);
    let mut hi = DVec3::splat(f64::NEG_INFINITY);
    let mut trims = Vec::new();
    for (hole, pieces) in loops {
        let segments: Vec<TrimSegment> = pieces
            .into_iter()
            .map(|p| {
                let points: Vec<DVec3> = p
                    .curve
                    .points
                    .iter()
                    .map(|q| {
                        let r = q.truncate() - frame.origin * q.w;
                        DVec3::new(r.dot(frame.x), r.dot(frame.y), q.w)
                    })
                    .collect();
                for q in &points {
                    let e = *q / q.z;
                    lo = lo.min(e);
                    hi = hi.max(e);
                }
                TrimSegment {
                    t0: p.t0,
                    t1: p.t1,
                    curve: ParamCurve {
                        degree: p.curve.degree,
                        knots: p.curve.knots,
                        points,
                    },
                }
            })
            .collect();
        trims.push(TrimLoop { hole, segments });
    }
    // The control polygons' box holds the curves (convex hull property).
    let (s, maps) = analytic::plane(&frame, lo.x, hi.x, lo.y, hi.y)
        .map_err(|e| format!("plane bounds: {e}"))?;
    Ok(Surface {
        geometry: SurfaceGeometry::Nurbs(s),
        trims,
        trim_space: maps,
    })
}
