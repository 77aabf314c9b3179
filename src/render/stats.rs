//! Render statistics for `--stats`: rays by type, per-ray work, time per phase.

use serde::Serialize;

use crate::accel::scene::QueryStats;
use crate::kernel::cached::CachedStats;
use crate::kernel::toth::TothStats;

/// The kinds of ray the integrator traces.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RayKind {
    Primary,
    Shadow,
    Reflection,
    Refraction,
}

/// Minimum, mean and maximum of a per-ray quantity.
#[derive(Clone, Copy, Debug, Serialize, PartialEq)]
pub struct Spread {
    pub min: u64,
    pub mean: f64,
    pub max: u64,
}

/// Running sum of one per-ray quantity.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Tally {
    min: u64,
    max: u64,
    sum: u64,
}

impl Default for Tally {
    fn default() -> Self {
        Tally {
            min: u64::MAX,
            max: 0,
            sum: 0,
        }
    }
}

impl Tally {
    fn push(&mut self, x: u64) {
        self.min = self.min.min(x);
        self.max = self.max.max(x);
        self.sum += x;
    }
    fn merge(&mut self, o: &Tally) {
        self.min = self.min.min(o.min);
        self.max = self.max.max(o.max);
        self.sum += o.sum;
    }
    fn spread(&self, n: u64) -> Spread {
        Spread {
            min: if n == 0 { 0 } else { self.min },
            mean: if n == 0 {
                0.0
            } else {
                self.sum as f64 / n as f64
            },
            max: self.max,
        }
    }
}

/// Per-thread accumulation of ray statistics; merged at the end.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RayTally {
    counts: [u64; 4],
    /// Secondary rays not traced: weight below the plan's minimum, or the tree's budget
    /// spent.
    cut: u64,
    surface_tests: Tally,
    patch_tests: Tally,
    splits: Tally,
    jumps: Tally,
    jump_drops: Tally,
    box_tests: Tally,
    nodes: Tally,
    voxels: Tally,
    toth: TothStats,
    cached: CachedStats,
}

impl RayTally {
    pub fn record(&mut self, kind: RayKind, q: &QueryStats) {
        self.counts[kind as usize] += 1;
        self.surface_tests.push(q.surface_tests);
        self.patch_tests.push(q.kernel.patch_tests);
        self.splits.push(q.kernel.splits);
        self.jumps.push(q.kernel.jumps);
        self.jump_drops.push(q.kernel.jump_drops);
        self.box_tests.push(q.kernel.box_tests + q.bvh_box_tests);
        self.nodes.push(q.nodes_visited);
        self.voxels.push(q.voxels_visited);
        self.toth.add(&q.kernel.toth);
        self.cached.add(&q.kernel.cached);
    }

    /// Counts a secondary ray that was not traced (adaptive depth control).
    pub fn cut_ray(&mut self) {
        self.cut += 1;
    }

    pub fn merge(mut self, o: RayTally) -> RayTally {
        for (a, b) in self.counts.iter_mut().zip(o.counts) {
            *a += b;
        }
        self.cut += o.cut;
        self.surface_tests.merge(&o.surface_tests);
        self.patch_tests.merge(&o.patch_tests);
        self.splits.merge(&o.splits);
        self.jumps.merge(&o.jumps);
        self.jump_drops.merge(&o.jump_drops);
        self.box_tests.merge(&o.box_tests);
        self.nodes.merge(&o.nodes);
        self.voxels.merge(&o.voxels);
        self.toth.add(&o.toth);
        self.cached.add(&o.cached);
        self
    }

    pub fn count(&self, kind: RayKind) -> u64 {
        self.counts[kind as usize]
    }

    /// de Casteljau splits of all rays recorded so far.
    pub fn splits(&self) -> u64 {
        self.splits.sum
    }

    pub fn total(&self) -> u64 {
        self.counts.iter().sum()
    }

    pub fn report(&self) -> RayReport {
        let n = self.total();
        RayReport {
            primary: self.counts[RayKind::Primary as usize],
            shadow: self.counts[RayKind::Shadow as usize],
            reflection: self.counts[RayKind::Reflection as usize],
            refraction: self.counts[RayKind::Refraction as usize],
            total: n,
            cut_off: self.cut,
            surfaces_tested_per_ray: self.surface_tests.spread(n),
            patch_tests_per_ray: self.patch_tests.spread(n),
            splits_per_ray: self.splits.spread(n),
            jumps_per_ray: self.jumps.spread(n),
            jump_drops_per_ray: self.jump_drops.spread(n),
            box_tests_per_ray: self.box_tests.spread(n),
            bvh_nodes_per_ray: self.nodes.spread(n),
            voxels_per_ray: self.voxels.spread(n),
            toth: (self.toth.searches > 0).then(|| TothReport::new(&self.toth, n)),
            cache: (self.cached.hits + self.cached.misses > 0).then(|| CacheReport {
                hits: self.cached.hits,
                misses: self.cached.misses,
                hit_ratio: self.cached.hit_ratio(),
                evictions: self.cached.evictions,
                nodes_created: self.cached.nodes_created,
                subdivisions: self.cached.subdivisions,
                uncached_subdivisions: self.cached.uncached_subdivisions,
            }),
        }
    }
}

#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct RayReport {
    pub primary: u64,
    pub shadow: u64,
    pub reflection: u64,
    pub refraction: u64,
    pub total: u64,
    /// Secondary rays not traced because their weight fell below `plan.min_weight`
    /// (adaptive depth control) or their primary ray's tree reached its ray budget.
    pub cut_off: u64,
    /// Primitives whose outermost box the accelerator tested (LG90 §7.1 "surfaces tested
    /// per ray"): the grid's tight-box tests, or the primitives of the BVH leaves reached.
    pub surfaces_tested_per_ray: Spread,
    /// Kernel calls: primitives whose box the ray hits (with the grid) or that sit in a
    /// reached BVH leaf, and triangle packs.
    pub patch_tests_per_ray: Spread,
    pub splits_per_ray: Spread,
    /// Newton jumps of the subdivision kernel (primary rays in ray space only).
    pub jumps_per_ray: Spread,
    /// Sub-patches a jump proved the ray misses, dropped without splitting.
    pub jump_drops_per_ray: Spread,
    pub box_tests_per_ray: Spread,
    pub bvh_nodes_per_ray: Spread,
    /// Grid voxels stepped through (`--accel grid`; 0 with the BVH).
    pub voxels_per_ray: Spread,
    /// The Toth kernel's rows of LG90 Tables 2–6, when it ran.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub toth: Option<TothReport>,
    /// The cached kernel's surface-tree cache (`--kernel cached`), when it ran.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub cache: Option<CacheReport>,
}

/// LG90 Tables 2–6 cache rows of the cached kernel, over all ray–patch tests ("cache
/// misses / surface" is `misses` over the scene's patch count).
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct CacheReport {
    pub hits: u64,
    pub misses: u64,
    /// `hits / (hits + misses)`, a fraction (the paper prints percent).
    pub hit_ratio: f64,
    pub evictions: u64,
    pub nodes_created: u64,
    pub subdivisions: u64,
    pub uncached_subdivisions: u64,
}

/// LG90 Tables 2–6 rows of the Toth kernel, per ray over all rays.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct TothReport {
    /// Patches whose search loop ran (LG90 §7.1): every Toth kernel call; for the cached
    /// kernel only those where the ray hits a leaf of the surface tree.
    pub surfaces_searched_per_ray: f64,
    pub search_iterations_per_ray: f64,
    pub newton_starts_per_ray: f64,
    pub newton_iterations_per_call: f64,
    pub mean_safe_region_width: f64,
    pub isrt_early_outs: u64,
    pub final_boxes: u64,
    pub cut_off_searches: u64,
    /// Boxes on the surface of origin dropped by LG90's triviality tests 1–3 (§6), per
    /// ray.
    pub trivial_per_ray: [f64; 3],
}

impl TothReport {
    fn new(t: &TothStats, rays: u64) -> TothReport {
        let per_ray = |x: u64| {
            if rays == 0 {
                0.0
            } else {
                x as f64 / rays as f64
            }
        };
        TothReport {
            surfaces_searched_per_ray: per_ray(t.searches),
            search_iterations_per_ray: per_ray(t.search_iterations),
            newton_starts_per_ray: per_ray(t.newton_starts),
            newton_iterations_per_call: t.newton_iterations_per_call(),
            mean_safe_region_width: t.mean_safe_width(),
            isrt_early_outs: t.early_outs,
            final_boxes: t.final_boxes,
            cut_off_searches: t.cut_off,
            trivial_per_ray: t.trivial.map(per_ray),
        }
    }
}

/// Wall-clock seconds per phase.
#[derive(Clone, Debug, Default, Serialize, PartialEq)]
pub struct PhaseTimes {
    pub load: f64,
    /// Preparing patches for the kernel and building (or loading) the BVH.
    pub prepare: f64,
    pub render: f64,
    pub write: f64,
}
