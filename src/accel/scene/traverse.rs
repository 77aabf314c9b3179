//! One query through the accelerator: the BVH or the grid, nearest hit or any hit, with
//! instances entered in object space.

use std::ops::ControlFlow;

use super::triangles::LeafPacks;
use super::{Accel, Kernel, QueryStats, SceneGeometry, SceneHit};
use crate::accel::bvh::Bvh;
use crate::accel::grid::Grid;
use crate::geom::{Aabb, Ray};
use crate::kernel::PatchHit;
use crate::kernel::subdivision::{self, SubdivisionConfig};
use crate::kernel::triangle::{self, PackShear, RayShear, TriangleHit, intersect_pack};

/// The nearest candidate found so far during traversal.
pub(super) enum Candidate {
    Patch(u32, PatchHit),
    /// A hit of the `f32` subdivision kernel, whose world hit box is made only for the
    /// nearest ([`subdivision::KernelHit`]).
    Subdivision(u32, subdivision::KernelHit),
    Triangle(u32, TriangleHit),
    /// A hit of instance `i`, finished in object space (each instance a ray hits finishes
    /// its own nearest hit; rays meet few instances).
    Instance(u32, Box<SceneHit>),
}

/// The ray as the `f32` subdivision kernel takes it, made at the first patch test of a
/// query (most rays that miss never reach one) and shared by every patch it meets.
pub(super) struct PatchRay<'a> {
    pub(super) ray: &'a Ray,
    pub(super) kernel: Option<subdivision::KernelRay>,
}

impl<'a> PatchRay<'a> {
    pub(super) fn new(ray: &'a Ray) -> Self {
        PatchRay { ray, kernel: None }
    }

    pub(super) fn kernel(&mut self, cfg: &SubdivisionConfig) -> &subdivision::KernelRay {
        self.kernel
            .get_or_insert_with(|| subdivision::KernelRay::new(self.ray, cfg))
    }
}

impl SceneGeometry {
    /// The margin the BVH grows its boxes by for `ray`: patches are searched in the ray's
    /// own space and may be hit a little outside their exact box
    /// ([`subdivision::cull_margin`]), as may instances, whose geometry takes the ray mapped
    /// into object space; triangles alone are tested exactly against exact boxes.
    pub(super) fn cull_margin(&self, bvh: &Bvh, ray: &Ray) -> f32 {
        if self.patches.len() == 0 && self.instances.is_empty() {
            return 0.0;
        }
        let b = bvh.bounds();
        let reach = b.min.abs().max(b.max.abs()).max_element();
        subdivision::cull_margin(ray.origin.to_array(), reach)
    }

    /// The nearest hit along `ray` in `[ray.tmin, ray.tmax]`.
    pub fn intersect(
        &self,
        ray: &Ray,
        precision: &Kernel,
        stats: &mut QueryStats,
    ) -> Option<SceneHit> {
        match precision {
            Kernel::F32(_) | Kernel::Toth(_) | Kernel::Cached(_) => {
                self.intersect_f32(ray, precision, stats)
            }
            Kernel::F64(cfg) => {
                let (o, d) = (ray.origin.as_dvec3(), ray.dir.as_dvec3());
                self.intersect_f64(o, d, ray.tmin as f64, ray.tmax as f64, cfg, stats)
            }
        }
    }

    pub(super) fn intersect_f32(
        &self,
        ray: &Ray,
        precision: &Kernel,
        stats: &mut QueryStats,
    ) -> Option<SceneHit> {
        let mut patch_ray = PatchRay::new(ray);
        let best = match &self.accel {
            Accel::Bvh(bvh, packs) => {
                self.nearest_in_bvh(bvh, packs, &mut patch_ray, precision, stats)
            }
            Accel::Grid(grid) => self.nearest_in_grid(grid, &mut patch_ray, precision, stats),
        };
        Some(match best? {
            Candidate::Patch(prim, h) => {
                self.finish_patch_hit(prim, h.t as f64, h.u as f64, h.v as f64, h.hit_box)
            }
            Candidate::Subdivision(prim, h) => {
                // The test that found `h` made the kernel ray.
                let hit_box = patch_ray
                    .kernel
                    .as_ref()
                    .map_or(Aabb::EMPTY, |k| k.hit_box(&h));
                let (u, v) = h.uv();
                self.finish_patch_hit(prim, h.t() as f64, u, v, hit_box)
            }
            Candidate::Triangle(k, h) => self.finish_triangle_hit(k, &h),
            Candidate::Instance(i, h) => self.instances[i as usize].hit_to_world(*h),
        })
    }

    /// True when anything blocks `ray` in `[tmin, tmax]` (shadow rays).
    pub fn occluded(&self, ray: &Ray, precision: &Kernel, stats: &mut QueryStats) -> bool {
        match precision {
            Kernel::F32(_) | Kernel::Toth(_) | Kernel::Cached(_) => match &self.accel {
                Accel::Bvh(bvh, packs) => self.blocked_in_bvh(bvh, packs, ray, precision, stats),
                Accel::Grid(grid) => self.blocked_in_grid(grid, ray, precision, stats),
            },
            Kernel::F64(_) => self.intersect(ray, precision, stats).is_some(),
        }
    }

    /// The nearest candidate in the BVH: a leaf's patches one at a time, then its triangles
    /// a pack at a time.
    pub(super) fn nearest_in_bvh(
        &self,
        bvh: &Bvh,
        packs: &LeafPacks,
        patch_ray: &mut PatchRay,
        precision: &Kernel,
        stats: &mut QueryStats,
    ) -> Option<Candidate> {
        let ray = patch_ray.ray;
        let mut best = None;
        // The kernel counters borrowed apart from the traversal counters the closure leaves.
        let kernel = &mut stats.kernel;
        // Made at the first leaf: most rays that miss never reach one.
        let mut shear = None;
        let patches = self.patches.len() as u32;
        let first_instance = patches + self.triangles.corners.len() as u32;
        let mut surface_tests = 0;
        // Instances' work, counted apart from `kernel`, which the closure holds.
        let mut nested = QueryStats::default();
        let margin = self.cull_margin(bvh, ray);
        let t = bvh.traverse_leaves(ray, margin, |range, tmax| {
            surface_tests += range.len() as u64;
            if patches > 0 || !self.instances.is_empty() {
                for &prim in &bvh.prim_indices()[range.clone()] {
                    if prim >= first_instance {
                        let k = prim - first_instance;
                        let r = Ray {
                            tmax: *tmax,
                            ..*ray
                        };
                        let (prototype, r, local) = self.enter_instance(k, &r, precision);
                        if let Some(h) = prototype.intersect(&r, &local, &mut nested) {
                            *tmax = tmax.min(h.t as f32);
                            best = Some(Candidate::Instance(k, Box::new(h)));
                        }
                        continue;
                    }
                    if prim >= patches {
                        continue;
                    }
                    if let Some((t, hit)) =
                        self.patch_hit(prim, patch_ray, *tmax, precision, kernel)
                    {
                        *tmax = tmax.min(t);
                        best = Some(hit);
                    }
                }
            }
            let (first, leaf_packs) = packs.of_leaf(&range);
            let shear = shear.get_or_insert_with(|| PackShear::new(&RayShear::new(ray)));
            for (i, pack) in leaf_packs.iter().enumerate() {
                kernel.patch_tests += 1;
                let hits = intersect_pack(shear, pack, ray.tmin, *tmax);
                if hits.mask == 0 {
                    continue;
                }
                if let Some((lane, hit)) = hits.nearest(tmax) {
                    best = Some(Candidate::Triangle(packs.lanes[first + i][lane], hit));
                }
            }
            ControlFlow::Continue(())
        });
        stats.add_bvh(&nested, &t, surface_tests);
        best
    }

    /// What instance `k` is queried with for `ray`: its shared geometry, the ray in
    /// object space and the precision for it.
    pub(super) fn enter_instance(
        &self,
        k: u32,
        ray: &Ray,
        precision: &Kernel,
    ) -> (&SceneGeometry, Ray, Kernel) {
        let placement = &self.instances[k as usize];
        let prototype = &self.prototypes[placement.prototype as usize];
        let local = placement.precision_in_object(precision, prototype.patches.len() as u32);
        (prototype, placement.ray_to_object(ray), local)
    }

    /// Whether anything in the BVH blocks `ray`.
    pub(super) fn blocked_in_bvh(
        &self,
        bvh: &Bvh,
        packs: &LeafPacks,
        ray: &Ray,
        precision: &Kernel,
        stats: &mut QueryStats,
    ) -> bool {
        let shear = PackShear::new(&RayShear::new(ray));
        let patches = self.patches.len() as u32;
        let first_instance = patches + self.triangles.corners.len() as u32;
        let kernel = &mut stats.kernel;
        let mut nested = QueryStats::default();
        let mut patch_ray = PatchRay::new(ray);
        let mut hit = false;
        let mut surface_tests = 0;
        let margin = self.cull_margin(bvh, ray);
        let t = bvh.traverse_leaves(ray, margin, |range, _| {
            surface_tests += range.len() as u64;
            hit = bvh.prim_indices()[range.clone()].iter().any(|&prim| {
                if prim >= first_instance {
                    let (prototype, r, local) =
                        self.enter_instance(prim - first_instance, ray, precision);
                    prototype.occluded(&r, &local, &mut nested)
                } else {
                    prim < patches && self.patch_occluded(prim, &mut patch_ray, precision, kernel)
                }
            }) || packs.of_leaf(&range).1.iter().any(|pack| {
                kernel.patch_tests += 1;
                intersect_pack(&shear, pack, ray.tmin, ray.tmax).mask != 0
            });
            if hit {
                ControlFlow::Break(())
            } else {
                ControlFlow::Continue(())
            }
        });
        stats.add_bvh(&nested, &t, surface_tests);
        hit
    }

    /// The nearest candidate in the grid, one primitive at a time.
    pub(super) fn nearest_in_grid(
        &self,
        grid: &Grid,
        patch_ray: &mut PatchRay,
        precision: &Kernel,
        stats: &mut QueryStats,
    ) -> Option<Candidate> {
        let ray = patch_ray.ray;
        let mut best = None;
        let kernel = &mut stats.kernel;
        let shear = RayShear::new(ray);
        let patches = self.patches.len() as u32;
        let g = grid.traverse(ray, |prim, tmax| {
            kernel.patch_tests += (prim >= patches) as u64;
            if prim < patches {
                let (t, hit) = self.patch_hit(prim, patch_ray, tmax, precision, kernel)?;
                best = Some(hit);
                Some(t)
            } else {
                let k = prim - patches;
                let [a, b, c] = self.triangles.corners[k as usize];
                let hit = triangle::intersect_triangle(&shear, a, b, c, ray.tmin, tmax)?;
                best = Some(Candidate::Triangle(k, hit));
                Some(hit.t)
            }
        });
        stats.add_grid(&g);
        best
    }

    /// Whether anything in the grid blocks `ray`.
    pub(super) fn blocked_in_grid(
        &self,
        grid: &Grid,
        ray: &Ray,
        precision: &Kernel,
        stats: &mut QueryStats,
    ) -> bool {
        let shear = RayShear::new(ray);
        let patches = self.patches.len() as u32;
        let kernel = &mut stats.kernel;
        let mut patch_ray = PatchRay::new(ray);
        let (hit, g) = grid.traverse_any(ray, |prim| {
            if prim < patches {
                self.patch_occluded(prim, &mut patch_ray, precision, kernel)
            } else {
                kernel.patch_tests += 1;
                let [a, b, c] = self.triangles.corners[(prim - patches) as usize];
                triangle::intersect_triangle(&shear, a, b, c, ray.tmin, ray.tmax).is_some()
            }
        });
        stats.add_grid(&g);
        hit
    }
}
