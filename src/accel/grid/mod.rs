//! The uniform grid of Lischinski and Gonczarowski 1990 §3.1: the scene box cut into cubic
//! voxels about a quarter of the mean primitive box edge, each voxel listing the patches that
//! may pass through it, traversed along a ray with a 3D DDA that stops after the voxel
//! holding the closest hit.
//!
//! - [`register`]: the voxel list `l_a(S)` of a patch by recursive quartering (k = 2), and
//!   the tight patch box from the same recursion.
//! - [`cells`]: only non-empty voxels are stored, in a hash table (Cleary and Wyvill 1988).
//! - [`dda`]: the voxel walk (Amanatides and Woo 1987).
//! - [`traverse`](Grid::traverse) / [`traverse_any`](Grid::traverse_any): the space tracing
//!   scheme of §3.1 with per-thread mailboxes, nearest hit or any hit.
//!
//! Primitive `i` is patch `i` below the patch count and triangle `i - patch count` above,
//! as in the BVH. A triangle is registered in the voxels its box overlaps.

mod cells;
mod dda;
mod register;
mod traverse;

use std::sync::atomic::{AtomicU64, Ordering};

use glam::{DVec3, Vec3};

pub use dda::{Dda, Voxel};
pub use register::K;
pub use traverse::GridStats;

use crate::geom::ulp::ulp_of;
use crate::geom::{Aabb, BezierPatch, DAabb, Ray};
use cells::CellTable;

/// Voxels per mean primitive box edge: LG90 §3.1 "We choose B/4 as the desired voxel side
/// length", B the average side length of a surface bounding box.
pub const VOXELS_PER_BOX_EDGE: f64 = 4.0;

/// Default memory budget of the grid (hash table and voxel lists), in bytes. LG90 §3.1
/// coarsens the grid "if the available physical memory is insufficient"; 256 MiB holds the
/// 100-teapot scene at B/4 a hundred times over, and stops a scene of a few huge patches
/// among tiny ones from registering a huge patch in millions of voxels.
pub const DEFAULT_BUDGET_BYTES: usize = 256 << 20;

/// Factor by which the voxel edge grows when the grid exceeds its budget. Registrations of
/// a surface fall about as the square of the edge, so each step cuts memory by about 2.
const COARSEN_FACTOR: f64 = std::f64::consts::SQRT_2;

/// Most voxels along one axis: keeps linear voxel numbers far inside `u64` and bounds the
/// walk of one ray, whatever the spread of primitive sizes.
const MAX_AXIS_VOXELS: f64 = 65536.0;

/// Ulps (of the largest scene coordinate, in `f32`) by which registration and tight boxes
/// are widened. The `f32` kernel works on control points rounded to `f32` and reports the
/// entry of a final box that spans up to [`DEFAULT_END_ULPS`] ulps, and the DDA may step a
/// corner a rounding error early or late; a hit near a voxel face must still be found in
/// the voxel the walk reaches first. Twice the end criterion covers all three.
///
/// [`DEFAULT_END_ULPS`]: crate::kernel::subdivision::DEFAULT_END_ULPS
pub const PAD_ULPS: f64 = 2.0 * crate::kernel::subdivision::DEFAULT_END_ULPS as f64;

/// Gives each grid a distinct number, so that a thread's mailboxes are reset when it moves
/// to another grid.
static NEXT_ID: AtomicU64 = AtomicU64::new(1);

/// A uniform grid over patches and triangles.
#[derive(Clone, Debug)]
pub struct Grid {
    lo: DVec3,
    edge: f64,
    dims: [u32; 3],
    cells: CellTable,
    /// Tight box of each primitive (the union of its `l_a` leaf boxes, widened by the pad).
    boxes: Vec<Aabb>,
    id: u64,
}

impl Grid {
    /// Builds the grid over `patches` then `triangles` with voxels of a quarter of the mean
    /// box edge, coarsened until it needs at most `budget_bytes` (or is one voxel).
    pub fn build(patches: &[BezierPatch], triangles: &[[Vec3; 3]], budget_bytes: usize) -> Grid {
        let tri_boxes: Vec<DAabb> = triangles
            .iter()
            .map(|c| c.iter().map(|p| p.as_dvec3()).collect())
            .collect();
        let first_boxes: Vec<DAabb> = patches
            .iter()
            .map(BezierPatch::tight_box)
            .chain(tri_boxes.iter().copied())
            .collect();
        let scene = first_boxes.iter().fold(DAabb::EMPTY, |a, b| a.union(b));
        let id = NEXT_ID.fetch_add(1, Ordering::Relaxed);
        if scene.is_empty() {
            return Grid {
                lo: DVec3::ZERO,
                edge: 1.0,
                dims: [1; 3],
                cells: CellTable::from_pairs(Vec::new()),
                boxes: Vec::new(),
                id,
            };
        }
        let extent = scene.extent();
        let largest = extent.max_element();
        let magnitude = scene.min.abs().max(scene.max.abs()).max_element();
        let pad = PAD_ULPS * ulp_of(magnitude as f32);
        let mean_edge = first_boxes
            .iter()
            .map(|b| b.extent().element_sum() / 3.0)
            .sum::<f64>()
            / first_boxes.len() as f64;
        let mut edge = (mean_edge / VOXELS_PER_BOX_EDGE).max(largest / MAX_AXIS_VOXELS);
        if !(edge > 0.0 && edge.is_finite()) {
            edge = if largest > 0.0 { largest } else { 1.0 };
        }
        loop {
            let dims = (extent / edge)
                .ceil()
                .max(DVec3::ONE)
                .to_array()
                .map(|d| d as u32);
            let coarsest = dims == [1; 3];
            let limit = if coarsest { usize::MAX } else { budget_bytes };
            let mut grid = Grid {
                lo: scene.min,
                edge,
                dims,
                cells: CellTable::from_pairs(Vec::new()),
                boxes: Vec::new(),
                id,
            };
            if grid.register(patches, &tri_boxes, pad, limit) {
                return grid;
            }
            edge *= COARSEN_FACTOR;
        }
    }

    /// Registers every primitive; `false` when the grid would exceed `limit` bytes.
    fn register(
        &mut self,
        patches: &[BezierPatch],
        triangles: &[DAabb],
        pad: f64,
        limit: usize,
    ) -> bool {
        // The list of (voxel, primitive) pairs is the peak of the build (16 bytes a pair,
        // the final table keeps 4), so the budget counts it: at 4 bytes a pair a mutated
        // scene took four times its budget (1 GB for the default 256 MiB).
        let max_pairs = limit / size_of::<(u64, u32)>();
        let mut pairs: Vec<(u64, u32)> = Vec::new();
        let target = self.edge / K;
        for (prim, patch) in patches.iter().enumerate() {
            let mut fits = true;
            let tight = register::quarter_boxes(patch, target, &mut |b| {
                fits = self.push_voxels(b, pad, prim as u32, &mut pairs, max_pairs);
                fits
            });
            if !fits {
                return false;
            }
            self.boxes.push(widen(&tight, pad).to_f32_outward());
        }
        for (k, b) in triangles.iter().enumerate() {
            if !self.push_voxels(b, pad, (patches.len() + k) as u32, &mut pairs, max_pairs) {
                return false;
            }
            self.boxes.push(widen(b, pad).to_f32_outward());
        }
        self.cells = CellTable::from_pairs(pairs);
        self.memory_bytes() <= limit
    }

    /// Appends `(voxel, prim)` for every voxel the widened box overlaps, unless that would
    /// make more than `max_pairs` pairs in all (`false`, nothing appended): one huge box
    /// among tiny ones could otherwise cover 2^48 voxels before any check.
    fn push_voxels(
        &self,
        b: &DAabb,
        pad: f64,
        prim: u32,
        pairs: &mut Vec<(u64, u32)>,
        max_pairs: usize,
    ) -> bool {
        let b = widen(b, pad);
        let lo = self.cell_of(b.min);
        let hi = self.cell_of(b.max);
        let count: u64 = (0..3).map(|a| u64::from(hi[a] - lo[a]) + 1).product();
        if pairs.len() as u64 + count > max_pairs as u64 {
            return false;
        }
        for z in lo[2]..=hi[2] {
            for y in lo[1]..=hi[1] {
                for x in lo[0]..=hi[0] {
                    pairs.push((self.key([x, y, z]), prim));
                }
            }
        }
        true
    }

    /// The voxel holding point `p`, clamped into the grid.
    fn cell_of(&self, p: DVec3) -> [u32; 3] {
        let c = ((p - self.lo) / self.edge).floor();
        [0, 1, 2].map(|a| (c[a].max(0.0) as u32).min(self.dims[a] - 1))
    }

    /// Linear number of a voxel, x fastest.
    fn key(&self, [x, y, z]: [u32; 3]) -> u64 {
        let [nx, ny, _] = self.dims.map(u64::from);
        u64::from(x) + nx * (u64::from(y) + ny * u64::from(z))
    }

    /// The voxels along `ray` within `[ray.tmin, ray.tmax]`, nearest first.
    pub fn voxels(&self, ray: &Ray) -> Dda {
        Dda::new(self, ray)
    }

    /// Voxel edge length `D`.
    pub fn voxel_edge(&self) -> f64 {
        self.edge
    }

    /// Voxels along x, y and z.
    pub fn dims(&self) -> [u32; 3] {
        self.dims
    }

    /// The box of voxel `cell`.
    pub fn voxel_box(&self, cell: [u32; 3]) -> DAabb {
        let c = DVec3::new(cell[0] as f64, cell[1] as f64, cell[2] as f64);
        DAabb {
            min: self.lo + c * self.edge,
            max: self.lo + (c + 1.0) * self.edge,
        }
    }

    /// The primitives registered in voxel `cell`.
    pub fn voxel_prims(&self, cell: [u32; 3]) -> &[u32] {
        self.cells.get(self.key(cell))
    }

    /// Every non-empty voxel with its primitives, in no particular order.
    pub fn non_empty_voxels(&self) -> impl Iterator<Item = ([u32; 3], &[u32])> {
        let [nx, ny, _] = self.dims.map(u64::from);
        self.cells.iter().map(move |(k, prims)| {
            let cell = [k % nx, (k / nx) % ny, k / (nx * ny)].map(|c| c as u32);
            (cell, prims)
        })
    }

    /// Number of non-empty voxels (the only ones stored).
    pub fn non_empty_count(&self) -> usize {
        self.cells.cell_count()
    }

    /// (voxel, primitive) registrations.
    pub fn registration_count(&self) -> usize {
        self.cells.registration_count()
    }

    /// The tight box of primitive `prim`.
    pub fn prim_box(&self, prim: u32) -> Aabb {
        self.boxes[prim as usize]
    }

    pub fn prim_count(&self) -> usize {
        self.boxes.len()
    }

    /// The box of everything.
    pub fn bounds(&self) -> Aabb {
        self.boxes.iter().fold(Aabb::EMPTY, |a, b| a.union(b))
    }

    /// Bytes the voxel storage holds (what the budget limits).
    pub fn memory_bytes(&self) -> usize {
        self.cells.memory_bytes()
    }
}

fn widen(b: &DAabb, pad: f64) -> DAabb {
    DAabb {
        min: b.min - pad,
        max: b.max + pad,
    }
}
