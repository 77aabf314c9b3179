//! STAND-IN until the real kernel lands: a slow f64 subdivision with the final API.

use glam::DVec3;

use crate::geom::bbox::DAabb;
use crate::geom::{Aabb, BezierPatch, Ray};
use crate::kernel::{KernelStats, PatchHit};

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SplitHeuristic {
    Length,
    CrossProduct,
}

#[derive(Clone, Copy, Debug)]
pub struct SubdivisionConfig {
    pub heuristic: SplitHeuristic,
    pub rational_dist: u32,
}

impl Default for SubdivisionConfig {
    fn default() -> Self {
        SubdivisionConfig {
            heuristic: SplitHeuristic::Length,
            rational_dist: 16,
        }
    }
}

pub struct PreparedPatch {
    patch: BezierPatch,
    bounds: Aabb,
}

impl PreparedPatch {
    pub fn new(patch: &BezierPatch) -> PreparedPatch {
        PreparedPatch {
            patch: patch.clone(),
            bounds: patch.control_box().to_f32_outward(),
        }
    }
    pub fn bounds(&self) -> Aabb {
        self.bounds
    }
}

pub struct PatchHit64 {
    pub t: f64,
    pub u: f64,
    pub v: f64,
    pub hit_box: DAabb,
}

pub fn intersect(
    p: &PreparedPatch,
    ray: &Ray,
    cfg: &SubdivisionConfig,
    stats: &mut KernelStats,
) -> Option<PatchHit> {
    stats.patch_tests += 1;
    let h = intersect_f64(
        &p.patch,
        ray.origin.as_dvec3(),
        ray.dir.as_dvec3(),
        ray.tmin as f64,
        ray.tmax as f64,
        cfg,
    )?;
    Some(PatchHit {
        t: h.t as f32,
        u: h.u as f32,
        v: h.v as f32,
        hit_box: h.hit_box.to_f32_outward(),
    })
}

pub fn occluded(
    p: &PreparedPatch,
    ray: &Ray,
    cfg: &SubdivisionConfig,
    stats: &mut KernelStats,
) -> bool {
    intersect(p, ray, cfg, stats).is_some()
}

pub fn intersect_f64(
    patch: &BezierPatch,
    o: DVec3,
    d: DVec3,
    tmin: f64,
    tmax: f64,
    _cfg: &SubdivisionConfig,
) -> Option<PatchHit64> {
    let mut best: Option<PatchHit64> = None;
    let mut stack = vec![(patch.clone(), 0u32)];
    let inv = d.recip();
    while let Some((p, depth)) = stack.pop() {
        let b = p.control_box();
        let t0 = (b.min - o) * inv;
        let t1 = (b.max - o) * inv;
        let enter = t0.min(t1).max_element().max(tmin);
        let exit = t0
            .max(t1)
            .min_element()
            .min(best.as_ref().map_or(tmax, |h| h.t));
        if enter > exit {
            continue;
        }
        if depth >= 40 {
            let dom = p.domain();
            best = Some(PatchHit64 {
                t: enter,
                u: 0.5 * (dom.u0 + dom.u1),
                v: 0.5 * (dom.v0 + dom.v1),
                hit_box: b,
            });
            continue;
        }
        let (a, c) = if depth % 2 == 0 {
            p.split_u()
        } else {
            p.split_v()
        };
        stack.push((c, depth + 1));
        stack.push((a, depth + 1));
    }
    best
}
