//! The 4×4 B-spline net of a quad face: the face and its 1-ring (Dammertz Fig. 2.30),
//! gathered through the mesh's adjacency, with phantom points across sharp boundary
//! edges. Net position `[i][j]` has i along the face's u (from corner 0 to corner 1) and
//! j along v (from corner 0 to corner 3); the face's corners are `[1][1]`, `[2][1]`,
//! `[2][2]`, `[1][2]`.
//!
//! A phantom point is the reflection of the inner neighbour through the boundary point,
//! `2 p - q`: with it the uniform B-spline reproduces the crease rule (1, 6, 1) / 8 and the
//! limit boundary is the cubic B-spline of the boundary points, which is what `EDGE_ONLY`
//! defines.

use super::stencil::Stencil;
use super::topology::{Mesh, Topology};

/// For edge k (from corner k to k + 1): the net positions across it, next to corner k
/// and next to corner k + 1.
const ACROSS: [[(usize, usize); 2]; 4] = [
    [(1, 0), (2, 0)],
    [(3, 1), (3, 2)],
    [(2, 3), (1, 3)],
    [(0, 2), (0, 1)],
];
/// The step from a position across edge k towards the face.
const INWARD: [(isize, isize); 4] = [(0, 1), (-1, 0), (0, -1), (1, 0)];
/// The net position diagonal to corner k.
const DIAGONAL: [(usize, usize); 4] = [(0, 0), (3, 0), (3, 3), (0, 3)];
/// The net positions of the face's corners.
pub const CORNER: [(usize, usize); 4] = [(1, 1), (2, 1), (2, 2), (1, 2)];

/// The net of quad `f`. Where the ring is incomplete (a sharp boundary, or around an
/// extraordinary vertex, where the net is only a stand-in) the missing points are
/// reflections, and failing that the face corner itself.
pub fn gather(mesh: &Mesh, topo: &Topology, f: u32) -> [[Stencil; 4]; 4] {
    let face = &mesh.faces[f as usize];
    let mut g: [[Option<Stencil>; 4]; 4] = Default::default();
    for (k, &(i, j)) in CORNER.iter().enumerate() {
        g[i][j] = Some(Stencil::point(face[k]));
    }
    let mut open = [false; 4];
    for k in 0..4 {
        if let Some((h, m)) = topo.across(mesh, face, k) {
            let hv = &mesh.faces[h as usize];
            if hv.len() == 4 {
                open[k] = true;
                let [(i0, j0), (i1, j1)] = ACROSS[k];
                g[i0][j0] = Some(Stencil::point(hv[(m + 2) % 4]));
                g[i1][j1] = Some(Stencil::point(hv[(m + 3) % 4]));
            }
        }
    }
    for k in 0..4 {
        if open[k]
            && open[(k + 3) % 4]
            && let Some(d) = diagonal(mesh, topo, face, k)
        {
            let (i, j) = DIAGONAL[k];
            g[i][j] = Some(Stencil::point(d));
        }
    }
    let at =
        |g: &[[Option<Stencil>; 4]; 4], (i, j): (usize, usize), s: isize, d: (isize, isize)| {
            let (ii, jj) = (i as isize + s * d.0, j as isize + s * d.1);
            g[ii as usize][jj as usize].clone()
        };
    for k in 0..4 {
        if !open[k] {
            for pos in ACROSS[k] {
                let (a, b) = (at(&g, pos, 1, INWARD[k]), at(&g, pos, 2, INWARD[k]));
                if let (Some(a), Some(b)) = (a, b) {
                    g[pos.0][pos.1] = Some(Stencil::reflect(&a, &b));
                }
            }
        }
    }
    for k in 0..4 {
        let pos = DIAGONAL[k];
        if g[pos.0][pos.1].is_some() {
            continue;
        }
        // Reflect across whichever edge at this corner is sharp.
        let reflected = [k, (k + 3) % 4]
            .into_iter()
            .filter(|&e| !open[e])
            .find_map(
                |e| match (at(&g, pos, 1, INWARD[e]), at(&g, pos, 2, INWARD[e])) {
                    (Some(a), Some(b)) => Some(Stencil::reflect(&a, &b)),
                    _ => None,
                },
            );
        g[pos.0][pos.1] = Some(reflected.unwrap_or_else(|| Stencil::point(face[k])));
    }
    // Anything still missing (an incomplete ring next to an extraordinary vertex).
    std::array::from_fn(|i| {
        std::array::from_fn(|j| {
            g[i][j].clone().unwrap_or_else(|| {
                let k = match (i < 2, j < 2) {
                    (true, true) => 0,
                    (false, true) => 1,
                    (false, false) => 2,
                    (true, false) => 3,
                };
                Stencil::point(face[k])
            })
        })
    })
}

/// The vertex diagonal to corner k: cross edge k, then the next edge around corner k.
fn diagonal(mesh: &Mesh, topo: &Topology, face: &[u32], k: usize) -> Option<u32> {
    let (g, m) = topo.across(mesh, face, k)?;
    let gv = &mesh.faces[g as usize];
    // In g, corner k's vertex is at m + 1 and the next edge around it is (m + 1, m + 2).
    let (h, n) = topo.across(mesh, gv, (m + 1) % gv.len())?;
    let hv = &mesh.faces[h as usize];
    (hv.len() == 4).then(|| hv[(n + 3) % 4])
}
