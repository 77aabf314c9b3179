//! The stack-based subdivision search of Dammertz §2.2–2.3 (algorithm 2.2.1, code 2.3.8),
//! written once for every control-net storage ([`NetStack`]) and both precisions.
//!
//! The current sub-patch is split at 1/2 in place; both children's boxes are tested against
//! the ray at once, the nearer hit child is continued with and the farther pushed (the
//! "nearer side first" optimisation of §2.5, which needs no copy here because the net
//! storage writes the children where they belong). Whether a child is a final box is
//! [`Stop::is_final`]: a hit at its entry `t`, which shortens the ray so that farther stack
//! entries are dropped.
//!
//! Where the net storage can ([`NetStack::try_jump`], the ray-space bicubic net), a node
//! from [`JUMP_FROM_LEVEL`] levels on first tries a Newton jump ([`super::jump`]): when
//! the sub-patch is linear enough for the crossing to be unique and located, the search
//! goes straight to the dyadic sub-cell holding the crossing, or drops the node where the
//! jump proves that the ray does not cross its sub-patch.
//!
//! Two rules keep the work bounded. A ray at a small angle θ to the surface hits about 1/θ
//! boxes on every level along the stretch where it runs close to the surface, and the
//! nearest-first search must split each before it can reject it, so the work has no bound
//! in θ (BENCHMARKS.md, stability).
//! - Once a final box is hit, a pending box entered less than that box's extent (largest
//!   edge, over the largest direction component) before the hit is dropped: a hit in it
//!   would lie within the final box's extent of the one found (the stability criteria count hits within
//!   the final box's own extent as agreeing), and its sub-boxes are entered no earlier,
//!   since de Casteljau averages stay within the parent's coordinates.
//! - After [`SubdivisionConfig::full_precision_splits`] splits the end game coarsens: the
//!   diameter below which a box is final starts at [`COARSEN_BASE_ULPS`] ulps of the
//!   patch scale and doubles every [`COARSEN_STEP_SPLITS`] splits. After
//!   [`COARSEN_DOUBLINGS`] doublings it exceeds every box (see there), so every live box
//!   is final and no split follows: a test takes at most `full_precision_splits +
//!   COARSEN_DOUBLINGS · COARSEN_STEP_SPLITS` splits ([`super::config::MAX_SPLITS_PER_TEST`]
//!   for the default). A box final by this rule is still a sub-patch's box hit by the ray,
//!   so the hit is within its own extent of the surface; rays that exhaust the budget get a
//!   larger box, never a hole. Until the last doubling a coarsened box must not contain
//!   the ray's origin (entry `t` above `tmin`): a secondary ray that grazes its surface
//!   near its origin would otherwise take the coarse box around the origin for a hit.

use super::config::{
    COARSEN_BASE_ULPS, COARSEN_DOUBLINGS, COARSEN_STEP_SPLITS, SubdivisionConfig, Termination,
};
use super::float::{GBox, GRay, KernelFloat};
use super::heuristics::{Corners, choose};
use super::jump::JumpOutcome;
use super::param::{ParamCell, Split};
use crate::geom::trim::PatchTrim;
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
    /// A jump ([`super::jump`]) from the current net, whose cell is `cell`: where it lands,
    /// the sub-cell's net becomes current and its cell, box and entry `t` (clipped to
    /// `tmax`) are returned. Nothing changes otherwise; [`JumpOutcome::Undecided`] where
    /// the storage has no jumps.
    fn try_jump(&mut self, _cell: ParamCell, _tmax: T) -> JumpOutcome<(ParamCell, GBox<T>, T)> {
        JumpOutcome::Undecided
    }
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
    /// The level (u + v) from which this node and its descendants try jumps: raised after
    /// a jump that does not apply, so that the next few levels do not pay for it again.
    jump_from: u8,
}

/// Jumps are tried from this many levels (u + v) on: on coarser cells the teapot's
/// sub-patches are rarely linear enough for a jump, and the refused tries cost more than
/// they save (measured from 2 to 14 levels, BENCHMARKS.md, kernel).
const JUMP_FROM_LEVEL: u8 = 6;

/// Levels (u + v) below a node whose jump did not apply before its descendants try again
/// (measured from 1 to 4, BENCHMARKS.md).
const JUMP_RETRY_LEVELS: u8 = 1;

/// A final box hit by the ray.
#[derive(Clone, Copy, Debug)]
pub struct SearchHit<T> {
    pub t: T,
    pub cell: ParamCell,
    pub bbox: GBox<T>,
}

/// Runs the search from the root net (already in `nets`, with box `root`). `nodes` is
/// reused scratch (cleared here). With `any_hit` the first final box ends the search.
/// With `trim`, a final box whose parameter cell's centre the patch's trim loops cut away
/// is no hit and the search goes on behind it (Dammertz §2.6): the answer is the nearest
/// surviving hit. Sub-patches whose cells lie inside `trivial` are dropped unsearched: the
/// ray provably does not cross them ([`super::trivial`]).
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
    trim: Option<&PatchTrim>,
    trivial: Option<ParamCell>,
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
        jump_from: JUMP_FROM_LEVEL,
    };
    let mut best: Option<SearchHit<T>> = None;
    let max = T::MAX_LEVEL;
    let stop = Stop::new(cfg, &root, ray, rational, nets.end_game_floor());
    let (mut splits, mut doublings) = (0u32, 0u32);
    // The coarsened end game: boxes with an L1 diameter up to this are final.
    let mut coarse = -T::INFINITY;
    'search: loop {
        // A popped entry was tested against an older, longer ray; after a hit only boxes
        // entered more than the hit box's extent before it matter (`tmax` is that bound).
        let live = cur.t_enter <= tmax
            && (best.is_none() || cur.t_enter < tmax)
            && trivial.is_none_or(|q| !q.contains(&cur.cell));
        // A coarsened box is final only if the ray starts outside it (so a secondary ray
        // cannot take the coarse box around its own origin for a hit), until the last
        // doubling, after which every box is.
        let coarse_final = doublings > 0
            && (cur.t_enter > ray.tmin || doublings > COARSEN_DOUBLINGS)
            && cur.bbox.l1_diameter() <= coarse;
        if live && (cur.is_final || coarse_final) {
            let kept = trim.is_none_or(|trim| {
                let (u, v) = cur.cell.centre();
                stats.trim_tests += 1;
                trim.keeps(u, v)
            });
            if kept {
                best = Some(SearchHit {
                    t: cur.t_enter,
                    cell: cur.cell,
                    bbox: cur.bbox,
                });
                tmax = cur.t_enter - stop.extent_along_ray(&cur.bbox);
                if any_hit {
                    return best;
                }
            }
        } else if live {
            if let Some(full) = stop.full_precision_splits {
                // Update j (j = 0 sets the base, then doublings) once `full + j · step`
                // splits are done; after update j = COARSEN_DOUBLINGS every box is final.
                if doublings <= COARSEN_DOUBLINGS
                    && splits >= full.saturating_add(doublings * COARSEN_STEP_SPLITS)
                {
                    coarse = if doublings == 0 {
                        stop.coarse_base
                    } else {
                        coarse + coarse
                    };
                    doublings += 1;
                    continue;
                }
            }
            'split: {
                let (lu, lv) = cur.cell.levels();
                if lu + lv >= cur.jump_from {
                    match nets.try_jump(cur.cell, tmax) {
                        JumpOutcome::Landed((cell, bbox, t)) => {
                            stats.jumps += 1;
                            stats.box_tests += 1;
                            cur = stop.child(bbox, cell, cur.bbox.l1_diameter(), t, 0);
                            continue 'search;
                        }
                        JumpOutcome::Empty => {
                            stats.jump_drops += 1;
                            break 'split;
                        }
                        JumpOutcome::Undecided => cur.jump_from = lu + lv + JUMP_RETRY_LEVELS,
                    }
                }
                splits += 1;
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
                // Children are built by an always-inlined method, not a closure: the compiler
                // stopped inlining the closure when the search grew, and the call spilled every
                // vector register (a quarter of the bicubic search's time).
                let lower = |t| stop.child(boxes[0], cells.0, d, t, cur.jump_from);
                let upper = |t| stop.child(boxes[1], cells.1, d, t, cur.jump_from);
                match (hit0, hit1) {
                    (Some(t0), Some(t1)) => {
                        let far_is_lower = t1 < t0;
                        nets.push_far(far_is_lower);
                        if far_is_lower {
                            nodes.push(lower(t0));
                            cur = upper(t1);
                        } else {
                            nodes.push(upper(t1));
                            cur = lower(t0);
                        }
                        continue 'search;
                    }
                    (Some(t0), None) => {
                        nets.keep(true);
                        cur = lower(t0);
                        continue 'search;
                    }
                    (None, Some(t1)) => {
                        nets.keep(false);
                        cur = upper(t1);
                        continue 'search;
                    }
                    (None, None) => {}
                }
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
    let scale = root_scale(root);
    (scale.next_up() - scale) * T::from_f64(end_ulps as f64)
}

/// The largest coordinate magnitude of `root`, the scale the net rounds to.
fn root_scale<T: KernelFloat>(root: &GBox<T>) -> T {
    (0..3)
        .map(|i| {
            root.min[i]
                .max(-root.min[i])
                .max(root.max[i])
                .max(-root.max[i])
        })
        .fold(T::ZERO, |a, b| a.max(b))
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
    /// [`SubdivisionConfig::full_precision_splits`].
    full_precision_splits: Option<u32>,
    /// Where the coarsened end game starts: [`COARSEN_BASE_ULPS`] ulps of the root box's
    /// largest coordinate magnitude.
    coarse_base: T,
    /// Largest magnitude of a ray direction component: a box of extent `e` (largest edge)
    /// spans at most `e / dir_max` of `t` along the ray in its largest coordinate.
    dir_max: T,
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
        let scale = root_scale(root);
        let ulp = scale.next_up() - scale;
        Stop {
            end_diameter: (ulp * T::from_f64(cfg.end_ulps as f64)).max(floor),
            rational_dist: rational.then_some(cfg.rational_dist),
            criterion,
            full_precision_splits: cfg.full_precision_splits,
            coarse_base: ulp * T::from_f64(COARSEN_BASE_ULPS as f64),
            dir_max: ray.dir.iter().fold(T::ZERO, |a, &d| a.max(d).max(-d)),
        }
    }

    /// How much smaller than a final box's entry `t` a hit must be to lie outside the box's
    /// extent (its largest edge) from the box's entry point, in the max norm the stability
    /// suite compares points in.
    #[inline(always)]
    fn extent_along_ray(&self, b: &GBox<T>) -> T {
        let extent = (0..3)
            .map(|i| b.max[i] - b.min[i])
            .fold(T::ZERO, |a, e| a.max(e));
        extent / self.dir_max
    }

    /// The search node of a child box `bbox` with parameter cell `cell`, entered by the ray
    /// at `t_enter`, of a parent with L1 diameter `parent_diameter`.
    #[inline(always)]
    fn child(
        &self,
        bbox: GBox<T>,
        cell: ParamCell,
        parent_diameter: T,
        t_enter: T,
        jump_from: u8,
    ) -> Node<T> {
        Node {
            bbox,
            t_enter,
            cell,
            is_final: self.is_final(&bbox, parent_diameter, cell, t_enter),
            jump_from,
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

#[cfg(test)]
mod tests {
    use glam::{DVec3, Vec3};

    use super::super::bicubic::Net;
    use super::super::config::MAX_SPLITS_PER_TEST;
    use super::super::prepared::Prepared;
    use super::super::register::LaneNet;
    use super::super::{PreparedPatch, SubdivisionConfig, intersect};
    use crate::geom::{BezierPatch, Ray};
    use crate::kernel::{KernelStats, PatchHit};

    /// The plane z = SLOPE_X x + SLOPE_Y y, tilted so that the boxes of its pieces are
    /// thick in every axis (a grazing ray then hits many of them on every level).
    const SLOPE_X: f64 = 0.5;
    const SLOPE_Y: f64 = 0.3;

    /// The angle (radians) between the test's grazing ray and the plane: small enough that
    /// an unbudgeted world-space search exceeds the split bound.
    const GRAZING_ANGLE: f64 = 1e-4;

    fn plane_z(x: f64, y: f64) -> f64 {
        SLOPE_X * x + SLOPE_Y * y
    }

    /// A bicubic patch on the plane over [0,1]² (a linear map of the parameters, so the
    /// control points lie on the plane; all are exact in `f32` but for the rounding of z).
    fn plane_patch() -> PreparedPatch {
        let pts: Vec<DVec3> = (0..16)
            .map(|k| {
                let (x, y) = ((k % 4) as f64 / 3.0, (k / 4) as f64 / 3.0);
                DVec3::new(x, y, plane_z(x, y))
            })
            .collect();
        // Affine, so `PreparedPatch::new` would take the closed form: this test is about
        // the search, so the patch is prepared as the bicubic it is.
        let net = Net::from_patch(&BezierPatch::from_points(3, 3, &pts).unwrap());
        PreparedPatch {
            bounds: net.bounds().to_aabb(),
            data: Prepared::Bicubic(net),
        }
    }

    /// A ray at `angle` (radians) to the plane, from outside the patch, crossing the plane
    /// over the patch's centre after running along it over most of the patch.
    fn grazing_ray(angle: f64) -> Ray {
        let normal = DVec3::new(-SLOPE_X, -SLOPE_Y, 1.0).normalize();
        let along = DVec3::new(1.0, 0.0, SLOPE_X).normalize();
        let target = DVec3::new(0.5, 0.5, plane_z(0.5, 0.5));
        let dir = along * angle.cos() - normal * angle.sin();
        let origin = target - dir;
        Ray::new(origin.as_vec3(), dir.as_vec3())
    }

    fn run(ray: &Ray, cfg: &SubdivisionConfig) -> (Option<PatchHit>, u64) {
        let mut stats = KernelStats::default();
        let hit = intersect(&plane_patch(), None, ray, cfg, &mut stats);
        (hit, stats.splits)
    }

    /// Distance of a point from the plane, in `f64`.
    fn plane_distance(p: Vec3) -> f64 {
        let p = p.as_dvec3();
        (p.z - plane_z(p.x, p.y)).abs() / DVec3::new(SLOPE_X, SLOPE_Y, 1.0).length()
    }

    #[test]
    fn grazing_ray_splits_stay_within_the_bound_and_hit_within_the_box() {
        // About 1/GRAZING_ANGLE boxes per level along the stretch where the ray runs
        // within a box size of the plane.
        // In world space (the search of paths without ray space, such as CPUs without
        // AVX-512): ray-space boxes are tight across the ray, so there the same ray needs
        // few splits (checked below).
        let ray = grazing_ray(GRAZING_ANGLE);
        let world = SubdivisionConfig {
            ray_space: false,
            ..SubdivisionConfig::default()
        };
        let unbounded = SubdivisionConfig {
            full_precision_splits: None,
            ..world
        };
        let (_, splits_unbounded) = run(&ray, &unbounded);
        assert!(
            splits_unbounded > MAX_SPLITS_PER_TEST,
            "the case must need the budget: {splits_unbounded} splits"
        );
        let (in_ray_space, ray_space_splits) = run(&ray, &SubdivisionConfig::default());
        assert!(in_ray_space.is_some() && ray_space_splits < MAX_SPLITS_PER_TEST);
        let (hit, splits) = run(&ray, &world);
        assert!(splits <= MAX_SPLITS_PER_TEST, "{splits} splits");
        let hit = hit.expect("the ray crosses the patch: no hole");
        let p = ray.origin + ray.dir * hit.t;
        let extent = hit.hit_box.extent().max_element() as f64;
        // The reported point is the box's entry point, so within the box's extent (plus
        // the f32 rounding of the plane's control points, an ulp of 1) of the plane.
        assert!(
            plane_distance(p) <= extent + f32::EPSILON as f64,
            "{hit:?}: {} from the plane",
            plane_distance(p)
        );
    }

    #[test]
    fn steep_rays_never_reach_the_budget() {
        for angle in [0.1, 0.5, 1.5] {
            let ray = grazing_ray(angle);
            let unbounded = SubdivisionConfig {
                full_precision_splits: None,
                ..SubdivisionConfig::default()
            };
            let (want, splits) = run(&ray, &unbounded);
            assert!(splits < super::super::config::DEFAULT_FULL_PRECISION_SPLITS as u64);
            assert_eq!(run(&ray, &SubdivisionConfig::default()).0, want);
            assert!(want.is_some());
        }
    }
}
