//! Trimmed surfaces (OpenCASCADE's `IGESToBRep_TopoSurface`): 144 (a surface, an optional
//! outer boundary and holes, each a 142 curve on the surface), 143 (a surface and its 141
//! boundaries, each a chain of model-space curves with their parameter-space curves), and
//! bare surfaces. A parameter-space curve is used where it is given, not marked second
//! choice and, laid on the surface, near its model-space curve; otherwise the model-space
//! curve is projected into the domain (`geom::pcurve` on B-spline-like surfaces: refined to
//! a chord tolerance, unwrapped across seams, through poles, reporting the largest
//! distance; in closed form on the analytic 190–198). Planes (108, and 190 without parameterisation) have no
//! parameterisation of their own: their patch is laid in a frame of the plane around the
//! boundary curves, projected onto it exactly (an affine map of the control points).

use glam::{DVec2, DVec3, DVec4};

use super::curves::{self, Piece};
use super::elementary::{self, Placed};
use super::entities::{Elementary, Entity};
use super::projection::{Part, Target};
use super::surfaces::{self, Converted};
use super::{Model, Report};
use crate::geom::nurbs::NurbsSurface;
use crate::geom::nurbs::analytic::{self, Frame};
use crate::geom::pcurve;
use crate::geom::segment::distance_to_segment;
use crate::geom::trim::{AxisMap, ParamCurve, TrimLoop, TrimSegment};
use crate::scene::model::{Surface, SurfaceGeometry};

/// Points per Bézier segment of a model-space trim curve that are projected; the loop
/// through them is a polyline (the projection has no exact form).
const PROJECTED_PER_SEGMENT: usize = 24;

/// One curve of a boundary: a model-space curve and the parameter-space curves that
/// represent it (either may be absent: 0 and empty).
struct Edge {
    model: usize,
    parameter: Vec<usize>,
    /// The model-space curve runs against the boundary's direction (141 SENSE 2, 508
    /// OF 0).
    reversed: bool,
    /// So do the parameter-space curves: in a 141 they follow their model-space curve; in
    /// a 508 they already follow the loop (as OpenCASCADE writes and reads them).
    parameter_reversed: bool,
}

/// A closed boundary of a surface, from a 142 or a 141.
struct Boundary {
    hole: bool,
    model_preferred: bool,
    edges: Vec<Edge>,
}

/// A bare surface entity (no trims but a narrower 128 range, or the whole of a closed
/// analytic surface).
pub fn untrimmed(model: &Model, pointer: usize, report: &mut Report) -> Result<Surface, String> {
    let (_, entity) = model.get(pointer)?;
    match entity {
        Entity::Plane { boundary, .. } => {
            if *boundary == 0 {
                return Err("an unbounded plane (108 form 0) has no extent to draw".into());
            }
            // The 108's boundary is a model-space curve in the plane's definition space.
            let edge = Edge {
                model: *boundary,
                parameter: Vec::new(),
                reversed: false,
                parameter_reversed: false,
            };
            let loops = vec![Boundary {
                hole: false,
                model_preferred: true,
                edges: vec![edge],
            }];
            with_loops(model, pointer, &loops, report, true)
        }
        _ => with_loops(model, pointer, &[], report, false),
    }
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
    let loops = outer
        .iter()
        .map(|&o| curve_on_surface(model, o, false))
        .chain(holes.iter().map(|&h| curve_on_surface(model, h, true)))
        .collect::<Result<Vec<_>, String>>()?;
    let mut s = with_loops(model, *surface, &loops, report, false)?;
    s.transform(&model.transform(entry.transform)?);
    Ok(s)
}

/// A 143 bounded surface. The standard does not say which boundary is outer; the first is
/// taken as the outer one, which matters only when there is one loop (the even–odd rule
/// sorts out nesting whatever the flags).
pub fn bounded(model: &Model, pointer: usize, report: &mut Report) -> Result<Surface, String> {
    let (entry, entity) = model.get(pointer)?;
    let Entity::Bounded {
        surface,
        boundaries,
    } = entity
    else {
        return Err("not a 143".into());
    };
    if boundaries.is_empty() {
        return Err("a bounded surface (143) without boundaries".into());
    }
    let loops = boundaries
        .iter()
        .enumerate()
        .map(|(k, &b)| boundary_entity(model, b, k > 0))
        .collect::<Result<Vec<_>, String>>()?;
    let mut s = with_loops(model, *surface, &loops, report, false)?;
    s.transform(&model.transform(entry.transform)?);
    Ok(s)
}

/// A 510 face of a 186 solid: its surface cut by its 508 loops, whose edges are the
/// model-space curves of 504 edge lists with their parameter-space curves (used where
/// given). Without OF 1 no loop is outer, and the domain's boundary is.
pub fn face(model: &Model, pointer: usize, report: &mut Report) -> Result<Surface, String> {
    let Entity::Face {
        surface,
        outer_first,
        loops,
    } = model.get(pointer)?.1
    else {
        return Err(format!("D {pointer} is not a face (510)"));
    };
    let mut boundaries = Vec::new();
    for (k, &l) in loops.iter().enumerate() {
        let Entity::Loop(entries) = model.get(l)?.1 else {
            return Err(format!("the loop D {l} is not a loop (508)"));
        };
        let mut edges = Vec::new();
        // Vertex entries (list 0) bound nothing.
        for e in entries.iter().filter(|e| e.list != 0) {
            let Entity::Edges(curves) = model.get(e.list)?.1 else {
                return Err(format!(
                    "the edge list D {} is not an edge list (504)",
                    e.list
                ));
            };
            let curve = *e
                .index
                .checked_sub(1)
                .and_then(|i| curves.get(i))
                .ok_or_else(|| {
                    format!(
                        "edge {} of the edge list D {} does not exist",
                        e.index, e.list
                    )
                })?;
            edges.push(Edge {
                model: curve,
                parameter: e.parameter.clone(),
                reversed: e.reversed,
                parameter_reversed: false,
            });
        }
        boundaries.push(Boundary {
            hole: !(*outer_first && k == 0),
            model_preferred: false,
            edges,
        });
    }
    with_loops(model, *surface, &boundaries, report, false)
}

/// A 142 as a boundary.
fn curve_on_surface(model: &Model, pointer: usize, hole: bool) -> Result<Boundary, String> {
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
    Ok(Boundary {
        hole,
        // PREF 2: the model-space curve C is preferred (§4.22).
        model_preferred: *preferred == 2,
        edges: vec![Edge {
            model: *model_curve,
            parameter: (*parameter_curve != 0)
                .then_some(*parameter_curve)
                .into_iter()
                .collect(),
            reversed: false,
            parameter_reversed: false,
        }],
    })
}

/// A 141 as a boundary.
fn boundary_entity(model: &Model, pointer: usize, hole: bool) -> Result<Boundary, String> {
    let Entity::Boundary {
        model_preferred,
        curves,
        ..
    } = model.get(pointer)?.1
    else {
        return Err(format!("the boundary D {pointer} is not a boundary (141)"));
    };
    Ok(Boundary {
        hole,
        model_preferred: *model_preferred,
        edges: curves
            .iter()
            .map(|c| Edge {
                model: c.model,
                parameter: c.parameter.clone(),
                reversed: c.reversed,
                parameter_reversed: c.reversed,
            })
            .collect(),
    })
}

/// The surface entity at `pointer` with the given boundaries as its trim loops. `in_plane`:
/// the boundaries are in the surface's own definition space (a 108's bounding curve)
/// rather than in the model space the surface's transform maps into.
fn with_loops(
    model: &Model,
    pointer: usize,
    loops: &[Boundary],
    report: &mut Report,
    in_plane: bool,
) -> Result<Surface, String> {
    let (entry, entity) = model.get(pointer)?;
    if let Entity::Plane { coefficients, .. } = entity {
        // The frame: normal (A, B, C), origin the plane's point nearest the definition
        // origin, in model space.
        let [a, b, c, d] = *coefficients;
        let n = DVec3::new(a, b, c);
        let m = model.transform(entry.transform)?;
        let origin = m.transform_point3(n * (d / n.length_squared()));
        let frame = Frame::new(origin, m.transform_vector3(n), None).map_err(err)?;
        let mut trims = Vec::new();
        for l in loops {
            let mut segments = Vec::new();
            for e in &l.edges {
                for mut p in edge_pieces(model, e.model, e.reversed)? {
                    if in_plane {
                        transform(&mut p.curve.points, &m);
                    }
                    segments.push(in_frame(&frame, p));
                }
            }
            trims.push(TrimLoop {
                hole: l.hole,
                segments,
            });
        }
        return planar(&frame, trims);
    }
    if let Some(placed) = elementary::placed(model, pointer)? {
        return analytic_with_loops(model, &placed, loops);
    }
    let c = surfaces::surface(model, pointer)?;
    let mut target = None;
    let mut trims = Vec::new();
    let mut stray = 0.0f64;
    let far = STRAY * c.surface.net_diagonal();
    for l in loops {
        let mut parts = Vec::new();
        for e in &l.edges {
            let given = parameter_segments(model, l.model_preferred, e, UvMap::axes(c.to_trim))?;
            let mut off = 0.0;
            if let Some(s) = &given
                && e.model != 0
            {
                off = stray_from_model(model, e, s, &c)?;
            }
            if let Some(s) = &given
                && off <= far
            {
                parts.extend(s.iter().cloned().map(Part::Given));
                continue;
            }
            let target = target.get_or_insert_with(|| Target::new(&c.surface));
            let mut projected_parts = Vec::new();
            let (mut chord, mut gap) = (0.0f64, 0.0f64);
            for piece in edge_pieces(model, e.model, e.reversed)? {
                let projected = pcurve::project(
                    &*target,
                    |t| piece.curve.eval(t),
                    piece.t0,
                    piece.t1,
                    target.tolerance,
                )
                .map_err(|p| format!("the model-space trim point {p} could not be projected"))?;
                chord = chord.max(projected.chord);
                gap = gap.max(projected.gap);
                if projected.points.len() >= 2 {
                    projected_parts.push(Part::Projected(projected.points));
                }
            }
            // A model-space curve that does not lie on the surface either cannot stand
            // for a parameter-space curve that disagrees with it: the file's own
            // preference, the parameter-space curve, is kept (Rhino 98 writes a unit
            // square 200 mm from the surface it trims), as OpenCASCADE keeps it.
            if let Some(s) = given
                && gap > far
            {
                report.off_surface.push(model.get(e.model)?.0.sequence);
                parts.extend(s.into_iter().map(Part::Given));
                continue;
            }
            stray = stray.max(off);
            report.max_trim_error = report.max_trim_error.max(chord);
            report.max_curve_gap = report.max_curve_gap.max(gap);
            parts.extend(projected_parts);
            report.projected += 1;
        }
        let segments = match &target {
            Some(target) => target.join(parts, &c.maps),
            None => parts
                .into_iter()
                .filter_map(|p| match p {
                    Part::Given(s) => Some(s),
                    Part::Projected(_) => None,
                })
                .collect(),
        };
        trims.push(TrimLoop {
            hole: l.hole,
            segments,
        });
    }
    if stray > 0.0 {
        report.strayed.push(model.get(pointer)?.0.sequence);
        report.max_stray = report.max_stray.max(stray);
    }
    Ok(finish(c, trims))
}

/// A parameter-space trim curve laid on its surface may lie this far, as a fraction of
/// the surface's size, from the model-space curve it stands for before the two are taken
/// to disagree: far above any writer's rounding or fitting, far below a curve in another
/// place.
const STRAY: f64 = 1e-3;

/// How far the parameter-space curves of an edge (`given`, as trim segments), laid on the
/// surface, lie from its model-space curve: the largest distance of nine points per piece
/// from the polyline through the model-space curve's samples. §4.22 (142) lets a writer give both curves
/// for one boundary; when they disagree by far more than rounding, the parameter-space
/// one follows a parameterisation this reader does not share (SolidWorks measures the
/// parameter of a 100 arc generatrix of a 120 from the arc's start, not as §4.3's
/// angle), and the model-space curve, which needs none, is the one to draw, as
/// OpenCASCADE's reading of such files shows.
fn stray_from_model(
    model: &Model,
    e: &Edge,
    given: &[TrimSegment],
    c: &Converted,
) -> Result<f64, String> {
    let polyline: Vec<DVec3> = edge_pieces(model, e.model, false)?
        .iter()
        .flat_map(samples)
        .collect();
    let d = c.surface.domain();
    // The NURBS parameter of a trim parameter, brought into the domain (a closed
    // surface's loops may run past its seam).
    let into = |x: f64, (a, b): (f64, f64)| {
        if x < a || x > b {
            a + (x - a).rem_euclid(b - a)
        } else {
            x
        }
    };
    let mut largest = 0.0f64;
    for seg in given {
        for k in 0..=8 {
            let q = seg.curve.point(seg.t0 + (seg.t1 - seg.t0) * k as f64 / 8.0);
            let u = into(c.maps[0].invert(q.x), (d.u0, d.u1));
            let v = into(c.maps[1].invert(q.y), (d.v0, d.v1));
            let p = c.surface.eval(u, v);
            let nearest = polyline
                .windows(2)
                .map(|w| distance_to_segment(p, w[0], w[1]))
                .fold(f64::INFINITY, f64::min);
            largest = largest.max(nearest);
        }
    }
    Ok(largest)
}

fn err(e: impl std::fmt::Display) -> String {
    e.to_string()
}

/// An affine map of the parameter plane: `u' = m[0] · (u, v, 1)`, `v' = m[1] · (u, v, 1)`,
/// applied exactly to homogeneous points.
#[derive(Clone, Copy, Debug, PartialEq)]
struct UvMap([[f64; 3]; 2]);

impl UvMap {
    /// Each parameter scaled and moved on its own: `(scale, offset)` for u and for v.
    fn axes([(su, ou), (sv, ov)]: [(f64, f64); 2]) -> UvMap {
        UvMap([[su, 0.0, ou], [0.0, sv, ov]])
    }

    fn apply(&self, q: DVec3) -> DVec3 {
        let [a, b] = self.0;
        DVec3::new(
            a[0] * q.x + a[1] * q.y + a[2] * q.z,
            b[0] * q.x + b[1] * q.y + b[2] * q.z,
            q.z,
        )
    }
}

/// The parameter-space curves of an edge as trim segments (the affine `to_trim` applied,
/// exact on the homogeneous points), or `None` where the model-space curve is to be used:
/// there are none, or the model-space curve is preferred and present.
fn parameter_segments(
    model: &Model,
    model_preferred: bool,
    e: &Edge,
    to_trim: UvMap,
) -> Result<Option<Vec<TrimSegment>>, String> {
    if e.parameter.is_empty() || (model_preferred && e.model != 0) {
        if e.model == 0 {
            return Err(
                "a boundary curve has neither a parameter-space nor a model-space curve".into(),
            );
        }
        return Ok(None);
    }
    let mut out = Vec::new();
    for &pc in &e.parameter {
        for p in oriented(curves::pieces(model, pc)?, e.parameter_reversed) {
            out.push(TrimSegment {
                t0: p.t0,
                t1: p.t1,
                curve: ParamCurve {
                    degree: p.curve.degree,
                    knots: p.curve.knots,
                    points: p
                        .curve
                        .points
                        .iter()
                        .map(|q| to_trim.apply(DVec3::new(q.x, q.y, q.w)))
                        .collect(),
                },
            });
        }
    }
    if e.parameter_reversed {
        out.reverse();
    }
    Ok(Some(out))
}

/// The pieces of a model-space curve, run backwards where the edge is reversed.
fn edge_pieces(model: &Model, pointer: usize, reversed: bool) -> Result<Vec<Piece>, String> {
    if pointer == 0 {
        return Err("a boundary curve of a plane has no model-space curve".into());
    }
    let mut pieces = oriented(curves::pieces(model, pointer)?, reversed);
    if reversed {
        pieces.reverse();
    }
    Ok(pieces)
}

fn oriented(pieces: Vec<Piece>, reversed: bool) -> Vec<Piece> {
    if reversed {
        pieces.iter().map(surfaces::reverse).collect()
    } else {
        pieces
    }
}

/// Points along a model-space curve piece, `PROJECTED_PER_SEGMENT` per Bézier segment.
fn samples(piece: &Piece) -> Vec<DVec3> {
    let mut points = Vec::new();
    for seg in piece.curve.bezier_segments() {
        let (a, b) = (seg.t0.max(piece.t0), seg.t1.min(piece.t1));
        if a >= b || a.is_nan() || b.is_nan() {
            continue;
        }
        let first = if points.is_empty() { 0 } else { 1 };
        for k in first..=PROJECTED_PER_SEGMENT {
            let t = a + (b - a) * k as f64 / PROJECTED_PER_SEGMENT as f64;
            points.push(piece.curve.eval(t));
        }
    }
    points
}

/// The map from the parameter-space curves OpenCASCADE writes on a 190–198 surface to the
/// standard's parameters, the inverse of what its writer applies and what its reader
/// undoes (`IGESToBRep_TopoSurface::ParamSurface`; see `Model`): angles in degrees (a
/// cylinder's and cone's u, both of a sphere's); a cone's v along its generatrix, as its
/// `Geom_ConicalSurface` measures it, where IGES 5.3 §4.41 measures height along the axis
/// (v cos α); a torus's parameters exchanged and turned, (a, b) written for
/// (360° − b, a).
fn opencascade_parameters(placed: &Placed) -> UvMap {
    let degree = std::f64::consts::PI / 180.0;
    match placed.shape {
        Elementary::Plane => UvMap::axes([(1.0, 0.0), (1.0, 0.0)]),
        Elementary::Cylinder { .. } => UvMap::axes([(degree, 0.0), (1.0, 0.0)]),
        Elementary::Cone { semi_angle, .. } => {
            UvMap::axes([(degree, 0.0), ((semi_angle * degree).cos(), 0.0)])
        }
        Elementary::Sphere { .. } => UvMap::axes([(degree, 0.0), (degree, 0.0)]),
        Elementary::Torus { .. } => {
            UvMap([[0.0, -degree, std::f64::consts::TAU], [degree, 0.0, 0.0]])
        }
    }
}

/// A 190–198 surface over the box of its loops. Parameter-space curves apply as written
/// (the trim parameters are the standard's); model-space curves are mapped to parameters
/// in closed form, angles unwrapped along the curve so a loop crossing the seam stays
/// connected.
fn analytic_with_loops(
    model: &Model,
    placed: &Placed,
    loops: &[Boundary],
) -> Result<Surface, String> {
    let plane = matches!(placed.shape, Elementary::Plane);
    let frame = placed_frame(placed);
    let angular = placed.angular();
    let to_trim = if model.angles_in_degrees {
        opencascade_parameters(placed)
    } else {
        UvMap::axes([(1.0, 0.0), (1.0, 0.0)])
    };
    let mut trims = Vec::new();
    for l in loops {
        let mut segments = Vec::new();
        for e in &l.edges {
            // Form 0 has no parameterisation the writer and this reader share: its
            // parameter-space curves are the last resort.
            let prefer_model = l.model_preferred || !placed.parameterised;
            if let Some(s) = parameter_segments(model, prefer_model, e, to_trim)? {
                segments.extend(s);
                continue;
            }
            for piece in edge_pieces(model, e.model, e.reversed)? {
                if plane {
                    // The parameters of a plane are its frame coordinates: exact.
                    segments.push(in_frame(&frame, piece));
                    continue;
                }
                let mut points: Vec<DVec2> = Vec::new();
                for q in samples(&piece) {
                    let mut uv = placed.parameters_of(q);
                    // Unwrap against the previous point of the loop (its last segment).
                    let prev = points
                        .last()
                        .copied()
                        .or_else(|| segments.last().map(segment_end));
                    if let Some(prev) = prev {
                        for (k, periodic) in angular.iter().enumerate() {
                            if *periodic {
                                uv[k] += ((prev[k] - uv[k]) / std::f64::consts::TAU).round()
                                    * std::f64::consts::TAU;
                            }
                        }
                    }
                    points.push(uv);
                }
                if points.len() >= 2 {
                    segments.push(TrimSegment::polyline(&points));
                }
            }
        }
        trims.push(TrimLoop {
            hole: l.hole,
            segments,
        });
    }
    if plane && !placed.parameterised {
        return planar(&frame, trims);
    }
    let [u, v] = if trims.iter().any(|l| !l.hole) {
        let (lo, hi) = control_box(&trims);
        for (k, periodic) in angular.iter().enumerate() {
            // Loops within one turn have a control box a little wider at most; one over
            // two turns is not in radians (OpenCASCADE writes these angles in degrees).
            if *periodic && hi[k] - lo[k] > 2.0 * std::f64::consts::TAU {
                return Err(format!(
                    "the trim loops span {} in the angle {}, more than a turn: degrees? (IGES 5.3 gives radians)",
                    hi[k] - lo[k],
                    ["u", "v"][k]
                ));
            }
        }
        [[lo.x, hi.x], [lo.y, hi.y]]
    } else {
        placed.closed_box().ok_or(
            "a cylinder, cone or plane (190–194) without an outer boundary has no extent to draw",
        )?
    };
    let (surface, maps) = placed.surface(u, v)?;
    Ok(Surface {
        geometry: SurfaceGeometry::Nurbs(surface),
        trims,
        trim_space: maps,
    })
}

/// The model-space frame of a placed plane (its transform applied to the frame).
fn placed_frame(placed: &Placed) -> Frame {
    let m = placed.to_model;
    let f = &placed.frame;
    Frame {
        origin: m.transform_point3(f.origin),
        x: m.transform_vector3(f.x),
        y: m.transform_vector3(f.y),
        z: m.transform_vector3(f.z),
    }
}

fn segment_end(s: &TrimSegment) -> DVec2 {
    let q = s.curve.points[s.curve.points.len() - 1];
    DVec2::new(q.x / q.z, q.y / q.z)
}

/// The box of the loops' control points, which holds the loops (convex hull property).
fn control_box(trims: &[TrimLoop]) -> (DVec2, DVec2) {
    let mut lo = DVec2::splat(f64::INFINITY);
    let mut hi = DVec2::splat(f64::NEG_INFINITY);
    for q in trims
        .iter()
        .flat_map(|l| &l.segments)
        .flat_map(|s| &s.curve.points)
    {
        let e = DVec2::new(q.x / q.z, q.y / q.z);
        lo = lo.min(e);
        hi = hi.max(e);
    }
    (lo, hi)
}

/// The surface with its loops; a 128 whose range is narrower than its knots and that has
/// no outer loop gets the range as one (its domain, §4.24, is the range). A surface closed
/// in a direction whose loops reach across its seam is repeated over the periods they
/// reach (see `geom::nurbs::periodic`).
fn finish(mut c: Converted, mut loops: Vec<TrimLoop>) -> Surface {
    if let Some([u0, u1, v0, v1]) = c.range
        && loops.iter().all(|l| l.hole)
    {
        loops.insert(0, rectangle(u0, u1, v0, v1));
    }
    if !loops.is_empty() && c.maps == <[AxisMap; 2]>::default() {
        let size = c.surface.net_diagonal();
        let closed = [c.surface.is_closed_u(CLOSED * size), {
            c.surface.transposed().is_closed_u(CLOSED * size)
        }];
        if closed == [true, true] {
            complement_clockwise_outer(&c.surface, &mut loops);
        }
        c.surface = across_seams(c.surface, control_box(&loops), closed);
    }
    Surface {
        geometry: SurfaceGeometry::Nurbs(c.surface),
        trims: loops,
        trim_space: c.maps,
    }
}

/// A surface is closed in a direction when its first and last control points there meet
/// within this fraction of the net's size: writers round the seam's points alike, so this
/// only needs to be above the file's rounding.
pub(super) const CLOSED: f64 = 1e-7;

/// Loops reaching at most this many whole periods beyond a closed surface's domain are
/// followed there; farther is not a seam crossing but a wrong parameterisation.
const MAX_PERIODS: f64 = 2.0;

/// On a surface closed in both directions (a torus) a loop that does not go around bounds
/// two regions, and which one is meant is the loop's orientation: OpenCASCADE keeps the
/// region to the left of the wire (checked on `occt_OCC26138_Torus.igs`: its one outer
/// boundary runs clockwise, and OpenCASCADE's face is the torus without the rectangle the
/// loop draws, over a full period in u and v). So a lone outer loop running clockwise
/// becomes a hole in one period of the surface that starts at the loop's lower corner.
fn complement_clockwise_outer(s: &NurbsSurface, loops: &mut Vec<TrimLoop>) {
    let outer: Vec<usize> = (0..loops.len()).filter(|&i| !loops[i].hole).collect();
    let [i] = outer[..] else { return };
    if signed_area(&loops[i]) >= 0.0 {
        return;
    }
    let (lo, _) = control_box(std::slice::from_ref(&loops[i]));
    let d = s.domain();
    let (tu, tv) = (d.u1 - d.u0, d.v1 - d.v0);
    loops[i].hole = true;
    loops.insert(0, rectangle(lo.x, lo.x + tu, lo.y, lo.y + tv));
}

/// The signed area of a loop's control polygon (shoelace; positive counter-clockwise):
/// its sign is the loop's orientation for the simple loops trims are.
fn signed_area(l: &TrimLoop) -> f64 {
    let points: Vec<DVec2> = l
        .segments
        .iter()
        .flat_map(|s| &s.curve.points)
        .map(|q| DVec2::new(q.x / q.z, q.y / q.z))
        .collect();
    let n = points.len();
    (0..n)
        .map(|k| points[k].perp_dot(points[(k + 1) % n]))
        .sum::<f64>()
        / 2.0
}

/// `s` repeated over the periods the loops' box `(lo, hi)` reaches beyond its domain in
/// each direction in which it is `closed`.
fn across_seams(mut s: NurbsSurface, (lo, hi): (DVec2, DVec2), closed: [bool; 2]) -> NurbsSurface {
    for k in 0..2 {
        let d = s.domain();
        let (a, b) = if k == 0 { (d.u0, d.u1) } else { (d.v0, d.v1) };
        let period = b - a;
        let periods = |x: f64| (x / period - 1e-9).ceil().clamp(0.0, MAX_PERIODS) as usize;
        let (before, after) = (periods(a - lo[k]), periods(hi[k] - b));
        if before + after > 0 && closed[k] {
            let t = if k == 0 { s.clone() } else { s.transposed() };
            let r = t.repeated_u(before, after);
            s = if k == 0 { r } else { r.transposed() };
        }
    }
    s
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

fn transform(points: &mut [DVec4], m: &glam::DAffine3) {
    for p in points {
        let e = m.transform_point3(p.truncate() / p.w);
        *p = (e * p.w).extend(p.w);
    }
}

/// A model-space curve piece in the plane's frame coordinates: the projection along the
/// normal is affine, so exact on the homogeneous control points.
fn in_frame(frame: &Frame, p: Piece) -> TrimSegment {
    let points = p
        .curve
        .points
        .iter()
        .map(|q| {
            let r = q.truncate() - frame.origin * q.w;
            DVec3::new(r.dot(frame.x), r.dot(frame.y), q.w)
        })
        .collect();
    TrimSegment {
        t0: p.t0,
        t1: p.t1,
        curve: ParamCurve {
            degree: p.curve.degree,
            knots: p.curve.knots,
            points,
        },
    }
}

/// A plane as a bilinear patch in `frame` around its loops (in frame coordinates).
fn planar(frame: &Frame, trims: Vec<TrimLoop>) -> Result<Surface, String> {
    let (lo, hi) = control_box(&trims);
    let (s, maps) =
        analytic::plane(frame, lo.x, hi.x, lo.y, hi.y).map_err(|e| format!("plane bounds: {e}"))?;
    Ok(Surface {
        geometry: SurfaceGeometry::Nurbs(s),
        trims,
        trim_space: maps,
    })
}
