//! The pack-priced builder (`Bvh::build_packed`): its leaf decision against the SAH worked
//! out by hand, and its trees, on mixed packed and unpacked primitives, against brute force.

use crate::bvh_support;

use bvh_support::{Rng, brute_nearest, inner_sphere, random_boxes, random_ray, ray_sphere};
use glam::Vec3;
use patchtrace::accel::bvh::Bvh;
use patchtrace::geom::Aabb;

/// Two far-apart unit cubes in a root box [0,6]³ of area 216; each child box has area 6.
/// Splitting costs 216 (the node) + 6 + 6 (one test per child); a leaf costs 216 per
/// primitive when unpacked, and 216 for one pack when both are packed.
#[test]
fn a_pack_of_primitives_stays_one_leaf_where_single_ones_split() {
    let a = Aabb::new(Vec3::ZERO, Vec3::ONE);
    let b = Aabb::new(Vec3::splat(5.0), Vec3::splat(6.0));
    // Both packed: leaf 216 < split 228.
    assert_eq!(Bvh::build_packed(&[a, b], 0).node_count(), 1);
    // Neither packed: leaf 432 > split 228.
    assert_eq!(Bvh::build_packed(&[a, b], 2).node_count(), 3);
    // One of each: leaf 216 + 216 = 432 > split 228.
    assert_eq!(Bvh::build_packed(&[a, b], 1).node_count(), 3);
}

#[test]
fn packed_trees_find_the_brute_force_nearest_hit() {
    let mut rng = Rng::new(7);
    for &(n, first_packed) in &[(5usize, 0usize), (60, 20), (400, 0), (400, 150)] {
        let boxes = random_boxes(&mut rng, n);
        let spheres: Vec<_> = boxes.iter().map(inner_sphere).collect();
        let bvh = Bvh::build_packed(&boxes, first_packed);
        let mut seen = vec![0u32; n];
        for node in bvh.nodes().iter().filter(|node| node.is_leaf()) {
            let range = node.first as usize..(node.first + node.count) as usize;
            for &p in &bvh.prim_indices()[range] {
                seen[p as usize] += 1;
            }
        }
        assert!(seen.iter().all(|&s| s == 1), "a primitive not in one leaf");
        for _ in 0..300 {
            let mut ray = random_ray(&mut rng);
            if rng.range(0.0, 1.0) < 0.5 {
                let target = boxes[rng.next_u64() as usize % n].center();
                ray.dir = target - ray.origin;
            }
            let mut nearest: Option<(f32, u32)> = None;
            bvh.traverse(&ray, |prim, tmax| {
                let t = ray_sphere(&ray, spheres[prim as usize], ray.tmin, tmax)?;
                if nearest.is_none_or(|(best, _)| t < best) {
                    nearest = Some((t, prim));
                }
                Some(t)
            });
            assert_eq!(nearest, brute_nearest(&spheres, &ray), "n = {n}");
        }
    }
}
