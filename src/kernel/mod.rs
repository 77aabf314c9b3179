//! Ray–patch intersection kernels, one per method. A kernel is chosen by an enum on the
//! hot path, not a trait object (pbrt-v4's tagged dispatch).
//!
//! - [`subdivision`]: Dammertz 2005 §2.2–2.3 and §2.7: subdivide until the bounding box
//!   stops shrinking in `f32`, with an `f64` twin that is the accuracy reference.
//! - [`toth`]: Toth's interval Newton with Krawczyk's operator (LG90 §4.1, §6).
//! - [`cached`]: the same tests on regular quadtrees, with each patch's surface tree kept
//!   in a per-thread LRU cache (LG90 §4.2–4.3).
//! - [`triangle`]: the watertight ray–triangle test (Woop et al. 2013), four triangles
//!   at a time.
//! - [`secondary`]: origins of secondary rays at hit-box corners, §2.4.
//!
//! [`Kernel`] selects one for a query; the accelerator passes it down to each patch.

pub mod cached;
pub mod secondary;
pub mod subdivision;
pub mod toth;
pub mod triangle;

use crate::geom::Aabb;
use cached::CachedConfig;
use subdivision::SubdivisionConfig;
use toth::TothConfig;

/// Which kernel answers a query: the enum every layer above passes down to select it.
#[derive(Clone, Copy, Debug)]
pub enum Kernel {
    /// The float-precision kernel (Dammertz §2.3) in `f32`.
    F32(SubdivisionConfig),
    /// The same algorithm in `f64`: the accuracy reference.
    F64(SubdivisionConfig),
    /// Toth's interval Newton kernel (LG90 §4.1) on the `f64` patches, `f32` rays.
    Toth(TothConfig),
    /// The cached surface-tree kernel (LG90 §4.2–4.3) on the `f64` patches, `f32` rays.
    Cached(CachedConfig),
}

impl Kernel {
    /// The path for secondary rays: the same, with adaptive termination (defined by the
    /// camera's pixels) replaced by float precision.
    pub fn for_secondary_rays(self) -> Kernel {
        match self {
            Kernel::F32(cfg) => Kernel::F32(cfg.for_secondary_rays()),
            Kernel::F64(cfg) => Kernel::F64(cfg.for_secondary_rays()),
            other @ (Kernel::Toth(_) | Kernel::Cached(_)) => other,
        }
    }

    /// The path for secondary rays leaving a hit: [`Kernel::for_secondary_rays`] with the
    /// surface of origin (`None` for a triangle), on which the kernels apply triviality
    /// tests (LG90 §6, "improved treatment of secondary rays"): the `f32` subdivision
    /// kernel its own ([`subdivision::trivial`]), the LG90 kernels theirs with ISRT. The
    /// `f64` reference searches every surface in full.
    pub fn leaving(self, origin: Option<SurfaceOrigin>) -> Kernel {
        match self.for_secondary_rays() {
            Kernel::F32(cfg) => Kernel::F32(SubdivisionConfig {
                surface_of_origin: origin,
                ..cfg
            }),
            Kernel::Toth(cfg) if cfg.isrt => Kernel::Toth(TothConfig {
                surface_of_origin: origin.map(|o| o.primitive),
                ..cfg
            }),
            Kernel::Cached(mut cfg) if cfg.toth.isrt => {
                cfg.toth.surface_of_origin = origin.map(|o| o.primitive);
                Kernel::Cached(cfg)
            }
            other => other,
        }
    }
}

/// Where a secondary ray leaves a patch: the patch's primitive number and the (u, v) of
/// the hit on it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfaceOrigin {
    pub primitive: u32,
    pub u: f64,
    pub v: f64,
}

/// A hit on one patch: `t` at the entry of the final box, (u, v) the centre of the final
/// parameter interval in the patch's own [0,1]², and the final box itself (the hit
/// interval, Dammertz §2.3), from which secondary rays start.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PatchHit {
    pub t: f32,
    pub u: f32,
    pub v: f32,
    pub hit_box: Aabb,
}

/// Work counters of kernel calls, summed by the caller per ray and per image.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct KernelStats {
    /// Ray–patch tests started.
    pub patch_tests: u64,
    /// de Casteljau splits.
    pub splits: u64,
    /// Ray–box tests inside the kernel.
    pub box_tests: u64,
    /// Newton jumps of the subdivision kernel that landed (`subdivision::jump`).
    pub jumps: u64,
    /// Sub-patches a jump proved the ray does not cross, dropped without a split.
    pub jump_drops: u64,
    /// Candidate hits tested against a patch's trim loops.
    pub trim_tests: u64,
    /// The Toth kernel's own counters (LG90 Tables 2–6 rows).
    pub toth: toth::TothStats,
    /// The cached kernel's cache counters (LG90 Tables 2–6 rows).
    pub cached: cached::CachedStats,
}

impl KernelStats {
    pub fn add(&mut self, other: &KernelStats) {
        self.patch_tests += other.patch_tests;
        self.splits += other.splits;
        self.box_tests += other.box_tests;
        self.jumps += other.jumps;
        self.jump_drops += other.jump_drops;
        self.trim_tests += other.trim_tests;
        self.toth.add(&other.toth);
        self.cached.add(&other.cached);
    }
}
