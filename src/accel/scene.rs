//! The scene as the renderer sees it: every Bézier patch prepared for the kernel in `f32`,
//! its `f64` original kept for normals and the reference path, and a BVH over the tight
//! patch boxes (LG90 §3.1, Fig. 2). One query answers "nearest hit" or "anything in the
//! way" for a ray, counting the work it did.

use glam::DVec3;

use super::bvh::{Bvh, GeometryHasher};
use crate::geom::{Aabb, BezierPatch, DAabb, Ray};
use crate::kernel::subdivision::{self, PreparedPatch, SubdivisionConfig};
use crate::kernel::{KernelStats, PatchHit};
use crate::scene::Scene;

/// Which intersection path answers queries.
#[derive(Clone, Copy, Debug)]
pub enum Precision {
    /// The float-precision kernel (Dammertz §2.3) in `f32`.
    F32(SubdivisionConfig),
    /// The same algorithm in `f64`: the accuracy reference.
    F64(SubdivisionConfig),
}

/// Work done by one query.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct QueryStats {
    pub kernel: KernelStats,
    pub nodes_visited: u64,
    pub bvh_box_tests: u64,
}

impl QueryStats {
    pub fn add(&mut self, o: &QueryStats) {
        self.kernel.add(&o.kernel);
        self.nodes_visited += o.nodes_visited;
        self.bvh_box_tests += o.bvh_box_tests;
    }
}

/// A nearest hit with everything shading needs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SceneHit {
    /// Ray parameter, in units of the ray's direction.
    pub t: f64,
    pub object: u32,
    /// Patch number within its object (contract order).
    pub patch: u32,
    pub u: f64,
    pub v: f64,
    /// The final box of the subdivision (the hit interval), secondary rays start at its
    /// corners (Dammertz §2.4).
    pub hit_box: Aabb,
    /// Unit geometric normal `∂S/∂u × ∂S/∂v` at (u, v), from the exact `f64` derivatives.
    pub normal: DVec3,
}

/// Prepared geometry of a scene.
pub struct SceneGeometry {
    prepared: Vec<PreparedPatch>,
    originals: Vec<BezierPatch>,
    /// (object, patch within object) per primitive.
    ids: Vec<(u32, u32)>,
    bvh: Bvh,
}

impl SceneGeometry {
    /// Prepares the patches and builds the BVH.
    pub fn build(scene: &Scene) -> SceneGeometry {
        let (originals, ids) = collect_patches(scene);
        let boxes: Vec<Aabb> = originals
            .iter()
            .map(|p| p.tight_box().to_f32_outward())
            .collect();
        let bvh = Bvh::build(&boxes);
        Self::with_bvh(originals, ids, bvh)
    }

    fn with_bvh(originals: Vec<BezierPatch>, ids: Vec<(u32, u32)>, bvh: Bvh) -> SceneGeometry {
        let prepared = originals.iter().map(PreparedPatch::new).collect();
        SceneGeometry {
            prepared,
            originals,
            ids,
            bvh,
        }
    }

    /// A hash of the geometry the BVH indexes: degrees and control points in file order.
    /// A BVH file records it so that a stale file is refused.
    pub fn hash_scene(scene: &Scene) -> u64 {
        let mut h = GeometryHasher::new();
        let (patches, _) = collect_patches(scene);
        h.write_u64(patches.len() as u64);
        for p in &patches {
            h.write_u64(p.degree_u() as u64);
            h.write_u64(p.degree_v() as u64);
            for q in p.homogeneous_points() {
                for c in q.to_array() {
                    h.write_f64(c);
                }
            }
        }
        h.finish()
    }

    pub fn bvh(&self) -> &Bvh {
        &self.bvh
    }

    pub fn patch_count(&self) -> usize {
        self.prepared.len()
    }

    pub fn bounds(&self) -> Aabb {
        self.bvh.bounds()
    }

    /// The nearest hit along `ray` in `[ray.tmin, ray.tmax]`.
    pub fn intersect(
        &self,
        ray: &Ray,
        precision: &Precision,
        stats: &mut QueryStats,
    ) -> Option<SceneHit> {
        match precision {
            Precision::F32(cfg) => self.intersect_f32(ray, cfg, stats),
            Precision::F64(cfg) => {
                let (o, d) = (ray.origin.as_dvec3(), ray.dir.as_dvec3());
                self.intersect_f64(o, d, ray.tmin as f64, ray.tmax as f64, cfg, stats)
            }
        }
    }

    fn intersect_f32(
        &self,
        ray: &Ray,
        cfg: &SubdivisionConfig,
        stats: &mut QueryStats,
    ) -> Option<SceneHit> {
        let mut best: Option<(u32, PatchHit)> = None;
        let mut kernel = KernelStats::default();
        let t = self.bvh.traverse(ray, |prim, tmax| {
            let r = Ray { tmax, ..*ray };
            let hit = subdivision::intersect(&self.prepared[prim as usize], &r, cfg, &mut kernel)?;
            best = Some((prim, hit));
            Some(hit.t)
        });
        stats.kernel.add(&kernel);
        stats.nodes_visited += t.nodes_visited;
        stats.bvh_box_tests += t.box_tests;
        let (prim, h) = best?;
        Some(self.finish_hit(prim, h.t as f64, h.u as f64, h.v as f64, h.hit_box))
    }

    /// The `f64` reference: every patch whose box the ray meets (an `f64` slab test, so no
    /// `f32` rounding of the ray can drop a candidate) is intersected in `f64`.
    pub fn intersect_f64(
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
        for (prim, patch) in self.originals.iter().enumerate() {
            let b = self.prepared[prim].bounds();
            stats.bvh_box_tests += 1;
            let b = DAabb {
                min: b.min.as_dvec3(),
                max: b.max.as_dvec3(),
            };
            let limit = best.as_ref().map_or(tmax, |(_, h)| h.t);
            if b.intersect(origin, inv, tmin, limit).is_none() {
                continue;
            }
            stats.kernel.patch_tests += 1;
            if let Some(h) = subdivision::intersect_f64(patch, origin, dir, tmin, limit, cfg) {
                best = Some((prim as u32, h));
            }
        }
        let (prim, h) = best?;
        Some(self.finish_hit(prim, h.t, h.u, h.v, h.hit_box.to_f32_outward()))
    }

    /// True when anything blocks `ray` in `[tmin, tmax]` (shadow rays).
    pub fn occluded(&self, ray: &Ray, precision: &Precision, stats: &mut QueryStats) -> bool {
        match precision {
            Precision::F32(cfg) => {
                let mut kernel = KernelStats::default();
                let (hit, t) = self.bvh.traverse_any(ray, |prim| {
                    subdivision::occluded(&self.prepared[prim as usize], ray, cfg, &mut kernel)
                });
                stats.kernel.add(&kernel);
                stats.nodes_visited += t.nodes_visited;
                stats.bvh_box_tests += t.box_tests;
                hit
            }
            Precision::F64(_) => self.intersect(ray, precision, stats).is_some(),
        }
    }

    fn finish_hit(&self, prim: u32, t: f64, u: f64, v: f64, hit_box: Aabb) -> SceneHit {
        let (object, patch) = self.ids[prim as usize];
        SceneHit {
            t,
            object,
            patch,
            u,
            v,
            hit_box,
            normal: self.originals[prim as usize].normal(u, v),
        }
    }
}

/// All Bézier patches of the scene in contract order, with their (object, patch) ids.
fn collect_patches(scene: &Scene) -> (Vec<BezierPatch>, Vec<(u32, u32)>) {
    let mut patches = Vec::new();
    let mut ids = Vec::new();
    for (o, object) in scene.objects.iter().enumerate() {
        for (k, p) in object.bezier_patches().into_iter().enumerate() {
            patches.push(p);
            ids.push((o as u32, k as u32));
        }
    }
    (patches, ids)
}

impl SceneGeometry {
    /// Prepares the scene with the BVH from `path`, refusing a file built for other
    /// geometry or in another format with a message that says what to do.
    pub fn load(
        scene: &Scene,
        path: &std::path::Path,
    ) -> Result<SceneGeometry, crate::scene::LoadError> {
        use crate::scene::LoadError;
        let file = std::fs::File::open(path).map_err(|e| LoadError::io(path, e))?;
        let mut reader = std::io::BufReader::new(file);
        let bvh = Bvh::read(&mut reader, Self::hash_scene(scene))
            .map_err(|e| LoadError::invalid(path, e.to_string()))?;
        let (originals, ids) = collect_patches(scene);
        if bvh.prim_count() != originals.len() {
            return Err(LoadError::invalid(
                path,
                "the BVH indexes a different number of patches than the scene; rebuild it with `patchtrace bvh`",
            ));
        }
        Ok(Self::with_bvh(originals, ids, bvh))
    }

    /// Writes the BVH with the scene's geometry hash, atomically.
    pub fn save_bvh(
        &self,
        scene: &Scene,
        path: &std::path::Path,
    ) -> Result<(), crate::scene::LoadError> {
        let hash = Self::hash_scene(scene);
        crate::scene::write::write_atomic(path, |w| self.bvh.write(w, hash))
    }
}
