//! The stack-based subdivision search of Dammertz §2.2–2.3 (algorithm 2.2.1, code 2.3.8),
//! written once for every control-net storage ([`NetStack`]) and both precisions.
//!
//! The current sub-patch is split at 1/2 in place; both children's boxes are tested against
//! the ray at once, the nearer hit child is continued with and the farther pushed (the
//! "nearer side first" optimisation of §2.5, which needs no copy here because the net
//! storage writes the children where they belong). Whether a child is a final box is
//! [`Stop::is_final`]: a hit at its entry `t`, which shortens the ray so that farther stack
//! entries are dropped.

use super::config::{SubdivisionConfig, Termination};
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
    /// An L1 diameter below which boxes are rounding noise of the net the stack's nets
    /// came from (a net transformed into another frame is no more precise than its
    /// source): the end game stops there at the latest. Zero for nets searched as built.
    fn end_game_floor(&self) -> T {
        T::ZERO
    }
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
    let stop = Stop::new(cfg, &root, ray, rational, nets.end_game_floor());
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
                let b = boxes[i];
                Node {
                    bbox: b,
                    t_enter,
                    cell,
                    is_final: stop.is_final(&b, d, cell, t_enter),
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

/// The end-game L1 diameter of a search from `root`: `end_ulps` ulps of the largest
/// coordinate magnitude of the box (see [`Stop`]).
pub fn end_game_diameter<T: KernelFloat>(root: &GBox<T>, end_ulps: u32) -> T {
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

/// The termination test of one search, with what depends only on the root box and the
/// ray computed once.
struct Stop<T> {
    /// The end-game L1 diameter: `end_ulps` ulps of the largest coordinate magnitude of
    /// the root box. The net's rounding error grows from that scale (every de Casteljau
    /// average rounds to it), so a box narrower than a few of its ulps is noise.
    end_diameter: T,
    /// The mantissa distance of §2.7.2 when the patch is rational.
    rational_dist: Option<u32>,
    criterion: Criterion<T>,
}

/// The part of [`Termination`] beyond the guards, in the search's float type.
enum Criterion<T> {
    Float,
    /// Total splits (`level_u + level_v`) at which a cell is final.
    Depth(u8),
    /// `c (dir · f)` of [`super::config::ScreenFootprint`]: a box entered at `t` is final
    /// when its L1 diameter is at most this times `t`.
    Adaptive(T),
}

impl<T: KernelFloat> Stop<T> {
    fn new(
        cfg: &SubdivisionConfig,
        root: &GBox<T>,
        ray: &GRay<T>,
        rational: bool,
        floor: T,
    ) -> Self {
        let criterion = match cfg.termination {
            Termination::Float => Criterion::Float,
            Termination::Depth(d) => Criterion::Depth(d),
            Termination::Adaptive(fp) => {
                let along = (0..3)
                    .map(|i| ray.dir[i] * T::from_f64(fp.forward[i] as f64))
                    .fold(T::ZERO, |a, b| a + b);
                Criterion::Adaptive(T::from_f64(fp.half_pixel as f64) * along)
            }
        };
        Stop {
            end_diameter: end_game_diameter(root, cfg.end_ulps).max(floor),
            rational_dist: rational.then_some(cfg.rational_dist),
            criterion,
        }
    }

    /// Whether a child box `b` of a parent with L1 diameter `parent_diameter`, with
    /// parameter cell `cell`, entered by the ray at `t_enter`, is final: the guards of
    /// [`Termination`], then the selected criterion.
    #[inline(always)]
    fn is_final(&self, b: &GBox<T>, parent_diameter: T, cell: ParamCell, t_enter: T) -> bool {
        let (lu, lv) = cell.levels();
        let bd = b.l1_diameter();
        bd >= parent_diameter
            || bd < self.end_diameter
            || (lu >= T::MAX_LEVEL && lv >= T::MAX_LEVEL)
            || self
                .rational_dist
                .is_some_and(|dist| b.mantissa_close(dist))
            || match self.criterion {
                Criterion::Float => false,
                Criterion::Depth(d) => lu as u32 + lv as u32 >= d as u32,
                Criterion::Adaptive(k) => bd <= k * t_enter,
            }
    }
}
