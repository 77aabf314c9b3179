//! Toth's ray–patch intersection (Toth 1985, as summarized by Lischinski & Gonczarowski
//! 1990, §4.1–4.2 and §6): interval analysis on the two equations of the ray's planes in
//! (u, v) ([`raynet`]); Krawczyk's operator excludes boxes of parameter space or proves them
//! "safe" ([`krawczyk`]); simple Newton converges in a safe region ([`newton`]); undecided
//! boxes are bisected as `K ∩ X` across the wider parameter, and candidates are searched in
//! order of their ray parameter so the nearest hit is found first ([`search`]).
//!
//! The enclosures come from [`crate::geom::interval`]: outward-rounded `f64` intervals on
//! the `f64` patch, so exclusion and safety are proved, not estimated. Work is bounded by
//! [`TothConfig::max_iterations`] search iterations and
//! [`newton::NEWTON_MAX_ITERATIONS`] Newton steps per start.
//!
//! Shadow rays ([`occluded`]) stop at the first hit; with [`TothConfig::isrt`] they stop
//! already at the first safe region whose ray parameters lie in `[tmin, tmax]` (LG90 §6:
//! "the simple Newton iteration is not entered at all", the ISRT column of Tables 2–6).

pub mod krawczyk;
pub mod newton;
pub mod raynet;
pub mod search;
pub mod stats;

use std::cell::RefCell;

pub use krawczyk::{Classification, classify};
pub use stats::TothStats;

use crate::geom::trim::PatchTrim;
use crate::geom::{BezierPatch, Ray};
use crate::kernel::{KernelStats, PatchHit};
use search::{Goal, Scratch};

/// Search iterations allowed per ray–patch test before the search gives up (keeping the
/// nearest hit found so far). LG90 measured 6.7–7.4 iterations per ray on teapot scenes
/// (Tables 2–6); a box at a degenerate point (the teapot's collapsed edges) can need about
/// two bisections per bit of `f32` precision in each parameter (2 × 2 × 24 ≈ 100) along
/// each of a few paths, so 1024 leaves ample room while bounding pathological rays.
pub const DEFAULT_MAX_ITERATIONS: u32 = 1024;

/// A box whose extent in ray coordinates is below this many `f32` ulps of the patch's
/// largest coordinate is "too small for analysis" (LG90 §4.2 step 4) and answered as a hit:
/// the same end-game size as the subdivision kernel's
/// [`crate::kernel::subdivision::DEFAULT_END_ULPS`], so both kernels stop at one precision.
pub const DEFAULT_FINAL_ULPS: u32 = crate::kernel::subdivision::DEFAULT_END_ULPS;

/// Settings of the Toth kernel.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TothConfig {
    /// LG90 §6's improved treatment of secondary rays (ISRT): shadow rays stop at the
    /// first safe region, and secondary rays get the triviality tests on their surface of
    /// origin ([`crate::kernel::Kernel::leaving`]).
    pub isrt: bool,
    /// Search iterations per ray–patch test.
    pub max_iterations: u32,
    /// End-game size in ulps (see [`DEFAULT_FINAL_ULPS`]).
    pub final_ulps: u32,
    /// The accelerator's number of the patch the ray leaves, for secondary rays: the
    /// kernels apply LG90's triviality tests (§6) on that patch. Set per ray by
    /// [`crate::kernel::Kernel::leaving`].
    pub surface_of_origin: Option<u32>,
}

impl Default for TothConfig {
    fn default() -> Self {
        TothConfig {
            isrt: false,
            max_iterations: DEFAULT_MAX_ITERATIONS,
            final_ulps: DEFAULT_FINAL_ULPS,
            surface_of_origin: None,
        }
    }
}

thread_local! {
    static SCRATCH: RefCell<Scratch> = RefCell::new(Scratch::default());
}

/// Nearest hit with `t` in `[ray.tmin, ray.tmax]`. `t` is the ray parameter of the
/// converged Newton point; `hit_box` is the outward-rounded `f32` box of the patch over a
/// parameter box that holds the root (the contraction's error bound around the Newton
/// point), so secondary rays can start from its corners. `origin` when `ray` is a
/// secondary ray leaving this patch (LG90 §6's triviality tests apply).
pub fn intersect(
    patch: &BezierPatch,
    trim: Option<&PatchTrim>,
    ray: &Ray,
    cfg: &TothConfig,
    origin: bool,
    stats: &mut KernelStats,
) -> Option<PatchHit> {
    run(patch, ray, cfg, (Goal::Nearest, trim), origin, stats)
}

/// True when the patch blocks `ray` in `[tmin, tmax]` (shadow rays); `origin` as for
/// [`intersect`].
pub fn occluded(
    patch: &BezierPatch,
    trim: Option<&PatchTrim>,
    ray: &Ray,
    cfg: &TothConfig,
    origin: bool,
    stats: &mut KernelStats,
) -> bool {
    run(patch, ray, cfg, (Goal::Any, trim), origin, stats).is_some()
}

fn run(
    patch: &BezierPatch,
    ray: &Ray,
    cfg: &TothConfig,
    (goal, trim): (Goal, Option<&PatchTrim>),
    origin: bool,
    stats: &mut KernelStats,
) -> Option<PatchHit> {
    stats.patch_tests += 1;
    let before = stats.toth.box_tests;
    let hit = SCRATCH.with_borrow_mut(|s| {
        search::search(patch, ray, cfg, (goal, trim), s, origin, &mut stats.toth)
    });
    // The kernel's ray–box tests are counted with every other kernel's too.
    stats.box_tests += stats.toth.box_tests - before;
    hit
}
