//! The watertight triangle kernel on a closed tessellated mesh: no ray from inside escapes
//! (Woop, Benthin, Wald 2013), including rays aimed exactly at vertices and edges.

use std::collections::HashMap;

use glam::{DVec3, Vec3};
use patchtrace::geom::{BezierPatch, Ray};
use patchtrace::kernel::triangle::{RayShear, intersect_triangle};
use patchtrace::scene::model::TriangleMesh;
use patchtrace::tessellate::{TessellationMode, tessellate_patches};

/// A closed "pillow": the six faces of the cube [-1, 1]³ as bicubic patches with their
/// four inner control points pushed outward, so the faces bulge but share their edges.
fn pillow() -> Vec<BezierPatch> {
    let mut patches = Vec::new();
    for a in 0..3 {
        for s in [-1.0, 1.0] {
            let (b, c) = ((a + 1) % 3, (a + 2) % 3);
            let pts: Vec<DVec3> = (0..16)
                .map(|k| {
                    let (i, j) = (k % 4, k / 4);
                    let mut p = DVec3::ZERO;
                    let inner = (1..=2).contains(&i) && (1..=2).contains(&j);
                    p[a] = s * if inner { 1.3 } else { 1.0 };
                    p[b] = -1.0 + 2.0 * i as f64 / 3.0;
                    p[c] = -1.0 + 2.0 * j as f64 / 3.0;
                    p
                })
                .collect();
            patches.push(BezierPatch::from_points(3, 3, &pts).unwrap());
        }
    }
    patches
}

fn triangles(m: &TriangleMesh) -> Vec<[Vec3; 3]> {
    m.indices
        .iter()
        .map(|t| t.map(|i| m.positions[i as usize].as_vec3()))
        .collect()
}

fn hits(tris: &[[Vec3; 3]], ray: &Ray) -> bool {
    let s = RayShear::new(ray);
    tris.iter()
        .any(|t| intersect_triangle(&s, t[0], t[1], t[2], ray.tmin, ray.tmax).is_some())
}

fn assert_closed(m: &TriangleMesh) {
    let mut uses: HashMap<(u32, u32), u32> = HashMap::new();
    for t in &m.indices {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            *uses.entry((a.min(b), a.max(b))).or_default() += 1;
        }
    }
    assert!(
        uses.values().all(|&n| n == 2),
        "the pillow mesh is not closed"
    );
}

fn check(mode: TessellationMode, random_rays: usize) {
    let mesh = tessellate_patches(&pillow(), mode).unwrap().mesh;
    assert_closed(&mesh);
    let tris = triangles(&mesh);
    let origin = Vec3::new(0.013, -0.021, 0.007); // inside, off every symmetry plane
    // Rays through every vertex and every edge mid-point.
    for t in &tris {
        for k in 0..3 {
            for target in [t[k], 0.5 * (t[k] + t[(k + 1) % 3])] {
                let ray = Ray::new(origin, target - origin);
                assert!(hits(&tris, &ray), "ray through {target} escaped");
            }
        }
    }
    // Random directions (xorshift, uniform on the sphere by normalizing a cube sample
    // after rejection).
    let mut state = 0x9E37_79B9_7F4A_7C15u64;
    let mut rnd = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 40) as f32 / (1u64 << 23) as f32 - 1.0
    };
    let mut done = 0;
    while done < random_rays {
        let d = Vec3::new(rnd(), rnd(), rnd());
        if d.length_squared() > 1.0 || d.length_squared() < 1e-6 {
            continue;
        }
        let ray = Ray::new(origin, d);
        assert!(hits(&tris, &ray), "ray {d} escaped");
        done += 1;
    }
}

#[test]
fn no_ray_escapes_the_uniform_pillow() {
    check(
        TessellationMode::Uniform {
            grid_u: 5,
            grid_v: 5,
        },
        100_000,
    );
}

#[test]
fn no_ray_escapes_the_adaptive_pillow() {
    check(TessellationMode::Adaptive { tolerance: 0.02 }, 20_000);
}
