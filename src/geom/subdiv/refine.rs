//! One Catmull–Clark step (Catmull & Clark 1978; Dammertz §2.9.1, Fig. 2.29) on some of
//! a mesh's faces, with OpenSubdiv's `EDGE_ONLY` boundary rule: boundary edges are
//! infinitely sharp, so a boundary edge point is the edge midpoint and a boundary vertex
//! moves by the cubic B-spline crease mask (1, 6, 1) / 8 along its two boundary edges.
//!
//! Each new point is computed once per level, so every child face that uses it sees the
//! same bits. Points whose neighbourhood is only partly among the selected faces (the
//! rim of a partial level) get a value that is not the limit rule's; the adaptive
//! refinement ([`super::adaptive`]) selects two rings of faces around what it refines, so
//! those points are never part of a patch.

use std::collections::{HashMap, HashSet};

use glam::DVec3;

use super::topology::{Mesh, Topology, edge_key};

/// The next level: the children of the selected faces, face `f`'s `i`-th child (at its
/// corner `i`) being `[vertex point of f[i], edge point of (f[i], f[i+1]), face point of
/// f, edge point of (f[i-1], f[i])]`.
pub struct Refined {
    pub mesh: Mesh,
    /// Per selected face (in selection order), the index of its first child.
    pub first_child: Vec<u32>,
    /// Old vertex → its vertex point.
    pub vertex_point: HashMap<u32, u32>,
    /// Old edge → its edge point.
    pub edge_point: HashMap<(u32, u32), u32>,
}

/// One Catmull–Clark step on the faces `selected` of `mesh`.
pub fn refine(mesh: &Mesh, topo: &Topology, selected: &[u32]) -> Refined {
    let chosen: HashSet<u32> = selected.iter().copied().collect();
    let mut points = Vec::new();
    let mut face_point = HashMap::new();
    for &f in selected {
        let face = &mesh.faces[f as usize];
        let sum = face
            .iter()
            .fold(DVec3::ZERO, |acc, &v| acc + mesh.points[v as usize]);
        face_point.insert(f, points.len() as u32);
        points.push(sum / face.len() as f64);
    }
    let mut edge_point = HashMap::new();
    for &f in selected {
        let face = &mesh.faces[f as usize];
        for k in 0..face.len() {
            let (a, b) = (face[k], face[(k + 1) % face.len()]);
            let key = edge_key(a, b);
            if edge_point.contains_key(&key) {
                continue;
            }
            let (pa, pb) = (mesh.points[a as usize], mesh.points[b as usize]);
            let across = topo
                .across(mesh, face, k)
                .filter(|(g, _)| chosen.contains(g));
            let p = match across {
                // Interior: (a + b + both face points) / 4.
                Some((g, _)) => {
                    (pa + pb + points[face_point[&f] as usize] + points[face_point[&g] as usize])
                        * 0.25
                }
                // A boundary (sharp) edge, or the rim of a partial level.
                None => (pa + pb) * 0.5,
            };
            edge_point.insert(key, points.len() as u32);
            points.push(p);
        }
    }
    let mut vertex_point = HashMap::new();
    for &f in selected {
        for &v in &mesh.faces[f as usize] {
            if vertex_point.contains_key(&v) {
                continue;
            }
            let p = vertex_rule(mesh, topo, &chosen, &face_point, &points, v);
            vertex_point.insert(v, points.len() as u32);
            points.push(p);
        }
    }
    let mut faces = Vec::new();
    let mut first_child = Vec::with_capacity(selected.len());
    let mut boundary = HashSet::new();
    for &f in selected {
        first_child.push(faces.len() as u32);
        let face = &mesh.faces[f as usize];
        let n = face.len();
        let fp = face_point[&f];
        for i in 0..n {
            let (prev, v, next) = (face[(i + n - 1) % n], face[i], face[(i + 1) % n]);
            let vp = vertex_point[&v];
            let e_next = edge_point[&edge_key(v, next)];
            let e_prev = edge_point[&edge_key(prev, v)];
            faces.push(vec![vp, e_next, fp, e_prev]);
            // Halves of a boundary edge are boundary edges.
            if mesh.boundary.contains(&edge_key(v, next)) {
                boundary.insert(edge_key(vp, e_next));
            }
            if mesh.boundary.contains(&edge_key(prev, v)) {
                boundary.insert(edge_key(vp, e_prev));
            }
        }
    }
    Refined {
        mesh: Mesh {
            points,
            faces,
            boundary,
        },
        first_child,
        vertex_point,
        edge_point,
    }
}

/// The new position of vertex `v`: the crease mask on a boundary, Catmull–Clark's
/// `(Q + 2R + (n - 3) v) / n` inside (Q the mean of the face points, R of the edge
/// midpoints, n the valence).
fn vertex_rule(
    mesh: &Mesh,
    topo: &Topology,
    chosen: &HashSet<u32>,
    face_point: &HashMap<u32, u32>,
    points: &[DVec3],
    v: u32,
) -> DVec3 {
    let pv = mesh.points[v as usize];
    if topo.on_boundary[v as usize] {
        return match topo.boundary_neighbours(mesh, v)[..] {
            [a, b] => (mesh.points[a as usize] + pv * 6.0 + mesh.points[b as usize]) * 0.125,
            _ => pv,
        };
    }
    let corners = &topo.corners[v as usize];
    if corners.iter().any(|(f, _)| !chosen.contains(f)) {
        // The rim of a partial level: never part of a patch.
        return pv;
    }
    let n = corners.len() as f64;
    let q = corners.iter().fold(DVec3::ZERO, |acc, (f, _)| {
        acc + points[face_point[f] as usize]
    }) / n;
    let neighbours = topo.neighbours(mesh, v);
    let r = neighbours.iter().fold(DVec3::ZERO, |acc, &w| {
        acc + (pv + mesh.points[w as usize]) * 0.5
    }) / neighbours.len() as f64;
    (q + r * 2.0 + pv * (n - 3.0)) / n
}
