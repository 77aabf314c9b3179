//! Limit positions and limit normals of mesh vertices (Halstead, Kass & DeRose 1993,
//! "Efficient, fair interpolation using Catmull–Clark surfaces", §A; the eigenvector masks
//! of the subdivision matrix, exact at every level).

use std::f64::consts::PI;

use glam::DVec3;

use super::topology::{Mesh, Topology};

/// The limit position of vertex `v`: `(n² v + 4 Σ e_i + Σ f_i) / (n (n + 5))` inside (e the
/// edge neighbours, f the opposite corners of its quads), the cubic B-spline's
/// `(a + 4 v + b) / 6` on a sharp boundary.
pub fn position(mesh: &Mesh, topo: &Topology, v: u32) -> DVec3 {
    let p = |i: u32| mesh.points[i as usize];
    if topo.on_boundary[v as usize] {
        return match topo.boundary_neighbours(mesh, v)[..] {
            [a, b] => (p(a) + p(v) * 4.0 + p(b)) / 6.0,
            _ => p(v),
        };
    }
    let corners = &topo.corners[v as usize];
    let n = corners.len() as f64;
    let e = topo
        .neighbours(mesh, v)
        .iter()
        .fold(DVec3::ZERO, |acc, &w| acc + p(w));
    let f = corners.iter().fold(DVec3::ZERO, |acc, &(face, k)| {
        let fv = &mesh.faces[face as usize];
        acc + p(fv[(k + 2) % fv.len()])
    });
    (p(v) * (n * n) + e * 4.0 + f) / (n * (n + 5.0))
}

/// The limit normal (unnormalised) at an interior vertex `v` of quads, given one of its
/// corners: the cross product of the two tangent masks
/// `t = Σ A cos(2πi/n) e_i + (cos(2πi/n) + cos(2π(i+1)/n)) f_i` and its sine twin, with
/// `A = 1 + cos(2π/n) + cos(π/n) √(2 (9 + cos(2π/n)))`. `None` on a boundary.
pub fn normal(mesh: &Mesh, topo: &Topology, v: u32, face: u32, corner: usize) -> Option<DVec3> {
    if topo.on_boundary[v as usize] {
        return None;
    }
    let ring = topo.walk_around(mesh, face, corner);
    let n = ring.len();
    if n != topo.corners[v as usize].len() || n < 3 {
        return None;
    }
    // e_i: the neighbour along the edge crossed after face i; f_i: the corner between
    // e_i and e_{i+1}, opposite v in face i + 1.
    let p = |i: u32| mesh.points[i as usize];
    let e: Vec<DVec3> = ring
        .iter()
        .map(|&(f, k)| p(mesh.faces[f as usize][(k + 1) % 4]))
        .collect();
    let o: Vec<DVec3> = ring
        .iter()
        .map(|&(f, k)| p(mesh.faces[f as usize][(k + 2) % 4]))
        .collect();
    let nf = n as f64;
    let c1 = (2.0 * PI / nf).cos();
    let a = 1.0 + c1 + (PI / nf).cos() * (2.0 * (9.0 + c1)).sqrt();
    let (mut tu, mut tv) = (DVec3::ZERO, DVec3::ZERO);
    for i in 0..n {
        let (t0, t1) = (2.0 * PI * i as f64 / nf, 2.0 * PI * (i + 1) as f64 / nf);
        let f_i = o[(i + 1) % n];
        tu += e[i] * (a * t0.cos()) + f_i * (t0.cos() + t1.cos());
        tv += e[i] * (a * t0.sin()) + f_i * (t0.sin() + t1.sin());
    }
    Some(tu.cross(tv))
}
