//! Inline surfaces between their RON form and the model's: Bézier and NURBS surfaces
//! with their trim loops and trim spaces, checked as the kernels expect when read.

use crate::geom::BezierPatch;
use crate::geom::bezier::ParamRect;
use crate::geom::nurbs::NurbsSurface;
use crate::geom::trim::{AxisMap, ParamCurve, TrimLoop, TrimSegment};
use crate::scene::model::{Surface, SurfaceGeometry};

use super::schema::{AxisMapDef, SurfaceDef, TrimLoopDef, TrimSegmentDef, V3, v3};

fn homogeneous(
    points: &[V3],
    weights: &Option<Vec<f64>>,
) -> Result<Vec<glam::DVec4>, crate::geom::GeomError> {
    match weights {
        None => Ok(points.iter().map(|&p| v3(p).extend(1.0)).collect()),
        Some(w) if w.len() != points.len() => Err(crate::geom::GeomError::PointCount {
            expected: points.len(),
            found: w.len(),
        }),
        Some(w) => Ok(points
            .iter()
            .zip(w)
            .map(|(&p, &w)| (v3(p) * w).extend(w))
            .collect()),
    }
}

pub(super) fn surface_from_def(d: &SurfaceDef) -> Result<Surface, crate::geom::GeomError> {
    Ok(match d {
        SurfaceDef::Bezier {
            degree,
            points,
            weights,
            domain,
            trims,
            trim_space,
        } => {
            let patch = BezierPatch::new(degree.0, degree.1, homogeneous(points, weights)?)?;
            let patch = match domain {
                &Some((u0, u1, v0, v1)) => patch.with_domain(ParamRect { u0, u1, v0, v1 }),
                None => patch,
            };
            Surface {
                geometry: SurfaceGeometry::Bezier(patch),
                trims: trims_from_defs(trims)?,
                trim_space: trim_space_from_def(trim_space)?,
            }
        }
        SurfaceDef::Nurbs {
            degree,
            knots_u,
            knots_v,
            count,
            points,
            weights,
            trims,
            trim_space,
        } => Surface {
            geometry: SurfaceGeometry::Nurbs(NurbsSurface::new(
                degree.0,
                degree.1,
                knots_u.clone(),
                knots_v.clone(),
                count.0,
                count.1,
                homogeneous(points, weights)?,
            )?),
            trims: trims_from_defs(trims)?,
            trim_space: trim_space_from_def(trim_space)?,
        },
    })
}

fn trims_from_defs(defs: &[TrimLoopDef]) -> Result<Vec<TrimLoop>, crate::geom::GeomError> {
    defs.iter()
        .enumerate()
        .map(|(i, l)| trim_loop_from_def(i, l))
        .collect()
}

fn trim_space_from_def(
    d: &Option<(AxisMapDef, AxisMapDef)>,
) -> Result<[AxisMap; 2], crate::geom::GeomError> {
    Ok(match d {
        None => Default::default(),
        Some((u, v)) => [axis_map_from_def(u)?, axis_map_from_def(v)?],
    })
}

/// A trim loop, validated as the kernels expect: degrees 1..=15, valid knot vectors, finite
/// points with positive weights, finite non-empty ranges.
fn trim_loop_from_def(i: usize, l: &TrimLoopDef) -> Result<TrimLoop, crate::geom::GeomError> {
    let bad = |j: usize, what: String| {
        crate::geom::GeomError::Knots(format!("trim loop {i}, segment {j}: {what}"))
    };
    let segments = l
        .segments
        .iter()
        .enumerate()
        .map(|(j, s)| {
            if !(1..=crate::geom::MAX_DEGREE).contains(&s.degree) {
                return Err(bad(j, format!("degree {} is outside 1..=15", s.degree)));
            }
            crate::geom::nurbs::knots::validate(s.degree, &s.knots, s.points.len())
                .map_err(|e| bad(j, e.to_string()))?;
            if s.points
                .iter()
                .any(|p| !(p.0.is_finite() && p.1.is_finite() && p.2 > 0.0 && p.2.is_finite()))
            {
                return Err(bad(j, "points must be finite with positive weights".into()));
            }
            if !(s.t0.is_finite() && s.t1.is_finite() && s.t0 < s.t1) {
                return Err(bad(
                    j,
                    format!("the range [{}, {}] is empty or not finite", s.t0, s.t1),
                ));
            }
            Ok(TrimSegment {
                t0: s.t0,
                t1: s.t1,
                curve: ParamCurve {
                    degree: s.degree,
                    knots: s.knots.clone(),
                    points: s.points.iter().map(|&p| v3(p)).collect(),
                },
            })
        })
        .collect::<Result<_, _>>()?;
    Ok(TrimLoop {
        hole: l.hole,
        segments,
    })
}

fn axis_map_from_def(d: &AxisMapDef) -> Result<AxisMap, crate::geom::GeomError> {
    Ok(match d {
        AxisMapDef::Identity => AxisMap::Identity,
        AxisMapDef::Arcs { breaks, angles } => {
            let increasing =
                |v: &[f64]| v.iter().all(|x| x.is_finite()) && v.windows(2).all(|w| w[0] < w[1]);
            if breaks.len() != angles.len()
                || breaks.len() < 2
                || !increasing(breaks)
                || !increasing(angles)
            {
                return Err(crate::geom::GeomError::Knots(
                    "trim_space: Arcs needs as many breaks as angles (at least 2), both increasing"
                        .into(),
                ));
            }
            AxisMap::Arcs {
                breaks: breaks.clone(),
                angles: angles.clone(),
            }
        }
    })
}

fn axis_map_def(m: &AxisMap) -> AxisMapDef {
    match m {
        AxisMap::Identity => AxisMapDef::Identity,
        AxisMap::Arcs { breaks, angles } => AxisMapDef::Arcs {
            breaks: breaks.clone(),
            angles: angles.clone(),
        },
    }
}

/// The RON form of a surface's trim loops.
fn trim_defs(s: &Surface) -> Vec<TrimLoopDef> {
    s.trims
        .iter()
        .map(|l| TrimLoopDef {
            hole: l.hole,
            segments: l
                .segments
                .iter()
                .map(|g| TrimSegmentDef {
                    t0: g.t0,
                    t1: g.t1,
                    degree: g.curve.degree,
                    knots: g.curve.knots.clone(),
                    points: g.curve.points.iter().map(|p| (p.x, p.y, p.z)).collect(),
                })
                .collect(),
        })
        .collect()
}

/// The RON form of a surface's trim space, `None` for the identity.
fn trim_space_def(s: &Surface) -> Option<(AxisMapDef, AxisMapDef)> {
    (s.trim_space != <[AxisMap; 2]>::default()).then(|| {
        (
            axis_map_def(&s.trim_space[0]),
            axis_map_def(&s.trim_space[1]),
        )
    })
}

fn split_homogeneous(points: &[glam::DVec4]) -> (Vec<V3>, Option<Vec<f64>>) {
    let xyz = points
        .iter()
        .map(|p| {
            let e = p.truncate() / p.w;
            (e.x, e.y, e.z)
        })
        .collect();
    let weights = points
        .iter()
        .any(|p| p.w != 1.0)
        .then(|| points.iter().map(|p| p.w).collect());
    (xyz, weights)
}

/// The RON form of an inline surface (weights left out when all are 1).
pub(super) fn surface_def(s: &Surface) -> SurfaceDef {
    match &s.geometry {
        SurfaceGeometry::Bezier(p) => {
            let (points, weights) = split_homogeneous(p.homogeneous_points());
            let d = p.domain();
            SurfaceDef::Bezier {
                degree: (p.degree_u(), p.degree_v()),
                points,
                weights,
                domain: (d != ParamRect::UNIT).then_some((d.u0, d.u1, d.v0, d.v1)),
                trims: trim_defs(s),
                trim_space: trim_space_def(s),
            }
        }
        SurfaceGeometry::Nurbs(n) => {
            let (points, weights) = split_homogeneous(&n.points);
            SurfaceDef::Nurbs {
                degree: (n.degree_u, n.degree_v),
                knots_u: n.knots_u.clone(),
                knots_v: n.knots_v.clone(),
                count: (n.count_u, n.count_v),
                points,
                weights,
                trims: trim_defs(s),
                trim_space: trim_space_def(s),
            }
        }
    }
}
