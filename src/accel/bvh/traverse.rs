//! Stack-based traversal, nearer child first (Dammertz §3.2): both child boxes are tested, the
//! one the ray enters first is visited next and the other is pushed with its entry `t`, so
//! that once a hit has shortened the ray, pushed subtrees beyond it are skipped unvisited.

use std::ops::ControlFlow;

use super::{Bvh, MAX_DEPTH};
use crate::geom::Ray;

/// Work done by one traversal, for `--stats`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct TraversalStats {
    /// Nodes whose contents were examined (inner nodes and leaves).
    pub nodes_visited: u64,
    /// Ray–box tests against node boxes.
    pub box_tests: u64,
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
        self.walk(ray, |prim, tmax| {
            if let Some(t) = hit(prim, *tmax) {
                *tmax = tmax.min(t);
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
        let stats = self.walk(ray, |prim, _| {
            if hit(prim) {
                found = true;
                ControlFlow::Break(())
            } else {
                ControlFlow::Continue(())
            }
        });
        (found, stats)
    }

    /// The shared walk: `visit(prim, &mut tmax)` may shorten the ray or stop the walk.
    #[inline(always)]
    fn walk<F>(&self, ray: &Ray, mut visit: F) -> TraversalStats
    where
        F: FnMut(u32, &mut f32) -> ControlFlow<()>,
    {
        let mut stats = TraversalStats::default();
        let Some(root) = self.nodes.first() else {
            return stats;
        };
        let origin = ray.origin;
        let inv_dir = ray.dir.recip();
        let tmin = ray.tmin;
        let mut tmax = ray.tmax;
        stats.box_tests += 1;
        if root.bounds.intersect(origin, inv_dir, tmin, tmax).is_none() {
            return stats;
        }
        // At most one push per level (the far child), so MAX_DEPTH entries suffice: the builder
        // and `validate` keep every node above that depth.
        let mut stack = [(0u32, 0.0f32); MAX_DEPTH];
        let mut top = 0;
        let mut node = 0usize;
        loop {
            stats.nodes_visited += 1;
            let n = &self.nodes[node];
            let first = n.first as usize;
            let mut next = None;
            if n.is_leaf() {
                for &prim in &self.prim_indices[first..first + n.count as usize] {
                    if visit(prim, &mut tmax).is_break() {
                        return stats;
                    }
                }
            } else {
                stats.box_tests += 2;
                let hit = |i: usize| self.nodes[i].bounds.intersect(origin, inv_dir, tmin, tmax);
                next = match (hit(first), hit(first + 1)) {
                    (Some((ta, _)), Some((tb, _))) => {
                        let (near, far, t_far) = if tb < ta {
                            (first + 1, first, ta)
                        } else {
                            (first, first + 1, tb)
                        };
                        stack[top] = (far as u32, t_far);
                        top += 1;
                        Some(near)
                    }
                    (Some(_), None) => Some(first),
                    (None, Some(_)) => Some(first + 1),
                    (None, None) => None,
                };
            }
            node = match next {
                Some(child) => child,
                None => loop {
                    if top == 0 {
                        return stats;
                    }
                    top -= 1;
                    let (pushed, t_enter) = stack[top];
                    // Skip subtrees that start beyond a hit found since they were pushed.
                    if t_enter <= tmax {
                        break pushed as usize;
                    }
                },
            };
        }
    }
}
