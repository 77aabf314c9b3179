//! Unit tests of the construction: shared edges, parameter mapping, limit normals.

use std::collections::HashMap;

use glam::DVec3;

use super::*;

fn cube() -> SubdivisionSurface {
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
    SubdivisionSurface::new(p, f).unwrap()
}

type Key = [[u32; 3]; 2];

fn bits(p: DVec3) -> [u32; 3] {
    p.as_vec3().to_array().map(f32::to_bits)
}

/// Every patch edge in f32, keyed by its end points (in either order).
fn edges(s: &SubdivisionSurface) -> HashMap<Key, Vec<[[u32; 3]; 4]>> {
    let mut out: HashMap<Key, Vec<[[u32; 3]; 4]>> = HashMap::new();
    for p in &s.patches {
        let rows: [[(usize, usize); 4]; 4] = [
            [(0, 0), (1, 0), (2, 0), (3, 0)],
            [(3, 0), (3, 1), (3, 2), (3, 3)],
            [(3, 3), (2, 3), (1, 3), (0, 3)],
            [(0, 3), (0, 2), (0, 1), (0, 0)],
        ];
        for r in rows {
            let mut e = r.map(|(a, b)| bits(p.point(a, b)));
            if e[0] > e[3] {
                e.reverse();
            }
            out.entry([e[0], e[3]]).or_default().push(e);
        }
    }
    out
}

#[test]
fn shared_edges_are_bit_identical_in_f32() {
    for s in [cube()] {
        let mut shared = 0;
        for (key, list) in edges(&s) {
            if list.len() == 2 {
                shared += 1;
                assert_eq!(list[0], list[1], "edge {key:?}");
            }
        }
        assert!(shared > s.patches.len(), "{shared} shared edges");
    }
}

#[test]
fn patches_lie_in_the_cage_box() {
    let s = cube();
    let mut bad = Vec::new();
    for (k, p) in s.patches.iter().enumerate() {
        if p.euclidean_points()
            .any(|q| q.abs().max_element() > 0.5 + 1e-12)
        {
            bad.push((k, s.pieces[k]));
        }
    }
    assert!(
        bad.is_empty(),
        "{} of {}: {:?}",
        bad.len(),
        s.patches.len(),
        &bad[..bad.len().min(5)]
    );
}

#[test]
fn children_map_to_their_quarter_of_the_parent() {
    let p = Piece::whole(7).child(2).child(1);
    // Child 2 is the quarter at corner (1, 1), turned twice: its corner 1 is the parent's
    // (0.5, 1) and its centre (0.75, 0.75); its child 1 spans from the one to the other.
    let (u0, v0) = p.to_face(0.0, 0.0);
    let (u1, v1) = p.to_face(1.0, 1.0);
    assert_eq!(p.face, 7);
    assert_eq!((u0, v0), (0.5, 1.0));
    assert_eq!((u1, v1), (0.75, 0.75));
    // Corner 0 of every child of a child at corner 0 stays at the parent's corner 0.
    let mut q = Piece::whole(0);
    for _ in 0..10 {
        q = q.child(0);
    }
    assert_eq!(q.to_face(0.0, 0.0), (0.0, 0.0));
    assert_eq!(q.to_face(1.0, 1.0), (1.0 / 1024.0, 1.0 / 1024.0));
}

#[test]
fn limit_normal_at_a_cube_corner_is_the_diagonal() {
    // After one step the cube's corner (+,+,+) is a valence-3 vertex whose limit normal is
    // along (1, 1, 1) by symmetry.
    let s = cube();
    let topo = topology::Topology::new(&s.cage);
    let all: Vec<u32> = (0..6).collect();
    let level1 = refine::refine(&s.cage, &topo, &all);
    let t1 = topology::Topology::new(&level1.mesh);
    let v = level1.vertex_point[&7];
    let (f, k) = t1.corners[v as usize][0];
    let n = limit::normal(&level1.mesh, &t1, v, f, k)
        .unwrap()
        .normalize();
    let d = DVec3::ONE.normalize();
    assert!(n.dot(d).abs() > 1.0 - 1e-12, "{n}");
}

#[test]
fn bad_cages_are_refused_with_the_reason() {
    let p: Vec<DVec3> = (0..5)
        .map(|i| DVec3::new(i as f64, (i * i) as f64, 0.0))
        .collect();
    let err = |f: Vec<Vec<u32>>| SubdivisionSurface::new(p.clone(), f).unwrap_err();
    assert_eq!(err(vec![]), CageError::Empty);
    assert!(matches!(
        err(vec![vec![0, 1, 9]]),
        CageError::BadIndex { vertex: 10, .. }
    ));
    assert!(matches!(
        err(vec![vec![0, 1, 1]]),
        CageError::RepeatedVertex { .. }
    ));
    // Three triangles on edge (0, 1).
    let fan = vec![vec![0, 1, 2], vec![1, 0, 3], vec![0, 1, 4]];
    assert!(matches!(
        err(fan),
        CageError::NonManifoldEdge {
            a: 1,
            b: 2,
            count: 3
        }
    ));
    let flipped = vec![vec![0, 1, 2], vec![0, 1, 3]];
    assert!(matches!(err(flipped), CageError::Winding { .. }));
    // Two triangles touching only at vertex 0.
    let bowtie = vec![vec![0, 1, 2], vec![0, 3, 4]];
    assert!(matches!(
        err(bowtie),
        CageError::NonManifoldVertex { vertex: 1, fans: 2 }
    ));
}

#[test]
fn an_all_regular_cage_is_one_bezier_patch_per_quad_equal_to_the_b_spline() {
    // A torus of 8 × 6 quads: after one step 192 regular quads. Each patch must be the
    // uniform bicubic B-spline of its 4×4 grid, evaluated here by the B-spline basis.
    let (n, m) = (8usize, 6usize);
    let mut pts = Vec::new();
    for i in 0..n {
        let a = i as f64 / n as f64 * std::f64::consts::TAU;
        for j in 0..m {
            let b = j as f64 / m as f64 * std::f64::consts::TAU;
            let r = 1.0 + 0.4 * b.cos();
            pts.push(DVec3::new(r * a.cos(), r * a.sin(), 0.4 * b.sin()));
        }
    }
    let id = |i: usize, j: usize| ((i % n) * m + (j % m)) as u32;
    let faces = (0..n)
        .flat_map(|i| {
            (0..m).map(move |j| vec![id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)])
        })
        .collect();
    let s = SubdivisionSurface::new(pts, faces).unwrap();
    assert_eq!(s.patches.len(), 4 * n * m);
    assert_eq!(s.stats.levels, 1);
    // The patch corners are limit points of level-1 vertices: check one face's corners
    // against the closed-form limit mask on the level-1 mesh (independent of the nets).
    let topo = topology::Topology::new(&s.cage);
    let all: Vec<u32> = (0..(n * m) as u32).collect();
    let l1 = refine::refine(&s.cage, &topo, &all);
    let t1 = topology::Topology::new(&l1.mesh);
    for (f, patch) in s.patches.iter().enumerate().step_by(7) {
        let face = &l1.mesh.faces[f];
        for (k, (u, v)) in [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)]
            .into_iter()
            .enumerate()
        {
            let want = limit::position(&l1.mesh, &t1, face[k]);
            assert!((patch.eval(u, v) - want).length() < 1e-14);
        }
    }
}
