//! The search of Lischinski & Gonczarowski 1990, §4.2, on a surface tree: the ray first
//! descends the cached tree to the leaves whose boxes it hits ("only the parametric
//! subregions corresponding to those leaves ... need be searched"); each candidate then
//! goes through the same steps as Toth's search ([`examine`]), and an undecided box is
//! quartered (step 8), its quarters kept when they overlap `K` and the ray hits their
//! boxes (step 9). Quarters are new tree nodes down to [`CachedConfig::max_depth`];
//! below it they are searched but not cached (the paper's conclusion, §8).

use std::collections::BinaryHeap;

use crate::geom::interval::IntervalNet;
use crate::geom::trim::PatchTrim;
use crate::geom::{BezierPatch, Ray};
use crate::kernel::PatchHit;
use crate::kernel::toth::TothStats;
use crate::kernel::toth::search::{self, Goal, Nets, PatchRay, Step, examine, final_box};

use super::CachedConfig;
use super::stats::CachedStats;
use super::tree::{SurfaceTree, quarters};

/// A candidate box: a tree node, or a region below the depth limit (`node` is `None`).
type Candidate = search::Candidate<Option<u32>>;

/// Per-thread buffers: the Toth nets, the nets for node boxes, the candidate list and the
/// descent stack.
#[derive(Default)]
pub struct Scratch {
    nets: Nets,
    box_nets: [IntervalNet; 2],
    candidates: BinaryHeap<Candidate>,
    stack: Vec<u32>,
}

impl Scratch {
    /// The nets [`SurfaceTree::new`] and [`SurfaceTree::split`] compute boxes in.
    pub fn box_nets(&mut self) -> &mut [IntervalNet; 2] {
        &mut self.box_nets
    }
}

/// Searches `patch` for the nearest hit (or any, with `Goal::Any`) starting from the
/// leaves of `tree` that the ray hits, growing the tree where boxes stay undecided;
/// `origin` when the ray leaves this patch (LG90 §6's triviality tests apply).
pub fn search(
    patch: &BezierPatch,
    ray: &Ray,
    cfg: &CachedConfig,
    (goal, origin, trim): (Goal, bool, Option<&PatchTrim>),
    tree: &mut SurfaceTree,
    s: &mut Scratch,
    (toth, cache): (&mut TothStats, &mut CachedStats),
) -> Option<PatchHit> {
    let inv = ray.dir.recip();
    let hits_box = |t: &SurfaceTree, i: u32, tmax: f64, c: &mut CachedStats, trivial: &mut u64| {
        c.tree_box_tests += 1;
        let b = t.node(i).bounds;
        let hit = b.intersect(ray.origin, inv, ray.tmin, tmax as f32);
        // Triviality test 1 (LG90 §6) on the surface of origin: the box lies across the
        // ray wholly before its start. Counted by a second test, on that surface only.
        if hit.is_none() && origin {
            let before = b.intersect(ray.origin, inv, f32::NEG_INFINITY, tmax as f32);
            *trivial += before.is_some() as u64;
        }
        hit.map(|(t0, _)| t0 as f64)
    };
    s.candidates.clear();
    s.stack.clear();
    s.stack.push(0);
    while let Some(i) = s.stack.pop() {
        let Some(t_lo) = hits_box(tree, i, ray.tmax as f64, cache, &mut toth.trivial[0]) else {
            continue;
        };
        let n = tree.node(i);
        match n.children {
            Some(c) => s.stack.extend(c..c + 4),
            None => s.candidates.push(Candidate {
                t_lo,
                region: n.region,
                node: Some(i),
            }),
        }
    }
    if s.candidates.is_empty() {
        // The ray misses every leaf: the surface is not searched (LG90 §7.1).
        return None;
    }
    toth.searches += 1;
    let pr = PatchRay::new(patch, ray, &cfg.toth, origin, &mut s.nets);
    let mut tmax = ray.tmax as f64;
    let mut best: Option<PatchHit> = None;
    let start = toth.search_iterations;
    while let Some(c) = s.candidates.pop() {
        if c.t_lo > tmax {
            break;
        }
        if toth.search_iterations - start >= cfg.toth.max_iterations as u64 {
            toth.cut_off += 1;
            break;
        }
        // A cached leaf's stored sub-net, projected into the ray's frame, replaces
        // subdividing the patch's projected net down to the leaf's box.
        let leaf = c.node.and_then(|i| tree.leaf_net(i));
        match leaf {
            Some(net) => {
                let (nu, nv) = (patch.degree_u() + 1, patch.degree_v() + 1);
                pr.frame()
                    .project_enclosed(net.centres, net.radius, nu, nv, s.nets.sub_mut());
            }
            None => s.nets.subdivide_to(&c.region),
        }
        let hit = match examine(&pr, &mut s.nets, &c.region, tmax, &cfg.toth, goal, toth) {
            Step::Miss => None,
            Step::Hit(h) => Some(h),
            Step::Undecided { region, ray_box } => {
                let cached = c
                    .node
                    .filter(|&i| tree.node(i).depth < cfg.max_depth)
                    .and_then(|i| {
                        let before = tree.len();
                        let first = tree.split(i, patch, &mut s.box_nets)?;
                        cache.nodes_created += (tree.len() - before) as u64;
                        Some(first)
                    });
                match (cached, quarters(&c.region)) {
                    (Some(first), _) => {
                        cache.subdivisions += 1;
                        for i in first..first + 4 {
                            let q = tree.node(i).region;
                            if q.intersect(&region).is_none() {
                                continue;
                            }
                            let trivial = &mut toth.trivial[0];
                            if let Some(t_lo) = hits_box(tree, i, tmax, cache, trivial) {
                                s.candidates.push(Candidate {
                                    t_lo,
                                    region: q,
                                    node: Some(i),
                                });
                            }
                        }
                        None
                    }
                    (None, Some(qs)) => {
                        cache.subdivisions += 1;
                        cache.uncached_subdivisions += 1;
                        for q in qs {
                            if q.intersect(&region).is_some() {
                                s.candidates.push(Candidate {
                                    t_lo: ray_box.t.lo(),
                                    region: q,
                                    node: None,
                                });
                            }
                        }
                        None
                    }
                    // Too narrow to quarter in f64: answer it like a final box.
                    (None, None) => final_box(&pr, &mut s.nets, &region, &ray_box, toth),
                }
            }
        };
        if let Some(h) = hit.filter(|h| search::kept(trim, h)) {
            if goal == Goal::Any {
                return Some(h);
            }
            tmax = h.t as f64;
            best = Some(h);
        }
    }
    best
}
