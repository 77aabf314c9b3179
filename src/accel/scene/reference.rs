//! The `f64` reference path: every candidate tested in `f64`, no accelerator rounding.

use glam::DVec3;

use super::{QueryStats, SceneGeometry, SceneHit};
use crate::geom::Ray;
use crate::kernel::subdivision::{self, SubdivisionConfig};
use crate::kernel::triangle::{self, RayShear};

impl SceneGeometry {
    /// The `f64` reference: every patch whose box the ray meets (an `f64` slab test, so no
    /// `f32` rounding of the ray can drop a candidate) is intersected in `f64`. Triangles
    /// are flat already; they are intersected by the watertight kernel on the ray rounded
    /// to `f32`. Instances whose box the ray meets take the ray mapped into object space
    /// in `f64`, with no rounding to `f32`.
    pub fn intersect_f64(
        &self,
        origin: DVec3,
        dir: DVec3,
        tmin: f64,
        tmax: f64,
        cfg: &SubdivisionConfig,
        stats: &mut QueryStats,
    ) -> Option<SceneHit> {
        let mut best = self.nearest_own_f64(origin, dir, tmin, tmax, cfg, stats);
        let inv = dir.recip();
        for placement in &self.instances {
            let limit = best.as_ref().map_or(tmax, |h| h.t);
            stats.bvh_box_tests += 1;
            let b = placement.bounds.to_f64();
            if b.intersect(origin, inv, tmin, limit).is_none() {
                continue;
            }
            let prototype = &self.prototypes[placement.prototype as usize];
            let (o, d) = (
                placement.point_to_object(origin),
                placement.vector_to_object(dir),
            );
            if let Some(h) = prototype.intersect_f64(o, d, tmin, limit, cfg, stats) {
                best = Some(placement.hit_to_world(h));
            }
        }
        best
    }

    /// [`SceneGeometry::intersect_f64`] over the scene's own patches and triangles.
    pub(super) fn nearest_own_f64(
        &self,
        origin: DVec3,
        dir: DVec3,
        tmin: f64,
        tmax: f64,
        cfg: &SubdivisionConfig,
        stats: &mut QueryStats,
    ) -> Option<SceneHit> {
        let mut best: Option<(u32, subdivision::PatchHit64)> = None;
        let inv = dir.recip();
        for prim in 0..self.patches.len() {
            let b = self.patches.bounds(prim).to_f64();
            stats.bvh_box_tests += 1;
            let limit = best.as_ref().map_or(tmax, |(_, h)| h.t);
            if b.intersect(origin, inv, tmin, limit).is_none() {
                continue;
            }
            stats.kernel.patch_tests += 1;
            let trim = self.trim(prim as u32);
            let patch = self.patches.original(prim);
            if let Some(h) = subdivision::intersect_f64(&patch, origin, dir, tmin, limit, cfg, trim)
            {
                best = Some((prim as u32, h));
            }
        }
        let ray = Ray {
            origin: origin.as_vec3(),
            dir: dir.as_vec3(),
            tmin: tmin as f32,
            tmax: best.as_ref().map_or(tmax, |(_, h)| h.t) as f32,
        };
        let mut nearest_triangle = None;
        let shear = RayShear::new(&ray);
        let mut limit = ray.tmax;
        for (k, [a, b, c]) in self.triangles.corners.iter().enumerate() {
            stats.kernel.patch_tests += 1;
            if let Some(h) = triangle::intersect_triangle(&shear, *a, *b, *c, ray.tmin, limit) {
                limit = h.t;
                nearest_triangle = Some((k as u32, h));
            }
        }
        if let Some((k, h)) = nearest_triangle {
            return Some(self.finish_triangle_hit(k, &h));
        }
        let (prim, h) = best?;
        Some(self.finish_patch_hit(prim, h.t, h.u, h.v, h.hit_box.to_f32_outward()))
    }
}
