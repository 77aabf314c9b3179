//! The scene as the renderer sees it: every Bézier patch prepared for the kernel in `f32`,
//! its `f64` original kept for normals and the reference path, every mesh triangle in `f32`
//! for the watertight kernel, and one accelerator over them: a BVH over the tight patch
//! boxes (LG90 §3.1, Fig. 2) and the triangle boxes, or the uniform grid of LG90 §3.1.
//! Primitive `i` of either is patch `i` when `i` is below the patch count, and triangle
//! `i - patch count` otherwise, up to the triangle count, and instance `i - patches -
//! triangles` beyond that: instances (Dammertz §3.3, [`super::instance`]) share one
//! prepared copy of their geometry, a `SceneGeometry` of its own in object space. One
//! query answers "nearest hit" or "anything in the way" for a ray, counting the work it
//! did.

use std::borrow::Cow;
use std::ops::ControlFlow;

use glam::{DVec3, Vec3};
use rayon::prelude::*;

use super::bvh::Bvh;
use super::grid::Grid;
use super::instance::Placement;
use super::mapped;
use super::patches::{OwnedPatches, PatchStore};
use crate::geom::subdiv::Piece;
use crate::geom::trim::PatchTrim;
use crate::geom::{Aabb, BezierPatch, DAabb, Ray};
use crate::kernel::cached::{self, CachedConfig};
use crate::kernel::subdivision::{self, PreparedPatch, SubdivisionConfig};
use crate::kernel::toth::{self, TothConfig};
use crate::kernel::triangle::{
    self, PACK_WIDTH, PackShear, RayShear, TriangleHit, TrianglePack, intersect_pack,
};
use crate::kernel::{KernelStats, PatchHit};
use crate::progress::{Batched, ProgressBar};
use crate::scene::{Geometry, Scene};

/// Which intersection path answers queries.
#[derive(Clone, Copy, Debug)]
pub enum Precision {
    /// The float-precision kernel (Dammertz §2.3) in `f32`.
    F32(SubdivisionConfig),
    /// The same algorithm in `f64`: the accuracy reference.
    F64(SubdivisionConfig),
    /// Toth's interval Newton kernel (LG90 §4.1) on the `f64` patches, `f32` rays.
    Toth(TothConfig),
    /// The cached surface-tree kernel (LG90 §4.2–4.3) on the `f64` patches, `f32` rays.
    Cached(CachedConfig),
}

impl Precision {
    /// The path for secondary rays: the same, with adaptive termination (defined by the
    /// camera's pixels) replaced by float precision.
    pub fn for_secondary_rays(self) -> Precision {
        match self {
            Precision::F32(cfg) => Precision::F32(cfg.for_secondary_rays()),
            Precision::F64(cfg) => Precision::F64(cfg.for_secondary_rays()),
            other @ (Precision::Toth(_) | Precision::Cached(_)) => other,
        }
    }

    /// The path for secondary rays leaving `hit`: [`Precision::for_secondary_rays`], and
    /// for the LG90 kernels with ISRT (LG90 §6, "improved treatment of secondary rays")
    /// the surface of origin, on which they apply the triviality tests.
    pub fn leaving(self, hit: &SceneHit) -> Precision {
        let origin = hit.primitive;
        match self.for_secondary_rays() {
            Precision::Toth(cfg) if cfg.isrt => Precision::Toth(TothConfig {
                surface_of_origin: origin,
                ..cfg
            }),
            Precision::Cached(mut cfg) if cfg.toth.isrt => {
                cfg.toth.surface_of_origin = origin;
                Precision::Cached(cfg)
            }
            other => other,
        }
    }
}

/// Work done by one query.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct QueryStats {
    pub kernel: KernelStats,
    pub nodes_visited: u64,
    /// Box tests of the accelerator: BVH node boxes, or the grid's tight primitive boxes.
    pub bvh_box_tests: u64,
    /// Grid voxels stepped through (0 with the BVH).
    pub voxels_visited: u64,
    /// Primitives whose outermost box was tested (LG90 §7.1 "surfaces tested"): the grid's
    /// tight-box tests, or with the BVH the primitives of the leaves reached.
    pub surface_tests: u64,
}

impl QueryStats {
    pub fn add(&mut self, o: &QueryStats) {
        self.kernel.add(&o.kernel);
        self.nodes_visited += o.nodes_visited;
        self.bvh_box_tests += o.bvh_box_tests;
        self.voxels_visited += o.voxels_visited;
        self.surface_tests += o.surface_tests;
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
    /// The patch's number in the accelerator, `None` for a triangle: secondary rays name
    /// their surface of origin by it ([`Precision::leaving`]).
    pub primitive: Option<u32>,
    pub u: f64,
    pub v: f64,
    /// The final box of the subdivision (the hit interval), secondary rays start at its
    /// corners (Dammertz §2.4).
    pub hit_box: Aabb,
    /// The box secondary rays leave from (Dammertz §2.4): for a patch the hit box widened
    /// by the rounding of the kernel's sub-patch nets
    /// ([`subdivision::widen_by_net_rounding`]), for a triangle the hit box.
    pub leave_box: Aabb,
    /// Unit geometric normal: `∂S/∂u × ∂S/∂v` at (u, v) from the exact `f64` derivatives
    /// for a patch, the face normal for a triangle.
    pub normal: DVec3,
    /// Unit normal for shading: the geometric normal for a patch, the interpolated vertex
    /// normal (on the geometric normal's side) for a triangle of a mesh that has them.
    pub shading_normal: DVec3,
}

/// Mesh triangles in `f32`, with per-corner shading normals when the mesh has them.
#[derive(Default)]
struct Triangles {
    corners: Vec<[Vec3; 3]>,
    normals: Vec<Option<[DVec3; 3]>>,
    /// (object, triangle within object).
    ids: Vec<(u32, u32)>,
}

/// The triangles again in BVH leaf order, four to a [`TrianglePack`], so that a leaf's
/// triangles are one contiguous run tested four at a time with no index indirection.
struct LeafPacks {
    packs: Vec<TrianglePack>,
    /// Triangle number (into [`Triangles`]) of each lane of each pack.
    lanes: Vec<[u32; PACK_WIDTH]>,
    /// For the first position of each leaf's range in the BVH's primitive index array, and
    /// for the array's length, the index of the leaf's first pack: a leaf covering positions
    /// `a..b` has packs `start[a]..start[b]` (leaves tile the positions).
    start: Vec<u32>,
}

impl LeafPacks {
    fn new(bvh: &Bvh, patches: u32, corners: &[[Vec3; 3]]) -> LeafPacks {
        let triangles = patches..patches + corners.len() as u32;
        let mut leaves: Vec<(usize, usize)> = bvh
            .nodes()
            .iter()
            .filter(|n| n.is_leaf())
            .map(|n| (n.first as usize, n.count as usize))
            .collect();
        leaves.sort_unstable();
        let mut p = LeafPacks {
            packs: Vec::with_capacity(corners.len() / PACK_WIDTH + leaves.len()),
            lanes: Vec::new(),
            start: vec![0; bvh.prim_count() + 1],
        };
        let mut tris = Vec::with_capacity(PACK_WIDTH);
        for (first, count) in leaves {
            p.start[first] = p.packs.len() as u32;
            let in_leaf = &bvh.prim_indices()[first..first + count];
            let triangles: Vec<u32> = in_leaf
                .iter()
                .filter(|&&prim| triangles.contains(&prim))
                .map(|&prim| prim - patches)
                .collect();
            for chunk in triangles.chunks(PACK_WIDTH) {
                tris.clear();
                tris.extend(chunk.iter().map(|&k| corners[k as usize]));
                p.packs.push(TrianglePack::new(&tris));
                let mut lanes = [u32::MAX; PACK_WIDTH];
                lanes[..chunk.len()].copy_from_slice(chunk);
                p.lanes.push(lanes);
            }
        }
        p.start[bvh.prim_count()] = p.packs.len() as u32;
        p
    }

    /// The packs of the leaf covering `range` and their first pack's index.
    fn of_leaf(&self, range: &std::ops::Range<usize>) -> (usize, &[TrianglePack]) {
        let (a, b) = (
            self.start[range.start] as usize,
            self.start[range.end] as usize,
        );
        (a, &self.packs[a..b])
    }
}

/// The nearest candidate found so far during traversal.
enum Candidate {
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
struct PatchRay<'a> {
    ray: &'a Ray,
    kernel: Option<subdivision::KernelRay>,
}

impl<'a> PatchRay<'a> {
    fn new(ray: &'a Ray) -> Self {
        PatchRay { ray, kernel: None }
    }

    fn kernel(&mut self, cfg: &SubdivisionConfig) -> &subdivision::KernelRay {
        self.kernel
            .get_or_insert_with(|| subdivision::KernelRay::new(self.ray, cfg))
    }
}

/// The acceleration structure over the primitives.
enum Accel {
    /// The BVH, with the triangles again in its leaf order.
    Bvh(Bvh, LeafPacks),
    Grid(Grid),
}

impl Accel {
    fn bvh(bvh: Bvh, patches: usize, triangles: &Triangles) -> Accel {
        if triangles.corners.is_empty() {
            // No packs: every leaf's pack range is empty.
            let none = LeafPacks {
                packs: Vec::new(),
                lanes: Vec::new(),
                start: vec![0; bvh.prim_count() + 1],
            };
            return Accel::Bvh(bvh, none);
        }
        let packs = LeafPacks::new(&bvh, patches as u32, &triangles.corners);
        Accel::Bvh(bvh, packs)
    }
}

/// Prepared geometry of a scene.
pub struct SceneGeometry {
    patches: PatchStore,
    triangles: Triangles,
    accel: Accel,
    /// The instances, top-level primitives after the triangles, and the geometry they
    /// share, each prepared once in object space (Dammertz §3.3).
    instances: Vec<Placement>,
    prototypes: Vec<SceneGeometry>,
}

/// The scene's objects split for preparation: those placed in world space, and the
/// instances with the distinct geometry they share.
struct Split<'a> {
    own: Vec<(u32, &'a Geometry)>,
    /// (object, prototype, object to world) per instance.
    instances: Vec<(u32, u32, glam::DAffine3)>,
    prototypes: Vec<&'a Geometry>,
}

impl<'a> Split<'a> {
    fn of(scene: &'a Scene) -> Split<'a> {
        let mut split = Split {
            own: Vec::new(),
            instances: Vec::new(),
            prototypes: Vec::new(),
        };
        // Shared geometry is one `Arc`: its address names it.
        let mut seen: Vec<*const Geometry> = Vec::new();
        for (o, object) in scene.objects.iter().enumerate() {
            match &object.geometry {
                Geometry::Instance(i) => {
                    let key = std::sync::Arc::as_ptr(&i.geometry);
                    let k = seen.iter().position(|&s| s == key).unwrap_or_else(|| {
                        seen.push(key);
                        split.prototypes.push(&i.geometry);
                        seen.len() - 1
                    });
                    split.instances.push((o as u32, k as u32, i.transform));
                }
                g => split.own.push((o as u32, g)),
            }
        }
        split
    }

    /// Each shared geometry prepared in object space with its own BVH.
    fn prepare_prototypes(&self) -> Vec<SceneGeometry> {
        self.prototypes
            .iter()
            .map(|g| SceneGeometry::build_own(&[(0, g)], &[], Vec::new(), &ProgressBar::hidden()))
            .collect()
    }
}

impl SceneGeometry {
    /// Prepares the patches and builds the BVH, with instances under a top-level BVH.
    pub fn build(scene: &Scene) -> SceneGeometry {
        Self::build_with(scene, &ProgressBar::hidden())
    }

    /// [`build`](Self::build), advancing `progress` to twice the top-level primitive
    /// count: one step per primitive bounded (a trimmed patch's box is the costly part),
    /// one per primitive placed in a BVH leaf. Instances count as one primitive each.
    pub fn build_with(scene: &Scene, progress: &ProgressBar) -> SceneGeometry {
        let split = Split::of(scene);
        let prototypes = split.prepare_prototypes();
        SceneGeometry::build_own(&split.own, &split.instances, prototypes, progress)
    }

    /// The BVH over `own`'s primitives and the boxes of the instances `placed` (object,
    /// prototype, transform).
    fn build_own(
        own: &[(u32, &Geometry)],
        placed: &[(u32, u32, glam::DAffine3)],
        prototypes: Vec<SceneGeometry>,
        progress: &ProgressBar,
    ) -> SceneGeometry {
        let patches = collect_patches(own);
        let triangles = collect_triangles(own);
        let instances = place(placed, &prototypes, patches.originals.len());
        let primitives = patches.originals.len() + triangles.corners.len() + instances.len();
        progress.set_length(2 * primitives as u64);
        // Bounding is independent per patch (a trimmed patch's box is the costly part), so
        // it runs on every core.
        let mut boxes: Vec<Aabb> = patches
            .originals
            .par_iter()
            .zip(&patches.trims)
            .map_init(
                || Batched::new(progress),
                |bounded, (p, trim)| {
                    bounded.add(1);
                    surviving_box(p, trim.as_deref()).to_f32_outward()
                },
            )
            .collect();
        boxes.extend(
            triangles
                .corners
                .iter()
                .map(|c| c.iter().copied().collect::<Aabb>()),
        );
        boxes.extend(instances.iter().map(|i| i.bounds));
        progress.inc((triangles.corners.len() + instances.len()) as u64);
        let bvh = Bvh::build_packed_with(&boxes, patches.originals.len(), progress);
        let accel = Accel::bvh(bvh, patches.originals.len(), &triangles);
        Self::with_accel(patches, triangles, accel, instances, prototypes)
    }

    /// Prepares the patches and builds the uniform grid of LG90 §3.1 within `budget_bytes`
    /// (see [`Grid::build`]).
    /// LG90's grid has no instances: they are prepared as placed copies.
    pub fn build_grid(scene: &Scene, budget_bytes: usize) -> SceneGeometry {
        let resolved: Vec<(u32, Cow<Geometry>)> = scene
            .objects
            .iter()
            .enumerate()
            .map(|(o, object)| (o as u32, object.geometry.resolved()))
            .collect();
        let own: Vec<(u32, &Geometry)> = resolved.iter().map(|(o, g)| (*o, g.as_ref())).collect();
        let patches = collect_patches(&own);
        let triangles = collect_triangles(&own);
        let grid = Grid::build(&patches.originals, &triangles.corners, budget_bytes);
        Self::with_accel(
            patches,
            triangles,
            Accel::Grid(grid),
            Vec::new(),
            Vec::new(),
        )
    }

    fn with_accel(
        patches: Patches,
        triangles: Triangles,
        accel: Accel,
        instances: Vec<Placement>,
        prototypes: Vec<SceneGeometry>,
    ) -> SceneGeometry {
        let prepared = patches
            .originals
            .par_iter()
            .map(PreparedPatch::new)
            .collect();
        SceneGeometry {
            patches: PatchStore::Owned(OwnedPatches {
                prepared,
                originals: patches.originals,
                ids: patches.ids,
                trims: patches.trims,
            }),
            triangles,
            accel,
            instances,
            prototypes,
        }
    }

    /// The BVH, when the geometry was prepared with one.
    pub fn bvh(&self) -> Option<&Bvh> {
        match &self.accel {
            Accel::Bvh(bvh, _) => Some(bvh),
            Accel::Grid(_) => None,
        }
    }

    /// The grid, when the geometry was prepared with one.
    pub fn grid(&self) -> Option<&Grid> {
        match &self.accel {
            Accel::Grid(grid) => Some(grid),
            Accel::Bvh(..) => None,
        }
    }

    /// The patches of the scene, each instance's counted.
    pub fn patch_count(&self) -> usize {
        let instanced: usize = self
            .instances
            .iter()
            .map(|i| self.prototypes[i.prototype as usize].patch_count())
            .sum();
        self.patches.len() + instanced
    }

    /// The patches prepared in memory: those instances share, once.
    pub fn prepared_patch_count(&self) -> usize {
        self.patches.len()
            + self
                .prototypes
                .iter()
                .map(|p| p.patches.len())
                .sum::<usize>()
    }

    /// Points whose convex hull holds the surface of the scene's own patches and
    /// triangles: control points and corners.
    pub(super) fn hull_points(&self) -> Vec<DVec3> {
        let corners = self.triangles.corners.iter().flatten();
        (0..self.patches.len())
            .flat_map(|i| {
                self.patches
                    .original(i)
                    .euclidean_points()
                    .collect::<Vec<_>>()
            })
            .chain(corners.map(|c| c.as_dvec3()))
            .collect()
    }

    pub fn instance_count(&self) -> usize {
        self.instances.len()
    }

    pub fn triangle_count(&self) -> usize {
        self.triangles.corners.len()
    }

    pub fn bounds(&self) -> Aabb {
        match &self.accel {
            Accel::Bvh(bvh, _) => bvh.bounds(),
            Accel::Grid(grid) => grid.bounds(),
        }
    }

    /// The margin the BVH grows its boxes by for `ray`: patches are searched in the ray's
    /// own space and may be hit a little outside their exact box
    /// ([`subdivision::cull_margin`]), as may instances, whose geometry takes the ray mapped
    /// into object space; triangles alone are tested exactly against exact boxes.
    fn cull_margin(&self, bvh: &Bvh, ray: &Ray) -> f32 {
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
        precision: &Precision,
        stats: &mut QueryStats,
    ) -> Option<SceneHit> {
        match precision {
            Precision::F32(_) | Precision::Toth(_) | Precision::Cached(_) => {
                self.intersect_f32(ray, precision, stats)
            }
            Precision::F64(cfg) => {
                let (o, d) = (ray.origin.as_dvec3(), ray.dir.as_dvec3());
                self.intersect_f64(o, d, ray.tmin as f64, ray.tmax as f64, cfg, stats)
            }
        }
    }

    fn intersect_f32(
        &self,
        ray: &Ray,
        precision: &Precision,
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
            let b = &placement.bounds;
            let b = DAabb {
                min: b.min.as_dvec3(),
                max: b.max.as_dvec3(),
            };
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
    fn nearest_own_f64(
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
            let b = self.patches.bounds(prim);
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

    /// True when anything blocks `ray` in `[tmin, tmax]` (shadow rays).
    pub fn occluded(&self, ray: &Ray, precision: &Precision, stats: &mut QueryStats) -> bool {
        match precision {
            Precision::F32(_) | Precision::Toth(_) | Precision::Cached(_) => match &self.accel {
                Accel::Bvh(bvh, packs) => self.blocked_in_bvh(bvh, packs, ray, precision, stats),
                Accel::Grid(grid) => self.blocked_in_grid(grid, ray, precision, stats),
            },
            Precision::F64(_) => self.intersect(ray, precision, stats).is_some(),
        }
    }

    /// The nearest candidate in the BVH: a leaf's patches one at a time, then its triangles
    /// a pack at a time.
    fn nearest_in_bvh(
        &self,
        bvh: &Bvh,
        packs: &LeafPacks,
        patch_ray: &mut PatchRay,
        precision: &Precision,
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
        stats.add(&nested);
        stats.nodes_visited += t.nodes_visited;
        stats.bvh_box_tests += t.box_tests;
        stats.surface_tests += surface_tests;
        best
    }

    /// What instance `k` is queried with for `ray`: its shared geometry, the ray in
    /// object space and the precision for it.
    fn enter_instance(
        &self,
        k: u32,
        ray: &Ray,
        precision: &Precision,
    ) -> (&SceneGeometry, Ray, Precision) {
        let placement = &self.instances[k as usize];
        let prototype = &self.prototypes[placement.prototype as usize];
        let local = placement.precision_in_object(precision, prototype.patches.len() as u32);
        (prototype, placement.ray_to_object(ray), local)
    }

    /// Whether anything in the BVH blocks `ray`.
    fn blocked_in_bvh(
        &self,
        bvh: &Bvh,
        packs: &LeafPacks,
        ray: &Ray,
        precision: &Precision,
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
        stats.add(&nested);
        stats.nodes_visited += t.nodes_visited;
        stats.bvh_box_tests += t.box_tests;
        stats.surface_tests += surface_tests;
        hit
    }

    /// The nearest candidate in the grid, one primitive at a time.
    fn nearest_in_grid(
        &self,
        grid: &Grid,
        patch_ray: &mut PatchRay,
        precision: &Precision,
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
        stats.voxels_visited += g.voxels_visited;
        stats.bvh_box_tests += g.box_tests;
        stats.surface_tests += g.box_tests;
        best
    }

    /// Whether anything in the grid blocks `ray`.
    fn blocked_in_grid(
        &self,
        grid: &Grid,
        ray: &Ray,
        precision: &Precision,
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
        stats.voxels_visited += g.voxels_visited;
        stats.bvh_box_tests += g.box_tests;
        stats.surface_tests += g.box_tests;
        hit
    }

    /// Nearest hit on patch `prim` with `t` up to `tmax` by the `f32`-ray kernel
    /// `precision` selects, and its `t`.
    fn patch_hit(
        &self,
        prim: u32,
        ray: &mut PatchRay,
        tmax: f32,
        precision: &Precision,
        kernel: &mut KernelStats,
    ) -> Option<(f32, Candidate)> {
        let patch_hit = |h: PatchHit| (h.t, Candidate::Patch(prim, h));
        let r = Ray { tmax, ..*ray.ray };
        let trim = self.trim(prim);
        // The f64 patch only for the kernels that take it: a mapped one is made on demand.
        let patch = || self.patches.original(prim as usize);
        match precision {
            Precision::Toth(cfg) => {
                let origin = cfg.surface_of_origin == Some(prim);
                toth::intersect(&patch(), trim, &r, cfg, origin, kernel).map(patch_hit)
            }
            Precision::Cached(cfg) => {
                let origin = cfg.toth.surface_of_origin == Some(prim);
                cached::intersect(&patch(), trim, &r, cfg, origin, kernel).map(patch_hit)
            }
            Precision::F32(cfg) | Precision::F64(cfg) => {
                let prepared = self.patches.prepared(prim as usize);
                subdivision::nearest(&prepared, trim, ray.kernel(cfg), tmax, cfg, kernel)
                    .map(|h| (h.t(), Candidate::Subdivision(prim, h)))
            }
        }
    }

    /// Whether patch `prim` blocks the ray, by the kernel `precision` selects.
    fn patch_occluded(
        &self,
        prim: u32,
        ray: &mut PatchRay,
        precision: &Precision,
        kernel: &mut KernelStats,
    ) -> bool {
        let trim = self.trim(prim);
        let patch = || self.patches.original(prim as usize);
        match precision {
            Precision::Toth(cfg) => {
                let origin = cfg.surface_of_origin == Some(prim);
                toth::occluded(&patch(), trim, ray.ray, cfg, origin, kernel)
            }
            Precision::Cached(cfg) => {
                let origin = cfg.toth.surface_of_origin == Some(prim);
                cached::occluded(&patch(), trim, ray.ray, cfg, origin, kernel)
            }
            Precision::F32(cfg) | Precision::F64(cfg) => {
                let prepared = self.patches.prepared(prim as usize);
                subdivision::blocks(&prepared, trim, ray.kernel(cfg), cfg, kernel)
            }
        }
    }

    /// Patch `prim`'s trim, `None` where its loops do not cut it.
    #[inline]
    fn trim(&self, prim: u32) -> Option<&PatchTrim> {
        self.patches.trim(prim as usize)
    }

    fn finish_patch_hit(&self, prim: u32, t: f64, u: f64, v: f64, hit_box: Aabb) -> SceneHit {
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
    fn finish_triangle_hit(&self, k: u32, h: &TriangleHit) -> SceneHit {
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

/// The placements of the instances `placed` (object, prototype, transform), leaving out
/// any whose transform has no inverse. Their patches are numbered after the scene's own
/// `own_patches`, a run per instance, so a hit names its surface of origin uniquely.
fn place(
    placed: &[(u32, u32, glam::DAffine3)],
    prototypes: &[SceneGeometry],
    own_patches: usize,
) -> Vec<Placement> {
    let mut first = own_patches as u64;
    placed
        .iter()
        .filter_map(|&(object, k, to_world)| {
            let prototype = &prototypes[k as usize];
            let number = u32::try_from(first).ok();
            first += prototype.patches.len() as u64;
            Placement::new(k, object, prototype, to_world, number)
        })
        .collect()
}

/// The scene's patches as the accelerator indexes them.
struct Patches {
    originals: Vec<BezierPatch>,
    /// (object, patch within object) per patch.
    ids: Vec<(u32, u32)>,
    /// Per patch, its trim where its loops cut it (Dammertz §2.6).
    trims: Vec<Option<Box<PatchTrim>>>,
}

/// All Bézier patches of the scene in contract order, with their (object, patch) ids and
/// trims. Patches collapsed to a curve or a point are left out: they have no area, so no
/// ray hits them exactly, while rounding would let the `f32` kernel report hits on them
/// whose secondary rays, lacking a normal to leave along, re-hit the same curve.
/// So are patches their trim loops cut away wholly (culled).
fn collect_patches(objects: &[(u32, &Geometry)]) -> Patches {
    let mut out = Patches {
        originals: Vec::new(),
        ids: Vec::new(),
        trims: Vec::new(),
    };
    // Objects convert independently (NURBS to Bézier, trims), on every core, and are
    // joined in order.
    let per_object: Vec<_> = objects
        .par_iter()
        .map(|&(o, geometry)| (o, geometry.trimmed_patches()))
        .collect();
    for (o, entries) in per_object {
        for (k, entry) in entries.into_iter().enumerate() {
            let Some((p, trim)) = entry else { continue };
            if p.has_zero_area() {
                continue;
            }
            out.originals.push(p);
            out.ids.push((o, k as u32));
            out.trims.push(trim);
        }
    }
    out
}

/// A scene's geometry from its BVH file ([`mapped`]).
pub enum FromFile {
    /// The file holds the prepared patches: the geometry, mapped, and the scene's trim loop
    /// count (the scene itself was read without its geometry).
    Mapped(Box<SceneGeometry>, usize),
    /// The file holds the tree only (triangles, instances, trimmed or general patches): the
    /// geometry must be built from the scene, read with its geometry, with
    /// [`SceneGeometry::with_tree`].
    TreeOnly(Bvh),
}

impl SceneGeometry {
    /// The geometry of a BVH file accepted for the scene ([`mapped::Opened::check`]).
    pub fn from_file(file: mapped::BvhFile) -> FromFile {
        match file.patches {
            Some(patches) => {
                let accel = Accel::bvh(file.bvh, patches.len(), &Triangles::default());
                let geometry = SceneGeometry {
                    patches: PatchStore::Mapped(patches),
                    triangles: Triangles::default(),
                    accel,
                    instances: Vec::new(),
                    prototypes: Vec::new(),
                };
                FromFile::Mapped(Box::new(geometry), file.trim_loops)
            }
            None => FromFile::TreeOnly(file.bvh),
        }
    }

    /// Where the mapped patches of subdivision surfaces lie in their quads, by object and
    /// patch number (empty for other objects): what `trace` reports for a scene read from
    /// a BVH file without its geometry files ([`crate::scene::Object::trace_patch`]).
    pub fn mapped_pieces(&self, objects: usize) -> Vec<Vec<Piece>> {
        let mut by_object: Vec<Vec<Option<Piece>>> = vec![Vec::new(); objects];
        if let PatchStore::Mapped(m) = &self.patches {
            for i in 0..m.len() {
                let (object, patch) = m.id(i);
                if let (Some(piece), Some(list)) = (m.piece(i), by_object.get_mut(object as usize))
                {
                    if list.len() <= patch as usize {
                        list.resize(patch as usize + 1, None);
                    }
                    list[patch as usize] = Some(piece);
                }
            }
        }
        by_object
            .into_iter()
            .map(|list| {
                let patches = 0..list.len() as u32;
                list.into_iter()
                    .zip(patches)
                    .map(|(piece, p)| piece.unwrap_or(Piece::whole(p)))
                    .collect()
            })
            .collect()
    }

    /// Prepares `scene` with a tree from its BVH file ([`FromFile::TreeOnly`]); `path`
    /// names the file in the error when the tree indexes a different number of primitives.
    pub fn with_tree(
        scene: &Scene,
        bvh: Bvh,
        path: &std::path::Path,
    ) -> Result<SceneGeometry, crate::formats::LoadError> {
        let split = Split::of(scene);
        let prototypes = split.prepare_prototypes();
        let patches = collect_patches(&split.own);
        let triangles = collect_triangles(&split.own);
        let instances = place(&split.instances, &prototypes, patches.originals.len());
        if bvh.prim_count() != patches.originals.len() + triangles.corners.len() + instances.len() {
            return Err(crate::formats::LoadError::invalid(
                path,
                "the BVH indexes a different number of patches than the scene; rebuild it with `patchtrace bvh`",
            ));
        }
        let accel = Accel::bvh(bvh, patches.originals.len(), &triangles);
        Ok(Self::with_accel(
            patches, triangles, accel, instances, prototypes,
        ))
    }

    /// Writes the BVH file for inputs with key `key`, atomically: the tree, and the
    /// prepared patches when the geometry is only patches the file can hold, with the
    /// scene's `trim_loops` and the floating `origin` it was moved by (minus it) before it
    /// was built, and the scene file's `parsed` form (`ron_format::parsed_scene`)
    /// when there is one; whether it holds the patches. Refused for a grid.
    pub fn save_bvh(
        &self,
        path: &std::path::Path,
        key: u64,
        (trim_loops, origin): (usize, glam::DVec3),
        parsed: Option<(u64, &[u8])>,
        piece_of: &(dyn Fn(u32, u32) -> Option<Piece> + Sync),
    ) -> Result<bool, crate::io::OutputError> {
        let Accel::Bvh(bvh, _) = &self.accel else {
            return Err(crate::io::OutputError::invalid(
                path,
                "the geometry was prepared with a grid, which has no BVH to write",
            ));
        };
        let records = match &self.patches {
            PatchStore::Owned(p)
                if self.triangles.corners.is_empty() && self.instances.is_empty() =>
            {
                mapped::records(p, piece_of)
            }
            _ => None,
        };
        crate::io::write_atomic(path, |w| {
            mapped::write(
                w,
                bvh,
                key,
                (records.as_deref(), trim_loops),
                origin,
                parsed,
            )
        })?;
        Ok(records.is_some())
    }
}

/// Quarterings of a trimmed patch when bounding the part its loops keep: 4 × 4 pieces.
const SURVIVING_BOX_LEVELS: u32 = 2;

/// The BVH box of a patch: its tight box, or for a patch its trim loops cut, the union of
/// the tight boxes of those of its 4 × 4 sub-patches (de Casteljau halvings) that keep any
/// of the surface ([`PatchTrim::keeps_any_of`]). A plate mostly cut away then no longer
/// sends every ray through its whole rectangle to the kernel; 16 sub-patches per cut patch
/// at load is cheap. The kernel still starts from the whole patch.
fn surviving_box(p: &BezierPatch, trim: Option<&PatchTrim>) -> DAabb {
    let Some(trim) = trim else {
        return p.tight_box();
    };
    let mut parts = vec![p.clone()];
    for _ in 0..SURVIVING_BOX_LEVELS {
        parts = parts
            .iter()
            .flat_map(|q| {
                let (a, b) = q.split_u();
                let (a0, a1) = a.split_v();
                let (b0, b1) = b.split_v();
                [a0, a1, b0, b1]
            })
            .collect();
    }
    let kept = parts
        .iter()
        .filter(|q| trim.keeps_any_of(q.domain()))
        .fold(DAabb::EMPTY, |acc, q| acc.union(&q.tight_box()));
    if kept.is_empty() { p.tight_box() } else { kept }
}

/// All mesh triangles of `objects` in order, rounded to `f32`.
fn collect_triangles(objects: &[(u32, &Geometry)]) -> Triangles {
    let mut t = Triangles::default();
    for &(o, geometry) in objects {
        let Geometry::Mesh(mesh) = geometry else {
            continue;
        };
        let has_normals = mesh.normals.len() == mesh.positions.len();
        for (k, idx) in mesh.indices.iter().enumerate() {
            let [a, b, c] = idx.map(|i| mesh.positions[i as usize]);
            t.corners.push([a.as_vec3(), b.as_vec3(), c.as_vec3()]);
            t.normals
                .push(has_normals.then(|| idx.map(|i| mesh.normals[i as usize])));
            t.ids.push((o, k as u32));
        }
    }
    t
}
