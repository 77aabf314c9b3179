//! Catmull–Clark surfaces tessellated by uniform sampling of their limit surface, per quad
//! after the first step, not per Bézier patch: near an
//! extraordinary vertex a quad is covered by up to 3 · levels + 1 patches of the load-time
//! refinement ([`crate::geom::subdiv::adaptive`]), and a grid per patch would spend the
//! requested rate on each of them (the OpenSubdiv cube at 16 × 16 per patch: 1320 patches,
//! 193 MB of OBJ; per quad, 24 quads).
//!
//! A quad's grid point at `(u, v)` is the limit surface there: the point of the smallest
//! refined patch whose piece of the quad contains `(u, v)` ([`crate::geom::subdiv::Piece`]),
//! exact for regular patches (a bicubic B-spline patch is its Bézier patch); the corner at
//! an extraordinary vertex is the final child's corner, which the refinement made the
//! vertex's exact limit position. Crack freedom: the vertices of a quad's corners and
//! sides are made once, by the first quad that needs them, and reused by index by every
//! other quad at that vertex or edge of the mesh after the first step.

use std::collections::HashMap;

use glam::DVec3;

use super::{Budget, MAX_TRIANGLES, Plan, TessellateError, edge::segments_for_tolerance};
use crate::geom::subdiv::SubdivisionSurface;
use crate::geom::subdiv::refine::refine;
use crate::geom::subdiv::topology::{Topology, edge_key};
use crate::scene::model::TriangleMesh;

/// Slack, in quad parameter units, for deciding that a grid point lies in a piece: the
/// pieces' corners are dyadic and exact, the grid points `i / n` round once, so a point on
/// a piece's edge may fall outside it by an ulp of 1.
const PIECE_SLACK: f64 = 4.0 * f64::EPSILON;

/// The quads after the first step, per quad the indices of the patches covering it, and
/// per edge the quads and sides using it.
struct Quads<'a> {
    surface: &'a SubdivisionSurface,
    corners: Vec<[u32; 4]>,
    patches: Vec<Vec<usize>>,
    sides: HashMap<(u32, u32), Vec<(usize, usize)>>,
}

impl<'a> Quads<'a> {
    fn new(surface: &'a SubdivisionSurface) -> Quads<'a> {
        let cage = &surface.cage;
        let all: Vec<u32> = (0..cage.faces.len() as u32).collect();
        let first = refine(cage, &Topology::new(cage), &all).mesh;
        let corners: Vec<[u32; 4]> = first
            .faces
            .iter()
            .map(|f| [f[0], f[1], f[2], f[3]])
            .collect();
        let mut sides: HashMap<(u32, u32), Vec<(usize, usize)>> = HashMap::new();
        for (q, c) in corners.iter().enumerate() {
            for k in 0..4 {
                sides
                    .entry(edge_key(c[k], c[(k + 1) % 4]))
                    .or_default()
                    .push((q, k));
            }
        }
        let mut patches = vec![Vec::new(); corners.len()];
        for (i, piece) in surface.pieces.iter().enumerate() {
            if let Some(list) = patches.get_mut(piece.face as usize) {
                list.push(i);
            }
        }
        // Smallest pieces first: a point on the border of a refined child and a coarser
        // patch is taken from the child, whose net is nearer the limit surface (the
        // coarser patch's edge is pushed over T-junctions).
        for list in &mut patches {
            list.sort_by(|&a, &b| surface.pieces[a].size.total_cmp(&surface.pieces[b].size));
        }
        Quads {
            surface,
            corners,
            patches,
            sides,
        }
    }

    /// The point at `t` from `a` along the edge `(a, b)` of the mesh after the first step,
    /// taken from the quad whose covering patch there is smallest: where a patch meets two
    /// refined halves across quads, its edge is pushed over them (a T-junction) and lies
    /// a few `f32` ulps off the limit surface, the halves' do not.
    fn edge_point(&self, a: u32, b: u32, t: f64) -> (DVec3, DVec3) {
        let mut best: Option<(f64, (DVec3, DVec3))> = None;
        // A hole's quads have no patches (the quad asking has).
        for &(q, k) in &self.sides[&edge_key(a, b)] {
            if self.patches[q].is_empty() {
                continue;
            }
            let from_a = self.corners[q][k] == a;
            let (u, v) = side_param(k, if from_a { t } else { 1.0 - t });
            let (size, point) = self.eval_sized(q, u, v);
            if best.is_none_or(|(s, _)| size < s) {
                best = Some((size, point));
            }
        }
        best.expect("the edge's quad that asks has patches").1
    }

    /// The limit surface's point and unit normal at `(u, v)` of quad `q`.
    fn eval(&self, q: usize, u: f64, v: f64) -> (DVec3, DVec3) {
        self.eval_sized(q, u, v).1
    }

    /// [`Quads::eval`] and the size of the patch's piece it came from.
    fn eval_sized(&self, q: usize, u: f64, v: f64) -> (f64, (DVec3, DVec3)) {
        let s = self.surface;
        let in_piece = |i: usize| {
            let piece = &s.pieces[i];
            let local = piece.from_face(u, v);
            let inside = |x: f64| (-PIECE_SLACK..=1.0 + PIECE_SLACK).contains(&x);
            (inside(local.0) && inside(local.1)).then_some((i, local))
        };
        // Every point of a quad lies in one of its pieces; the first piece serves
        // (clamped) were rounding to leave a point in none.
        let (i, (pu, pv)) = self.patches[q]
            .iter()
            .find_map(|&i| in_piece(i))
            .unwrap_or_else(|| {
                (
                    self.patches[q][0],
                    s.pieces[self.patches[q][0]].from_face(u, v),
                )
            });
        let (pu, pv) = (pu.clamp(0.0, 1.0), pv.clamp(0.0, 1.0));
        let patch = &s.patches[i];
        (s.pieces[i].size, (patch.eval(pu, pv), patch.normal(pu, pv)))
    }

    /// Segments per quad side for `plan`: the uniform grid's larger count (a cage's quads
    /// meet turned, so their u and v counts must agree), or the finest count any quad's
    /// sides and mid-parameter curves need for the tolerance.
    fn segments(&self, plan: Plan) -> usize {
        match plan {
            Plan::Uniform { grid_u, grid_v } => grid_u.max(grid_v),
            Plan::Adaptive { tolerance } => (0..self.corners.len())
                .filter(|&q| !self.patches[q].is_empty())
                .flat_map(|q| {
                    let curves: [&dyn Fn(f64) -> (f64, f64); 6] = [
                        &|t| (t, 0.0),
                        &|t| (1.0, t),
                        &|t| (t, 1.0),
                        &|t| (0.0, t),
                        &|t| (t, 0.5),
                        &|t| (0.5, t),
                    ];
                    curves.map(|c| {
                        segments_for_tolerance(
                            &|t| {
                                let (u, v) = c(t);
                                self.eval(q, u, v).0
                            },
                            3,
                            tolerance,
                        )
                    })
                })
                .max()
                .unwrap_or(1),
        }
    }
}

/// The quad-local `(u, v)` of side `k` (from corner k to corner k + 1) at `t`.
fn side_param(k: usize, t: f64) -> (f64, f64) {
    match k {
        0 => (t, 0.0),
        1 => (1.0, t),
        2 => (1.0 - t, 1.0),
        _ => (0.0, 1.0 - t),
    }
}

/// Mesh being made, with the vertices shared between quads.
#[derive(Default)]
struct Builder {
    mesh: TriangleMesh,
    /// Vertex of the mesh after the first step → its output vertex.
    corners: HashMap<u32, u32>,
    /// Edge `(a, b)`, `a < b`, of the mesh after the first step → its inner vertices from
    /// `a` to `b`.
    sides: HashMap<(u32, u32), Vec<u32>>,
}

impl Builder {
    fn push(&mut self, (p, n): (DVec3, DVec3)) -> Result<u32, TessellateError> {
        let i = u32::try_from(self.mesh.positions.len())
            .ok()
            .filter(|&i| i != u32::MAX)
            .ok_or(TessellateError::TooManyVertices)?;
        self.mesh.positions.push(p);
        self.mesh.normals.push(n);
        Ok(i)
    }

    /// The `(n + 1)²` vertex indices of quad `q`'s grid, `[j][i]` at `(i / n, j / n)`.
    fn grid(&mut self, quads: &Quads, q: usize, n: usize) -> Result<Vec<u32>, TessellateError> {
        let at = |i: usize, j: usize| j * (n + 1) + i;
        let mut grid = vec![0u32; (n + 1) * (n + 1)];
        let c = quads.corners[q];
        let corner_ij = [(0, 0), (n, 0), (n, n), (0, n)];
        for k in 0..4 {
            let index = match self.corners.get(&c[k]) {
                Some(&i) => i,
                None => {
                    let (u, v) = side_param(k, 0.0);
                    let i = self.push(quads.eval(q, u, v))?;
                    self.corners.insert(c[k], i);
                    i
                }
            };
            grid[at(corner_ij[k].0, corner_ij[k].1)] = index;
        }
        for k in 0..4 {
            let (a, b) = (c[k], c[(k + 1) % 4]);
            let key = edge_key(a, b);
            let inner = match self.sides.get(&key) {
                Some(v) => v.clone(),
                None => {
                    let mut v = Vec::with_capacity(n.saturating_sub(1));
                    for s in 1..n {
                        let t = s as f64 / n as f64;
                        v.push(self.push(quads.edge_point(key.0, key.1, t))?);
                    }
                    self.sides.insert(key, v.clone());
                    v
                }
            };
            for s in 1..n {
                // Inner vertex s from corner k (key order reversed when a is not first).
                let from_a = if a == key.0 {
                    inner[s - 1]
                } else {
                    inner[n - 1 - s]
                };
                let (i, j) = match k {
                    0 => (s, 0),
                    1 => (n, s),
                    2 => (n - s, n),
                    _ => (0, n - s),
                };
                grid[at(i, j)] = from_a;
            }
        }
        for j in 1..n {
            for i in 1..n {
                grid[at(i, j)] =
                    self.push(quads.eval(q, i as f64 / n as f64, j as f64 / n as f64))?;
            }
        }
        Ok(grid)
    }
}

/// The limit surface of `surface` as triangles, `n × n` quads of two triangles per quad
/// after the first step (`n` from `plan`, see [`Quads::segments`]), counter-clockwise in
/// `(u, v)` so that their normals face as the patches' do; `quad_done()` after each.
pub(super) fn tessellate_surface(
    surface: &SubdivisionSurface,
    plan: Plan,
    budget: Budget,
    quad_done: &mut dyn FnMut(),
) -> Result<TriangleMesh, TessellateError> {
    let quads = Quads::new(surface);
    let n = quads.segments(plan).max(1);
    let triangles = 2 * (n as u64).pow(2) * quads.corners.len() as u64;
    if triangles > budget.triangles {
        // Named by the quad (after the first step) at which the budget runs out.
        return Err(TessellateError::Budget {
            object: budget.object.to_string(),
            patch: u32::try_from(budget.triangles / (2 * (n as u64).pow(2))).unwrap_or(u32::MAX),
            triangles: triangles + (MAX_TRIANGLES - budget.triangles),
            budget: MAX_TRIANGLES,
        });
    }
    let mut b = Builder::default();
    let at = |i: usize, j: usize| j * (n + 1) + i;
    for q in 0..quads.corners.len() {
        if quads.patches[q].is_empty() {
            continue;
        }
        let g = b.grid(&quads, q, n)?;
        for j in 0..n {
            for i in 0..n {
                let (p00, p10, p11, p01) = (
                    g[at(i, j)],
                    g[at(i + 1, j)],
                    g[at(i + 1, j + 1)],
                    g[at(i, j + 1)],
                );
                b.mesh.indices.push([p00, p10, p11]);
                b.mesh.indices.push([p00, p11, p01]);
            }
        }
        quad_done();
    }
    Ok(b.mesh)
}
