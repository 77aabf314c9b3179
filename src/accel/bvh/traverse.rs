//! Stack-based traversal of the wide tree, nearer children first (Dammertz §3.2; Dammertz,
//! Hanika and Keller 2008 §2.2): one SIMD slab test decides all four children of a node, the
//! nearest child the ray enters is visited next and the others are pushed with their entry
//! `t`, farthest first, so that once a hit has shortened the ray, pushed subtrees beyond it
//! are skipped unvisited.

use std::mem::MaybeUninit;
use std::ops::ControlFlow;

use glam::Vec4;

use super::wide::{Child, WIDTH};
use super::{Bvh, MAX_DEPTH};
use crate::geom::Ray;
use crate::geom::bbox::SLAB_FAR_SCALE;

/// Work done by one traversal, for `--stats`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct TraversalStats {
    /// Nodes whose contents were examined (wide inner nodes and leaves).
    pub nodes_visited: u64,
    /// Ray–box tests against node boxes (four per wide node, one SIMD test).
    pub box_tests: u64,
}

/// The ray in the form the 4-wide slab test wants: reciprocal direction splat per axis, per
/// axis the index in [`WideNode::planes`](super::wide::WideNode) of the box plane the ray
/// meets first (`near`) and last (`far`), and the origin as each of those planes sees it.
///
/// A cull margin `m` grows every box by `m` on each side: the near plane moves back by `m`
/// and the far plane forward, which is the plane unmoved against an origin moved the other
/// way (`min - m - o = min - (o + m)` going up an axis). So the margin costs nothing per box
/// test: `origin_near` is `o + m` going up an axis and `o - m` going down, `origin_far` the
/// reverse.
struct WideRay {
    origin_near: [Vec4; 3],
    origin_far: [Vec4; 3],
    inv_dir: [Vec4; 3],
    near: [usize; 3],
    far: [usize; 3],
}

impl WideRay {
    fn new(ray: &Ray, margin: f32) -> WideRay {
        let inv = ray.dir.recip();
        // 1 / -0 is -inf: a ray with a -0 component counts as going down that axis.
        let negative = [0, 1, 2].map(|k| usize::from(inv[k] < 0.0));
        let toward_near = [0, 1, 2].map(|k| if negative[k] == 1 { -margin } else { margin });
        WideRay {
            origin_near: [0, 1, 2].map(|k| Vec4::splat(ray.origin[k] + toward_near[k])),
            origin_far: [0, 1, 2].map(|k| Vec4::splat(ray.origin[k] - toward_near[k])),
            inv_dir: [0, 1, 2].map(|k| Vec4::splat(inv[k])),
            near: [0, 1, 2].map(|k| k + 3 * negative[k]),
            far: [0, 1, 2].map(|k| k + 3 * (1 - negative[k])),
        }
    }

    /// Entry and exit `t` of the four child boxes with `planes`, clipped to `[tmin, tmax]`;
    /// a lane is hit when entry <= exit. The robust slab test of [`crate::geom::bbox::slab`]
    /// on four boxes: the near plane of each axis is picked by the direction's sign, so an
    /// empty box (`min > max`) gives entry +inf and exit -inf. `0 * inf` (the origin on a
    /// plane the ray runs in) gives NaN, and that slab must bound nothing: `a.max(b)` and
    /// `a.min(b)` return `b` when `a` is NaN (SSE `maxps`/`minps`; `f32::max` ignores NaN
    /// either way), so each chain starts from the slab values and ends in a number.
    #[inline(always)]
    fn slab4(&self, planes: &[Vec4; 6], tmin: f32, tmax: f32) -> (Vec4, Vec4) {
        let t_near = |k: usize| (planes[self.near[k]] - self.origin_near[k]) * self.inv_dir[k];
        let t_far = |k: usize| (planes[self.far[k]] - self.origin_far[k]) * self.inv_dir[k];
        let enter = t_near(0).max(t_near(1).max(t_near(2).max(Vec4::splat(tmin))));
        let exit = t_far(0).min(t_far(1).min(t_far(2).min(Vec4::splat(f32::INFINITY))));
        (enter, (exit * SLAB_FAR_SCALE).min(Vec4::splat(tmax)))
    }
}

impl Bvh {
    /// Nearest-first traversal: calls `hit(prim, tmax)` for each primitive in a leaf whose box
    /// the ray enters before the current `tmax` (starting at `ray.tmax`); a returned `t`
    /// shortens `tmax` for the rest of the walk. A primitive may be called after a nearer hit
    /// is known only when its leaf box starts before that hit.
    pub fn traverse<F: FnMut(u32, f32) -> Option<f32>>(
        &self,
        ray: &Ray,
        mut hit: F,
    ) -> TraversalStats {
        self.traverse_leaves(ray, 0.0, |range, tmax| {
            for &prim in &self.prim_indices[range] {
                if let Some(t) = hit(prim, *tmax) {
                    *tmax = tmax.min(t);
                }
            }
            ControlFlow::Continue(())
        })
    }

    /// Any-hit traversal for shadow rays: calls `hit(prim)` for primitives in leaves the ray
    /// enters within `[ray.tmin, ray.tmax]` and stops at the first that returns `true`.
    pub fn traverse_any<F: FnMut(u32) -> bool>(
        &self,
        ray: &Ray,
        mut hit: F,
    ) -> (bool, TraversalStats) {
        let mut found = false;
        let stats = self.traverse_leaves(ray, 0.0, |range, _| {
            if self.prim_indices[range].iter().any(|&p| hit(p)) {
                found = true;
                ControlFlow::Break(())
            } else {
                ControlFlow::Continue(())
            }
        });
        (found, stats)
    }

    /// The walk itself, a leaf at a time: `visit(range, &mut tmax)` gets the leaf's range of
    /// [`prim_indices`](Bvh::prim_indices) (leaves own disjoint ranges, so callers can keep
    /// per-leaf data in that order) and may shorten the ray or stop the walk. Leaves are
    /// offered nearest entry first, and only while their entry is within `tmax`. Every box
    /// is grown by `margin` on each side (0 for the exact boxes): the leaves of primitives
    /// whose kernel may find a hit a little outside their box need it (patches in ray
    /// space, [`crate::kernel::subdivision::cull_margin`]).
    #[inline(always)]
    pub fn traverse_leaves<F>(&self, ray: &Ray, margin: f32, mut visit: F) -> TraversalStats
    where
        F: FnMut(std::ops::Range<usize>, &mut f32) -> ControlFlow<()>,
    {
        let mut stats = TraversalStats::default();
        // The stack bound below rests on unused lanes (empty boxes) never being entered,
        // which holds only for a finite origin and direction: from an infinite origin every
        // plane is at t = +inf (or NaN), so `enter <= exit` holds in every lane, the unused
        // lanes' child (index 0, the root) is pushed again and again, and the stack
        // overflows (origin 4e38 rounds to inf in f32). With finite values an
        // empty lane's near plane is +inf and its far plane -inf on every axis (the
        // reciprocal of a finite direction is never 0), so it is never entered. Such a ray
        // meets nothing the kernels could represent anyway.
        if self.wide.is_empty() || !(ray.origin.is_finite() && ray.dir.is_finite()) {
            return stats;
        }
        let wray = WideRay::new(ray, margin);
        let tmin = ray.tmin;
        let mut tmax = ray.tmax;
        // Each wide level pushes at most WIDTH - 1 entries, and what is on the stack was
        // pushed by ancestors of the current node (a popped entry's siblings and the
        // entries below them were); the wide tree is no deeper than the binary one, which
        // the builder and `validate` keep below MAX_DEPTH. Left
        // uninitialised: zeroing its 1.5 KB was two thirds of the instructions per ray
        // (callgrind, BENCHMARKS.md, scenes at scale).
        let mut stack = [MaybeUninit::<(Child, f32)>::uninit(); (WIDTH - 1) * MAX_DEPTH];
        let mut top = 0;
        let mut current = Child { index: 0, count: 0 };
        loop {
            stats.nodes_visited += 1;
            let mut next = None;
            if current.count > 0 {
                let first = current.index as usize;
                let range = first..first + current.count as usize;
                if visit(range, &mut tmax).is_break() {
                    return stats;
                }
            } else {
                let node = &self.wide[current.index as usize];
                stats.box_tests += WIDTH as u64;
                let (enter, exit) = wray.slab4(&node.planes, tmin, tmax);
                let mut mask = enter.cmple(exit).bitmask();
                // Most nodes a primary ray enters have one or two children hit: those
                // cases take no sort. The nearest child is visited straight away, the
                // others are pushed farthest first so the nearest of them is popped next.
                if mask != 0 {
                    let a = mask.trailing_zeros() as usize;
                    mask &= mask - 1;
                    if mask == 0 {
                        next = Some(node.children[a]);
                    } else {
                        let b = mask.trailing_zeros() as usize;
                        mask &= mask - 1;
                        // Ties go to the later lane, as the insertion sort below orders them.
                        let (near, far) = if enter[a] < enter[b] { (a, b) } else { (b, a) };
                        if mask == 0 {
                            stack[top].write((node.children[far], enter[far]));
                            top += 1;
                            next = Some(node.children[near]);
                        } else {
                            let mut hits = [(node.children[far], enter[far]); WIDTH];
                            hits[1] = (node.children[near], enter[near]);
                            let mut n = 2;
                            while mask != 0 {
                                let lane = mask.trailing_zeros() as usize;
                                mask &= mask - 1;
                                let entry = (node.children[lane], enter[lane]);
                                // Insertion sort by decreasing entry t: at most four elements.
                                let mut i = n;
                                while i > 0 && hits[i - 1].1 < entry.1 {
                                    hits[i] = hits[i - 1];
                                    i -= 1;
                                }
                                hits[i] = entry;
                                n += 1;
                            }
                            for &entry in &hits[..n - 1] {
                                stack[top].write(entry);
                                top += 1;
                            }
                            next = Some(hits[n - 1].0);
                        }
                    }
                }
            }
            current = match next {
                Some(child) => child,
                None => loop {
                    if top == 0 {
                        return stats;
                    }
                    top -= 1;
                    // SAFETY: entries below `top` were written by the pushes above.
                    let (pushed, t_enter) = unsafe { stack[top].assume_init() };
                    // Skip subtrees that start beyond a hit found since they were pushed.
                    if t_enter <= tmax {
                        break pushed;
                    }
                },
            };
        }
    }
}
