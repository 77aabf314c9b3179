//! An independent Catmull–Clark reference for the subdivision tests: a plain global
//! implementation on face lists (no stencils, no adaptive levels), limit positions by the
//! closed-form masks, and the test cages.

use std::collections::HashMap;

use glam::DVec3;
use patchtrace::geom::subdiv::SubdivisionSurface;

/// A polygon mesh as face lists.
#[derive(Clone, Debug)]
pub struct Poly {
    pub p: Vec<DVec3>,
    pub f: Vec<Vec<usize>>,
}

fn key(a: usize, b: usize) -> (usize, usize) {
    (a.min(b), a.max(b))
}

impl Poly {
    /// Undirected edge → faces using it.
    fn edge_faces(&self) -> HashMap<(usize, usize), Vec<usize>> {
        let mut m: HashMap<(usize, usize), Vec<usize>> = HashMap::new();
        for (fi, f) in self.f.iter().enumerate() {
            for k in 0..f.len() {
                m.entry(key(f[k], f[(k + 1) % f.len()]))
                    .or_default()
                    .push(fi);
            }
        }
        m
    }

    fn vertex_faces(&self) -> Vec<Vec<usize>> {
        let mut vf = vec![Vec::new(); self.p.len()];
        for (fi, f) in self.f.iter().enumerate() {
            for &v in f {
                vf[v].push(fi);
            }
        }
        vf
    }

    fn neighbours(&self, edges: &HashMap<(usize, usize), Vec<usize>>) -> Vec<Vec<usize>> {
        let mut nb = vec![Vec::new(); self.p.len()];
        for &(a, b) in edges.keys() {
            nb[a].push(b);
            nb[b].push(a);
        }
        nb
    }

    /// One global Catmull–Clark step, boundary edges sharp (EDGE_ONLY). `boundary` says
    /// which edges are true boundaries (a cropped mesh has cut edges that are not); new
    /// indices: face points, then edge points, then vertex points. Returns the mesh, its
    /// boundary and the map old vertex → vertex point.
    pub fn step(
        &self,
        boundary: &dyn Fn(usize, usize) -> bool,
    ) -> (Poly, Vec<(usize, usize)>, Vec<usize>) {
        let edges = self.edge_faces();
        let vf = self.vertex_faces();
        let nb = self.neighbours(&edges);
        let fp: Vec<DVec3> = self
            .f
            .iter()
            .map(|f| f.iter().map(|&v| self.p[v]).sum::<DVec3>() / f.len() as f64)
            .collect();
        let mut keys: Vec<(usize, usize)> = edges.keys().copied().collect();
        keys.sort();
        let eidx: HashMap<(usize, usize), usize> = keys
            .iter()
            .enumerate()
            .map(|(i, &k)| (k, fp.len() + i))
            .collect();
        let mut p = fp.clone();
        for &(a, b) in &keys {
            let fs = &edges[&(a, b)];
            p.push(if boundary(a, b) || fs.len() != 2 {
                (self.p[a] + self.p[b]) / 2.0
            } else {
                (self.p[a] + self.p[b] + fp[fs[0]] + fp[fs[1]]) / 4.0
            });
        }
        let base = p.len();
        for v in 0..self.p.len() {
            let bn: Vec<usize> = nb[v].iter().copied().filter(|&w| boundary(v, w)).collect();
            let n = vf[v].len() as f64;
            p.push(if bn.len() == 2 {
                (self.p[bn[0]] + self.p[v] * 6.0 + self.p[bn[1]]) / 8.0
            } else if bn.is_empty() && n > 0.0 && nb[v].len() == vf[v].len() {
                let q = vf[v].iter().map(|&f| fp[f]).sum::<DVec3>() / n;
                let r = nb[v]
                    .iter()
                    .map(|&w| (self.p[v] + self.p[w]) / 2.0)
                    .sum::<DVec3>()
                    / nb[v].len() as f64;
                (q + r * 2.0 + self.p[v] * (n - 3.0)) / n
            } else {
                self.p[v]
            });
        }
        let mut f = Vec::new();
        let mut new_boundary = Vec::new();
        for (fi, face) in self.f.iter().enumerate() {
            let n = face.len();
            for i in 0..n {
                let (a, v, b) = (face[(i + n - 1) % n], face[i], face[(i + 1) % n]);
                let (ea, eb) = (eidx[&key(a, v)], eidx[&key(v, b)]);
                f.push(vec![base + v, eb, fi, ea]);
                if boundary(v, b) {
                    new_boundary.push(key(base + v, eb));
                }
                if boundary(a, v) {
                    new_boundary.push(key(base + v, ea));
                }
            }
        }
        let vmap = (0..self.p.len()).map(|v| base + v).collect();
        (Poly { p, f }, new_boundary, vmap)
    }

    /// Global steps on a whole cage (boundary: edges with one face).
    pub fn subdivide(&self, levels: usize) -> (Poly, Vec<(usize, usize)>) {
        let mut m = self.clone();
        let edges = m.edge_faces();
        let mut bnd: Vec<(usize, usize)> = edges
            .iter()
            .filter(|(_, f)| f.len() == 1)
            .map(|(k, _)| *k)
            .collect();
        for _ in 0..levels {
            let set: std::collections::HashSet<_> = bnd.iter().copied().collect();
            let (n, b, _) = m.step(&|a, c| set.contains(&key(a, c)));
            m = n;
            bnd = b;
        }
        (m, bnd)
    }

    /// Limit position of a vertex: (n² v + 4 Σ e + Σ f) / (n (n + 5)) inside, the
    /// crease (a + 4 v + b) / 6 on a boundary. `None` when its ring is incomplete.
    pub fn limit(&self, v: usize, boundary: &dyn Fn(usize, usize) -> bool) -> Option<DVec3> {
        let edges = self.edge_faces();
        let mut nb: Vec<usize> = edges
            .keys()
            .filter_map(|&(a, b)| {
                if a == v {
                    Some(b)
                } else if b == v {
                    Some(a)
                } else {
                    None
                }
            })
            .collect();
        nb.sort();
        let faces: Vec<&Vec<usize>> = self.f.iter().filter(|f| f.contains(&v)).collect();
        let bn: Vec<usize> = nb.iter().copied().filter(|&w| boundary(v, w)).collect();
        if bn.len() == 2 {
            return Some((self.p[bn[0]] + self.p[v] * 4.0 + self.p[bn[1]]) / 6.0);
        }
        if !bn.is_empty() || nb.len() != faces.len() || faces.iter().any(|f| f.len() != 4) {
            return None;
        }
        let n = faces.len() as f64;
        let e: DVec3 = nb.iter().map(|&w| self.p[w]).sum();
        let o: DVec3 = faces
            .iter()
            .map(|f| {
                let k = f.iter().position(|&w| w == v).unwrap();
                self.p[f[(k + 2) % 4]]
            })
            .sum();
        Some((self.p[v] * n * n + e * 4.0 + o) / (n * (n + 5.0)))
    }

    /// An approximate normal at vertex v (sum of the ring's corner cross products), only
    /// to aim rays.
    pub fn ring_normal(&self, v: usize) -> DVec3 {
        let mut n = DVec3::ZERO;
        for f in self.f.iter().filter(|f| f.contains(&v)) {
            let k = f.iter().position(|&w| w == v).unwrap();
            let m = f.len();
            n += (self.p[f[(k + 1) % m]] - self.p[v]).cross(self.p[f[(k + m - 1) % m]] - self.p[v]);
        }
        n.normalize()
    }

    /// Faces within `rings` vertex rings of `v`, reindexed; returns the submesh, the
    /// true-boundary edges in it and v's new index.
    pub fn crop(
        &self,
        v: usize,
        rings: usize,
        boundary: &[(usize, usize)],
    ) -> (Poly, Vec<(usize, usize)>, usize) {
        let vf = self.vertex_faces();
        let mut dist = vec![usize::MAX; self.p.len()];
        dist[v] = 0;
        let mut frontier = vec![v];
        for d in 1..=rings {
            let mut next = Vec::new();
            for &w in &frontier {
                for &f in &vf[w] {
                    for &x in &self.f[f] {
                        if dist[x] == usize::MAX {
                            dist[x] = d;
                            next.push(x);
                        }
                    }
                }
            }
            frontier = next;
        }
        let kept: Vec<&Vec<usize>> = self
            .f
            .iter()
            .filter(|f| f.iter().any(|&x| dist[x] < rings))
            .collect();
        let mut remap = HashMap::new();
        let mut p = Vec::new();
        let mut faces = Vec::new();
        for f in kept {
            faces.push(
                f.iter()
                    .map(|&x| {
                        *remap.entry(x).or_insert_with(|| {
                            p.push(self.p[x]);
                            p.len() - 1
                        })
                    })
                    .collect(),
            );
        }
        let b = boundary
            .iter()
            .filter_map(|&(a, c)| Some(key(*remap.get(&a)?, *remap.get(&c)?)))
            .collect();
        (Poly { p, f: faces }, b, remap[&v])
    }
}

pub fn cube() -> Poly {
    let p = (0..8)
        .map(|i| DVec3::new((i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64) - 0.5)
        .collect();
    let f = vec![
        vec![0, 2, 3, 1],
        vec![4, 5, 7, 6],
        vec![0, 1, 5, 4],
        vec![2, 6, 7, 3],
        vec![0, 4, 6, 2],
        vec![1, 3, 7, 5],
    ];
    Poly { p, f }
}

/// A torus cage of `n × m` quads (all valence 4).
pub fn torus(n: usize, m: usize) -> Poly {
    let mut p = Vec::new();
    for i in 0..n {
        let a = i as f64 / n as f64 * std::f64::consts::TAU;
        for j in 0..m {
            let b = j as f64 / m as f64 * std::f64::consts::TAU;
            let r = 1.0 + 0.4 * b.cos();
            p.push(DVec3::new(r * a.cos(), r * a.sin(), 0.4 * b.sin()));
        }
    }
    let id = |i: usize, j: usize| (i % n) * m + (j % m);
    let f = (0..n)
        .flat_map(|i| {
            (0..m).map(move |j| vec![id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)])
        })
        .collect();
    Poly { p, f }
}

/// Icosahedron (triangles; vertices of valence 5).
pub fn icosahedron() -> Poly {
    let t = (1.0 + 5f64.sqrt()) / 2.0;
    let p = [
        (-1.0, t, 0.0),
        (1.0, t, 0.0),
        (-1.0, -t, 0.0),
        (1.0, -t, 0.0),
        (0.0, -1.0, t),
        (0.0, 1.0, t),
        (0.0, -1.0, -t),
        (0.0, 1.0, -t),
        (t, 0.0, -1.0),
        (t, 0.0, 1.0),
        (-t, 0.0, -1.0),
        (-t, 0.0, 1.0),
    ]
    .iter()
    .map(|&(x, y, z)| DVec3::new(x, y, z) * 0.5)
    .collect();
    let f = [
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ]
    .iter()
    .map(|f| f.to_vec())
    .collect();
    Poly { p, f }
}

/// A hexagonal bipyramid of quads and triangles around two valence-6 apexes: the
/// equator ring, a quad band, and triangle fans to the apexes.
pub fn hex_bipyramid() -> Poly {
    let mut p = Vec::new();
    for ring in 0..2 {
        for i in 0..6 {
            let a = i as f64 / 6.0 * std::f64::consts::TAU + 0.3 * ring as f64;
            p.push(DVec3::new(
                a.cos(),
                a.sin(),
                if ring == 0 { -0.4 } else { 0.4 },
            ));
        }
    }
    p.push(DVec3::new(0.0, 0.0, -1.1));
    p.push(DVec3::new(0.1, 0.0, 1.2));
    let mut f = Vec::new();
    for i in 0..6 {
        let j = (i + 1) % 6;
        f.push(vec![i, j, 6 + j, 6 + i]);
        f.push(vec![j, i, 12]);
        f.push(vec![6 + i, 6 + j, 13]);
    }
    Poly { p, f }
}

/// An open, curved 4×4 grid of quads: boundary edges, valence-3 boundary vertices and
/// valence-2 corners.
pub fn open_grid() -> Poly {
    let n = 5;
    let p = (0..n * n)
        .map(|k| {
            let (x, y) = ((k % n) as f64 - 2.0, (k / n) as f64 - 2.0);
            DVec3::new(x, y, 0.3 * (x * 0.7).sin() * (y * 0.5).cos() + 0.05 * x * y)
        })
        .collect();
    let f = (0..n - 1)
        .flat_map(|j| {
            (0..n - 1).map(move |i| {
                vec![
                    j * n + i,
                    j * n + i + 1,
                    (j + 1) * n + i + 1,
                    (j + 1) * n + i,
                ]
            })
        })
        .collect();
    Poly { p, f }
}

/// The cage as the library's subdivision surface.
pub fn surface(cage: &Poly) -> SubdivisionSurface {
    SubdivisionSurface::new(
        cage.p.clone(),
        cage.f
            .iter()
            .map(|f| f.iter().map(|&v| v as u32).collect())
            .collect(),
    )
    .expect("a valid cage")
}
