//! The search loop of Toth's method as Lischinski & Gonczarowski describe it (§4.2, with
//! Toth's bisection of `K ∩ X` instead of their regular subdivision): candidate boxes of
//! parameter space are kept ordered by the lower bound of their ray parameter, so the
//! first hit whose `t` is below every remaining bound is the nearest.
//!
//! Steps 3–7 of LG90's loop on one box (the ray–box test in ray coordinates, the box "too
//! small for analysis", Krawczyk's test, simple Newton in a safe region, ISRT) are
//! [`examine`]; only what happens to an undecided box differs between this kernel and the
//! cached quadtree kernel ([`crate::kernel::cached`]), which calls [`examine`] too.
//!
//! On the surface a secondary ray leaves, [`examine`] adds LG90's three "triviality tests"
//! (§6), which drop boxes holding only the trivial intersection before it is computed. Our
//! secondary rays start off the hit box (Dammertz §2.4), so the trivial root lies before
//! `tmin` and the paper's `δ` is `tmin`: (1) the box's ray parameters end before `tmin`;
//! (2) the ray parameters of the sub-patch over Krawczyk's `K` end before `tmin`; (3) in a
//! safe region, simple Newton's error bound proves the unique root's `t` below `tmin`
//! ([`super::newton::Trivial`]). Each only drops boxes whose roots all lie before `tmin`,
//! so the answer is the full search's; on other patches the extra bounds rarely pay.

use std::cmp::Ordering;
use std::collections::BinaryHeap;

use crate::geom::interval::{IntervalNet, ParamBox, euclidean_hull};
use crate::geom::trim::PatchTrim;
use crate::geom::ulp::ulp_of;
use crate::geom::{BezierPatch, DAabb, Ray};
use crate::kernel::PatchHit;

use super::TothConfig;
use super::krawczyk::{Classification, SafeRegion, classify, invert, newton_step};
use super::newton::{Newton, Trivial, eval_point, simple_newton};
use super::raynet::{G1, G2, RayBox, RayFrame};
use super::stats::TothStats;

/// A box waiting in the candidate list, keyed by a lower bound of its ray parameter; `node`
/// is what else a kernel keeps with it (the cached kernel's tree node).
#[derive(Clone, Copy, Debug)]
pub struct Candidate<N = ()> {
    pub t_lo: f64,
    pub region: ParamBox,
    pub node: N,
}

impl<N> PartialEq for Candidate<N> {
    fn eq(&self, o: &Self) -> bool {
        self.cmp(o) == Ordering::Equal
    }
}
impl<N> Eq for Candidate<N> {}
impl<N> PartialOrd for Candidate<N> {
    fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
        Some(self.cmp(o))
    }
}
impl<N> Ord for Candidate<N> {
    /// Reversed, so that `BinaryHeap` pops the smallest `t_lo` first.
    fn cmp(&self, o: &Self) -> Ordering {
        o.t_lo.total_cmp(&self.t_lo)
    }
}

/// Per-thread buffers of one ray–patch search: the projected net, a sub-net, and a
/// homogeneous net with its sub-net for hit boxes.
#[derive(Default)]
pub struct Nets {
    projected: IntervalNet,
    sub: IntervalNet,
    homogeneous: IntervalNet,
    euclid_sub: IntervalNet,
}

impl Nets {
    /// The sub-net [`examine`] reads, to be filled with an enclosure of the patch's
    /// projected net over the box being examined (the cached kernel projects a leaf's
    /// stored net into it).
    pub fn sub_mut(&mut self) -> &mut IntervalNet {
        &mut self.sub
    }

    /// Fills the sub-net [`examine`] reads by subdividing the patch's projected net down
    /// to `x`.
    pub fn subdivide_to(&mut self, x: &ParamBox) {
        self.projected.subnet_into(x, &mut self.sub);
    }
}

/// Per-thread buffers of the Toth kernel: the nets and the candidate list.
#[derive(Default)]
pub struct Scratch {
    nets: Nets,
    candidates: BinaryHeap<Candidate>,
}

/// What the search looks for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Goal {
    /// The nearest hit.
    Nearest,
    /// Any hit (shadow rays).
    Any,
}

/// One ray against one patch: the ray's frame (the patch is projected into it, in
/// [`Nets`]), the end-game size, the ray's start, and whether the ray leaves this patch.
pub struct PatchRay<'a> {
    patch: &'a BezierPatch,
    frame: RayFrame,
    final_extent: f64,
    tmin: f64,
    origin: bool,
}

impl<'a> PatchRay<'a> {
    /// Projects `patch` into the frame of `ray` (into `nets`); `origin` when the ray is a
    /// secondary ray leaving this patch (the triviality tests apply, LG90 §6).
    pub fn new(
        patch: &'a BezierPatch,
        ray: &Ray,
        cfg: &TothConfig,
        origin: bool,
        nets: &mut Nets,
    ) -> Self {
        let frame = RayFrame::new(ray);
        let (nu, nv) = (patch.degree_u() + 1, patch.degree_v() + 1);
        frame.project(patch.homogeneous_points(), nu, nv, &mut nets.projected);
        let b = patch.control_box();
        let scale = b.max.abs().max(b.min.abs()).max_element();
        PatchRay {
            patch,
            frame,
            final_extent: cfg.final_ulps as f64 * ulp_of(scale as f32),
            tmin: ray.tmin as f64,
            origin,
        }
    }
}

impl PatchRay<'_> {
    /// The ray's frame the patch is projected into.
    pub fn frame(&self) -> &RayFrame {
        &self.frame
    }
}

/// What [`examine`] found in one box.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Step {
    /// The ray misses the box, the box is excluded, or its root lies outside `[tmin, tmax]`.
    Miss,
    /// A root (or, for ISRT, a proved one) with `t` in `[tmin, tmax]`.
    Hit(PatchHit),
    /// Undecided: every root of the box lies in `region`, and `ray_box` bounds the box in
    /// ray coordinates. The caller subdivides, or answers it with [`final_box`] when it
    /// cannot.
    Undecided { region: ParamBox, ray_box: RayBox },
}

/// LG90 §4.2 steps 3–7 on the box `x`: the ray–box test in ray coordinates, the box too
/// small for analysis (step 4), Krawczyk's test (5–6), and simple Newton in a safe region
/// (7), or with `Goal::Any` and `cfg.isrt` the safe region alone (§6), with the
/// triviality tests of §6 on the surface of origin. Counts a search iteration when the ray
/// meets the box.
///
/// Reads the sub-net over `x` that [`Nets::subdivide_to`] or [`Nets::sub_mut`] filled.
pub fn examine(
    pr: &PatchRay,
    nets: &mut Nets,
    x: &ParamBox,
    tmax: f64,
    cfg: &TothConfig,
    goal: Goal,
    stats: &mut TothStats,
) -> Step {
    let Nets {
        projected,
        sub,
        homogeneous,
        euclid_sub,
    } = nets;
    let rb = pr.frame.ray_box(sub);
    stats.box_tests += 1;
    if !rb.is_hit(pr.tmin, tmax) {
        // Triviality test 1 is the ray–box test's own `t < tmin` bound; counted where it
        // alone decides on the surface of origin.
        let across = rb.g1.contains(0.0) && rb.g2.contains(0.0);
        if pr.origin && across && rb.t.hi() < pr.tmin {
            stats.trivial[0] += 1;
        }
        return Step::Miss;
    }
    stats.search_iterations += 1;
    if pr.frame.extent(&rb) <= pr.final_extent {
        return final_box(pr, nets, x, &rb, stats).map_or(Step::Miss, Step::Hit);
    }
    let class = classify(projected, sub, x);
    // The sub-patch over K in ray coordinates, for triviality test 2 and ISRT; `sub` is
    // then the sub-net over K, whose derivative bounds test 3 uses. The triviality tests
    // only run where the box reaches back before `tmin` (nothing else can be trivial), and
    // test 2 only on safe regions: on undecided boxes its extra sub-net cost more than it
    // saved, since the halves of a box it would drop fail the ray–box test next anyway
    // (measured on the half-pipe of tests/lib/lg6_trivial.rs: 224 sub-nets, 5 boxes dropped,
    // no search iteration saved).
    let isrt = goal == Goal::Any && cfg.isrt;
    let trivial_here = pr.origin && rb.t.lo() < pr.tmin;
    let k_box = match class {
        Classification::Safe(SafeRegion { region, .. })
            if (trivial_here || isrt) && region != *x =>
        {
            Some(region)
        }
        _ => None,
    }
    .map(|region| {
        projected.subnet_into(&region, sub);
        stats.box_tests += 1;
        pr.frame.ray_box(sub)
    });
    if trivial_here && k_box.is_some_and(|kb| kb.t.hi() < pr.tmin) {
        stats.trivial[1] += 1;
        return Step::Miss;
    }
    match class {
        Classification::Excluded => {
            stats.excluded += 1;
            Step::Miss
        }
        Classification::Undecided { region } => Step::Undecided {
            region,
            ray_box: rb,
        },
        Classification::Safe(safe) => {
            let region = safe.region;
            let kb = k_box.unwrap_or(rb);
            if isrt {
                // ISRT: the safe region proves a root; its ray parameter lies in the
                // sub-patch's t-range over K.
                if kb.t.lo() >= pr.tmin && kb.t.hi() <= tmax {
                    stats.early_outs += 1;
                    let (u, v) = region.mid();
                    return Step::Hit(PatchHit {
                        t: kb.t.mid() as f32,
                        u: u as f32,
                        v: v as f32,
                        hit_box: enclosure_box(pr.patch, &region, homogeneous, euclid_sub),
                    });
                }
                if kb.t.hi() < pr.tmin || kb.t.lo() > tmax {
                    return Step::Miss;
                }
            }
            // Triviality test 3 where the root may lie on either side of `tmin`; `sub` is
            // the sub-net over K (or over the box when K is the box).
            let over = if k_box.is_some() { region } else { *x };
            let trivial = (trivial_here && kb.t.lo() < pr.tmin)
                .then(|| sub.derivative_hulls(&over))
                .flatten()
                .map(|(du, dv)| Trivial {
                    tmin: pr.tmin,
                    du,
                    dv,
                });
            stats.newton_starts += 1;
            stats.safe_width_sum += x.width();
            match simple_newton(projected, &safe, trivial.as_ref()) {
                Newton::Converged(n) => {
                    stats.newton_iterations += n.iterations as u64;
                    ray_parameter(projected, n.u, n.v)
                        .filter(|&t| t >= pr.tmin && t <= tmax)
                        .map_or(Step::Miss, |t| {
                            Step::Hit(PatchHit {
                                t: t as f32,
                                u: n.u as f32,
                                v: n.v as f32,
                                hit_box: enclosure_box(
                                    pr.patch,
                                    &n.enclosure,
                                    homogeneous,
                                    euclid_sub,
                                ),
                            })
                        })
                }
                Newton::Trivial { iterations } => {
                    stats.newton_iterations += iterations as u64;
                    stats.trivial[2] += 1;
                    Step::Miss
                }
                Newton::Failed => Step::Miss,
            }
        }
    }
}

/// Runs the search on one patch. With `Goal::Any` and `cfg.isrt`, a safe region whose ray
/// parameters lie inside `[tmin, tmax]` answers at once (LG90 §6): the returned hit then
/// carries the safe region's centre and box rather than a converged point. A hit that
/// `trim` cuts away is no hit and the search goes on (Dammertz §2.6).
pub fn search(
    patch: &BezierPatch,
    ray: &Ray,
    cfg: &TothConfig,
    (goal, trim): (Goal, Option<&PatchTrim>),
    s: &mut Scratch,
    origin: bool,
    stats: &mut TothStats,
) -> Option<PatchHit> {
    stats.searches += 1;
    let pr = PatchRay::new(patch, ray, cfg, origin, &mut s.nets);
    let mut tmax = ray.tmax as f64;
    let mut best: Option<PatchHit> = None;
    s.candidates.clear();
    s.candidates.push(Candidate {
        t_lo: f64::NEG_INFINITY,
        region: ParamBox::UNIT,
        node: (),
    });
    let start = stats.search_iterations;
    while let Some(c) = s.candidates.pop() {
        if c.t_lo > tmax {
            break;
        }
        if stats.search_iterations - start >= cfg.max_iterations as u64 {
            stats.cut_off += 1;
            break;
        }
        s.nets.subdivide_to(&c.region);
        let hit = match examine(&pr, &mut s.nets, &c.region, tmax, cfg, goal, stats) {
            Step::Miss => None,
            Step::Hit(h) => Some(h),
            Step::Undecided { region, ray_box } => match region.bisect() {
                Some((a, b)) => {
                    stats.bisections += 1;
                    for region in [a, b] {
                        s.candidates.push(Candidate {
                            t_lo: ray_box.t.lo(),
                            region,
                            node: (),
                        });
                    }
                    None
                }
                // Too narrow to split in f64: answer it like a final box.
                None => final_box(&pr, &mut s.nets, &region, &ray_box, stats),
            },
        };
        if let Some(h) = hit.filter(|h| kept(trim, h)) {
            if goal == Goal::Any {
                return Some(h);
            }
            tmax = h.t as f64;
            best = Some(h);
        }
    }
    best
}

/// Whether a candidate hit survives the patch's trim loops (always, without loops).
pub fn kept(trim: Option<&PatchTrim>, h: &PatchHit) -> bool {
    trim.is_none_or(|trim| trim.keeps(h.u as f64, h.v as f64))
}

/// The ray parameter `τ / w` of the surface point at (u, v).
fn ray_parameter(projected: &IntervalNet, u: f64, v: f64) -> Option<f64> {
    let p = eval_point(projected, u, v);
    let t = p[super::raynet::TAU] / p[super::raynet::W];
    t.is_finite().then_some(t)
}

/// A box too small for analysis that the ray passes through (LG90 §4.2 step 4): one Newton
/// step from its centre refines (u, v) when it stays inside; the hit is at the box's entry
/// (`rb`, the box in ray coordinates).
pub fn final_box(
    pr: &PatchRay,
    nets: &mut Nets,
    region: &ParamBox,
    rb: &RayBox,
    stats: &mut TothStats,
) -> Option<PatchHit> {
    stats.final_boxes += 1;
    let (mut u, mut v) = region.mid();
    let (g, gu, gv) = nets.projected.eval(u, v);
    if let Some(inv) = invert([[gu[G1].mid(), gv[G1].mid()], [gu[G2].mid(), gv[G2].mid()]]) {
        let [du, dv] = newton_step(&inv, [g[G1].mid(), g[G2].mid()]);
        if region.contains(u + du, v + dv) {
            (u, v) = (u + du, v + dv);
        }
    }
    Some(PatchHit {
        t: rb.t.lo().max(pr.tmin) as f32,
        u: u as f32,
        v: v as f32,
        hit_box: enclosure_box(
            pr.patch,
            region,
            &mut nets.homogeneous,
            &mut nets.euclid_sub,
        ),
    })
}

/// The `f32` box, rounded outward, of the patch over `region`; `sub` is left holding the
/// homogeneous sub-net over `region` it was computed from.
pub fn enclosure_box(
    patch: &BezierPatch,
    region: &ParamBox,
    homogeneous: &mut IntervalNet,
    sub: &mut IntervalNet,
) -> crate::geom::Aabb {
    homogeneous.assign(
        patch.degree_u() + 1,
        patch.degree_v() + 1,
        patch
            .homogeneous_points()
            .iter()
            .map(|p| p.to_array().map(crate::geom::interval::Interval::point)),
    );
    homogeneous.subnet_into(region, sub);
    let e = euclidean_hull(sub);
    DAabb {
        min: glam::DVec3::new(e[0].lo(), e[1].lo(), e[2].lo()),
        max: glam::DVec3::new(e[0].hi(), e[1].hi(), e[2].hi()),
    }
    .to_f32_outward()
}
