//! The search loop of Toth's method as Lischinski & Gonczarowski describe it (§4.2, with
//! Toth's bisection of `K ∩ X` instead of their regular subdivision): candidate boxes of
//! parameter space are kept ordered by the lower bound of their ray parameter, so the
//! first hit whose `t` is below every remaining bound is the nearest.

use std::cmp::Ordering;
use std::collections::BinaryHeap;

use crate::geom::interval::{IntervalNet, ParamBox, euclidean_hull};
use crate::geom::ulp::ulp_of;
use crate::geom::{BezierPatch, DAabb, Ray};
use crate::kernel::PatchHit;

use super::TothConfig;
use super::krawczyk::{Classification, classify, invert, newton_step};
use super::newton::simple_newton;
use super::raynet::{G1, G2, RayBox, RayFrame};
use super::stats::TothStats;

/// A box waiting in the candidate list, keyed by a lower bound of its ray parameter.
#[derive(Clone, Copy, Debug)]
struct Candidate {
    t_lo: f64,
    region: ParamBox,
}

impl PartialEq for Candidate {
    fn eq(&self, o: &Self) -> bool {
        self.cmp(o) == Ordering::Equal
    }
}
impl Eq for Candidate {}
impl PartialOrd for Candidate {
    fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
        Some(self.cmp(o))
    }
}
impl Ord for Candidate {
    /// Reversed, so that `BinaryHeap` pops the smallest `t_lo` first.
    fn cmp(&self, o: &Self) -> Ordering {
        o.t_lo.total_cmp(&self.t_lo)
    }
}

/// Per-thread buffers: the projected net, a sub-net, a homogeneous net for hit boxes, and
/// the candidate list.
#[derive(Default)]
pub struct Scratch {
    projected: IntervalNet,
    sub: IntervalNet,
    homogeneous: IntervalNet,
    euclid_sub: IntervalNet,
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

/// Runs the search on one patch. With `Goal::Any` and `cfg.isrt`, a safe region whose ray
/// parameters lie inside `[tmin, tmax]` answers at once (LG90 §6): the returned hit then
/// carries the safe region's centre and box rather than a converged point.
pub fn search(
    patch: &BezierPatch,
    ray: &Ray,
    cfg: &TothConfig,
    goal: Goal,
    s: &mut Scratch,
    stats: &mut TothStats,
) -> Option<PatchHit> {
    stats.searches += 1;
    let frame = RayFrame::new(ray);
    let (nu, nv) = (patch.degree_u() + 1, patch.degree_v() + 1);
    frame.project(patch.homogeneous_points(), nu, nv, &mut s.projected);
    let scale = patch
        .control_box()
        .max
        .abs()
        .max(patch.control_box().min.abs())
        .max_element();
    let final_extent = cfg.final_ulps as f64 * ulp_of(scale as f32);
    let tmin = ray.tmin as f64;
    let mut tmax = ray.tmax as f64;
    let mut best: Option<PatchHit> = None;
    s.candidates.clear();
    s.candidates.push(Candidate {
        t_lo: f64::NEG_INFINITY,
        region: ParamBox::UNIT,
    });
    let mut iterations = 0u32;
    while let Some(c) = s.candidates.pop() {
        if c.t_lo > tmax {
            break;
        }
        if iterations >= cfg.max_iterations {
            stats.cut_off += 1;
            break;
        }
        s.projected.subnet_into(&c.region, &mut s.sub);
        let rb = frame.ray_box(&s.sub);
        stats.box_tests += 1;
        if !rb.is_hit(tmin, tmax) {
            continue;
        }
        iterations += 1;
        stats.search_iterations += 1;
        let hit = if frame.extent(&rb) <= final_extent {
            stats.final_boxes += 1;
            final_box_hit(
                patch,
                &s.projected,
                &c.region,
                &rb,
                tmin,
                (&mut s.homogeneous, &mut s.euclid_sub),
            )
        } else {
            match classify(&s.projected, &s.sub, &c.region) {
                Classification::Excluded => {
                    stats.excluded += 1;
                    None
                }
                Classification::Undecided { region } => {
                    match region.bisect() {
                        Some((a, b)) => {
                            stats.bisections += 1;
                            for region in [a, b] {
                                s.candidates.push(Candidate {
                                    t_lo: rb.t.lo(),
                                    region,
                                });
                            }
                            None
                        }
                        // Too narrow to split in f64: answer it like a final box.
                        None => {
                            stats.final_boxes += 1;
                            final_box_hit(
                                patch,
                                &s.projected,
                                &region,
                                &rb,
                                tmin,
                                (&mut s.homogeneous, &mut s.euclid_sub),
                            )
                        }
                    }
                }
                Classification::Safe {
                    region,
                    contraction,
                    inverse,
                } => {
                    if goal == Goal::Any && cfg.isrt {
                        // ISRT: the safe region proves a root; its ray parameter lies in
                        // the sub-patch's t-range over K.
                        s.projected.subnet_into(&region, &mut s.sub);
                        let kb = frame.ray_box(&s.sub);
                        stats.box_tests += 1;
                        if kb.t.lo() >= tmin && kb.t.hi() <= tmax {
                            stats.early_outs += 1;
                            let (u, v) = region.mid();
                            return Some(PatchHit {
                                t: kb.t.mid() as f32,
                                u: u as f32,
                                v: v as f32,
                                hit_box: enclosure_box(
                                    patch,
                                    &region,
                                    &mut s.homogeneous,
                                    &mut s.euclid_sub,
                                ),
                            });
                        }
                        if kb.t.hi() < tmin || kb.t.lo() > tmax {
                            continue;
                        }
                    }
                    stats.newton_starts += 1;
                    stats.safe_width_sum += c.region.width();
                    simple_newton(&s.projected, &c.region, &region, contraction, &inverse).and_then(
                        |n| {
                            stats.newton_iterations += n.iterations as u64;
                            let t = ray_parameter(&s.projected, n.u, n.v)?;
                            (t >= tmin && t <= tmax).then(|| PatchHit {
                                t: t as f32,
                                u: n.u as f32,
                                v: n.v as f32,
                                hit_box: enclosure_box(
                                    patch,
                                    &n.enclosure,
                                    &mut s.homogeneous,
                                    &mut s.euclid_sub,
                                ),
                            })
                        },
                    )
                }
            }
        };
        if let Some(h) = hit {
            if goal == Goal::Any {
                return Some(h);
            }
            tmax = h.t as f64;
            best = Some(h);
        }
    }
    best
}

/// The ray parameter `τ / w` of the surface point at (u, v).
fn ray_parameter(projected: &IntervalNet, u: f64, v: f64) -> Option<f64> {
    let (p, _, _) = projected.eval(u, v);
    let t = p[super::raynet::TAU].mid() / p[super::raynet::W].mid();
    t.is_finite().then_some(t)
}

/// A box too small for analysis that the ray passes through (LG90 §4.2 step 4): one Newton
/// step from its centre refines (u, v) when it stays inside; the hit is at the box's entry.
fn final_box_hit(
    patch: &BezierPatch,
    projected: &IntervalNet,
    region: &ParamBox,
    rb: &RayBox,
    tmin: f64,
    (homogeneous, sub): (&mut IntervalNet, &mut IntervalNet),
) -> Option<PatchHit> {
    let (mut u, mut v) = region.mid();
    let (g, gu, gv) = projected.eval(u, v);
    if let Some(inv) = invert([[gu[G1].mid(), gv[G1].mid()], [gu[G2].mid(), gv[G2].mid()]]) {
        let [du, dv] = newton_step(&inv, &g);
        if region.contains(u + du, v + dv) {
            (u, v) = (u + du, v + dv);
        }
    }
    Some(PatchHit {
        t: rb.t.lo().max(tmin) as f32,
        u: u as f32,
        v: v as f32,
        hit_box: enclosure_box(patch, region, homogeneous, sub),
    })
}

/// The `f32` box, rounded outward, of the patch over `region`.
fn enclosure_box(
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
