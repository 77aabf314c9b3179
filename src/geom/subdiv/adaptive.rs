//! Feature-adaptive refinement: from the quads after the first Catmull–Clark step, every
//! face whose corners are all regular is one bicubic B-spline patch, written as its exact
//! Bézier patch; a face with an extraordinary vertex is split by one more step into three
//! regular children and one child that keeps the extraordinary vertex (Dammertz §2.9.1,
//! Fig. 2.31), level after level, until that child's convex hull (the points of its
//! 1-ring, which contain its limit patch) is as small as the kernel's end game
//! ([`DEFAULT_END_ULPS`] ulps of its coordinates) or [`MAX_LEVELS`] is reached.
//!
//! This expands Dammertz's in-place subdivision of the irregular patch once, at load time:
//! the regular children go to the bicubic kernel as Bézier patches, and the last child,
//! smaller than the kernel's final box, is a stand-in patch inside that box (its net's
//! Bézier form, with its edges at the extraordinary vertex made from the limit positions
//! and the limit tangent plane, so normals there are the limit normal).
//!
//! Cracks. Neighbours at the same level share their edge's Bézier points bit for bit
//! ([`super::stencil`]), and every patch corner is the vertex's limit position computed
//! once. Where a refined face meets a regular face of its own level, two half-edges meet
//! one whole edge (a T-junction). There the kernel's halving of the whole edge (in the
//! ray's frame, rounded in `f32`) and the halves' own nets differ by rounding, which could
//! leave a gap of an ulp; so the whole edge's two inner Bézier points are moved
//! [`T_JUNCTION_OVERLAP_ULPS`] ulps outwards in the surface's tangent direction across
//! the edge, and the regular patch overlaps the children by that much instead. The moved
//! edge stays in the tangent plane, so the surface it adds lies within rounding of the
//! limit surface.

use std::collections::{HashMap, HashSet};

use glam::DVec3;

use super::limit;
use super::net::gather;
use super::refine::refine;
use super::stencil::bezier_stencils;
use super::topology::{Mesh, Topology};
use super::{Piece, Stats};
use crate::geom::BezierPatch;
use crate::geom::ulp::DEFAULT_END_ULPS;
use crate::geom::ulp::ulp_of;

/// The deepest level: the extraordinary child then spans 2^-48 of its face, and its hull
/// at most `λ^47` of the face's ring, λ ≤ 0.66 the subdominant eigenvalue of
/// Catmull–Clark (Stam 1998), i.e. below 2^-28 of the ring: under an `f32` ulp.
pub const MAX_LEVELS: u32 = 48;

/// How far (in ulps of the edge's coordinates) a whole edge at a T-junction is pushed over
/// the two half edges it meets: more than the few ulps by which the kernel's halving of
/// the whole edge in `f32` and the halves' own nets can differ (each side rounds a handful
/// of times, [`DEFAULT_END_ULPS`] is the end game's allowance for the same thing).
pub const T_JUNCTION_OVERLAP_ULPS: f64 = 16.0;

/// Bézier points `[a][b]` (a along u).
type Net = [[DVec3; 4]; 4];

/// Edge k's Bézier points from corner k to corner k + 1.
fn edge_index(k: usize, t: usize) -> (usize, usize) {
    match k {
        0 => (t, 0),
        1 => (3, t),
        2 => (3 - t, 3),
        _ => (0, 3 - t),
    }
}

/// The row next to edge k, in the same order.
fn inner_index(k: usize, t: usize) -> (usize, usize) {
    match k {
        0 => (t, 1),
        1 => (2, t),
        2 => (3 - t, 2),
        _ => (1, 3 - t),
    }
}

fn to_patch(net: &Net) -> BezierPatch {
    let points: Vec<DVec3> = (0..16).map(|k| net[k % 4][k / 4]).collect();
    BezierPatch::from_points(3, 3, &points).expect("16 finite points make a bicubic patch")
}

/// One refinement level: the mesh, which faces are patches to make here (with where they
/// lie in their face after the first step), and what earlier levels fixed.
struct Level {
    mesh: Mesh,
    depth: u32,
    pieces: Vec<Option<Piece>>,
    /// Limit positions, computed once per vertex and inherited by its vertex points.
    limits: Vec<Option<DVec3>>,
}

struct Output {
    patches: Vec<BezierPatch>,
    pieces: Vec<Piece>,
    stats: Stats,
}

impl Output {
    fn push(&mut self, net: &Net, piece: Piece) -> usize {
        self.patches.push(to_patch(net));
        self.pieces.push(piece);
        self.patches.len() - 1
    }
}

/// All patches of the cage's limit surface but those of the faces `holes` (ascending),
/// and where each lies. A hole's quads are never targets, so nothing is emitted or
/// refined for them; they stay in every level's mesh, where they shape their neighbours.
pub fn build(cage: &Mesh, holes: &[u32]) -> (Vec<BezierPatch>, Vec<Piece>, Stats) {
    let topo = Topology::new(cage);
    let all: Vec<u32> = (0..cage.faces.len() as u32).collect();
    let first = refine(cage, &topo, &all);
    let count = first.mesh.faces.len();
    let points = first.mesh.points.len();
    let mut pieces: Vec<Option<Piece>> = (0..count as u32).map(|f| Some(Piece::whole(f))).collect();
    for &f in holes {
        let start = first.first_child[f as usize] as usize;
        pieces[start..start + cage.faces[f as usize].len()].fill(None);
    }
    let mut level = Level {
        mesh: first.mesh,
        depth: 1,
        pieces,
        limits: vec![None; points],
    };
    let mut out = Output {
        patches: Vec::new(),
        pieces: Vec::new(),
        stats: Stats {
            cage_faces: cage.faces.len(),
            holes: holes.len(),
            faces: count,
            ..Stats::default()
        },
    };
    loop {
        // One topology per level, shared by both passes over it.
        let topo = Topology::new(&level.mesh);
        let refined = level_patches(&mut level, &topo, &mut out);
        if refined.is_empty() {
            break;
        }
        level = next_level(level, &topo, &refined);
    }
    (out.patches, out.pieces, out.stats)
}

fn is_regular(mesh: &Mesh, topo: &Topology, v: u32) -> bool {
    let faces = topo.corners[v as usize].len();
    let quads = topo.corners[v as usize]
        .iter()
        .all(|&(f, _)| mesh.faces[f as usize].len() == 4);
    quads && faces == if topo.on_boundary[v as usize] { 2 } else { 4 }
}

fn limit_of(level: &mut Level, topo: &Topology, v: u32) -> DVec3 {
    *level.limits[v as usize].get_or_insert_with(|| limit::position(&level.mesh, topo, v))
}

/// Emits this level's regular patches and final extraordinary children; returns the
/// faces to refine.
fn level_patches(level: &mut Level, topo: &Topology, out: &mut Output) -> Vec<u32> {
    let targets: Vec<u32> = (0..level.pieces.len() as u32)
        .filter(|&f| level.pieces[f as usize].is_some())
        .collect();
    let mut irregular = Vec::new();
    let mut emitted: HashMap<u32, usize> = HashMap::new();
    for &f in &targets {
        let face = level.mesh.faces[f as usize].clone();
        if face.iter().all(|&v| is_regular(&level.mesh, topo, v)) {
            let net = regular_net(level, topo, f);
            let index = out.push(&net, level.pieces[f as usize].expect("target"));
            emitted.insert(f, index);
            out.stats.regular += 1;
        } else {
            irregular.push(f);
        }
    }
    // Below level 2 a face may hold two extraordinary vertices; from level 2 on it holds
    // one, at corner 0 (it is the child at that vertex). All faces around one vertex stop
    // together, so their shared edges are made the same way.
    let mut groups: HashMap<u32, Vec<u32>> = HashMap::new();
    let mut refine_now = Vec::new();
    for &f in &irregular {
        let face = &level.mesh.faces[f as usize];
        let single = face[1..].iter().all(|&v| is_regular(&level.mesh, topo, v));
        if level.depth >= 2 && single {
            groups.entry(face[0]).or_default().push(f);
        } else if level.depth >= MAX_LEVELS {
            // Unreachable for a manifold cage (two extraordinary vertices never share a
            // face below level 2); ends the refinement whatever the input.
            let net = regular_net(level, topo, f);
            out.push(&net, level.pieces[f as usize].expect("target"));
            out.stats.extraordinary_ends += 1;
        } else {
            refine_now.push(f);
        }
    }
    let mut group_keys: Vec<u32> = groups.keys().copied().collect();
    group_keys.sort_unstable();
    for ev in group_keys {
        let faces = &groups[&ev];
        if level.depth >= MAX_LEVELS || hull_is_final(&level.mesh, topo, faces) {
            for &f in faces {
                let net = final_net(level, topo, f);
                out.push(&net, level.pieces[f as usize].expect("target"));
                out.stats.extraordinary_ends += 1;
            }
            out.stats.levels = out.stats.levels.max(level.depth);
        } else {
            refine_now.extend(faces);
        }
    }
    refine_now.sort_unstable();
    // T-junctions: a refined face next to a regular patch of this level.
    for &f in &refine_now {
        let face = &level.mesh.faces[f as usize];
        for k in 0..4 {
            let Some((g, m)) = topo.across(&level.mesh, face, k) else {
                continue;
            };
            if let Some(&patch) = emitted.get(&g) {
                overlap_edge(&mut out.patches[patch], m);
                out.stats.t_junctions += 1;
            }
        }
    }
    refine_now
}

/// Whether the hull of the faces' 1-rings is within the kernel's end game in `f32`.
fn hull_is_final(mesh: &Mesh, topo: &Topology, faces: &[u32]) -> bool {
    let mut lo = DVec3::splat(f64::INFINITY);
    let mut hi = DVec3::splat(f64::NEG_INFINITY);
    for &f in faces {
        for &v in &mesh.faces[f as usize] {
            for &(g, _) in &topo.corners[v as usize] {
                for &w in &mesh.faces[g as usize] {
                    let p = mesh.points[w as usize];
                    lo = lo.min(p);
                    hi = hi.max(p);
                }
            }
        }
    }
    // Ulps of the largest coordinate, as the kernel's end game measures a box: a hull at
    // x = 0 is as precise as its largest coordinate allows, not as 0's ulp.
    let scale = lo.abs().max(hi.abs()).max_element() as f32;
    let allowance = DEFAULT_END_ULPS as f64 * ulp_of(scale);
    (0..3).all(|a| f64::from(hi[a] as f32) - f64::from(lo[a] as f32) <= allowance)
}

/// The Bézier net of a regular face from its B-spline net, with the limit positions at
/// its corners and any edges fixed by T-junctions.
fn regular_net(level: &mut Level, topo: &Topology, f: u32) -> Net {
    let grid = gather(&level.mesh, topo, f);
    let stencils = bezier_stencils(&grid);
    let mut net: Net = std::array::from_fn(|a| {
        std::array::from_fn(|b| stencils[a][b].eval(&level.mesh.points, 36.0))
    });
    let face = level.mesh.faces[f as usize].clone();
    for (k, &v) in face.iter().enumerate() {
        let (a, b) = edge_index(k, 0);
        net[a][b] = limit_of(level, topo, v);
    }
    net
}

/// The last child at an extraordinary vertex (corner 0): the Bézier form of its net as if
/// it were regular, inside its hull, which is below the kernel's final box. Its two edges
/// at the vertex are made from the limit positions at their ends only (the same on both
/// faces that share them), their first inner point in the limit tangent plane, so the
/// normal at the vertex is the limit normal.
fn final_net(level: &mut Level, topo: &Topology, f: u32) -> Net {
    let mut net = regular_net(level, topo, f);
    let face = level.mesh.faces[f as usize].clone();
    let ev = face[0];
    let e = limit_of(level, topo, ev);
    let tangent_normal = limit::normal(&level.mesh, topo, ev, f, 0).and_then(|n| n.try_normalize());
    let flatten = |d: DVec3| match tangent_normal {
        Some(n) => d - n * n.dot(d),
        None => d,
    };
    for (k, far) in [(0usize, face[1]), (3, face[3])] {
        let x = limit_of(level, topo, far);
        // Points along the edge from the vertex: e, near(e), near(x), x.
        let near_e = e + flatten((x - e) / 3.0);
        let near_x = x + (e - x) / 3.0;
        let row = [e, near_e, near_x, x];
        for t in 0..4 {
            let (a, b) = edge_index(k, if k == 0 { t } else { 3 - t });
            net[a][b] = row[t];
        }
    }
    net[1][1] = net[1][0] + net[0][1] - net[0][0];
    net
}

/// Pushes edge `m`'s two inner Bézier points [`T_JUNCTION_OVERLAP_ULPS`] ulps outwards,
/// along the net's direction across the edge (from the next row to the edge), which lies
/// in the tangent plane at the edge.
fn overlap_edge(patch: &mut BezierPatch, m: usize) {
    let mut net: Net = std::array::from_fn(|a| std::array::from_fn(|b| patch.point(a, b)));
    for t in 1..3 {
        let (a, b) = edge_index(m, t);
        let (ia, ib) = inner_index(m, t);
        let p = net[a][b];
        let Some(out) = (p - net[ia][ib]).try_normalize() else {
            continue;
        };
        let scale = p.abs().max_element() as f32;
        net[a][b] = p + out * (T_JUNCTION_OVERLAP_ULPS * ulp_of(scale));
    }
    *patch = to_patch(&net);
}

/// Refines `faces` of `level` by one step: the next level's targets are their children,
/// with the limit positions carried over.
fn next_level(level: Level, topo: &Topology, faces: &[u32]) -> Level {
    // Two rings of faces around what is refined: enough for every child's 1-ring to get
    // its exact new points (see `refine`).
    let mut selected: HashSet<u32> = faces.iter().copied().collect();
    for _ in 0..2 {
        let ring: Vec<u32> = selected
            .iter()
            .flat_map(|&f| level.mesh.faces[f as usize].iter())
            .flat_map(|&v| topo.corners[v as usize].iter().map(|&(g, _)| g))
            .collect();
        selected.extend(ring);
    }
    let mut selected: Vec<u32> = selected.into_iter().collect();
    selected.sort_unstable();
    let r = refine(&level.mesh, topo, &selected);
    let position: HashMap<u32, usize> = selected.iter().enumerate().map(|(i, &f)| (f, i)).collect();
    let mut pieces = vec![None; r.mesh.faces.len()];
    let mut limits = vec![None; r.mesh.points.len()];
    for (&v, &vp) in &r.vertex_point {
        limits[vp as usize] = level.limits[v as usize];
    }
    for &f in faces {
        let first = r.first_child[position[&f]];
        let piece = level.pieces[f as usize].expect("refined faces are targets");
        for i in 0..4 {
            pieces[(first + i as u32) as usize] = Some(piece.child(i));
        }
    }
    Level {
        mesh: r.mesh,
        depth: level.depth + 1,
        pieces,
        limits,
    }
}
