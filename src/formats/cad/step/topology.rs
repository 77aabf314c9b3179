//! B-rep faces to trimmed NURBS surfaces: every ADVANCED_FACE's bounds become trim loops
//! in its surface's parameters (ISO 10303-42 §5.4: face_bound, edge_loop, oriented_edge,
//! edge_curve), and the surface becomes an exact NURBS over the loops' extent
//! (OpenCASCADE's StepToTopoDS_TranslateFace).
//!
//! An edge's piece of a loop is its PCURVE on the face's surface where the file gives one
//! that agrees with the 3D curve, exact (lines, B-splines, circle and ellipse arcs);
//! otherwise the 3D edge curve is projected (`geom::pcurve`), sample by sample, into the surface's
//! parameters (closed forms for the elementary surfaces, point inversion for B-splines),
//! refined until the chord between samples lies within [`CHORD_TOLERANCE`] of the projection,
//! and the largest distance found is reported as the projection error.
//!
//! Periodic parameters (the angles of cylinders, cones, spheres, tori, revolutions) are
//! unwrapped across the seam so that each loop is continuous: a piece is shifted by whole
//! periods to start where the previous one ended, and the two sides of a seam edge (its two
//! pcurves) are taken once each. A loop that goes once around a periodic direction (the
//! circle bounding a cylinder face) is closed through a line beyond the surface's other
//! parameter range, so that even–odd parity over all loops (how the kernels apply trims)
//! still sees the band between two such loops as inside.

use std::collections::HashMap;

use glam::{DVec2, DVec3};

use super::entities::{Curve, Edge, Face, PCurve, SurfaceDef};
use super::geometry::{curve_to_nurbs, surface_to_nurbs};
use super::loop_piece::{Piece, as_param};
use crate::formats::cad::{POINT_TOLERANCE, projection_tolerance};
use crate::geom::nurbs::NurbsSurface;
use crate::geom::nurbs::inversion::Inverter;
use crate::geom::pcurve::{self, ParamSurface, unwrap};
use crate::geom::trim::{ParamCurve, TrimLoop, TrimSegment};
use crate::scene::model::{Surface, SurfaceGeometry};

/// How far a pcurve may stray from its 3D curve, relative to the model's size, and still
/// be used: CAD systems write edges to tolerances of about 1e-7 to 1e-4 of the part.
pub(super) const PCURVE_TOLERANCE: f64 = 1e-4;

/// A converted face and what its conversion measured.
pub struct FaceOutcome {
    pub surface: Surface,
    /// Largest distance between a projected edge's trim and the edge's projection onto
    /// the surface: this reader's approximation.
    pub trim_error: f64,
    /// The edges whose pieces came from projection rather than a pcurve, each with its
    /// largest distance from the surface: the file's own gap between edge and face.
    pub edge_gaps: Vec<(u64, f64)>,
}

/// The face's surface as far as the loops need it: its definition, its periods, and a
/// point inverter for B-spline surfaces.
struct Domain<'f> {
    def: &'f SurfaceDef,
    periods: [Option<f64>; 2],
    inverter: Option<Inverter>,
    /// Model-size length tolerance for chords and pcurve agreement.
    scale: f64,
}

impl ParamSurface for Domain<'_> {
    fn point(&self, uv: DVec2) -> DVec3 {
        // A closed B-spline (surface or profile) taken as periodic: parameters beyond its
        // domain wrap into it.
        let mut w = uv;
        for axis in 0..2 {
            if let (Some(p), Some((lo, _))) = (self.periods[axis], self.def.fixed_span(axis)) {
                w[axis] = lo + (w[axis] - lo).rem_euclid(p);
            }
        }
        self.def.point(w.x, w.y)
    }

    fn parameters(&self, p: DVec3) -> Option<DVec2> {
        match self.def.parameters_of(p) {
            Some(uv) => Some(uv),
            None => {
                let hit = self.inverter.as_ref()?.project(p)?;
                Some(DVec2::new(hit.u, hit.v))
            }
        }
    }

    fn periods(&self) -> [Option<f64>; 2] {
        self.periods
    }
}

impl Domain<'_> {
    /// Parameters of `p`, unwrapped to lie nearest `near`.
    fn uv(&self, p: DVec3, near: Option<DVec2>) -> Option<DVec2> {
        pcurve::parameters_near(self, p, near)
    }

    /// Whether the periodic u collapses at `uv` (a sphere's pole, a cone's apex), where the
    /// angle of a point means nothing.
    fn collapsed_u(&self, uv: DVec2) -> bool {
        pcurve::collapsed(self, uv, 0, self.scale * POINT_TOLERANCE)
    }

    /// The projection of `c` over `[ta, tb]` into the parameter plane (`geom::pcurve`),
    /// its chords within [`CHORD_TOLERANCE`](crate::formats::cad::CHORD_TOLERANCE) of the model.
    fn project(&self, c: &Curve, ta: f64, tb: f64) -> Result<pcurve::Projected, String> {
        pcurve::project(
            self,
            |t| c.point(t),
            ta,
            tb,
            projection_tolerance(self.scale),
        )
        .map_err(|p| format!("cannot project the edge point {p} onto the surface"))
    }

    /// The pcurve `pc` over `[ta, tb]`, exact, if it agrees with the 3D curve there (its
    /// parameter the 3D curve's, as ISO 10303-42 intends for surface curves).
    /// An edge on a plane, exactly: the plane's parameters are affine in space, so the
    /// edge's homogeneous control points map to parameter-plane control points with their
    /// weights. A curve lying in the plane has every control point in it (its basis
    /// functions are independent), so a point off the plane means the edge is not on it.
    fn planar_piece(&self, c: &Curve, ta: f64, tb: f64) -> Option<TrimSegment> {
        let SurfaceDef::Plane(frame) = self.def else {
            return None;
        };
        let (curve, _) = curve_to_nurbs(c, [ta, tb]).ok()?;
        let tol = self.scale * PCURVE_TOLERANCE;
        let mut points = Vec::with_capacity(curve.points.len());
        for p in &curve.points {
            if p.w.is_nan() || p.w <= 0.0 {
                return None;
            }
            let l = frame.local(p.truncate() / p.w);
            if l.z.abs() > tol {
                return None;
            }
            points.push(DVec3::new(l.x * p.w, l.y * p.w, p.w));
        }
        let (d0, d1) = crate::geom::nurbs::knots::domain(curve.degree, &curve.knots);
        Some(TrimSegment {
            t0: ta.max(d0),
            t1: tb.min(d1),
            curve: ParamCurve {
                degree: curve.degree,
                knots: curve.knots,
                points,
            },
        })
    }

    fn pcurve_piece(&self, pc: &PCurve, c3: &Curve, ta: f64, tb: f64) -> Option<TrimSegment> {
        let tol = self.scale * PCURVE_TOLERANCE;
        // Checked at nine points: a wrong pcurve can agree with its edge at the ends
        // and the middle (one that bulges the other way between them).
        let agrees = (0..=8).map(|k| ta + (tb - ta) * k as f64 / 8.0).all(|t| {
            self.point(pc.curve.point(t).truncate())
                .distance(c3.point(t))
                <= tol
        });
        if !agrees {
            return None;
        }
        let (curve, _) = curve_to_nurbs(&pc.curve, [ta, tb]).ok()?;
        let (d0, d1) = crate::geom::nurbs::knots::domain(curve.degree, &curve.knots);
        let mut piece = Piece::new(
            TrimSegment {
                t0: ta.max(d0),
                t1: tb.min(d1),
                curve: as_param(&curve),
            },
            false,
        );
        // A sphere's latitude is only meaningful in [-π/2, π/2], but its closed form is
        // 2π-periodic, so a pcurve may agree with its edge a whole turn away (OpenCASCADE
        // writes the seam of a hemisphere at v = t − 2π): bring it back by whole turns.
        if let SurfaceDef::Sphere { .. } = self.def {
            let mid = 0.5 * (piece.start().y + piece.end().y);
            let turns = (mid / std::f64::consts::TAU).round();
            piece.shift(DVec2::new(0.0, -turns * std::f64::consts::TAU));
        }
        Some(piece.seg)
    }
}

/// A loop of a face on a surface periodic in some parameter, placed on the surface's range
/// `[lo, hi]` (one period or less along a periodic axis) and copied a period over where it
/// reaches beyond it: a hole across the seam is cut on both sides of it. A closed loop
/// is first moved by whole periods to lie nearest the range's middle; a loop winding
/// around the axis (closed beyond the range already) spans a whole period from wherever
/// its first vertex is: moved to start nearest the range's start, the copy a period over
/// covers the rest of the range, and the two copies' closing lines at that vertex
/// coincide and cancel under even–odd parity.
fn across_range(
    pieces: &mut [Piece],
    winds: Option<usize>,
    lo: DVec2,
    hi: DVec2,
    periods: [Option<f64>; 2],
) -> Vec<Vec<Piece>> {
    let mut copies = Vec::new();
    for axis in 0..2 {
        let Some(p) = periods[axis] else { continue };
        let extent = |pieces: &[Piece]| {
            pieces
                .iter()
                .flat_map(Piece::samples)
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), q| {
                    (a.min(q[axis]), b.max(q[axis]))
                })
        };
        let (a, b) = extent(pieces);
        let turns = if winds == Some(axis) {
            ((lo[axis] - a) / p).round()
        } else {
            ((0.5 * (lo[axis] + hi[axis]) - 0.5 * (a + b)) / p).round()
        };
        if turns != 0.0 {
            let mut d = DVec2::ZERO;
            d[axis] = turns * p;
            pieces.iter_mut().for_each(|q| q.shift(d));
        }
        let (a, b) = extent(pieces);
        let slack = 1e-9 * p;

        for (beyond, by) in [(a < lo[axis] - slack, p), (b > hi[axis] + slack, -p)] {
            if beyond {
                let mut d = DVec2::ZERO;
                d[axis] = by;
                let mut copy = pieces.to_vec();
                copy.iter_mut().for_each(|q| q.shift(d));
                copies.push(copy);
            }
        }
    }
    copies
}

/// Joins `next` to `prev` where their ends differ in the parameters (edges meet at a vertex
/// in the model): a gap a rounding wide, one point in the model and short beside both
/// edges (a file's tolerance: two edges' ends projected a hair apart), is closed by moving
/// a projected edge's end vertex onto the other's, since a chord there would double back
/// along an edge, a spur of no area that readers of the faces we write make degenerate
/// faces of; any other gap (a pole or apex, a wider tolerance) is bridged by the returned
/// chord, so the loop stays closed.
fn close_gap(dom: &Domain, prev: &mut Piece, next: &mut Piece) -> Option<Piece> {
    let (end, start) = (prev.end(), next.start());
    let gap = start.distance(end);
    if gap <= 1e-9 * (1.0 + end.length()) {
        return None;
    }
    let one_point = dom.point(end).distance(dom.point(start)) <= dom.scale * POINT_TOLERANCE;
    let short = |p: &Piece| gap <= SHORT_GAP * p.start().distance(p.end());
    if one_point
        && short(prev)
        && short(next)
        && !dom.collapsed_u(end)
        && (next.move_end(0, end) || prev.move_end(1, start))
    {
        return None;
    }
    Some(Piece::new(TrimSegment::polyline(&[end, start]), false))
}

/// How short, beside the edges it joins, a gap between two edges' ends must be to be
/// closed by moving an end rather than bridged: a thousandth leaves a pole's or an apex's
/// collapsed edge, as long as the edges around it, to its bridge.
const SHORT_GAP: f64 = 1e-3;

/// The parameter interval `[ta, tb]` of the edge on its 3D curve (increasing) and whether
/// the edge runs along the curve: vertices located on the curve, periodic curves
/// unwrapped, a closed edge taking a whole period (or the whole B-spline).
fn edge_interval(e: &Edge) -> (f64, f64) {
    let c = e.curve.space_curve();
    let (ps, pe) = (c.parameter_of(e.start), c.parameter_of(e.end));
    let (a, mut b) = if e.same_sense { (ps, pe) } else { (pe, ps) };
    match c.period() {
        Some(p) if matches!(c, Curve::Circle { .. } | Curve::Ellipse { .. }) => {
            b = a + (b - a).rem_euclid(p);
            if e.closed || b - a <= p * 1e-12 {
                b = a + p;
            }
            (a, b)
        }
        _ => {
            if e.closed {
                let (d0, d1) = c.domain();
                if d0.is_finite() && d1.is_finite() {
                    return (d0, d1);
                }
            }
            (a.min(b), a.max(b))
        }
    }
}

/// The periods of a B-spline surface closed in u or v (its two boundary curves across
/// that direction the same within `tol`, checked at 17 points): the length of its domain
/// there, so that a trim crossing the seam is unwrapped as on an elementary surface.
fn closed_periods(n: &NurbsSurface, tol: f64) -> [Option<f64>; 2] {
    let d = n.domain();
    let closed = |a: &dyn Fn(f64) -> DVec3, b: &dyn Fn(f64) -> DVec3| {
        (0..=16).all(|k| a(k as f64 / 16.0).distance(b(k as f64 / 16.0)) <= tol)
    };
    let at_v = |s: f64| d.v0 + (d.v1 - d.v0) * s;
    let at_u = |s: f64| d.u0 + (d.u1 - d.u0) * s;
    let closed_u = closed(&|s| n.eval(d.u0, at_v(s)), &|s| n.eval(d.u1, at_v(s)));
    let closed_v = closed(&|s| n.eval(at_u(s), d.v0), &|s| n.eval(at_u(s), d.v1));
    [
        closed_u.then_some(d.u1 - d.u0),
        closed_v.then_some(d.v1 - d.v0),
    ]
}

/// Twice the signed area a loop encloses in the parameter plane as traversed (positive
/// counter-clockwise), from its pieces' samples.
fn signed_area(pieces: &[Piece]) -> f64 {
    let mut points: Vec<DVec2> = Vec::new();
    for p in pieces {
        let start = points.len();
        points.extend(p.samples());
        if p.reversed {
            points[start..].reverse();
        }
    }
    (0..points.len())
        .map(|k| points[k].perp_dot(points[(k + 1) % points.len()]))
        .sum()
}

/// The whole range of v of a surface closed in it (from pole to pole of a sphere, over a
/// revolution's profile, a turn of a torus's tube from `v0`, a B-spline's domain).
fn natural_v(def: &SurfaceDef, v0: f64) -> Option<(f64, f64)> {
    use std::f64::consts::{FRAC_PI_2, TAU};
    match def {
        SurfaceDef::Sphere { .. } => Some((-FRAC_PI_2, FRAC_PI_2)),
        SurfaceDef::Torus { .. } => Some((v0, v0 + TAU)),
        SurfaceDef::Revolution { profile, .. } => {
            let (a, b) = profile.domain();
            (a.is_finite() && b.is_finite()).then_some((a, b))
        }
        SurfaceDef::BSpline(n) => {
            let d = n.domain();
            Some((d.v0, d.v1))
        }
        _ => None,
    }
}

/// Where a sphere's or cone's v meets its axis beyond `v`, upwards (`high`) or
/// downwards: a pole (v = ±π/2) or the apex (v = −r / tan α); `None` on that side of
/// every other surface, which goes on without end there.
fn pole_towards(def: &SurfaceDef, v: f64, high: bool) -> Option<f64> {
    let pole = match def {
        SurfaceDef::Sphere { .. } => {
            if high {
                std::f64::consts::FRAC_PI_2
            } else {
                -std::f64::consts::FRAC_PI_2
            }
        }
        SurfaceDef::Cone {
            radius, semi_angle, ..
        } if *semi_angle != 0.0 => -radius / semi_angle.tan(),
        _ => return None,
    };
    (if high { pole > v } else { pole < v }).then_some(pole)
}

/// A face without edge bounds: the whole of a closed surface (ISO 10303-42 §5.4.x: a
/// face's bounds may be empty when its surface is closed; OpenCASCADE takes the natural
/// bounds): a sphere, a torus, a B-spline surface over its domain.
fn whole_face(face: &Face) -> Result<FaceOutcome, String> {
    use std::f64::consts::{FRAC_PI_2, TAU};
    let (u, v) = match &*face.surface {
        SurfaceDef::Sphere { .. } => ([0.0, TAU], [-FRAC_PI_2, FRAC_PI_2]),
        SurfaceDef::Torus { .. } => ([0.0, TAU], [0.0, TAU]),
        SurfaceDef::BSpline(n) => {
            let d = n.domain();
            ([d.u0, d.u1], [d.v0, d.v1])
        }
        _ => {
            return Err(
                "it has no edge bounds and its surface is unbounded (only a sphere, torus or B-spline surface can be a whole face)".into(),
            );
        }
    };
    let (nurbs, trim_space) = surface_to_nurbs(&face.surface, u, v).map_err(|e| e.to_string())?;
    let mut surface = Surface {
        geometry: SurfaceGeometry::Nurbs(nurbs),
        trims: Vec::new(),
        trim_space,
    };
    if !face.same_sense {
        surface.flip_sides();
    }
    Ok(FaceOutcome {
        surface,
        trim_error: 0.0,
        edge_gaps: Vec::new(),
    })
}

/// The diagonal of the box of the faces' vertices (edge ends and vertex loops): the
/// model's size as its B-rep spans it; `None` for faces without vertices.
pub fn faces_extent<'f>(faces: impl Iterator<Item = &'f Face>) -> Option<f64> {
    let mut lo = DVec3::splat(f64::INFINITY);
    let mut hi = DVec3::splat(f64::NEG_INFINITY);
    for b in faces.flat_map(|f| &f.bounds) {
        let ends = b.edges.iter().flat_map(|oe| [oe.edge.start, oe.edge.end]);
        for p in ends.chain(b.vertex).filter(|p| p.is_finite()) {
            lo = lo.min(p);
            hi = hi.max(p);
        }
    }
    (lo.x <= hi.x).then(|| lo.distance(hi).max(f64::MIN_POSITIVE))
}

/// Converts one face; the error says why it could not be (the caller names the face).
/// `scale` is the model's size, which the tolerances are relative to.
pub fn convert_face(face: &Face, scale: f64) -> Result<FaceOutcome, String> {
    let def = &*face.surface;
    let inverter = match def {
        SurfaceDef::BSpline(n) => Some(Inverter::new(n)),
        _ => None,
    };
    let periods = match def {
        SurfaceDef::BSpline(n) => closed_periods(n, scale * POINT_TOLERANCE),
        _ => def.periods(),
    };
    let dom = Domain {
        def,
        periods,
        inverter,
        scale,
    };
    let mut trim_error: f64 = 0.0;
    let mut edge_gaps = Vec::new();
    // Each edge's candidate pieces, once per face (a seam edge appears twice in a loop).
    let mut candidates: HashMap<u64, Vec<TrimSegment>> = HashMap::new();
    if face.bounds.iter().all(|b| b.edges.is_empty()) {
        return whole_face(face);
    }
    // Each loop's pieces, the periodic axis it winds around (if it does), whether it
    // runs towards increasing parameter along that axis as a bound of the face, and
    // whether the face lies to the left of its pieces as traversed.
    let mut loops: Vec<(Vec<Piece>, Option<usize>, bool, bool)> = Vec::new();
    let mut extent_points: Vec<DVec2> = Vec::new();
    let mut outer_u: Option<(f64, f64)> = None;
    let outer_index = face.bounds.iter().position(|b| b.outer).unwrap_or(0);
    let mut order: Vec<usize> = (0..face.bounds.len()).collect();
    order.retain(|&k| k != outer_index);
    order.insert(0, outer_index.min(face.bounds.len().saturating_sub(1)));
    for &bi in order.iter().take(face.bounds.len()) {
        let bound = &face.bounds[bi];
        if bound.edges.is_empty() {
            if let Some(p) = bound.vertex {
                let near = extent_points.last().copied();
                if let Some(uv) = dom.uv(p, near) {
                    extent_points.push(uv);
                }
            }
            continue;
        }
        let mut pieces: Vec<Piece> = Vec::new();
        let mut used: HashMap<u64, usize> = HashMap::new();
        for oe in &bound.edges {
            let e = &oe.edge;
            let (ta, tb) = edge_interval(e);
            if !(ta.is_finite() && tb.is_finite() && ta < tb) {
                return Err(format!("edge #{} has an empty parameter range", e.id));
            }
            if let std::collections::hash_map::Entry::Vacant(slot) = candidates.entry(e.id) {
                let c3 = e.curve.space_curve();
                let mut list = Vec::new();
                if let Curve::OnSurface { pcurves, .. } = &*e.curve {
                    for pc in pcurves.iter().filter(|pc| pc.surface == face.surface_id) {
                        if let Some(seg) = dom.pcurve_piece(pc, c3, ta, tb) {
                            list.push(seg);
                        }
                    }
                }
                if list.is_empty()
                    && let Some(seg) = dom.planar_piece(c3, ta, tb)
                {
                    list.push(seg);
                }
                if list.is_empty() {
                    let projected = dom
                        .project(c3, ta, tb)
                        .map_err(|m| format!("edge #{}: {m}", e.id))?;
                    trim_error = trim_error.max(projected.chord);
                    edge_gaps.push((e.id, projected.gap));
                    list.push(TrimSegment::polyline(&projected.points));
                }
                slot.insert(list);
            }
            let list = &candidates[&e.id];
            let reversed = oe.orientation != e.same_sense;
            let prev_end = pieces.last().map(Piece::end);
            let placed = |k: usize| -> Piece {
                let mut p = Piece::new(list[k].clone(), reversed);
                if let Some(end) = prev_end {
                    let s = p.start();
                    let du = if dom.collapsed_u(end) {
                        0.0
                    } else {
                        unwrap(s.x, end.x, dom.periods[0]) - s.x
                    };
                    let dv = unwrap(s.y, end.y, dom.periods[1]) - s.y;
                    p.shift(DVec2::new(du, dv));
                }
                p
            };
            let k = match (used.get(&e.id), prev_end) {
                (Some(&k0), _) if list.len() > 1 => 1 - k0.min(1),
                (_, Some(end)) => (0..list.len())
                    .min_by(|&a, &b| {
                        placed(a)
                            .start()
                            .distance(end)
                            .total_cmp(&placed(b).start().distance(end))
                    })
                    .unwrap_or(0),
                _ => 0,
            };
            used.insert(e.id, k);
            let mut piece = placed(k);
            let bridge = pieces
                .last_mut()
                .and_then(|prev| close_gap(&dom, prev, &mut piece));
            pieces.extend(bridge);
            pieces.push(piece);
        }
        // On a closed B-spline (surface or profile) the outer loop is placed by whole
        // periods over its domain (the seam's points invert to either end).
        if outer_u.is_none() {
            let mut lo = DVec2::splat(f64::INFINITY);
            let mut hi = DVec2::splat(f64::NEG_INFINITY);
            for q in pieces.iter().flat_map(Piece::samples) {
                lo = lo.min(q);
                hi = hi.max(q);
            }
            let mut shift = DVec2::ZERO;
            for axis in 0..2 {
                if let (Some(p), Some((a, b))) = (dom.periods[axis], def.fixed_span(axis)) {
                    let centre = 0.5 * (a + b);
                    shift[axis] = ((centre - 0.5 * (lo[axis] + hi[axis])) / p).round() * p;
                }
            }
            if shift != DVec2::ZERO {
                for p in &mut pieces {
                    p.shift(shift);
                }
            }
        }
        // Holes first placed within the outer loop's periodic range.
        if let (Some((u0, _)), Some(period)) = (outer_u, dom.periods[0]) {
            let s = pieces[0].start().x;
            let d = u0 + (s - u0).rem_euclid(period) - s;
            for p in &mut pieces {
                p.shift(DVec2::new(d, 0.0));
            }
        }
        let (first, last) = (pieces[0].start(), pieces[pieces.len() - 1].end());
        let gap = first - last;
        let winds = (0..2).find(|&axis| {
            dom.periods[axis].is_some_and(|p| {
                (gap[axis].abs() - p).abs() <= 1e-9 * p
                    && gap[1 - axis].abs() <= 1e-9 * (1.0 + last.length())
            })
        });
        if winds.is_none() {
            let bridge = match pieces.len() {
                1 if gap.length() > 1e-9 * (1.0 + last.length()) => {
                    Some(Piece::new(TrimSegment::polyline(&[last, first]), false))
                }
                1 => None,
                n => {
                    let (head, tail) = pieces.split_at_mut(n - 1);
                    close_gap(&dom, &mut tail[0], &mut head[0])
                }
            };
            pieces.extend(bridge);
        }
        let mut lo = f64::INFINITY;
        let mut hi = f64::NEG_INFINITY;
        for p in &pieces {
            let [a, b] = p.extent();
            lo = lo.min(a.x);
            hi = hi.max(b.x);
            extent_points.extend([a, b]);
        }
        if outer_u.is_none() {
            outer_u = Some((lo, hi));
        }
        // ISO 10303-42 §5.4.x: a FALSE face_bound orientation reverses every oriented
        // edge of its loop, and a face whose same_sense is FALSE has its normal against
        // the surface's, so its loops' left side is the surface's right.
        let left = bound.orientation == face.same_sense;
        let forwards = winds.is_some_and(|axis| gap[axis] < 0.0) == left;
        loops.push((pieces, winds, forwards, left));
    }
    // The surface over the loops' extent (B-splines keep their own domain).
    let mut lo = DVec2::splat(f64::INFINITY);
    let mut hi = DVec2::splat(f64::NEG_INFINITY);
    for q in &extent_points {
        lo = lo.min(*q);
        hi = hi.max(*q);
    }
    if matches!(def, SurfaceDef::BSpline(_)) {
        let d = match def {
            SurfaceDef::BSpline(n) => n.domain(),
            _ => unreachable!(),
        };
        lo = DVec2::new(d.u0, d.v0);
        hi = DVec2::new(d.u1, d.v1);
    }
    for axis in 0..2 {
        if let Some(p) = dom.periods[axis] {
            hi[axis] = hi[axis].min(lo[axis] + p);
        }
    }
    if let SurfaceDef::Sphere { .. } = def {
        lo.y = lo.y.max(-std::f64::consts::FRAC_PI_2);
        hi.y = hi.y.min(std::f64::consts::FRAC_PI_2);
    }
    // Bounds that are all holes (each loop has the face on its right, ISO 10303-42
    // face_bound): the face is its closed surface with those holes cut out (a ball drilled
    // through), so it spans the surface's natural range. On an analytic closed surface a
    // `FACE_OUTER_BOUND` is no exception: both sides of its loop are bounded, and the face
    // is the one on the loop's left (a sphere written as two faces between the same two
    // half circles, one loop each way round, is its two hemispheres). A B-spline's outer
    // bound is kept as the outer loop: loops inverted onto a B-spline beside its poles can
    // enclose their area the wrong way round (Alias writes such faces).
    let outer_given = face.bounds.iter().any(|b| b.outer && !b.edges.is_empty());
    let all_holes = !(outer_given && matches!(def, SurfaceDef::BSpline(_)))
        && loops
            .iter()
            .all(|l| l.1.is_none() && (signed_area(&l.0) > 0.0) != l.3);
    // Only a surface closed around u (or a B-spline closed either way) can be such a
    // face; elsewhere the loops are taken as they come, as before.
    let natural = match (all_holes, dom.periods[0], def) {
        (false, ..) => None,
        (true, Some(p), _) => natural_v(def, lo.y).map(|v| ([lo.x, lo.x + p], v)),
        (true, None, SurfaceDef::BSpline(_)) if dom.periods[1].is_some() => {
            natural_v(def, lo.y).map(|v| ([lo.x, hi.x], v))
        }
        _ => None,
    };
    if let Some(([u0, u1], (v0, v1))) = natural {
        lo = DVec2::new(u0, v0);
        hi = DVec2::new(u1, v1);
    }
    let all_holes = natural.is_some();
    // Loops winding around u an odd number of times leave one side of the face open,
    // where every winding loop is closed beyond the range so that even–odd parity keeps
    // the face. Alone, the first such loop gives that side by its orientation (a face
    // lies to the left of its bounds, ISO 10303-42 face_bound) and the face reaches the
    // pole or apex there; otherwise the other bounds' extent gives it.
    let mut close_high = true;
    let mut around_u = loops.iter().filter(|l| l.1 == Some(0));
    if around_u.clone().count() % 2 == 1
        && let Some(first) = around_u.next()
    {
        let v = first.0[0].start().y;
        // No extent in v beyond the loop's own rounding: nothing else bounds that side.
        let slack = 1e-9 * (1.0 + lo.y.abs().max(hi.y.abs()));
        if (hi.y - lo.y).partial_cmp(&slack) != Some(std::cmp::Ordering::Greater) {
            close_high = first.2;
            let pole = pole_towards(def, v, close_high).ok_or_else(|| {
                "its single loop around the surface leaves the face unbounded on one side"
                    .to_string()
            })?;
            if close_high {
                hi.y = pole;
            } else {
                lo.y = pole;
            }
        } else {
            // Other bounds (a vertex loop at the apex, a seam run to the pole) give the
            // open side, whatever the loop's orientation says (OpenCASCADE's healing
            // turns such a loop around too).
            close_high = (v - lo.y).abs() <= (hi.y - v).abs();
        }
    }
    if !(lo.x < hi.x && lo.y < hi.y) {
        return Err(
            "its bounds enclose no area of the surface (an unbounded or degenerate face)".into(),
        );
    }
    let (nurbs, trim_space) =
        surface_to_nurbs(def, [lo.x, hi.x], [lo.y, hi.y]).map_err(|e| e.to_string())?;
    // Winding loops close beyond the other parameter's range, all on the same side.
    let mut trims = Vec::new();
    for (k, (mut pieces, winds, _, _)) in loops.into_iter().enumerate() {
        if let Some(axis) = winds {
            let other = 1 - axis;
            let margin = (hi[other] - lo[other]).max(1.0);
            let far = if close_high || axis == 1 {
                hi[other] + margin
            } else {
                lo[other] - margin
            };
            let (first, last) = (pieces[0].start(), pieces[pieces.len() - 1].end());
            let mut a = last;
            a[other] = far;
            let mut b = first;
            b[other] = far;
            pieces.push(Piece::new(
                TrimSegment::polyline(&[last, a, b, first]),
                false,
            ));
        }
        // Holes only: the surface's domain is the outer bound (`geom::trim`).
        let hole = all_holes || k > 0;
        let copies = across_range(&mut pieces, winds, lo, hi, dom.periods);
        for pieces in std::iter::once(pieces).chain(copies) {
            trims.push(TrimLoop {
                hole,
                // A segment runs from t0 to t1 in either order (`geom::trim`): reversed
                // pieces swap them, so each segment starts where the previous one ended.
                segments: pieces
                    .into_iter()
                    .map(|p| match p.reversed {
                        false => p.seg,
                        true => TrimSegment {
                            t0: p.seg.t1,
                            t1: p.seg.t0,
                            curve: p.seg.curve,
                        },
                    })
                    .collect(),
            });
        }
    }
    let mut surface = Surface {
        geometry: SurfaceGeometry::Nurbs(nurbs),
        trims,
        trim_space,
    };
    if !face.same_sense {
        surface.flip_sides();
    }
    Ok(FaceOutcome {
        surface,
        trim_error,
        edge_gaps,
    })
}
