//! The stack-based subdivision search of Dammertz §2.2–2.3 (algorithm 2.2.1, code 2.3.8),
//! written once for every control-net storage ([`NetStack`]) and both precisions.
//!
//! The current sub-patch is split at 1/2 in place; both children's boxes are tested against
//! the ray at once, the nearer hit child is continued with and the farther pushed (the
//! "nearer side first" optimisation of §2.5, which needs no copy here because the net
//! storage writes the children where they belong). A child whose box did not shrink in the
//! L1 diameter (§2.3.3: a convex combination of neighbouring floats returns one of them, so
//! the box stops changing at full precision) or, for a rational patch, whose box corners
//! are within the mantissa distance (§2.7.2), or whose L1 diameter is below the end-game
//! threshold ([`SubdivisionConfig::end_ulps`]), or whose parameter cell reached the depth
//! limit ([`super::param`]), is a final box: a hit at its entry `t`, which shortens the ray
//! so that farther stack entries are dropped.

use super::config::SubdivisionConfig;
use super::float::{GBox, GRay, KernelFloat};
use super::heuristics::{Corners, choose};
use super::param::{ParamCell, Split};
use crate::kernel::KernelStats;

/// Storage of the control nets of the current sub-patch and of the pushed ones.
pub trait NetStack<T: KernelFloat> {
    /// Corner points of the current net for the split heuristics.
    fn corners(&self) -> Corners<T>;
    /// Splits the current net at 1/2 in `dir` into a lower and an upper child, both pending,
    /// and returns their boxes (lower first), each with the entry `t` of the slab test
    /// ([`KernelFloat::slab`]) against `ray` clipped to `tmax` if the ray hits it. The split
    /// and the test are one step so that the fast paths can compute both boxes and both
    /// tests together in SIMD registers.
    fn split_test(&mut self, dir: Split, ray: &GRay<T>, tmax: T) -> [(GBox<T>, Option<T>); 2];
    /// Both pending children are hit: push the farther one, continue with the nearer.
    fn push_far(&mut self, far_is_lower: bool);
    /// Only one pending child is hit: continue with it, drop the other.
    fn keep(&mut self, lower: bool);
    /// Drop the current net and continue with the most recently pushed one.
    fn pop(&mut self);
}

/// What the search keeps per sub-patch besides its control net.
#[derive(Clone, Copy, Debug)]
pub struct Node<T> {
    pub bbox: GBox<T>,
    pub t_enter: T,
    pub cell: ParamCell,
    is_final: bool,
}

/// A final box hit by the ray.
#[derive(Clone, Copy, Debug)]
pub struct SearchHit<T> {
    pub t: T,
    pub cell: ParamCell,
    pub bbox: GBox<T>,
}

/// Runs the search from the root net (already in `nets`, with box `root`). `nodes` is
/// reused scratch (cleared here). With `any_hit` the first final box ends the search.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub fn search<T: KernelFloat, S: NetStack<T>>(
    nets: &mut S,
    nodes: &mut Vec<Node<T>>,
    root: GBox<T>,
    ray: &GRay<T>,
    rational: bool,
    cfg: &SubdivisionConfig,
    any_hit: bool,
    stats: &mut KernelStats,
) -> Option<SearchHit<T>> {
    stats.patch_tests += 1;
    stats.box_tests += 1;
    let mut tmax = ray.tmax;
    let (t_enter, _) = T::slab(&root, ray, tmax)?;
    nodes.clear();
    let mut cur = Node {
        bbox: root,
        t_enter,
        cell: ParamCell::ROOT,
        is_final: false,
    };
    let mut best: Option<SearchHit<T>> = None;
    let max = T::MAX_LEVEL;
    let end_diameter = end_game_diameter(&root, cfg.end_ulps);
    loop {
        // A popped entry was tested against an older, longer ray; after a hit only strictly
        // nearer boxes matter.
        let live = cur.t_enter <= tmax && (best.is_none() || cur.t_enter < tmax);
        if live && cur.is_final {
            best = Some(SearchHit {
                t: cur.t_enter,
                cell: cur.cell,
                bbox: cur.bbox,
            });
            tmax = cur.t_enter;
            if any_hit {
                return best;
            }
        } else if live {
            let (lu, lv) = cur.cell.levels();
            let dir = if lu >= max {
                Split::V
            } else if lv >= max {
                Split::U
            } else {
                choose(cfg.heuristic, &nets.corners(), ray.dir)
            };
            stats.splits += 1;
            stats.box_tests += 2;
            let [(box0, hit0), (box1, hit1)] = nets.split_test(dir, ray, tmax);
            let boxes = [box0, box1];
            let cells = cur.cell.split(dir);
            let d = cur.bbox.l1_diameter();
            let child = |i: usize, t_enter: T| {
                let cell = if i == 0 { cells.0 } else { cells.1 };
                let (lu, lv) = cell.levels();
                let b = boxes[i];
                let bd = b.l1_diameter();
                Node {
                    bbox: b,
                    t_enter,
                    cell,
                    is_final: bd >= d
                        || bd < end_diameter
                        || (lu >= max && lv >= max)
                        || (rational && b.mantissa_close(cfg.rational_dist)),
                }
            };
            match (hit0, hit1) {
                (Some(t0), Some(t1)) => {
                    let far_is_lower = t1 < t0;
                    nets.push_far(far_is_lower);
                    if far_is_lower {
                        nodes.push(child(0, t0));
                        cur = child(1, t1);
                    } else {
                        nodes.push(child(1, t1));
                        cur = child(0, t0);
                    }
                    continue;
                }
                (Some(t0), None) => {
                    nets.keep(true);
                    cur = child(0, t0);
                    continue;
                }
                (None, Some(t1)) => {
                    nets.keep(false);
                    cur = child(1, t1);
                    continue;
                }
                (None, None) => {}
            }
        }
        match nodes.pop() {
            Some(n) => {
                nets.pop();
                cur = n;
            }
            None => return best,
        }
    }
}

/// The L1 diameter below which a box is final: `end_ulps` ulps of the largest coordinate
/// magnitude of the root box. The net's rounding error grows from that scale (every de
/// Casteljau average rounds to it), so a box narrower than a few of its ulps is noise.
fn end_game_diameter<T: KernelFloat>(root: &GBox<T>, end_ulps: u32) -> T {
    let scale = (0..3)
        .map(|i| {
            root.min[i]
                .max(-root.min[i])
                .max(root.max[i])
                .max(-root.max[i])
        })
        .fold(T::ZERO, |a, b| a.max(b));
    (scale.next_up() - scale) * T::from_f64(end_ulps as f64)
}
