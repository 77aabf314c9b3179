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

mod build;
mod file;
mod primitive;
mod reference;
mod traverse;
mod triangles;

pub use file::FromFile;

use glam::DVec3;

use crate::accel::bvh::{Bvh, TraversalStats};
use crate::accel::grid::{Grid, GridStats};
use crate::accel::instance::Placement;
use crate::accel::patches::PatchStore;
use crate::geom::Aabb;
use crate::kernel::{Kernel, KernelStats, secondary};
use triangles::{LeafPacks, Triangles};

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

    /// Adds a BVH traversal's counts: the instances' work `nested`, the traversal `t`
    /// itself, and the primitives of the leaves it reached.
    fn add_bvh(&mut self, nested: &QueryStats, t: &TraversalStats, surface_tests: u64) {
        self.add(nested);
        self.nodes_visited += t.nodes_visited;
        self.bvh_box_tests += t.box_tests;
        self.surface_tests += surface_tests;
    }

    /// Adds a grid traversal's counts: its tight-box tests are the surfaces tested.
    fn add_grid(&mut self, g: &GridStats) {
        self.voxels_visited += g.voxels_visited;
        self.bvh_box_tests += g.box_tests;
        self.surface_tests += g.box_tests;
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
    /// their surface of origin by it ([`Kernel::leaving`]).
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

impl SceneHit {
    /// Where a secondary ray leaving this hit starts (Dammertz §2.4): the corner of the
    /// leave box on the side of `normal` (the opposite side when not `outside`, for rays
    /// going in), moved `ulps` further ([`secondary::secondary_origin`]).
    pub fn secondary_origin(&self, normal: glam::Vec3, outside: bool, ulps: u32) -> glam::Vec3 {
        secondary::secondary_origin(&self.leave_box, normal, outside, ulps)
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

impl SceneGeometry {
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

    pub fn bounds(&self) -> Aabb {
        match &self.accel {
            Accel::Bvh(bvh, _) => bvh.bounds(),
            Accel::Grid(grid) => grid.bounds(),
        }
    }
}
