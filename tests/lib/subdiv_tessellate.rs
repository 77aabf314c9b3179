//! `tessellate` of Catmull–Clark cages: the limit surface sampled uniformly per
//! quad after the first step. Against the independent global Catmull–Clark of
//! `subdiv_common`: with a 4 × 4 grid per quad the vertices are exactly the limit points of
//! the vertices after three global steps (quad parameters in quarters), one for one; the
//! mesh is closed (every edge used by exactly two triangles, once in each direction, after
//! welding identical positions) and its size is the quad count times the grid's, however
//! deeply the load-time refinement went at extraordinary vertices.

use crate::subdiv_common;

use std::collections::HashMap;

use glam::DVec3;
use patchtrace::geom::subdiv::SubdivisionSurface;
use patchtrace::geom::subdiv::adaptive::T_JUNCTION_OVERLAP_ULPS;
use patchtrace::scene::{Geometry, Object, TriangleMesh};
use patchtrace::tessellate::{TessellationMode, tessellate_object};
use subdiv_common::{Poly, cube, hex_bipyramid, icosahedron, surface, torus};

fn tessellate(s: &SubdivisionSurface, n: u32) -> TriangleMesh {
    let object = Object {
        name: "cage".into(),
        material: 0,
        geometry: Geometry::Subdivision(s.clone()),
    };
    let mode = TessellationMode::Uniform {
        grid_u: n,
        grid_v: n,
    };
    match tessellate_object(&object, mode)
        .expect("tessellates")
        .0
        .geometry
    {
        Geometry::Mesh(m) => m,
        other => panic!("not a mesh: {other:?}"),
    }
}

/// Each vertex's number after welding bit-identical positions.
fn welded(m: &TriangleMesh) -> Vec<usize> {
    let mut weld: HashMap<[u64; 3], usize> = HashMap::new();
    m.positions
        .iter()
        .map(|p| {
            let n = weld.len();
            *weld.entry(p.to_array().map(f64::to_bits)).or_insert(n)
        })
        .collect()
}

/// Directed edges after welding identical positions: each must occur once, with its
/// reverse once (a closed, consistently wound surface without cracks or T-junctions).
fn assert_closed(name: &str, m: &TriangleMesh) {
    let ids = welded(m);
    let mut directed: HashMap<(usize, usize), usize> = HashMap::new();
    for t in &m.indices {
        let v = t.map(|i| ids[i as usize]);
        assert!(
            v[0] != v[1] && v[1] != v[2] && v[2] != v[0],
            "{name}: degenerate {t:?}"
        );
        for k in 0..3 {
            *directed.entry((v[k], v[(k + 1) % 3])).or_default() += 1;
        }
    }
    for (&(a, b), &count) in &directed {
        assert_eq!(count, 1, "{name}: edge {a}→{b} used {count} times");
        assert_eq!(
            directed.get(&(b, a)),
            Some(&1),
            "{name}: edge {a}→{b} has no twin (a crack)"
        );
    }
}

/// Distance, relative to the surface's size, below which a vertex counts as exact: the
/// `f64` evaluation of a Bézier patch against the reference's masks, a few hundred ulps.
const EXACT: f64 = 1e-12;

/// Each tessellation vertex against the nearest limit point of the global reference,
/// and the reference points all used: the largest distance relative to the size, and
/// how many vertices are within [`EXACT`].
fn distances_to_limit_points(cage: &Poly, m: &TriangleMesh) -> (f64, usize) {
    let (fine, _) = cage.subdivide(3);
    let limits: Vec<DVec3> = (0..fine.p.len())
        .map(|v| fine.limit(v, &|_, _| false).expect("closed cage"))
        .collect();
    let size = limits
        .iter()
        .map(|p| p.abs().max_element())
        .fold(0.0, f64::max);
    let mut used = vec![false; limits.len()];
    let (mut worst, mut exact) = (0.0f64, 0);
    for p in &m.positions {
        let (k, d) = limits
            .iter()
            .enumerate()
            .map(|(k, q)| (k, (*p - *q).length()))
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .expect("limit points");
        used[k] = true;
        worst = worst.max(d / size);
        exact += usize::from(d / size < EXACT);
    }
    assert_eq!(
        m.positions.len(),
        limits.len(),
        "one vertex per limit point"
    );
    assert!(used.iter().all(|&u| u), "every limit point is a vertex");
    (worst, exact)
}

#[test]
fn cage_tessellations_are_closed_limit_points_one_for_one() {
    for (name, cage) in [
        ("cube", cube()),
        ("torus", torus(6, 4)),
        ("icosahedron", icosahedron()),
        ("bipyramid", hex_bipyramid()),
    ] {
        let s = surface(&cage);
        let m = tessellate(&s, 4);
        assert_closed(name, &m);
        let (worst, exact) = distances_to_limit_points(&cage, &m);
        let vertices = m.positions.len();
        println!(
            "{name}: {vertices} vertices, {exact} exact, largest distance {worst:.2e} of the size"
        );
        // Exact but inside regular patches whose edge the refinement pushed over a
        // T-junction (T_JUNCTION_OVERLAP_ULPS f32 ulps of the size, in the tangent plane,
        // which moves the patch's inside by less): the torus has none.
        let pushed = T_JUNCTION_OVERLAP_ULPS * f64::from(f32::EPSILON);
        assert!(
            worst < pushed,
            "{name}: a vertex {worst:e} off the limit surface"
        );
        if s.stats.t_junctions == 0 {
            assert_eq!(
                exact, vertices,
                "{name}: no T-junctions, every vertex exact"
            );
        } else {
            assert!(
                exact * 2 > vertices,
                "{name}: only {exact} of {vertices} exact"
            );
        }
        // Vertex normals face the way the triangles wind (outward for these cages).
        for t in &m.indices {
            let [a, b, c] = t.map(|i| m.positions[i as usize]);
            let face = (b - a).cross(c - a);
            let normals: DVec3 = t.iter().map(|&i| m.normals[i as usize]).sum();
            assert!(
                face.dot(normals) > 0.0,
                "{name}: triangle {t:?} wound against its normals"
            );
            assert!(face.dot((a + b + c) / 3.0 - centre(&cage)) > 0.0 || name == "torus");
        }
    }
}

fn centre(cage: &Poly) -> DVec3 {
    cage.p.iter().sum::<DVec3>() / cage.p.len() as f64
}

/// The size follows the quads, not the load-time refinement: 2 n² triangles per quad after
/// the first step on the cube (every quad refined to many patches) as on the torus.
#[test]
fn cage_tessellation_size_is_per_quad() {
    for (name, cage) in [("cube", cube()), ("torus", torus(8, 6))] {
        let s = surface(&cage);
        let quads = s.stats.faces;
        for n in [1u32, 3, 16] {
            let m = tessellate(&s, n);
            assert_eq!(
                m.indices.len(),
                2 * (n * n) as usize * quads,
                "{name} at {n}×{n}: {} patches",
                s.patches.len()
            );
            assert_closed(name, &m);
        }
        assert!(
            name != "cube" || s.patches.len() > 10 * quads,
            "the cube is refined"
        );
    }
}

/// A hole face (USD's `holeIndices`) has no triangles, and its neighbours' sides along
/// the hole are its rim: the cube without face 2 at 4 × 4 per quad is 20 quads' worth of
/// triangles, and its only untwinned edges are the rim's 4 sides × 2 quads × 4 segments.
#[test]
fn a_hole_face_is_left_out_and_its_rim_is_the_only_boundary() {
    let c = cube();
    let faces =
        c.f.iter()
            .map(|f| f.iter().map(|&v| v as u32).collect())
            .collect();
    let s = SubdivisionSurface::with_holes(c.p.clone(), faces, vec![2]).unwrap();
    assert_eq!(s.stats.holes, 1);
    let m = tessellate(&s, 4);
    assert_eq!(m.indices.len(), 2 * 16 * 20);
    let ids = welded(&m);
    let mut directed: HashMap<(usize, usize), usize> = HashMap::new();
    for t in &m.indices {
        let v = t.map(|i| ids[i as usize]);
        for k in 0..3 {
            *directed.entry((v[k], v[(k + 1) % 3])).or_default() += 1;
        }
    }
    assert!(directed.values().all(|&n| n == 1));
    let rim = directed
        .keys()
        .filter(|&&(a, b)| !directed.contains_key(&(b, a)))
        .count();
    assert_eq!(rim, 4 * 2 * 4);
}
