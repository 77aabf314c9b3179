//! One primitive under a query: a patch through the kernel the query selects, and the
//! hit finished with what shading needs.

use glam::DVec3;

use super::traverse::{Candidate, PatchRay};
use super::{Kernel, SceneGeometry, SceneHit};
use crate::geom::trim::PatchTrim;
use crate::geom::{Aabb, Ray};
use crate::kernel::cached::{self};
use crate::kernel::subdivision::{self, SubdivisionConfig};
use crate::kernel::toth::{self};
use crate::kernel::triangle::{self, TriangleHit};
use crate::kernel::{KernelStats, PatchHit};

impl SceneGeometry {
    /// Nearest hit on patch `prim` with `t` up to `tmax` by the `f32`-ray kernel
    /// `precision` selects, and its `t`.
    pub(super) fn patch_hit(
        &self,
        prim: u32,
        ray: &mut PatchRay,
        tmax: f32,
        precision: &Kernel,
        kernel: &mut KernelStats,
    ) -> Option<(f32, Candidate)> {
        let patch_hit = |h: PatchHit| (h.t, Candidate::Patch(prim, h));
        let r = Ray { tmax, ..*ray.ray };
        let trim = self.trim(prim);
        // The f64 patch only for the kernels that take it: a mapped one is made on demand.
        let patch = || self.patches.original(prim as usize);
        match precision {
            Kernel::Toth(cfg) => {
                let origin = cfg.surface_of_origin == Some(prim);
                toth::intersect(&patch(), trim, &r, cfg, origin, kernel).map(patch_hit)
            }
            Kernel::Cached(cfg) => {
                let origin = cfg.toth.surface_of_origin == Some(prim);
                cached::intersect(&patch(), trim, &r, cfg, origin, kernel).map(patch_hit)
            }
            Kernel::F32(cfg) | Kernel::F64(cfg) => {
                let prepared = self.patches.prepared(prim as usize);
                let leaving = leaving(cfg, prim);
                subdivision::nearest(&prepared, trim, ray.kernel(cfg), tmax, cfg, leaving, kernel)
                    .map(|h| (h.t(), Candidate::Subdivision(prim, h)))
            }
        }
    }

    /// Whether patch `prim` blocks the ray, by the kernel `precision` selects.
    pub(super) fn patch_occluded(
        &self,
        prim: u32,
        ray: &mut PatchRay,
        precision: &Kernel,
        kernel: &mut KernelStats,
    ) -> bool {
        let trim = self.trim(prim);
        let patch = || self.patches.original(prim as usize);
        match precision {
            Kernel::Toth(cfg) => {
                let origin = cfg.surface_of_origin == Some(prim);
                toth::occluded(&patch(), trim, ray.ray, cfg, origin, kernel)
            }
            Kernel::Cached(cfg) => {
                let origin = cfg.toth.surface_of_origin == Some(prim);
                cached::occluded(&patch(), trim, ray.ray, cfg, origin, kernel)
            }
            Kernel::F32(cfg) | Kernel::F64(cfg) => {
                let prepared = self.patches.prepared(prim as usize);
                let leaving = leaving(cfg, prim);
                subdivision::blocks(&prepared, trim, ray.kernel(cfg), cfg, leaving, kernel)
            }
        }
    }

    /// Patch `prim`'s trim, `None` where its loops do not cut it.
    #[inline]
    pub(super) fn trim(&self, prim: u32) -> Option<&PatchTrim> {
        self.patches.trim(prim as usize)
    }

    pub(super) fn finish_patch_hit(
        &self,
        prim: u32,
        t: f64,
        u: f64,
        v: f64,
        hit_box: Aabb,
    ) -> SceneHit {
        let (object, patch) = self.patches.id(prim as usize);
        let normal = self.patches.original(prim as usize).normal(u, v);
        SceneHit {
            t,
            object,
            patch,
            primitive: Some(prim),
            u,
            v,
            hit_box,
            leave_box: subdivision::widen_by_net_rounding(
                hit_box,
                &self.patches.bounds(prim as usize),
            ),
            normal,
            shading_normal: normal,
        }
    }

    /// A triangle hit: (u, v) are the barycentric weights of corners 1 and 2, the hit box
    /// bounds the rounding of the hit point (pbrt-v3 §3.9.5) so secondary rays leave from
    /// its corners like from a patch's final box.
    pub(super) fn finish_triangle_hit(&self, k: u32, h: &TriangleHit) -> SceneHit {
        let [a, b, c] = self.triangles.corners[k as usize];
        let (object, index) = self.triangles.ids[k as usize];
        let (da, db, dc) = (a.as_dvec3(), b.as_dvec3(), c.as_dvec3());
        let normal = (db - da).cross(dc - da).normalize_or(DVec3::Z);
        let shading_normal = match self.triangles.normals[k as usize] {
            Some([na, nb, nc]) => {
                let n =
                    (na * h.b0 as f64 + nb * h.b1 as f64 + nc * h.b2 as f64).normalize_or(normal);
                if n.dot(normal) < 0.0 { -n } else { n }
            }
            None => normal,
        };
        SceneHit {
            t: h.t as f64,
            object,
            patch: index,
            primitive: None,
            u: h.b1 as f64,
            v: h.b2 as f64,
            hit_box: triangle::hit_box(h, a, b, c),
            leave_box: triangle::hit_box(h, a, b, c),
            normal,
            shading_normal,
        }
    }
}

/// The (u, v) of a secondary ray's origin on patch `prim` when the ray leaves that patch.
fn leaving(cfg: &SubdivisionConfig, prim: u32) -> Option<(f64, f64)> {
    cfg.surface_of_origin
        .filter(|o| o.primitive == prim)
        .map(|o| (o.u, o.v))
}
