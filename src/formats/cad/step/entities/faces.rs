//! Topology (ISO 10303-42 topology schema): faces, their bounds as loops of oriented
//! edges, edges between vertices along their curves.

use std::sync::Arc;

use glam::DVec3;

use super::{Curve, Rec, Resolver, SurfaceDef};
use crate::formats::cad::step::records::Instance;
use crate::formats::error::ParseError;

/// A resolved ADVANCED_FACE (or FACE_SURFACE).
#[derive(Clone, Debug)]
pub struct Face {
    pub id: u64,
    pub surface_id: u64,
    pub surface: Arc<SurfaceDef>,
    pub same_sense: bool,
    pub bounds: Vec<Bound>,
}

/// FACE_OUTER_BOUND / FACE_BOUND over an EDGE_LOOP (or a VERTEX_LOOP, a degenerate bound
/// at a cone apex or sphere pole, kept as an empty edge list).
#[derive(Clone, Debug)]
pub struct Bound {
    pub id: u64,
    pub outer: bool,
    pub orientation: bool,
    pub edges: Vec<OrientedEdge>,
    /// The point of a VERTEX_LOOP.
    pub vertex: Option<DVec3>,
}

#[derive(Clone, Debug)]
pub struct OrientedEdge {
    /// False: the loop traverses the edge from its end vertex to its start.
    pub orientation: bool,
    pub edge: Arc<Edge>,
}

/// EDGE_CURVE: from `start` to `end` along `curve` (against it when `same_sense` is false).
#[derive(Clone, Debug)]
pub struct Edge {
    pub id: u64,
    pub start: DVec3,
    pub end: DVec3,
    /// The two vertices are one VERTEX_POINT: a closed edge (a full circle).
    pub closed: bool,
    pub curve: Arc<Curve>,
    pub same_sense: bool,
}

/// Cosine of the largest angle between a LINE and the chord of its edge's vertices for
/// which a line off its vertices is taken as displaced (cos 4.5e-5 rad): directions
/// written to four or five digits are that far from the true one.
const PARALLEL_COS: f64 = 1.0 - 1e-9;

/// An edge's LINE moved to pass through the edge's vertices when it runs parallel to
/// them but beside them, as OpenCASCADE's reader does (StepToTopoDS_TranslateEdge: some
/// ECAD writers place an edge's line away from its true position with the right
/// direction). Any other curve, or a line through its vertices, is returned unchanged.
fn line_through_vertices(curve: Arc<Curve>, start: DVec3, end: DVec3) -> Arc<Curve> {
    let shifted = |c: &Curve| -> Option<Curve> {
        let Curve::Line { origin, direction } = c else {
            return None;
        };
        let d = direction.try_normalize()?;
        let chord = end - start;
        let off = {
            let r = start - *origin;
            r - r.dot(d) * d
        };
        let parallel = chord.dot(d).abs() >= PARALLEL_COS * chord.length();
        (parallel && off != DVec3::ZERO && chord != DVec3::ZERO).then(|| Curve::Line {
            origin: *origin + off,
            direction: *direction,
        })
    };
    match &*curve {
        Curve::OnSurface { curve: c3, pcurves } => match shifted(c3) {
            Some(line) => Arc::new(Curve::OnSurface {
                curve: Arc::new(line),
                pcurves: pcurves.clone(),
            }),
            None => curve,
        },
        c => shifted(c).map_or(curve, Arc::new),
    }
}

impl<'e, 'a> Resolver<'e, 'a> {
    /// An ADVANCED_FACE or FACE_SURFACE(name, bounds, face_geometry, same_sense).
    pub fn face(&self, inst: &'e Instance<'a>) -> Result<Face, ParseError> {
        let r = self.rec(inst);
        if !matches!(r.rec.name, "ADVANCED_FACE" | "FACE_SURFACE") {
            return Err(r.error("expected an ADVANCED_FACE or FACE_SURFACE"));
        }
        let surface_id = r.reference(2, "the face geometry")?;
        let surface = self.surface_by_id(&r, surface_id)?;
        let same_sense = r.boolean(3, "same_sense")?;
        let mut bounds = Vec::new();
        for id in r.references(1, "face bounds")? {
            let b = self.expect_type(&r, id, &["FACE_OUTER_BOUND", "FACE_BOUND"], 1)?;
            bounds.push(self.deeper(&r, || self.bound(&b))?);
        }
        Ok(Face {
            id: inst.id,
            surface_id,
            surface,
            same_sense,
            bounds,
        })
    }

    fn bound(&self, b: &Rec) -> Result<Bound, ParseError> {
        let orientation = b.boolean(2, "orientation")?;
        let l = self.follow(b, 1, &["EDGE_LOOP", "VERTEX_LOOP"])?;
        let mut edges = Vec::new();
        let mut vertex = None;
        if l.rec.name == "VERTEX_LOOP" {
            vertex = Some(self.vertex(&l, 1)?);
        } else {
            for id in l.references(1, "oriented edges")? {
                let oe = self.expect_type(&l, id, &["ORIENTED_EDGE"], 1)?;
                let orientation = oe.boolean(4, "orientation")?;
                let eid = oe.reference(3, "an EDGE_CURVE")?;
                match self.deeper(&oe, || self.composite_edge(&oe, eid, orientation))? {
                    Some(pieces) => edges.extend(pieces),
                    None => {
                        let edge = self.deeper(&oe, || self.edge(&oe, eid))?;
                        edges.push(OrientedEdge { orientation, edge });
                    }
                }
            }
        }
        Ok(Bound {
            id: b.inst.id,
            outer: b.rec.name == "FACE_OUTER_BOUND",
            orientation,
            edges,
            vertex,
        })
    }

    fn vertex(&self, from: &Rec, i: usize) -> Result<DVec3, ParseError> {
        let v = self.follow(from, i, &["VERTEX_POINT"])?;
        self.point(&v, 1)
    }

    /// An EDGE_CURVE on a COMPOSITE_CURVE(name, segments, self_intersect) as one edge per
    /// segment, in the order the loop runs them (`None` for an edge on any other curve), as
    /// OpenCASCADE's StepToTopoDS_TranslateEdge splits it into a wire. The composite runs
    /// from the edge's start vertex to its end when the edge's same_sense is true; a lone
    /// segment on an unbounded parent (a LINE) runs between the vertices.
    fn composite_edge(
        &self,
        from: &Rec,
        id: u64,
        orientation: bool,
    ) -> Result<Option<Vec<OrientedEdge>>, ParseError> {
        let e = self.expect_type(from, id, &["EDGE_CURVE"], 3)?;
        let curve = self.instance(&e, e.reference(3, "a curve")?)?;
        if curve.records[0].name != "COMPOSITE_CURVE" {
            return Ok(None);
        }
        let c = self.rec(curve);
        let same_sense = e.boolean(4, "same_sense")?;
        let (start, end) = (self.vertex(&e, 1)?, self.vertex(&e, 2)?);
        let ends = if same_sense {
            (start, end)
        } else {
            (end, start)
        };
        let ids = c.references(1, "composite curve segments")?;
        if ids.is_empty() {
            return Err(c.error("expected at least one segment"));
        }
        let lone = (ids.len() == 1).then_some(ends);
        let mut pieces = ids
            .iter()
            .map(|&s| self.segment(&c, s, lone))
            .collect::<Result<Vec<_>, _>>()?;
        if orientation != same_sense {
            pieces.reverse();
            for p in &mut pieces {
                p.orientation = !p.orientation;
            }
        }
        Ok(Some(pieces))
    }

    /// COMPOSITE_CURVE_SEGMENT(transition, same_sense, parent_curve) `id`, referenced from
    /// `from`, as an edge from the parent's start to its end, traversed along it when
    /// `same_sense`. An unbounded parent takes the composite's `ends` (its start and end
    /// points in its own direction) when given.
    pub fn segment(
        &self,
        from: &Rec,
        id: u64,
        ends: Option<(DVec3, DVec3)>,
    ) -> Result<OrientedEdge, ParseError> {
        let s = self.expect_type(
            from,
            id,
            &[
                "COMPOSITE_CURVE_SEGMENT",
                "REPARAMETRISED_COMPOSITE_CURVE_SEGMENT",
            ],
            1,
        )?;
        self.deeper(&s, || {
            let same_sense = s.boolean(1, "same_sense")?;
            let curve = self.curve(&s, 2)?;
            let (t0, t1) = curve.space_curve().domain();
            let (start, end) = match ends {
                _ if t0.is_finite() && t1.is_finite() && t0 < t1 => {
                    (curve.point(t0), curve.point(t1))
                }
                Some((a, b)) if same_sense => (a, b),
                Some((a, b)) => (b, a),
                None => return Err(s.error("expected a bounded parent curve")),
            };
            // A parent that closes on itself (a whole circle, a closed B-spline) is one
            // edge around it, as an edge on a single vertex is (ends equal within
            // rounding, as `Curve::closed_period` takes them).
            let closed = start.distance(end) <= 1e-9 * (1.0 + start.abs().max_element());
            Ok(OrientedEdge {
                orientation: same_sense,
                edge: Arc::new(Edge {
                    id: s.inst.id,
                    start,
                    end,
                    closed,
                    curve,
                    same_sense: true,
                }),
            })
        })
    }

    fn edge(&self, from: &Rec, id: u64) -> Result<Arc<Edge>, ParseError> {
        if let Some(e) = self.edges.borrow().get(&id) {
            return Ok(e.clone());
        }
        let e = self.expect_type(from, id, &["EDGE_CURVE"], 3)?;
        let (start, end) = (self.vertex(&e, 1)?, self.vertex(&e, 2)?);
        let edge = Arc::new(Edge {
            id,
            start,
            end,
            closed: e.reference(1, "a vertex")? == e.reference(2, "a vertex")?,
            curve: line_through_vertices(self.curve(&e, 3)?, start, end),
            same_sense: e.boolean(4, "same_sense")?,
        });
        self.edges.borrow_mut().insert(id, edge.clone());
        Ok(edge)
    }
}
