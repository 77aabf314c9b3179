//! Builder edge cases and invariants, each checked against an independent computation: box
//! containment, every primitive in exactly one leaf, the depth bound, the SAH cost in closed
//! form, and traversal against brute force on degenerate and huge boxes.

use crate::bvh_support;

use bvh_support::{Rng, random_boxes};
use glam::Vec3;
use patchtrace::accel::bvh::{Bvh, MAX_DEPTH, Node};
use patchtrace::geom::{Aabb, Ray};

fn contains(outer: &Aabb, inner: &Aabb) -> bool {
    outer.min.cmple(inner.min).all() && outer.max.cmpge(inner.max).all()
}

/// Walks the tree recursively (unlike the traversal's stack) and checks that node boxes
/// contain their children and primitives, that each primitive is in exactly one leaf, and
/// returns the depth of the deepest node (the root has depth 0).
fn check_structure(bvh: &Bvh, boxes: &[Aabb]) -> usize {
    fn walk(bvh: &Bvh, boxes: &[Aabb], i: usize, depth: usize, seen: &mut [u32]) -> usize {
        let n: Node = bvh.nodes()[i];
        if n.is_leaf() {
            let range = n.first as usize..(n.first + n.count) as usize;
            for &p in &bvh.prim_indices()[range] {
                assert!(
                    contains(&n.bounds, &boxes[p as usize]),
                    "leaf {i} misses prim {p}"
                );
                seen[p as usize] += 1;
            }
            depth
        } else {
            let c = n.first as usize;
            for child in [c, c + 1] {
                assert!(contains(&n.bounds, &bvh.nodes()[child].bounds));
            }
            walk(bvh, boxes, c, depth + 1, seen).max(walk(bvh, boxes, c + 1, depth + 1, seen))
        }
    }
    let mut seen = vec![0; boxes.len()];
    let depth = if bvh.node_count() == 0 {
        0
    } else {
        walk(bvh, boxes, 0, 0, &mut seen)
    };
    assert!(
        seen.iter().all(|&s| s == 1),
        "some primitive is not in exactly one leaf"
    );
    let union = boxes.iter().fold(Aabb::EMPTY, |a, b| a.union(b));
    assert_eq!(bvh.bounds(), union);
    depth
}

/// Nearest prim box entry over all boxes, with an `f64` slab test written here.
fn box_entry(b: &Aabb, ray: &Ray, tmax: f32) -> Option<f32> {
    let (o, d) = (ray.origin.as_dvec3(), ray.dir.as_dvec3());
    let (mut t0, mut t1) = (ray.tmin as f64, tmax as f64);
    for k in 0..3 {
        let (lo, hi) = (b.min[k] as f64, b.max[k] as f64);
        if d[k] == 0.0 {
            if o[k] < lo || o[k] > hi {
                return None;
            }
            continue;
        }
        let (a, c) = ((lo - o[k]) / d[k], (hi - o[k]) / d[k]);
        t0 = t0.max(a.min(c));
        t1 = t1.min(a.max(c));
    }
    (t0 <= t1).then_some(t0 as f32)
}

fn assert_traversal_matches_brute_force(boxes: &[Aabb], rays: &[Ray]) {
    let bvh = Bvh::build(boxes);
    for ray in rays {
        let brute = boxes
            .iter()
            .filter_map(|b| box_entry(b, ray, ray.tmax))
            .min_by(f32::total_cmp);
        let mut nearest: Option<f32> = None;
        bvh.traverse(ray, |p, tmax| {
            let t = box_entry(&boxes[p as usize], ray, tmax)?;
            nearest = Some(nearest.map_or(t, |n: f32| n.min(t)));
            Some(t)
        });
        assert_eq!(nearest, brute, "ray {ray:?}");
    }
}

#[test]
fn zero_one_and_two_primitives() {
    let empty = Bvh::build(&[]);
    assert_eq!((empty.node_count(), empty.prim_count()), (0, 0));
    assert_eq!(empty.bounds(), Aabb::EMPTY);
    assert_eq!(empty.sah_cost(), 0.0);

    let a = Aabb::new(Vec3::ZERO, Vec3::ONE);
    let one = Bvh::build(&[a]);
    assert_eq!(one.node_count(), 1);
    check_structure(&one, &[a]);

    let b = Aabb::new(Vec3::splat(5.0), Vec3::splat(6.0));
    let two = Bvh::build(&[a, b]);
    check_structure(&two, &[a, b]);
    // Two far-apart unit cubes: splitting costs 1 + (6 + 6) / A(root) per the SAH, far below
    // the leaf's 2, so the builder must split. Root box is [0,6]^3 with area 216.
    assert_eq!(two.node_count(), 3);
    let expected = 1.0 + 12.0 / 216.0;
    assert!(
        (two.sah_cost() as f64 - expected).abs() < 1e-6,
        "{}",
        two.sah_cost()
    );
}

#[test]
fn identical_boxes_build_a_bounded_tree() {
    let b = Aabb::new(Vec3::new(-1.0, 2.0, 3.0), Vec3::new(0.0, 2.5, 7.0));
    let boxes = vec![b; 1000];
    let bvh = Bvh::build(&boxes);
    assert!(check_structure(&bvh, &boxes) < MAX_DEPTH);
    // A ray through the box must be offered every primitive.
    let ray = Ray::new(Vec3::new(-0.5, 2.2, -10.0), Vec3::Z);
    let mut calls = 0;
    bvh.traverse(&ray, |_, _| {
        calls += 1;
        None
    });
    assert_eq!(calls, 1000);
}

#[test]
fn flat_and_point_boxes() {
    let mut rng = Rng::new(10);
    let boxes: Vec<Aabb> = (0..300)
        .map(|i| {
            let c = rng.vec(-10.0, 10.0);
            match i % 3 {
                // flat in z, like a planar patch
                0 => Aabb::new(c - Vec3::new(1.0, 0.7, 0.0), c + Vec3::new(1.0, 0.7, 0.0)),
                // flat in x and y: a segment
                1 => Aabb::new(c - Vec3::new(0.0, 0.0, 2.0), c + Vec3::new(0.0, 0.0, 2.0)),
                _ => Aabb::new(c, c),
            }
        })
        .collect();
    let bvh = Bvh::build(&boxes);
    check_structure(&bvh, &boxes);
    assert!(bvh.sah_cost().is_finite());
    let rays: Vec<Ray> = (0..300)
        .map(|_| {
            let o = rng.vec(-12.0, 12.0) + Vec3::Z * 20.0;
            Ray::new(o, rng.vec(-10.0, 10.0) - o)
        })
        .collect();
    assert_traversal_matches_brute_force(&boxes, &rays);
}

#[test]
fn huge_coordinates() {
    let mut rng = Rng::new(11);
    let big = f32::MAX / 2.0;
    let mut boxes = random_boxes(&mut rng, 100);
    for b in &mut boxes {
        *b = Aabb::new(b.min * (big / 10.0), b.max * (big / 10.0));
    }
    boxes.push(Aabb::new(Vec3::splat(-f32::MAX), Vec3::splat(f32::MAX)));
    boxes.push(Aabb::new(Vec3::splat(f32::MAX), Vec3::splat(f32::MAX)));
    let bvh = Bvh::build(&boxes);
    check_structure(&bvh, &boxes);
    let rays: Vec<Ray> = (0..200)
        .map(|_| {
            let o = rng.vec(-15.0, 15.0) * (big / 10.0);
            Ray::new(o, rng.vec(-1.0, 1.0))
        })
        .collect();
    assert_traversal_matches_brute_force(&boxes, &rays);
}

#[test]
fn exponentially_spread_boxes_respect_the_depth_limit() {
    // Centroids at 2^i: each binned split peels off only the largest few, the worst case for
    // depth. The builder must stop at MAX_DEPTH and still keep every primitive.
    let boxes: Vec<Aabb> = (0..250)
        .map(|i| {
            let x = 2f32.powi(i - 125);
            Aabb::new(Vec3::new(x, 0.0, 0.0), Vec3::new(x * 1.5, 1.0, 1.0))
        })
        .collect();
    let bvh = Bvh::build(&boxes);
    assert!(check_structure(&bvh, &boxes) < MAX_DEPTH);
    let rays: Vec<Ray> = (0..60)
        .map(|i| Ray::new(Vec3::new(2f32.powi(i * 4 - 120) * 1.2, 0.5, -5.0), Vec3::Z))
        .collect();
    assert_traversal_matches_brute_force(&boxes, &rays);
}

#[test]
fn sah_beats_a_tree_that_ignores_geometry() {
    // An independent builder: split the primitive list in the middle of its (random) order.
    fn index_order_tree(boxes: &[Aabb]) -> Bvh {
        fn node(boxes: &[Aabb], lo: usize, hi: usize, nodes: &mut Vec<Node>, i: usize) {
            let bounds = boxes[lo..hi].iter().fold(Aabb::EMPTY, |a, b| a.union(b));
            if hi - lo == 1 {
                nodes[i] = Node {
                    bounds,
                    first: lo as u32,
                    count: 1,
                };
                return;
            }
            let first = nodes.len();
            nodes[i] = Node {
                bounds,
                first: first as u32,
                count: 0,
            };
            nodes.extend([nodes[i]; 2]);
            node(boxes, lo, (lo + hi) / 2, nodes, first);
            node(boxes, (lo + hi) / 2, hi, nodes, first + 1);
        }
        let mut nodes = vec![Node {
            bounds: Aabb::EMPTY,
            first: 0,
            count: 0,
        }];
        node(boxes, 0, boxes.len(), &mut nodes, 0);
        Bvh::from_parts(nodes, (0..boxes.len() as u32).collect()).expect("valid tree")
    }
    let mut rng = Rng::new(12);
    let boxes = random_boxes(&mut rng, 500);
    let naive = index_order_tree(&boxes);
    let sah = Bvh::build(&boxes);
    assert!(
        sah.sah_cost() < 0.5 * naive.sah_cost(),
        "{} vs {}",
        sah.sah_cost(),
        naive.sah_cost()
    );
    // The closed form of the cost for the naive tree: sum of area ratios, leaves cost 1 each.
    let root = naive.bounds();
    let area = |b: &Aabb| {
        let e = (b.max - b.min).as_dvec3();
        2.0 * (e.x * e.y + e.y * e.z + e.z * e.x)
    };
    let expected: f64 = naive
        .nodes()
        .iter()
        .map(|n| area(&n.bounds) / area(&root))
        .sum();
    assert!((naive.sah_cost() as f64 - expected).abs() < 1e-4 * expected);
}
