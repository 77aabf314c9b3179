//! Trimmed surfaces: a constrained Delaunay triangulation of the surface's parameter domain
//! (Chew, "Constrained Delaunay triangulations", Algorithmica 4, 1989; here the `spade`
//! crate, which decides orientation and in-circle tests exactly with Shewchuk's adaptive
//! predicates, so slivers next to the loops cannot make it fail).
//!
//! The points are the patch grid points the trim keeps (the same grids as untrimmed patches)
//! and the samples of every loop piece; consecutive samples of a piece are constraint edges,
//! so no triangle crosses the sampled loops. Which triangles are kept is decided against the
//! sampled loops themselves, the polygon the mesh's boundary is made of: by parity across
//! constraint edges, flooding from the triangulation's hull (the even–odd rule, so outer
//! loops, holes and islands need no orientation or nesting information). Where that polygon
//! is not closed or a constraint could not be added (loops that touch or cross), the exact
//! even–odd test of each triangle's centre against the loops decides
//! ([`TrimRegion::contains`]).
//!
//! Loops are sampled to the tessellation's own accuracy: in adaptive mode until both the
//! loop's image on the surface and the surface along each chord in the parameter plane lie
//! within the tolerance of the chord in space; with a fixed grid, until no loop segment
//! spans more than a grid cell in either parameter. Samples that another face shares are
//! added by [`super::shared`] before the face is triangulated, with the vertex position
//! both faces use.
//!
//! The distance from the surface to the mesh is measured, not assumed: at
//! [`PROBES`] of every triangle the surface is evaluated in `f64` at the interpolated
//! parameters and its distance to the triangle taken. In adaptive mode a triangle whose
//! probe is farther than the tolerance gets that probe as a new point (Delaunay refinement,
//! Ruppert, "A Delaunay refinement algorithm for quality 2-dimensional mesh generation",
//! J. Algorithms 18, 1995, with the chordal error in place of the angle criterion), until
//! every probe off the boundary is within it.

use std::collections::{HashMap, HashSet, VecDeque};

use glam::{DVec2, DVec3, DVec4};
use spade::handles::{DirectedEdgeHandle, FixedFaceHandle, FixedVertexHandle, InnerTag};
use spade::{
    CdtEdge, ConstrainedDelaunayTriangulation, Point2, PositionInTriangulation, Triangulation,
};

use super::edge::{CHORD_PROBES, EdgeCurve, Side, segments_until};
use super::{Budget, MAX_TRIANGLES, Plan, TessellateError};
use crate::geom::BezierPatch;
use crate::geom::bezier::{ParamRect, de_casteljau_point, dehomogenize};
use crate::geom::segment::{distance_to_segment, distance_to_triangle};
use crate::geom::trim::{Coverage, TrimRegion};
use crate::scene::model::{Surface, TriangleMesh};

/// A trimmed surface triangulated in its (NURBS) parameters: `params[k]` is vertex k,
/// triangles run counter-clockwise in (u, v), and `boundary` lists, per loop piece, the
/// vertices its samples became, in order.
#[derive(Clone, Debug, Default)]
pub(super) struct ParamTriangulation {
    pub params: Vec<DVec2>,
    pub triangles: Vec<[u32; 3]>,
    pub boundary: Vec<Vec<u32>>,
    /// The largest distance from the surface to the mesh at the probes.
    pub deviation: f64,
}

/// A trimmed surface's mesh, its boundary polylines in space (one per loop piece), the
/// largest distance from the surface to the mesh at the probes, and the largest distance
/// of a boundary vertex from the face's own surface point (nonzero where the vertex is the
/// point of the neighbouring face it is shared with).
pub(super) struct TrimmedFace {
    pub mesh: TriangleMesh,
    /// Each mesh vertex's parameters in the surface's own domain.
    pub params: Vec<DVec2>,
    pub boundary: Vec<Vec<DVec3>>,
    pub deviation: f64,
    pub offset: f64,
}

/// Barycentric points at which a triangle's distance from the surface is probed: its
/// centroid, the three points halfway from the centroid to a corner, and the edge
/// midpoints and quarter points (the chord heights of [`CHORD_PROBES`]: along an edge
/// over a span whose curvature changes, as a ruled B-spline strip's does, the chord is
/// farthest from the surface off its middle).
const PROBES: [[f64; 3]; 13] = [
    [0.75, 0.25, 0.0],
    [0.25, 0.75, 0.0],
    [0.0, 0.75, 0.25],
    [0.0, 0.25, 0.75],
    [0.25, 0.0, 0.75],
    [0.75, 0.0, 0.25],
    [1.0 / 3.0, 1.0 / 3.0, 1.0 / 3.0],
    [2.0 / 3.0, 1.0 / 6.0, 1.0 / 6.0],
    [1.0 / 6.0, 2.0 / 3.0, 1.0 / 6.0],
    [1.0 / 6.0, 1.0 / 6.0, 2.0 / 3.0],
    [0.5, 0.5, 0.0],
    [0.0, 0.5, 0.5],
    [0.5, 0.0, 0.5],
];

/// The fraction of the tolerance the probes are refined to: the probes sample each
/// triangle, and between them the surface can lie a little farther from it (up to 5 %
/// past the probes on a ruled B-spline strip at a 28-point lattice), so refining to
/// 4/5 of the tolerance keeps the surface within the tolerance, not only the probes.
const PROBED_FRACTION: f64 = 0.8;

/// How near a grid point may come to a boundary edge, as a fraction of its patch's grid
/// cell in each parameter: a quarter cell keeps the triangles between the loops and the
/// grid no thinner than a quarter of the grid's own.
const BOUNDARY_CLEARANCE: f64 = 0.25;

/// Most rounds of refinement; each round adds at most one point per triangle that is too
/// far from the surface, so the count at most doubles per round and the tolerance, once
/// the loops' samples are fine enough, is met in a few.
const MAX_REFINE_ROUNDS: usize = 16;

/// A surface's Bézier patches located by parameter: the sorted span breaks in u and v and,
/// per span cell, the patch over it.
struct Patches {
    list: Vec<(BezierPatch, Coverage)>,
    /// Each patch's grid cell in the surface's parameters.
    cells: Vec<DVec2>,
    u: Vec<f64>,
    v: Vec<f64>,
    cell: HashMap<(usize, usize), usize>,
    domain: ParamRect,
}

impl Patches {
    fn of(surface: &Surface, plan: Plan) -> Option<Patches> {
        let list = surface.trimmed_patches();
        let cells = list
            .iter()
            .map(|(patch, _)| {
                let (gu, gv) = grid(patch, plan);
                let d = patch.domain();
                DVec2::new((d.u1 - d.u0) / gu as f64, (d.v1 - d.v0) / gv as f64)
            })
            .collect();
        let breaks = |f: &dyn Fn(&ParamRect) -> [f64; 2]| {
            let mut b: Vec<f64> = list.iter().flat_map(|(p, _)| f(&p.domain())).collect();
            b.sort_by(f64::total_cmp);
            b.dedup();
            b
        };
        let u = breaks(&|d| [d.u0, d.u1]);
        let v = breaks(&|d| [d.v0, d.v1]);
        if u.len() < 2 || v.len() < 2 {
            return None;
        }
        let (u0, u1, v0, v1) = (u[0], u[u.len() - 1], v[0], v[v.len() - 1]);
        let cell = list
            .iter()
            .enumerate()
            .map(|(k, (p, _))| {
                let d = p.domain();
                ((span(&u, d.u0), span(&v, d.v0)), k)
            })
            .collect();
        Some(Patches {
            list,
            cells,
            u,
            v,
            cell,
            domain: ParamRect { u0, u1, v0, v1 },
        })
    }

    /// The patch over (u, v) (clamped to the domain) and the local parameters there.
    fn at(&self, p: DVec2) -> (&BezierPatch, f64, f64) {
        let patch = &self.list[self.index(p)].0;
        let d = patch.domain();
        let (u, v) = self.clamp(p);
        let local = |t: f64, a: f64, b: f64| ((t - a) / (b - a)).clamp(0.0, 1.0);
        (patch, local(u, d.u0, d.u1), local(v, d.v0, d.v1))
    }

    /// The index of the patch over (u, v), clamped to the domain.
    fn index(&self, p: DVec2) -> usize {
        let (u, v) = self.clamp(p);
        // A NURBS surface's patches tile its grid of non-empty spans, so every cell has
        // one; the first patch stands in should that ever not hold.
        self.cell
            .get(&(span(&self.u, u), span(&self.v, v)))
            .copied()
            .unwrap_or(0)
    }

    fn clamp(&self, p: DVec2) -> (f64, f64) {
        let d = &self.domain;
        (p.x.clamp(d.u0, d.u1), p.y.clamp(d.v0, d.v1))
    }

    fn eval(&self, p: DVec2) -> DVec3 {
        let (patch, s, t) = self.at(p);
        patch.eval(s, t) + DVec3::ZERO
    }
}

/// About how many triangles a patch needs for the surface to lie within `tolerance` of
/// them: the uniform grid for which the error bound of linear interpolation,
/// (h_u² M_uu + 2 h_u h_v M_uv + h_v² M_vv) / 8 over cells h_u × h_v (Ciarlet, "The Finite
/// Element Method for Elliptic Problems", 1978, Theorem 3.1.6), is within it, with the
/// second derivatives bounded by the control net's differences (Farin, "Curves and
/// Surfaces for CAGD", §§5.3 and 16.4: M_uu ≤ p(p−1) max |Δ²_u P|, M_uv ≤ pq max
/// |Δ_u Δ_v P|), from the Euclidean points of a rational net. Refinement stops well short
/// of it on a fair surface; it is for telling, before any work, a face that no budget
/// holds (a control point thrown 10¹⁸ out by a damaged file).
fn refined_triangles(patch: &BezierPatch, tolerance: f64) -> f64 {
    let (p, q) = (patch.degree_u(), patch.degree_v());
    let at = |i: usize, j: usize| patch.point(i, j);
    let (mut uu, mut uv, mut vv) = (0.0f64, 0.0f64, 0.0f64);
    for j in 0..=q {
        for i in 0..=p {
            if i + 2 <= p {
                uu = uu.max((at(i + 2, j) - 2.0 * at(i + 1, j) + at(i, j)).length());
            }
            if j + 2 <= q {
                vv = vv.max((at(i, j + 2) - 2.0 * at(i, j + 1) + at(i, j)).length());
            }
            if i < p && j < q {
                uv = uv.max((at(i + 1, j + 1) - at(i + 1, j) - at(i, j + 1) + at(i, j)).length());
            }
        }
    }
    let (p, q) = (p as f64, q as f64);
    let (m_uu, m_uv, m_vv) = (p * (p - 1.0) * uu, p * q * uv, q * (q - 1.0) * vv);
    // Cells per direction n_u, n_v with each term within a third of the tolerance.
    let n_u = ((m_uu + m_uv) * 3.0 / (8.0 * tolerance))
        .sqrt()
        .ceil()
        .max(1.0);
    let n_v = ((m_vv + m_uv) * 3.0 / (8.0 * tolerance))
        .sqrt()
        .ceil()
        .max(1.0);
    2.0 * n_u * n_v
}

/// The span of sorted breaks `b` (at least two) that holds `t`, the end spans beyond them.
fn span(b: &[f64], t: f64) -> usize {
    b.partition_point(|&x| x <= t).clamp(1, b.len() - 1) - 1
}

/// A patch's grid size under `plan`, as for an untrimmed patch.
fn grid(patch: &BezierPatch, plan: Plan) -> (usize, usize) {
    let curves = Side::ALL.map(|s| EdgeCurve::of(patch, s));
    let (gu, gv, _) = plan.grid(patch, &curves);
    (gu, gv)
}

/// One sample of a loop piece.
#[derive(Clone, Copy, Debug)]
pub(super) struct Sample {
    /// The piece's own parameter, in [0, 1].
    pub t: f64,
    /// The surface's parameters there.
    pub param: DVec2,
    /// The face's surface at `param`.
    pub point: DVec3,
    /// The mesh vertex: `point`, or the point of the face this sample is shared with.
    pub position: DVec3,
}

/// A trimmed surface ready to be triangulated: its patches, its loops (as rational Bézier
/// pieces in trim parameters), the grid points the trim keeps, and per piece its samples in
/// order of the piece's parameter.
pub(super) struct Face {
    patches: Patches,
    region: TrimRegion,
    /// Each piece's homogeneous points `(w u, w v, 0, w)`, for de Casteljau.
    curves: Vec<Vec<DVec4>>,
    /// Per piece, the trim coordinates (u, v) it keeps constant, if any.
    lines: Vec<[Option<f64>; 2]>,
    grid: Vec<DVec2>,
    pub samples: Vec<Vec<Sample>>,
}

impl Face {
    /// The face of `surface` cut by `region`, its loops sampled for `plan`; `Ok(None)` when
    /// the surface has no patches. The triangles the patches the trim keeps any of will
    /// need are estimated before any work (their grids, and in adaptive mode
    /// [`refined_triangles`]): where that passes [`MAX_TRIANGLES`] (a damaged control point
    /// far out, a tolerance far below the face's size), the face is refused with the
    /// estimate (`Err`), before the time and memory are spent.
    pub fn new(surface: &Surface, region: TrimRegion, plan: Plan) -> Result<Option<Face>, f64> {
        let Some(patches) = Patches::of(surface, plan) else {
            return Ok(None);
        };
        let estimate: f64 = patches
            .list
            .iter()
            .filter(|(_, coverage)| *coverage != Coverage::Outside)
            .map(|(patch, _)| {
                let (gu, gv) = grid(patch, plan);
                let refined = match plan {
                    Plan::Adaptive { tolerance } => refined_triangles(patch, tolerance),
                    Plan::Uniform { .. } => 0.0,
                };
                (2.0 * gu as f64 * gv as f64).max(refined)
            })
            .sum();
        // NaN (a control point at infinity) is refused too.
        if estimate.is_nan() || estimate > MAX_TRIANGLES as f64 {
            return Err(estimate);
        }
        let mut grid_points = Vec::new();
        for (patch, coverage) in &patches.list {
            if *coverage == Coverage::Outside {
                continue;
            }
            let (gu, gv) = grid(patch, plan);
            let d = patch.domain();
            for j in 0..=gv {
                for i in 0..=gu {
                    let (s, t) = (i as f64 / gu as f64, j as f64 / gv as f64);
                    let keep = match coverage {
                        Coverage::Partial(trim) => trim.keeps(s, t),
                        _ => true,
                    };
                    if keep {
                        let (u, v) = d.to_parent(s, t);
                        grid_points.push(DVec2::new(u, v));
                    }
                }
            }
        }
        let curves = region
            .pieces()
            .iter()
            .map(|piece| {
                piece
                    .points
                    .iter()
                    .map(|q| DVec4::new(q.x, q.y, 0.0, q.z))
                    .collect()
            })
            .collect();
        let lines = region
            .pieces()
            .iter()
            .map(|piece| {
                let axis = |a: usize| {
                    let x = piece.points[0][a] / piece.points[0].z;
                    piece
                        .points
                        .iter()
                        .all(|q| (q[a] / q.z).to_bits() == x.to_bits())
                        .then_some(x)
                };
                [axis(0), axis(1)]
            })
            .collect();
        let mut face = Face {
            patches,
            region,
            curves,
            lines,
            grid: grid_points,
            samples: Vec::new(),
        };
        face.samples = (0..face.curves.len())
            .map(|k| face.sample_piece(k, plan))
            .collect();
        Ok(Some(face))
    }

    /// The sample of piece `k` at `t`. The ends are the piece's end points themselves, so
    /// pieces that meet share their sample bit for bit.
    pub fn sample(&self, k: usize, t: f64) -> Sample {
        let curve = &self.curves[k];
        let h = if t == 0.0 {
            curve[0]
        } else if t == 1.0 {
            curve[curve.len() - 1]
        } else {
            de_casteljau_point(curve, t)
        };
        // A piece along a parameter line stays exactly on it: de Casteljau's rounding would
        // make its samples zigzag about the line by an ulp, and the triangulation would
        // keep the slivers between them, which the surface's parametrization can make wide
        // in space (a plane's polar parameters at an arc).
        let q = dehomogenize(h).truncate();
        let [lu, lv] = self.lines[k];
        let q = DVec2::new(lu.unwrap_or(q.x), lv.unwrap_or(q.y));
        let maps = self.region.maps();
        let param = DVec2::new(maps[0].invert(q.x), maps[1].invert(q.y));
        let point = self.patches.eval(param);
        Sample {
            t,
            param,
            point,
            position: point,
        }
    }

    fn sample_piece(&self, k: usize, plan: Plan) -> Vec<Sample> {
        let degree = self.curves[k].len() - 1;
        let n = match plan {
            // The boundary edges are constraints that refinement may not split (the
            // neighbouring face shares them), so they are made fine enough here: the curve
            // and the surface across the chord in the parameter plane both stay near the
            // chord in space.
            Plan::Adaptive { tolerance } => segments_until(degree, &|t0, t1| {
                let (a, b) = (self.sample(k, t0), self.sample(k, t1));
                CHORD_PROBES.iter().all(|&f| {
                    let along = self.sample(k, t0 + (t1 - t0) * f).point;
                    let across = self.patches.eval(a.param.lerp(b.param, f));
                    distance_to_segment(along, a.point, b.point) <= tolerance
                        && distance_to_segment(across, a.point, b.point) <= tolerance
                })
            }),
            // No segment longer than the grid cell of the patch where it starts.
            Plan::Uniform { .. } => segments_until(degree, &|t0, t1| {
                let (a, b) = (self.sample(k, t0).param, self.sample(k, t1).param);
                let cell = self.patches.cells[self.patches.index(a)];
                let d = (b - a).abs();
                d.x <= cell.x && d.y <= cell.y
            }),
        };
        (0..=n)
            .map(|i| self.sample(k, i as f64 / n as f64))
            .collect()
    }

    /// Triangulates the face in its parameter domain, refining in adaptive mode until the
    /// surface is within the tolerance of the mesh at every probe off the boundary, with
    /// each point's position in space; more triangles than `budget` allows is an error
    /// naming the face by its number `face`.
    pub fn triangulate(
        &self,
        plan: Plan,
        budget: Budget,
        face: u32,
    ) -> Result<(ParamTriangulation, Vec<DVec3>), TessellateError> {
        // The loops first, as constraints; then the grid points clear of them.
        let mut points = Points::default();
        let boundary: Vec<Vec<u32>> = self
            .samples
            .iter()
            .map(|line| line.iter().map(|s| points.add(s.param)).collect())
            .collect();
        let mut positions = vec![DVec3::ZERO; points.list.len()];
        for (line, samples) in boundary.iter().zip(&self.samples) {
            for (&i, s) in line.iter().zip(samples) {
                positions[i as usize] = s.position;
            }
        }
        let mut cdt = ConstrainedDelaunayTriangulation::<Point2<f64>>::new();
        for p in &points.list {
            insert(&mut cdt, *p)?;
        }
        let mut constraints = HashSet::new();
        let mut all_added = true;
        for line in &boundary {
            for w in line.windows(2).filter(|w| w[0] != w[1]) {
                let (a, b) = (vertex(w[0]), vertex(w[1]));
                if !cdt.exists_constraint(a, b) && cdt.try_add_constraint(a, b).is_empty() {
                    all_added = false;
                }
                constraints.insert((w[0].min(w[1]), w[0].max(w[1])));
            }
        }
        for &q in &self.grid {
            if self.clear_of_boundary(&cdt, q) {
                let before = points.list.len();
                if points.add(q) as usize == before {
                    positions.push(self.patches.eval(q));
                    insert(&mut cdt, q)?;
                }
            }
        }
        let by_parity = all_added && loops_close(&boundary);
        let mut rounds = 0;
        loop {
            let triangles = if by_parity {
                kept_by_parity(&cdt, self.region.outer_is_domain())
            } else {
                kept_by_centre(&cdt, &points.list, &self.region)
            };
            let count = triangles.len() as u64;
            if count > budget.triangles {
                return Err(TessellateError::Budget {
                    object: budget.object.to_string(),
                    patch: face,
                    triangles: count + (MAX_TRIANGLES - budget.triangles),
                    budget: MAX_TRIANGLES,
                });
            }
            let mut deviation = 0.0f64;
            let mut refine = Vec::new();
            for t in &triangles {
                let (d, worst) = self.probe(t, &points.list, &positions, &constraints);
                deviation = deviation.max(d);
                if let (Plan::Adaptive { tolerance }, Some((far, q))) = (plan, worst)
                    && far > tolerance * PROBED_FRACTION
                {
                    let centroid = t.map(|i| points.list[i as usize]).iter().sum::<DVec2>() / 3.0;
                    refine.push((q, centroid));
                }
            }
            if refine.is_empty() || rounds == MAX_REFINE_ROUNDS {
                return Ok((
                    ParamTriangulation {
                        params: points.list,
                        triangles,
                        boundary,
                        deviation,
                    },
                    positions,
                ));
            }
            for (q, centroid) in refine {
                // A probe that is a point already (the midpoint of an edge that rounding
                // kept beside the point made there) would stall the refinement: the
                // triangle's centroid is taken instead.
                for p in [q, centroid] {
                    let before = points.list.len();
                    if points.add(p) as usize == before {
                        positions.push(self.patches.eval(p));
                        insert(&mut cdt, p)?;
                        break;
                    }
                }
            }
            rounds += 1;
        }
    }

    /// Whether grid point `q` is clear of the loops: not on a boundary edge (which would
    /// split it, and the neighbouring face would not have the split) and not within
    /// [`BOUNDARY_CLEARANCE`] of its patch's grid cell of one (which would make a sliver).
    /// The edges looked at are those of the triangle (or two) the point falls in, which
    /// are the nearest ones for a point that near.
    fn clear_of_boundary(&self, cdt: &Cdt, q: DVec2) -> bool {
        let cell = self.patches.cells[self.patches.index(q)];
        let scale = |p: Point2<f64>| DVec3::new(p.x / cell.x, p.y / cell.y, 0.0);
        let at = DVec3::new(q.x / cell.x, q.y / cell.y, 0.0);
        let near = |e: DirectedEdgeHandle<Point2<f64>, (), CdtEdge<()>, ()>| {
            let [a, b] = e.positions();
            e.is_constraint_edge()
                && distance_to_segment(at, scale(a), scale(b)) < BOUNDARY_CLEARANCE
        };
        let face_clear = |f: FixedFaceHandle<InnerTag>| {
            cdt.face(f).adjacent_edges().into_iter().all(|e| !near(e))
        };
        match cdt.locate(Point2::new(q.x, q.y)) {
            PositionInTriangulation::OnVertex(_) => false,
            PositionInTriangulation::OnEdge(e) => {
                let e = cdt.directed_edge(e);
                !e.is_constraint_edge()
                    && [e.face(), e.rev().face()]
                        .into_iter()
                        .filter_map(|f| f.as_inner())
                        .all(|f| face_clear(f.fix()))
            }
            PositionInTriangulation::OnFace(f) => face_clear(f),
            PositionInTriangulation::OutsideOfConvexHull(_)
            | PositionInTriangulation::NoTriangulation => true,
        }
    }

    /// The largest distance from the surface to triangle `t` at the probes, and the
    /// farthest probe that may become a point (not on a boundary edge) with its distance.
    fn probe(
        &self,
        t: &[u32; 3],
        params: &[DVec2],
        positions: &[DVec3],
        constraints: &HashSet<(u32, u32)>,
    ) -> (f64, Option<(f64, DVec2)>) {
        let [a, b, c] = t.map(|i| params[i as usize]);
        let [pa, pb, pc] = t.map(|i| positions[i as usize]);
        let mut largest = 0.0f64;
        let mut worst: Option<(f64, DVec2)> = None;
        for w in PROBES {
            let q = a * w[0] + b * w[1] + c * w[2];
            let d = distance_to_triangle(self.patches.eval(q), pa, pb, pc);
            largest = largest.max(d);
            // An edge probe lies on the edge between the two corners it weighs.
            let on_boundary = match w.iter().position(|&x| x == 0.0) {
                Some(k) => {
                    let (i, j) = (t[(k + 1) % 3], t[(k + 2) % 3]);
                    constraints.contains(&(i.min(j), i.max(j)))
                }
                None => false,
            };
            if !on_boundary && worst.is_none_or(|(far, _)| d > far) {
                worst = Some((d, q));
            }
        }
        (largest, worst)
    }

    /// The face's mesh (boundary vertices at their samples' shared positions, the rest on
    /// the exact surface, every normal the face's own) and its boundary in space.
    pub fn tessellate(
        &self,
        plan: Plan,
        budget: Budget,
        face: u32,
    ) -> Result<TrimmedFace, TessellateError> {
        let (tri, positions) = self.triangulate(plan, budget, face)?;
        let mut mesh = TriangleMesh::default();
        let mut params = Vec::new();
        let mut index = vec![u32::MAX; tri.params.len()];
        for t in &tri.triangles {
            // Two corners at one position (samples of one face joined to one point of its
            // neighbour) make no triangle.
            let [a, b, c] = t.map(|i| positions[i as usize]);
            if a == b || b == c || c == a {
                continue;
            }
            let mut out = [0u32; 3];
            for (k, &i) in t.iter().enumerate() {
                let slot = &mut index[i as usize];
                if *slot == u32::MAX {
                    let (patch, s, w) = self.patches.at(tri.params[i as usize]);
                    *slot = mesh.positions.len() as u32;
                    mesh.positions.push(positions[i as usize]);
                    mesh.normals.push(patch.normal(s, w));
                    params.push(tri.params[i as usize]);
                }
                out[k] = *slot;
            }
            mesh.indices.push(out);
        }
        let boundary = tri
            .boundary
            .iter()
            .map(|line| line.iter().map(|&i| positions[i as usize]).collect())
            .collect();
        let offset = self
            .samples
            .iter()
            .flatten()
            .map(|s| (s.position - s.point).length())
            .fold(0.0, f64::max);
        Ok(TrimmedFace {
            mesh,
            params,
            boundary,
            deviation: tri.deviation,
            offset,
        })
    }
}

/// The points of a triangulation, each made once (by its exact bits).
#[derive(Default)]
struct Points {
    list: Vec<DVec2>,
    index: HashMap<[u64; 2], u32>,
}

impl Points {
    fn add(&mut self, p: DVec2) -> u32 {
        // spade refuses coordinates below 2^-142 in magnitude (its exact predicates would
        // underflow); such a parameter is zero for any purpose here.
        let p = DVec2::from(p.to_array().map(|x| {
            if x.abs() < spade::MIN_ALLOWED_VALUE {
                0.0
            } else {
                x
            }
        }));
        let next = self.list.len() as u32;
        *self
            .index
            .entry(p.to_array().map(f64::to_bits))
            .or_insert_with(|| {
                self.list.push(p);
                next
            })
    }
}

type Cdt = ConstrainedDelaunayTriangulation<Point2<f64>>;

/// Inserts a point; points are distinct, so spade's handles are the points' indices in
/// insertion order.
fn insert(cdt: &mut Cdt, p: DVec2) -> Result<(), TessellateError> {
    cdt.insert(Point2::new(p.x, p.y))
        .map(|_| ())
        .map_err(|e| TessellateError::Parameter(e.to_string()))
}

fn vertex(i: u32) -> FixedVertexHandle {
    FixedVertexHandle::from_index(i as usize)
}

/// Whether every piece's last sample is some piece's first (each loop's pieces follow one
/// another end to start), so the constraint edges make closed polygons.
fn loops_close(boundary: &[Vec<u32>]) -> bool {
    let mut starts: Vec<u32> = boundary.iter().filter_map(|l| l.first().copied()).collect();
    let mut ends: Vec<u32> = boundary.iter().filter_map(|l| l.last().copied()).collect();
    starts.sort_unstable();
    ends.sort_unstable();
    starts == ends
}

/// The triangles inside the constraint polygons by the even–odd rule: parity flips across
/// every constraint edge, starting outside at the hull (inverted when the domain's
/// boundary is the outer loop).
fn kept_by_parity(cdt: &Cdt, outer_is_domain: bool) -> Vec<[u32; 3]> {
    let mut parity: Vec<Option<bool>> = vec![None; cdt.num_all_faces()];
    let mut queue = VecDeque::new();
    for face in cdt.inner_faces() {
        if let Some(e) = face
            .adjacent_edges()
            .into_iter()
            .find(|e| e.rev().face().is_outer())
        {
            parity[face.fix().index()] = Some(e.is_constraint_edge());
            queue.push_back(face.fix());
        }
    }
    while let Some(f) = queue.pop_front() {
        let inside = parity[f.index()].unwrap_or(false);
        for e in cdt.face(f).adjacent_edges() {
            if let Some(next) = e.rev().face().as_inner() {
                let slot = &mut parity[next.fix().index()];
                if slot.is_none() {
                    *slot = Some(inside != e.is_constraint_edge());
                    queue.push_back(next.fix());
                }
            }
        }
    }
    cdt.inner_faces()
        .filter(|f| parity[f.fix().index()].unwrap_or(false) != outer_is_domain)
        .map(|f| f.vertices().map(|v| v.fix().index() as u32))
        .collect()
}

/// The triangles whose centres `region` keeps.
fn kept_by_centre(cdt: &Cdt, points: &[DVec2], region: &TrimRegion) -> Vec<[u32; 3]> {
    cdt.inner_faces()
        .filter_map(|face| {
            let tri = face.vertices().map(|v| v.fix().index() as u32);
            let c = tri.iter().map(|&i| points[i as usize]).sum::<DVec2>() / 3.0;
            region.contains(c.x, c.y).then_some(tri)
        })
        .collect()
}

#[cfg(test)]
mod tests;
