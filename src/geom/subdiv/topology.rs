//! Polygon meshes and their adjacency: the control cage as read, and every refined level.
//! Faces are counter-clockwise vertex loops; a directed edge `(a, b)` belongs to the one
//! face that runs from `a` to `b`, so the face across it is the one that runs `(b, a)`.

use std::collections::{HashMap, HashSet};

use glam::DVec3;
use thiserror::Error;

/// An undirected edge, smaller index first.
pub fn edge_key(a: u32, b: u32) -> (u32, u32) {
    if a < b { (a, b) } else { (b, a) }
}

/// A polygon mesh with the edges that are true mesh boundaries. On a refined level that
/// holds only part of the surface, an edge with one face may be the cut of that part
/// rather than a boundary: only `boundary` says which edges are boundaries.
#[derive(Clone, Debug, PartialEq)]
pub struct Mesh {
    pub points: Vec<DVec3>,
    pub faces: Vec<Vec<u32>>,
    pub boundary: HashSet<(u32, u32)>,
}

/// Why a cage cannot be a Catmull–Clark control mesh. Vertex numbers are 1-based, as
/// OBJ writes them; face numbers are 0-based, in file order.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum CageError {
    #[error("the cage has no faces")]
    Empty,
    #[error("face {face} has {count} vertices; a face needs at least 3")]
    TooFewVertices { face: usize, count: usize },
    #[error("face {face} refers to vertex {vertex}, which does not exist ({count} vertices)")]
    BadIndex {
        face: usize,
        vertex: usize,
        count: usize,
    },
    #[error("face {face} uses vertex {vertex} twice")]
    RepeatedVertex { face: usize, vertex: usize },
    #[error(
        "the edge between vertices {a} and {b} is used by {count} faces (non-manifold); Catmull–Clark needs every edge on one or two faces"
    )]
    NonManifoldEdge { a: usize, b: usize, count: usize },
    #[error(
        "faces {first} and {second} both run from vertex {a} to vertex {b}: their windings disagree; orient the faces consistently"
    )]
    Winding {
        first: usize,
        second: usize,
        a: usize,
        b: usize,
    },
    #[error(
        "the faces around vertex {vertex} form {fans} separate fans (non-manifold vertex); Catmull–Clark needs one"
    )]
    NonManifoldVertex { vertex: usize, fans: usize },
    #[error("vertex {vertex} has a non-finite coordinate")]
    NonFinite { vertex: usize },
    #[error("hole face {face} does not exist ({count} faces)")]
    BadHole { face: usize, count: usize },
}

impl Mesh {
    /// A cage as read: checks that it is a manifold polygon mesh with consistent winding,
    /// and takes the edges with one face as its boundary.
    pub fn cage(points: Vec<DVec3>, faces: Vec<Vec<u32>>) -> Result<Mesh, CageError> {
        if faces.is_empty() {
            return Err(CageError::Empty);
        }
        if let Some(v) = points.iter().position(|p| !p.is_finite()) {
            return Err(CageError::NonFinite { vertex: v + 1 });
        }
        let mut uses: HashMap<(u32, u32), usize> = HashMap::new();
        for (f, face) in faces.iter().enumerate() {
            if face.len() < 3 {
                return Err(CageError::TooFewVertices {
                    face: f,
                    count: face.len(),
                });
            }
            for (k, &v) in face.iter().enumerate() {
                if v as usize >= points.len() {
                    return Err(CageError::BadIndex {
                        face: f,
                        vertex: v as usize + 1,
                        count: points.len(),
                    });
                }
                if face[..k].contains(&v) {
                    return Err(CageError::RepeatedVertex {
                        face: f,
                        vertex: v as usize + 1,
                    });
                }
                *uses
                    .entry(edge_key(v, face[(k + 1) % face.len()]))
                    .or_default() += 1;
            }
        }
        if let Some((&(a, b), &count)) = uses.iter().filter(|(_, c)| **c > 2).min() {
            return Err(CageError::NonManifoldEdge {
                a: a as usize + 1,
                b: b as usize + 1,
                count,
            });
        }
        let mut directed: HashMap<(u32, u32), usize> = HashMap::new();
        for (f, face) in faces.iter().enumerate() {
            for k in 0..face.len() {
                let (a, b) = (face[k], face[(k + 1) % face.len()]);
                if let Some(&first) = directed.get(&(a, b)) {
                    return Err(CageError::Winding {
                        first,
                        second: f,
                        a: a as usize + 1,
                        b: b as usize + 1,
                    });
                }
                directed.insert((a, b), f);
            }
        }
        let boundary = uses
            .into_iter()
            .filter(|(_, c)| *c == 1)
            .map(|(e, _)| e)
            .collect();
        let mesh = Mesh {
            points,
            faces,
            boundary,
        };
        let topo = Topology::new(&mesh);
        for v in 0..mesh.points.len() as u32 {
            let fans = topo.fans(&mesh, v);
            if fans > 1 {
                return Err(CageError::NonManifoldVertex {
                    vertex: v as usize + 1,
                    fans,
                });
            }
        }
        Ok(mesh)
    }
}

/// Adjacency of a [`Mesh`]: which face runs along each directed edge, and the faces and
/// neighbours of each vertex.
pub struct Topology {
    half: HashMap<(u32, u32), (u32, usize)>,
    /// Per vertex: (face, corner) with `faces[face][corner] == vertex`.
    pub corners: Vec<Vec<(u32, usize)>>,
    /// Per vertex: whether a boundary edge ends there.
    pub on_boundary: Vec<bool>,
}

impl Topology {
    pub fn new(mesh: &Mesh) -> Topology {
        let mut half = HashMap::new();
        let mut corners = vec![Vec::new(); mesh.points.len()];
        for (f, face) in mesh.faces.iter().enumerate() {
            for (k, &v) in face.iter().enumerate() {
                half.insert((v, face[(k + 1) % face.len()]), (f as u32, k));
                corners[v as usize].push((f as u32, k));
            }
        }
        let mut on_boundary = vec![false; mesh.points.len()];
        for &(a, b) in &mesh.boundary {
            on_boundary[a as usize] = true;
            on_boundary[b as usize] = true;
        }
        Topology {
            half,
            corners,
            on_boundary,
        }
    }

    /// The face running from `a` to `b` and the corner of `a` in it.
    pub fn edge_face(&self, a: u32, b: u32) -> Option<(u32, usize)> {
        self.half.get(&(a, b)).copied()
    }

    /// The face across edge `k` (from `face[k]` to `face[k + 1]`) of a face, unless the edge
    /// is a boundary: the face `g` and the corner `m` with `g[m] = face[k + 1]`,
    /// `g[m + 1] = face[k]`.
    pub fn across(&self, mesh: &Mesh, face: &[u32], k: usize) -> Option<(u32, usize)> {
        let (a, b) = (face[k], face[(k + 1) % face.len()]);
        if mesh.boundary.contains(&edge_key(a, b)) {
            return None;
        }
        self.edge_face(b, a)
    }

    /// The distinct neighbours of `v`, in the order its faces list them.
    pub fn neighbours(&self, mesh: &Mesh, v: u32) -> Vec<u32> {
        let mut out = Vec::new();
        for &(f, k) in &self.corners[v as usize] {
            let face = &mesh.faces[f as usize];
            let n = face.len();
            for w in [face[(k + 1) % n], face[(k + n - 1) % n]] {
                if !out.contains(&w) {
                    out.push(w);
                }
            }
        }
        out
    }

    /// The neighbours of `v` along boundary edges.
    pub fn boundary_neighbours(&self, mesh: &Mesh, v: u32) -> Vec<u32> {
        self.neighbours(mesh, v)
            .into_iter()
            .filter(|&w| mesh.boundary.contains(&edge_key(v, w)))
            .collect()
    }

    /// How many fans (face sets connected across edges at `v`) meet at `v`.
    fn fans(&self, mesh: &Mesh, v: u32) -> usize {
        let all = &self.corners[v as usize];
        let mut seen: HashSet<u32> = HashSet::new();
        let mut fans = 0;
        for &(start, _) in all {
            if seen.contains(&start) {
                continue;
            }
            fans += 1;
            let mut stack = vec![start];
            while let Some(f) = stack.pop() {
                if !seen.insert(f) {
                    continue;
                }
                let face = &mesh.faces[f as usize];
                let n = face.len();
                let k = face.iter().position(|&w| w == v).unwrap_or(0);
                for w in [face[(k + 1) % n], face[(k + n - 1) % n]] {
                    for g in [self.edge_face(v, w), self.edge_face(w, v)]
                        .into_iter()
                        .flatten()
                    {
                        stack.push(g.0);
                    }
                }
            }
        }
        fans
    }

    /// The faces around `v` in order, starting at `(face, corner)` and crossing the edge
    /// from `v` to `face[corner + 1]` each step: `(face, corner)` pairs, until the walk
    /// returns or reaches a boundary.
    pub fn walk_around(&self, mesh: &Mesh, face: u32, corner: usize) -> Vec<(u32, usize)> {
        let mut out = vec![(face, corner)];
        let (mut f, mut k) = (face, corner);
        loop {
            let fv = &mesh.faces[f as usize];
            let next = fv[(k + 1) % fv.len()];
            let Some((g, m)) = self.across(mesh, fv, k) else {
                break;
            };
            let gv = &mesh.faces[g as usize];
            // In g the edge runs from `next` (corner m) to v (corner m + 1).
            debug_assert_eq!(gv[m], next);
            let c = (m + 1) % gv.len();
            if (g, c) == (face, corner) || out.len() > mesh.faces.len() {
                break;
            }
            out.push((g, c));
            (f, k) = (g, c);
        }
        out
    }
}
