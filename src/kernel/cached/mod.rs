//! The cached kernel of Lischinski & Gonczarowski 1990 (§4.2–4.3): Toth's Krawczyk and
//! Newton tests ([`crate::kernel::toth::search::examine`]) with regular quadtree
//! subdivision of the parameter domain instead of Toth's bisection of `K ∩ X`. Because the
//! quadtree does not depend on the ray, the search's tree of each patch (its "surface
//! tree", [`tree`]) is kept: a later ray starts from the leaves whose boxes it hits, and
//! most rays near an earlier one miss every leaf or start close to a safe region (ray
//! coherence, §4.2). Trees live in an LRU cache with a byte budget ([`lru`], §4.3), one
//! cache per worker thread, so threads never wait for each other.
//!
//! The paper's conclusion (§8) observes that with coherent rays safe regions shrink and
//! trees grow deep, filling the cache; "branches beyond certain depth should not be
//! cached". [`DEFAULT_MAX_DEPTH`] is that limit: below it the search quarters boxes as
//! before but does not store them.

pub mod lru;
pub mod search;
pub mod stats;
pub mod tree;

use std::cell::RefCell;
use std::sync::atomic::{AtomicU64, Ordering};

pub use stats::CachedStats;

use crate::geom::trim::PatchTrim;
use crate::geom::{BezierPatch, Ray};
use crate::kernel::toth::TothConfig;
use crate::kernel::toth::search::Goal;
use crate::kernel::{KernelStats, PatchHit};
use lru::Lru;
use tree::SurfaceTree;

/// Cache budget per worker thread, in bytes. LG90 ran with 500K–1000K (Table 1). Our
/// nodes are 72 bytes (`f64` parameter boxes, an `f32` box, a child index, a sub-net slot)
/// and each leaf keeps its sub-net (272 bytes for a bicubic patch, [`tree::LeafNet`]); LG90
/// test case 1 at 512² (one teapot) grows about 90 k nodes, some 22 MiB, in a single worker
/// at [`DEFAULT_MAX_DEPTH`] (BENCHMARKS.md, LG90 cache), so 32 MiB holds it without evictions
/// while staying small next to a machine's memory.
pub const DEFAULT_CACHE_BYTES: usize = 32 << 20;

/// Depth below which tree nodes are not cached (the paper's conclusion, §8). Depth 6
/// leaves are 1/64 of the domain on a side: at 512² a teapot patch covers about 50 × 50
/// pixels, so a depth-6 leaf is about a pixel and deeper nodes would serve about one ray
/// each; measured against depth 10 in BENCHMARKS.md.
pub const DEFAULT_MAX_DEPTH: u8 = 6;

/// Settings of the cached kernel.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CachedConfig {
    /// The Krawczyk/Newton settings shared with the Toth kernel (ISRT, iteration bound,
    /// end-game size).
    pub toth: TothConfig,
    /// Cache budget per worker thread, in bytes.
    pub cache_bytes: usize,
    /// Deepest cached tree level.
    pub max_depth: u8,
    /// Identity of this configuration: a worker's cache is emptied when it first sees a
    /// new one, so two renders in one process do not share trees or inflate hit ratios.
    epoch: u64,
}

/// Source of [`CachedConfig::epoch`].
static NEXT_EPOCH: AtomicU64 = AtomicU64::new(1);

impl CachedConfig {
    /// A configuration with its own, initially empty, caches.
    pub fn new(toth: TothConfig, cache_bytes: usize, max_depth: u8) -> CachedConfig {
        CachedConfig {
            toth,
            cache_bytes,
            max_depth,
            epoch: NEXT_EPOCH.fetch_add(1, Ordering::Relaxed),
        }
    }
}

impl Default for CachedConfig {
    fn default() -> Self {
        CachedConfig::new(
            TothConfig::default(),
            DEFAULT_CACHE_BYTES,
            DEFAULT_MAX_DEPTH,
        )
    }
}

/// One worker's cache and buffers.
struct Worker {
    epoch: u64,
    trees: Lru<SurfaceTree>,
    scratch: search::Scratch,
}

thread_local! {
    static WORKER: RefCell<Worker> = RefCell::new(Worker {
        epoch: 0,
        trees: Lru::new(0),
        scratch: search::Scratch::default(),
    });
}

/// Nearest hit with `t` in `[ray.tmin, ray.tmax]`, as [`crate::kernel::toth::intersect`]
/// reports it; `origin` when `ray` leaves this patch (LG90 §6's triviality tests apply).
pub fn intersect(
    patch: &BezierPatch,
    trim: Option<&PatchTrim>,
    ray: &Ray,
    cfg: &CachedConfig,
    origin: bool,
    stats: &mut KernelStats,
) -> Option<PatchHit> {
    run(patch, ray, cfg, (Goal::Nearest, trim), origin, stats)
}

/// True when the patch blocks `ray` in `[tmin, tmax]` (shadow rays; with `cfg.toth.isrt`
/// the first safe region answers, LG90 §6); `origin` as for [`intersect`].
pub fn occluded(
    patch: &BezierPatch,
    trim: Option<&PatchTrim>,
    ray: &Ray,
    cfg: &CachedConfig,
    origin: bool,
    stats: &mut KernelStats,
) -> bool {
    run(patch, ray, cfg, (Goal::Any, trim), origin, stats).is_some()
}

/// Bytes of surface trees the calling thread caches under `cfg` (0 when it has none).
pub fn cached_bytes(cfg: &CachedConfig) -> usize {
    WORKER.with_borrow(|w| {
        if w.epoch == cfg.epoch {
            w.trees.used()
        } else {
            0
        }
    })
}

fn run(
    patch: &BezierPatch,
    ray: &Ray,
    cfg: &CachedConfig,
    (goal, trim): (Goal, Option<&PatchTrim>),
    origin: bool,
    stats: &mut KernelStats,
) -> Option<PatchHit> {
    stats.patch_tests += 1;
    let before = stats.toth.box_tests + stats.cached.tree_box_tests;
    // Trees are keyed by the patch's address and checked against its net, so a patch
    // moved or freed since never reuses a stale tree.
    let key = patch as *const BezierPatch as usize;
    let hit = WORKER.with_borrow_mut(|w| {
        if w.epoch != cfg.epoch {
            w.epoch = cfg.epoch;
            w.trees.reset(cfg.cache_bytes);
        }
        let mut tree = match w.trees.take(key).filter(|t| t.is_of(patch)) {
            Some(t) => {
                stats.cached.hits += 1;
                t
            }
            None => {
                stats.cached.misses += 1;
                SurfaceTree::new(patch, w.scratch.box_nets())
            }
        };
        let hit = search::search(
            patch,
            ray,
            cfg,
            (goal, origin, trim),
            &mut tree,
            &mut w.scratch,
            (&mut stats.toth, &mut stats.cached),
        );
        stats.cached.evictions += w.trees.put(key, tree);
        hit
    });
    // The kernel's ray–box tests are counted with every other kernel's too.
    stats.box_tests += stats.toth.box_tests + stats.cached.tree_box_tests - before;
    hit
}
