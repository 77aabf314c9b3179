//! The Dammertz subdivision kernel (Dammertz 2005, §2.2–2.3, §2.5.2, §2.7): intersect a ray
//! with a Bézier patch by splitting it at 1/2 with de Casteljau's algorithm until its
//! bounding box stops shrinking in `f32`. The final box is the hit interval (§2.2); the hit
//! reports `t` at the box entry and (u, v) at the centre of the box's parameter cell.
//!
//! - [`search`]: the stack-based search, once for every net storage and precision.
//! - [`bicubic`], [`bilinear`]: the SIMD fast paths for bicubic and bilinear integral
//!   patches, on the shared [`register`] net stack; [`avx512`]: the bicubic path with the
//!   whole net in four AVX-512 registers.
//! - [`ray_space`], [`jump`]: the net transformed into a frame where the ray is the
//!   z-axis, and Newton jumps there past levels a linearisation already decides.
//! - [`prepared`]: the per-patch data of the `f32` kernel, built once per patch.
//! - [`affine`]: no search for affine patches (parallelograms, CAD planes): the ray meets
//!   the plane once, in closed form.
//! - [`general`]: any degree up to 15, rational patches (homogeneous nets, §2.7.2).
//! - [`reference`]: the same algorithm in `f64`, the accuracy reference (§2.3.4).
//! - [`heuristics`], [`config`], [`param`], [`float`]: split direction, settings,
//!   parameter cells (and the depth bound that guarantees termination), scalar types.
//!
//! No fixed epsilon appears anywhere: termination is the box's own precision (the L1
//! diameter stops shrinking, or falls below `end_ulps` ulps of the patch's coordinates, or
//! for rational patches the box corners come within `rational_dist` ulps), and depth is
//! bounded by the parameter cell ([`param`]). A coarser [`Termination`] (fixed depth,
//! adaptive screen-space) can end it earlier, never later.

pub mod affine;
#[cfg(target_arch = "x86_64")]
pub mod avx512;
pub mod bicubic;
pub mod bilinear;
pub mod config;
pub mod float;
pub mod general;
pub mod heuristics;
pub mod jump;
pub mod param;
pub mod prepared;
pub mod ray_space;
pub mod reference;
pub mod register;
pub mod search;
pub mod trivial;

use std::cell::RefCell;

use glam::Vec3;

pub use config::{
    DEFAULT_END_ULPS, DEFAULT_RATIONAL_DIST, MAX_SPLITS_PER_TEST, ScreenFootprint, SplitHeuristic,
    SubdivisionConfig, Termination,
};
pub use prepared::PreparedPatch;
pub use ray_space::cull_margin;
pub use reference::{PatchHit64, intersect_f64};

use affine::{AffineHit, AffinePatch};
use bicubic::Net;
use bilinear::BilinearNet;
use float::{GBox, GRay};
use general::{GeneralStack, Scratch};
use param::ParamCell;
use prepared::Prepared;
use ray_space::{RayFrame, SpacedHit};
use register::{Query, search_register};
use search::search;

use crate::geom::trim::PatchTrim;
use crate::geom::ulp::ulp_of;
use crate::geom::{Aabb, Ray};
use crate::kernel::{KernelStats, PatchHit};

thread_local! {
    /// Per-thread buffers of the bicubic path: the pushed nets and the search nodes.
    static BICUBIC_SCRATCH: RefCell<register::Scratch<Net>> =
        const { RefCell::new((Vec::new(), Vec::new())) };
    /// Per-thread buffers of the bicubic path on AVX-512.
    #[cfg(target_arch = "x86_64")]
    static BICUBIC16_SCRATCH: RefCell<register::Scratch<avx512::Net16>> =
        const { RefCell::new((Vec::new(), Vec::new())) };
    /// Per-thread buffers of the bilinear path.
    static BILINEAR_SCRATCH: RefCell<register::Scratch<BilinearNet>> =
        const { RefCell::new((Vec::new(), Vec::new())) };
    /// Per-thread buffers of the general path.
    static GENERAL_SCRATCH: RefCell<Scratch<f32>> = RefCell::new(Scratch::default());
}

/// Per-axis margin, in ulps of the patch's largest coordinate magnitude, by which a hit box
/// is widened before secondary rays leave from its corner, to cover the rounding of the
/// sub-patch net. Every de Casteljau average rounds
/// to the scale of the values it averages, which early in the search is the whole patch's
/// (Dammertz §2.3.3), so a final box that is thin where the coordinates are small (near a
/// coordinate plane) can miss the exact surface by a fraction of that ulp, and a secondary
/// ray leaving from its corner (§2.4) re-hit its own surface. Measured on
/// testdata/distorted_patch.ron at 512² (patch scale 3): without the margin 5 of 33,409
/// shadow rays re-hit their origin, the worst box missing the surface by 0.36 of an ulp of
/// the scale; 2 ulps leaves five times that room.
pub const NET_ROUNDING_ULPS: f64 = 2.0;

/// A ray in the form the kernel takes it, made once per ray for every patch it is tested
/// against: the reciprocal direction and, for a search in ray space ([`ray_space`]), the
/// frame, which depend on the ray alone.
#[derive(Clone, Copy, Debug)]
pub struct KernelRay {
    ray: GRay<f32>,
    frame: Option<RayFrame>,
}

impl KernelRay {
    /// `ray` for searches with `cfg`: with a frame when `cfg` searches in ray space (which
    /// needs the float-precision criterion, whose end game the frame's floor applies to).
    pub fn new(ray: &Ray, cfg: &SubdivisionConfig) -> KernelRay {
        let ray = GRay::new(
            ray.origin.to_array(),
            ray.dir.to_array(),
            ray.tmin,
            ray.tmax,
        );
        let in_ray_space = cfg.ray_space && cfg.termination == Termination::Float;
        KernelRay {
            frame: in_ray_space.then(|| RayFrame::new(&ray)),
            ray,
        }
    }

    /// The world box of `hit`'s final box (see [`SpacedHit`]).
    pub fn hit_box(&self, hit: &KernelHit) -> Aabb {
        match hit {
            KernelHit::Affine(h) => h.hit_box,
            KernelHit::Searched(h) => match (h.ray_space_scale, &self.frame) {
                (Some(scale), Some(frame)) => frame.world_box(&h.hit.bbox, scale).to_aabb(),
                _ => h.hit.bbox.to_aabb(),
            },
        }
    }

    /// The [`PatchHit`] of `hit`, world box included.
    pub fn patch_hit(&self, hit: &KernelHit) -> PatchHit {
        let (u, v) = hit.uv();
        PatchHit {
            t: hit.t(),
            u: u as f32,
            v: v as f32,
            hit_box: self.hit_box(hit),
        }
    }
}

/// A hit of [`nearest`]: a search's, whose box is still in the space the search ran in
/// (its world box, [`KernelRay::hit_box`], is made only for the ray's nearest hit), or an
/// affine patch's closed-form crossing.
#[derive(Clone, Copy, Debug)]
pub enum KernelHit {
    Searched(SpacedHit),
    Affine(AffineHit),
}

impl KernelHit {
    /// The ray parameter at the final box's entry, or of the closed form's crossing.
    pub fn t(&self) -> f32 {
        match self {
            KernelHit::Searched(h) => h.hit.t,
            KernelHit::Affine(h) => h.t,
        }
    }

    /// The centre of the final parameter cell (Dammertz code 2.3.8), or the closed form's
    /// (u, v).
    pub fn uv(&self) -> (f64, f64) {
        match self {
            KernelHit::Searched(h) => h.hit.cell.centre(),
            KernelHit::Affine(h) => (h.u, h.v),
        }
    }
}

/// Nearest hit with `t` in `[ray.tmin, ray.tmax]`; `ray.tmax` is the current closest hit.
pub fn intersect(
    patch: &PreparedPatch,
    trim: Option<&PatchTrim>,
    ray: &Ray,
    cfg: &SubdivisionConfig,
    stats: &mut KernelStats,
) -> Option<PatchHit> {
    let ray = KernelRay::new(ray, cfg);
    nearest(patch, trim, &ray, ray.ray.tmax, cfg, None, stats).map(|h| ray.patch_hit(&h))
}

/// [`intersect`] for a ray made once for every patch it meets, with `t` up to `tmax`.
/// `leaving` is the (u, v) of the ray's origin when the ray leaves this patch (a
/// secondary ray and its surface of origin): the search then skips the region around it
/// that the ray provably does not cross ([`trivial`]).
pub fn nearest(
    patch: &PreparedPatch,
    trim: Option<&PatchTrim>,
    ray: &KernelRay,
    tmax: f32,
    cfg: &SubdivisionConfig,
    leaving: Option<(f64, f64)>,
    stats: &mut KernelStats,
) -> Option<KernelHit> {
    run(patch, trim, ray, tmax, cfg, false, leaving, stats)
}

/// `hit_box` grown on every side by [`NET_ROUNDING_ULPS`] ulps of the largest coordinate
/// magnitude of `root`, the patch's box: the box secondary rays leave from. The hit box
/// itself (and `t` at its entry) stays the final box, so the margin costs no accuracy.
pub fn widen_by_net_rounding(hit_box: Aabb, root: &Aabb) -> Aabb {
    let scale = root.min.abs().max(root.max.abs()).max_element();
    let margin = Vec3::splat((ulp_of(scale) * NET_ROUNDING_ULPS) as f32);
    Aabb::new(hit_box.min - margin, hit_box.max + margin)
}

/// Any hit in `[ray.tmin, ray.tmax]` (shadow rays): stops at the first final box found.
pub fn occluded(
    patch: &PreparedPatch,
    trim: Option<&PatchTrim>,
    ray: &Ray,
    cfg: &SubdivisionConfig,
    stats: &mut KernelStats,
) -> bool {
    blocks(patch, trim, &KernelRay::new(ray, cfg), cfg, None, stats)
}

/// [`occluded`] for a ray made once for every patch it meets; `leaving` as for
/// [`nearest`].
pub fn blocks(
    patch: &PreparedPatch,
    trim: Option<&PatchTrim>,
    ray: &KernelRay,
    cfg: &SubdivisionConfig,
    leaving: Option<(f64, f64)>,
    stats: &mut KernelStats,
) -> bool {
    run(patch, trim, ray, ray.ray.tmax, cfg, true, leaving, stats).is_some()
}

#[allow(clippy::too_many_arguments)]
fn run(
    patch: &PreparedPatch,
    trim: Option<&PatchTrim>,
    ray: &KernelRay,
    tmax: f32,
    cfg: &SubdivisionConfig,
    any_hit: bool,
    leaving: Option<(f64, f64)>,
    stats: &mut KernelStats,
) -> Option<KernelHit> {
    let gray = GRay { tmax, ..ray.ray };
    // On the AVX-512 path the descent around the origin is cheap (ray space, jumps): the
    // triviality test saved about as much as it cost there (BENCHMARKS.md), so only the
    // other paths take it.
    #[cfg(target_arch = "x86_64")]
    let leaving =
        leaving.filter(|_| !(matches!(patch.data, Prepared::Bicubic(_)) && avx512::available()));
    let trivial = leaving.and_then(|uv| trivial::trivial_cell(&patch.data, &gray, uv));
    if trivial == Some(ParamCell::ROOT) {
        stats.patch_tests += 1;
        return None;
    }
    let root = GBox::from_aabb(patch.bounds);
    let query = Query {
        root,
        ray: &gray,
        frame: ray.frame.as_ref(),
        cfg,
        any_hit,
        trim,
        trivial,
    };
    let found = match &patch.data {
        Prepared::Affine(plane) => return closed_form(plane, trim, &gray, leaving, stats),
        #[cfg(target_arch = "x86_64")]
        Prepared::Bicubic(net) if avx512::available() => {
            BICUBIC16_SCRATCH.with_borrow_mut(|s| avx512::search_net16(net, s, query, stats))
        }
        Prepared::Bicubic(net) => BICUBIC_SCRATCH
            .with_borrow_mut(|s| search_register(*net, s, query, stats))
            .map(SpacedHit::world),
        Prepared::Bilinear(net) => BILINEAR_SCRATCH
            .with_borrow_mut(|s| search_register(*net, s, query, stats))
            .map(SpacedHit::world),
        Prepared::General { net, shape } => GENERAL_SCRATCH.with_borrow_mut(|s| {
            let mut nets = GeneralStack::new(&mut s.nets, net, *shape);
            search(
                &mut nets,
                &mut s.nodes,
                root,
                &gray,
                shape.rational,
                cfg,
                any_hit,
                trim,
                trivial,
                stats,
            )
            .map(SpacedHit::world)
        }),
    };
    found.map(KernelHit::Searched)
}

/// The hit on an affine patch (a ray meets it at most once); `leaving` is set when the ray
/// leaves this patch.
fn closed_form(
    plane: &AffinePatch,
    trim: Option<&PatchTrim>,
    ray: &GRay<f32>,
    leaving: Option<(f64, f64)>,
    stats: &mut KernelStats,
) -> Option<KernelHit> {
    stats.patch_tests += 1;
    // A line meets a plane once or lies in it: a ray leaving the patch met it at its
    // origin and cannot meet it again. Exact, so it needs no origin offset; rays from
    // other surfaces take the closed form.
    if leaving.is_some() {
        return None;
    }
    let hit = plane.hit(ray, ray.tmax)?;
    let kept = trim.is_none_or(|trim| {
        stats.trim_tests += 1;
        trim.keeps(hit.u, hit.v)
    });
    kept.then_some(KernelHit::Affine(hit))
}
