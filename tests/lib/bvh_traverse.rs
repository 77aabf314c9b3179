//! Traversal against brute force: the nearest hit and the any-hit answer over random scenes
//! and rays must equal those found by testing every primitive.

use crate::bvh_support;

use bvh_support::{Rng, brute_nearest, inner_sphere, random_boxes, random_ray, ray_sphere};
use patchtrace::accel::bvh::Bvh;

#[test]
fn nearest_hit_equals_brute_force() {
    let mut rng = Rng::new(1);
    for &n in &[1usize, 2, 3, 7, 50, 400] {
        let boxes = random_boxes(&mut rng, n);
        let spheres: Vec<_> = boxes.iter().map(inner_sphere).collect();
        let bvh = Bvh::build(&boxes);
        let mut hits = 0;
        for _ in 0..500 {
            let mut ray = random_ray(&mut rng);
            if rng.range(0.0, 1.0) < 0.5 {
                // Aim at a primitive so that many rays hit something.
                let target = boxes[rng.next_u64() as usize % n].center();
                ray.dir = target - ray.origin;
            }
            if rng.range(0.0, 1.0) < 0.3 {
                ray.tmax = rng.range(0.0, 1.5);
            }
            let mut nearest: Option<(f32, u32)> = None;
            let stats = bvh.traverse(&ray, |prim, tmax| {
                let t = ray_sphere(&ray, spheres[prim as usize], ray.tmin, tmax)?;
                if nearest.is_none_or(|(best, _)| t < best) {
                    nearest = Some((t, prim));
                }
                Some(t)
            });
            assert_eq!(
                nearest,
                brute_nearest(&spheres, &ray),
                "n = {n}, ray {ray:?}"
            );
            // Wide nodes and leaves are fewer than the binary nodes, but a one-leaf tree
            // still gets a wide root above its leaf.
            assert!(stats.nodes_visited as usize <= bvh.node_count() + 1);
            hits += usize::from(nearest.is_some());
        }
        assert!(
            hits > 100,
            "too few hits ({hits}) for the test to mean much"
        );
    }
}

#[test]
fn nearest_first_visits_fewer_nodes_than_the_tree_has() {
    // With 400 scattered boxes, a ray that hits something early must not walk the whole tree.
    let mut rng = Rng::new(2);
    let boxes = random_boxes(&mut rng, 400);
    let bvh = Bvh::build(&boxes);
    let mut visited = 0;
    for _ in 0..200 {
        let ray = random_ray(&mut rng);
        visited += bvh.traverse(&ray, |_, _| None).nodes_visited;
    }
    assert!((visited as f64 / 200.0) < bvh.node_count() as f64 / 4.0);
}

#[test]
fn any_hit_equals_brute_force() {
    let mut rng = Rng::new(3);
    for &n in &[1usize, 2, 9, 300] {
        let boxes = random_boxes(&mut rng, n);
        let spheres: Vec<_> = boxes.iter().map(inner_sphere).collect();
        let bvh = Bvh::build(&boxes);
        for _ in 0..500 {
            let mut ray = random_ray(&mut rng);
            ray.tmax = rng.range(0.0, 1.2);
            let mut calls_after_hit = 0;
            let mut found = false;
            let (any, _) = bvh.traverse_any(&ray, |prim| {
                calls_after_hit += u32::from(found);
                found |= ray_sphere(&ray, spheres[prim as usize], ray.tmin, ray.tmax).is_some();
                found
            });
            assert_eq!(any, brute_nearest(&spheres, &ray).is_some(), "n = {n}");
            assert_eq!(calls_after_hit, 0, "traverse_any went on after a hit");
        }
    }
}

#[test]
fn empty_tree_visits_nothing() {
    let bvh = Bvh::build(&[]);
    let mut rng = Rng::new(4);
    let ray = random_ray(&mut rng);
    let stats = bvh.traverse(&ray, |_, _| panic!("no primitives to call"));
    assert_eq!(stats.nodes_visited, 0);
    assert!(!bvh.traverse_any(&ray, |_| true).0);
}

/// A cull margin grows every box by that much on each side, and by nothing else: rays
/// running in the plane of a flat box (a patch lying in a coordinate plane), with a
/// direction component of 0, -0 or ±1e-18 across it, enter the box when they pass within
/// the margin and not when they pass twice as far; with no margin, one ulp off the plane
/// is a miss.
#[test]
fn cull_margin_grows_boxes_by_the_margin() {
    use glam::Vec3;
    use patchtrace::geom::{Aabb, Ray};
    use std::ops::ControlFlow;
    // Several boxes, so that the flat one sits below a wide inner node.
    let flat = Aabb {
        min: Vec3::new(0.0, 0.0, 0.5),
        max: Vec3::new(1.0, 1.0, 0.5),
    };
    let others: Vec<Aabb> = (1..6)
        .map(|k| Aabb {
            min: Vec3::new(3.0 * k as f32, 0.0, 0.0),
            max: Vec3::new(3.0 * k as f32 + 1.0, 1.0, 1.0),
        })
        .collect();
    let boxes: Vec<Aabb> = std::iter::once(flat).chain(others).collect();
    let bvh = Bvh::build(&boxes);
    let enters_flat = |ray: &Ray, margin: f32| {
        let mut seen = false;
        bvh.traverse_leaves(ray, margin, |range, _| {
            seen |= bvh.prim_indices()[range].contains(&0);
            ControlFlow::Continue(())
        });
        seen
    };
    let margin = 1e-5;
    for across in [0.0, -0.0, 1e-18, -1e-18] {
        let ray_at = |z: f32| Ray {
            origin: Vec3::new(-1.0, 0.2, z),
            dir: Vec3::new(1.0, 0.3, across),
            tmin: 0.0,
            tmax: f32::INFINITY,
        };
        for side in [1.0f32, -1.0] {
            let z = |offset: f32| 0.5 + side * offset;
            assert!(
                enters_flat(&ray_at(z(0.5 * margin)), margin),
                "{across} {side}"
            );
            assert!(
                !enters_flat(&ray_at(z(2.0 * margin)), margin),
                "{across} {side}"
            );
            let one_ulp = if side > 0.0 {
                0.5f32.next_up()
            } else {
                0.5f32.next_down()
            };
            assert!(!enters_flat(&ray_at(one_ulp), 0.0), "{across} {side}");
            assert!(enters_flat(&ray_at(one_ulp), margin), "{across} {side}");
        }
        // Beside the box rather than above it: the margin applies on every axis.
        let beside = Ray {
            origin: Vec3::new(-1.0, 1.0 + 0.5 * margin, 0.5),
            dir: Vec3::new(1.0, across, 0.0),
            tmin: 0.0,
            tmax: f32::INFINITY,
        };
        assert!(enters_flat(&beside, margin), "{across}");
        assert!(!enters_flat(&beside, 0.0), "{across}");
    }
}
