//! Running one case against one kernel path and comparing it ray by ray with the `f64`
//! reference (Dammertz §2.3.4: the same subdivision in double precision).
//!
//! **Holes and false hits, precisely.** A hole is a ray the reference hits and the kernel
//! misses, or hits only farther along (it went through the surface the reference hit); a
//! false hit is a ray the kernel hits and the reference misses, or hits only farther along.
//! Two hits agree when their points (at the entry of their final boxes) are no farther
//! apart, per coordinate, than the two final boxes' extents plus
//! [`BOX_TOLERANCE_ULPS`] ulps of the hit's largest coordinate, or when they are the same
//! crossing of one patch moved along a grazing ray (see [`same_crossing`]); the distance
//! reported is the point distance either way. A disagreement is *within
//! the final box's extent* (counted apart, not as a hole or false hit) when moving the ray
//! sideways by that box extent (the kernel's final box, or the reference's when only the
//! reference hit) plus the tolerance, in any of the four directions perpendicular to it,
//! makes the reference agree with the kernel: the ray then passes within one final box of
//! the outline, where the answer is decided by rounding. The shifted rays are traced by the
//! reference in `f64` without rounding.
//!
//! **Self-hits.** From every kernel hit, a reflection ray and a shadow ray leave from
//! [`secondary_origin`] with `outside = true` and a refraction ray with `outside = false`
//! (Dammertz §2.4), [`DEFAULT_ULPS`] ulps out. A self-hit is a secondary ray whose nearest
//! hit is on the same patch with a final box overlapping the origin's final box: "t ≈ 0 on
//! the surface of origin", defined without any scale.

use std::path::Path;

use glam::{DVec3, Vec3};
use indicatif::ProgressBar;

use super::cases::Case;
use crate::accel::scene::{QueryStats, SceneGeometry, SceneHit};
use crate::formats::load::check_f32_range;
use crate::geom::ulp::ulp_of;
use crate::geom::{Aabb, BezierPatch, DAabb, Ray};
use crate::kernel::Kernel;
use crate::kernel::secondary::{DEFAULT_ULPS, secondary_origin};
use crate::kernel::subdivision::SubdivisionConfig;
use crate::render::integrator::{Integrator, TraceSettings};
use crate::render::plan::EffectPlan;
use crate::render::renderer::render_image;
use crate::scene::generate::SplitMix64;

/// Slack, in ulps of the hit's largest coordinate, allowed beyond the final boxes when
/// comparing hits: the `f32` kernel's final box is decided by rounding of its own corners
/// (Dammertz §2.3: the box stops shrinking within a few ulps), and this is the same bound
/// the issue sets for the median hit distance.
pub const BOX_TOLERANCE_ULPS: f64 = 4.0;

/// Index of refraction of the refraction rays (glass).
const REFRACTION_IOR: f64 = 1.5;

/// A kernel path under test. Adding one (Toth, cached, adaptive) is one variant here and
/// its arm in [`KernelPath::precision`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum KernelPath {
    /// The float-precision subdivision kernel (Dammertz §2.3) in `f32`.
    F32,
    /// The same algorithm in `f64` through the renderer's query (the `--precision f64`
    /// path), checked against the reference like any kernel.
    F64,
}

impl KernelPath {
    /// Every path, in report order.
    pub const ALL: &'static [KernelPath] = &[KernelPath::F32, KernelPath::F64];

    pub fn name(self) -> &'static str {
        match self {
            KernelPath::F32 => "f32",
            KernelPath::F64 => "f64",
        }
    }

    /// The query settings of this path.
    pub fn precision(self) -> Kernel {
        let cfg = SubdivisionConfig::default();
        match self {
            KernelPath::F32 => Kernel::F32(cfg),
            KernelPath::F64 => Kernel::F64(cfg),
        }
    }

    /// Whether the path's queries count de Casteljau splits (the `f64` query does not
    /// report its kernel's work).
    pub fn counts_splits(self) -> bool {
        matches!(self, KernelPath::F32)
    }
}

/// Everything measured for one case and one kernel path.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Figures {
    pub rays: usize,
    pub reference_hits: usize,
    pub hits: usize,
    pub holes: usize,
    pub false_hits: usize,
    /// Disagreements within the final box's extent (see the module docs).
    pub within_box: usize,
    pub secondary_rays: usize,
    pub self_hits: usize,
    /// Hits (primary and secondary) whose normal is not finite.
    pub non_finite_normals: usize,
    /// Distance from the reference hit point, in ulps of the hit's largest coordinate, over
    /// rays both hit and agree on.
    pub distance_median: f64,
    pub distance_max: f64,
    /// The same distance measured across the surface (along the reference normal): the
    /// error of the surface position itself, which a ray at angle θ to the surface turns
    /// into `1 / sin θ` times as much along the ray.
    pub normal_distance_median: f64,
    /// Splits per primary ray, when the path counts them.
    pub splits: Option<SplitFigures>,
    pub pixels: usize,
    pub nan_pixels: usize,
    /// The loader's message when it refuses the case's scene (nothing is traced then).
    pub refused: Option<String>,
}

#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SplitFigures {
    pub mean: f64,
    pub max: u64,
    /// Largest number of splits in one ray–patch test.
    pub max_per_patch: u64,
}

/// Runs every ray of `case` through `path` and the reference, and renders the case scene
/// at `image_size`² to count NaN pixels.
pub fn run_case(case: &Case, path: KernelPath, image_size: u32, seed: u64) -> Figures {
    // The stability criteria allow inputs near the denormal range to be "flushed or refused with a clear
    // message": the loader refuses them, so such a case checks the refusal instead.
    if let Err(e) = check_f32_range(Path::new(&case.name), &case.scene) {
        return Figures {
            rays: case.rays.len(),
            refused: Some(e.to_string()),
            ..Figures::default()
        };
    }
    let geometry = SceneGeometry::build(&case.scene);
    let precision = path.precision();
    let mut rng = SplitMix64::new(seed);
    let mut f = Figures {
        rays: case.rays.len(),
        ..Figures::default()
    };
    let (mut distances, mut normal_distances) = (Vec::new(), Vec::new());
    let (mut split_sum, mut split_max, mut split_per_patch) = (0u64, 0u64, 0u64);
    for ray in &case.rays {
        let reference = trace_reference(&geometry, ray.origin.as_dvec3(), ray.dir.as_dvec3());
        let mut stats = QueryStats::default();
        let hit = geometry.intersect(ray, &precision, &mut stats);
        split_sum += stats.kernel.splits;
        split_max = split_max.max(stats.kernel.splits);
        if stats.kernel.patch_tests > 0 {
            split_per_patch =
                split_per_patch.max(stats.kernel.splits.div_ceil(stats.kernel.patch_tests));
        }
        f.reference_hits += reference.is_some() as usize;
        f.hits += hit.is_some() as usize;
        match compare(case, ray, hit.as_ref(), reference.as_ref()) {
            Verdict::Agree(Some((d, dn))) => {
                distances.push(d);
                normal_distances.push(dn);
            }
            Verdict::Agree(None) => {}
            Verdict::Hole if hole_excused(&geometry, ray, hit.as_ref(), reference.as_ref()) => {
                f.within_box += 1;
            }
            Verdict::FalseHit if hit.is_some_and(|h| false_hit_excused(case, ray, &h)) => {
                f.within_box += 1;
            }
            Verdict::Hole => f.holes += 1,
            Verdict::FalseHit => f.false_hits += 1,
        }
        if let Some(h) = hit {
            secondaries(&geometry, &precision, ray, &h, &mut rng, &mut f);
        }
    }
    f.distance_median = median(&mut distances);
    f.distance_max = distances.last().copied().unwrap_or(0.0);
    f.normal_distance_median = median(&mut normal_distances);
    f.splits = path.counts_splits().then(|| SplitFigures {
        mean: split_sum as f64 / case.rays.len().max(1) as f64,
        max: split_max,
        max_per_patch: split_per_patch,
    });
    (f.pixels, f.nan_pixels) = nan_pixels(case, &geometry, precision, image_size);
    f
}

/// The median of `values` (sorted in place), 0 for none.
fn median(values: &mut [f64]) -> f64 {
    values.sort_by(f64::total_cmp);
    values.get(values.len() / 2).copied().unwrap_or(0.0)
}

/// The reference hit of a ray given in `f64`.
fn trace_reference(geometry: &SceneGeometry, origin: DVec3, dir: DVec3) -> Option<SceneHit> {
    let mut stats = QueryStats::default();
    let cfg = SubdivisionConfig::default();
    geometry.intersect_f64(origin, dir, 0.0, f64::INFINITY, &cfg, &mut stats)
}

enum Verdict {
    /// Same answer; when both hit, the point distance and the distance across the surface,
    /// in ulps.
    Agree(Option<(f64, f64)>),
    Hole,
    FalseHit,
}

fn point(ray: &Ray, t: f64) -> DVec3 {
    ray.origin.as_dvec3() + ray.dir.as_dvec3() * t
}

/// Largest extent of a box, in `f64`.
fn box_extent(b: &Aabb) -> f64 {
    b.extent().max_element().max(0.0) as f64
}

/// The unit of hit distances: one `f32` ulp of the largest coordinate of the hit point or
/// the ray origin. A kernel reports `p = o + t d` with `t` in `f32`, so even a correctly
/// rounded `t` is off by half an ulp of `|p - o|`: ulps of the hit's own coordinates alone
/// would make a hit near the origin, seen from afar, look arbitrarily wrong.
fn ulp_at(ray: &Ray, p: DVec3) -> f64 {
    let o = ray.origin.abs().max_element() as f64;
    ulp_of(p.abs().max_element().max(o) as f32)
}

/// Whether hit `h` agrees with reference hit `r` (see the module docs).
fn hits_agree(ray_h: &Ray, h: &SceneHit, ray_r: &Ray, r: &SceneHit) -> bool {
    let (ph, pr) = (point(ray_h, h.t), point(ray_r, r.t));
    let slack =
        box_extent(&h.hit_box) + box_extent(&r.hit_box) + BOX_TOLERANCE_ULPS * ulp_at(ray_r, pr);
    (ph - pr).abs().max_element() <= slack
}

fn compare(
    case: &Case,
    ray: &Ray,
    hit: Option<&SceneHit>,
    reference: Option<&SceneHit>,
) -> Verdict {
    match (hit, reference) {
        (None, None) => Verdict::Agree(None),
        (None, Some(_)) => Verdict::Hole,
        (Some(_), None) => Verdict::FalseHit,
        (Some(h), Some(r)) => {
            if hits_agree(ray, h, ray, r) || same_crossing(case, ray, h, r) {
                let (ph, pr) = (point(ray, h.t), point(ray, r.t));
                let across = if r.normal.is_finite() {
                    (ph - pr).dot(r.normal).abs()
                } else {
                    (ph - pr).abs().max_element()
                };
                let ulp = ulp_at(ray, pr);
                Verdict::Agree(Some(((ph - pr).abs().max_element() / ulp, across / ulp)))
            } else if h.t > r.t {
                Verdict::Hole
            } else {
                Verdict::FalseHit
            }
        }
    }
}

/// Whether two hits on the same patch are one crossing of its surface, moved along a grazing
/// ray: the kernel's point is within the slack of [`hits_agree`] of the reference's tangent
/// plane, and the kernel's final box, grown by that slack, meets the exact surface. A box
/// that is off the surface by an ulp across it is off by that ulp over `sin θ` along a ray
/// at angle θ to the surface, so the point distance alone would call the same crossing of a
/// grazing ray a hole; the tangent-plane distance is the one that decides whether the ray
/// went through the surface. A second crossing of the same patch is far from the first
/// one's tangent plane and does not qualify.
fn same_crossing(case: &Case, ray: &Ray, h: &SceneHit, r: &SceneHit) -> bool {
    if (h.object, h.patch) != (r.object, r.patch) || !r.normal.is_finite() {
        return false;
    }
    let (ph, pr) = (point(ray, h.t), point(ray, r.t));
    let slack =
        box_extent(&h.hit_box) + box_extent(&r.hit_box) + BOX_TOLERANCE_ULPS * ulp_at(ray, pr);
    (ph - pr).dot(r.normal).abs() <= slack && false_hit_excused(case, ray, h)
}

/// True when a hole is decided within a final box of the outline: the reference, on the ray
/// moved sideways by the reference box's extent plus the tolerance, agrees with the kernel
/// (see the module docs).
fn hole_excused(
    geometry: &SceneGeometry,
    ray: &Ray,
    hit: Option<&SceneHit>,
    reference: Option<&SceneHit>,
) -> bool {
    let Some(r) = reference else {
        return true;
    };
    let p = point(ray, r.t);
    let shift = box_extent(&r.hit_box) + BOX_TOLERANCE_ULPS * ulp_at(ray, p);
    let d = ray.dir.as_dvec3();
    let a = d.normalize().any_orthonormal_vector();
    let b = d.normalize().cross(a);
    [a, -a, b, -b].into_iter().any(|side| {
        let origin = ray.origin.as_dvec3() + side * shift;
        match (hit, trace_reference(geometry, origin, d)) {
            (None, None) => true,
            (Some(h), Some(m)) => {
                // The moved ray is exact in `f64`: its hit lies on the moved line.
                let pm = origin + d * m.t;
                let slack = box_extent(&h.hit_box) + box_extent(&m.hit_box) + shift;
                (point(ray, h.t) - pm).abs().max_element() <= slack
            }
            _ => false,
        }
    })
}

/// True when a false hit is within its final box's own extent: the exact surface of the hit
/// patch comes within the kernel's final box grown by its extent plus the tolerance, so the
/// ray really passes within that distance of the surface (a tangent or silhouette ray, or
/// a patch collapsed to a curve).
fn false_hit_excused(case: &Case, ray: &Ray, h: &SceneHit) -> bool {
    let Some(patch) = case
        .scene
        .objects
        .get(h.object as usize)
        .and_then(|o| o.bezier_patches().into_iter().nth(h.patch as usize))
    else {
        return false;
    };
    let grow = box_extent(&h.hit_box) + BOX_TOLERANCE_ULPS * ulp_at(ray, point(ray, h.t));
    let target = DAabb {
        min: h.hit_box.min.as_dvec3() - DVec3::splat(grow),
        max: h.hit_box.max.as_dvec3() + DVec3::splat(grow),
    };
    surface_meets_box(&patch, &target, 0)
}

/// Depth limit of [`surface_meets_box`]: 2 × 61 halvings take any `f64` parameter interval
/// to its resolution, so deeper splits change nothing.
const MEET_MAX_DEPTH: u32 = 122;

/// Whether the patch has a point in `target`, by de Casteljau subdivision in `f64`
/// (the convex hull property: a sub-patch lies in its control box). Only sub-patches whose
/// control box meets the target are split, so the work is one thin branch.
fn surface_meets_box(patch: &BezierPatch, target: &DAabb, depth: u32) -> bool {
    let b = patch.control_box();
    let meets = b.min.cmple(target.max).all() && target.min.cmple(b.max).all();
    if !meets {
        return false;
    }
    let inside = b.min.cmpge(target.min).all() && b.max.cmple(target.max).all();
    if inside || depth >= MEET_MAX_DEPTH {
        return true;
    }
    let halves = if depth.is_multiple_of(2) {
        patch.split_u()
    } else {
        patch.split_v()
    };
    surface_meets_box(&halves.0, target, depth + 1)
        || surface_meets_box(&halves.1, target, depth + 1)
}

/// Traces the reflection, shadow and refraction rays of a hit and counts self-hits and
/// non-finite normals.
fn secondaries(
    geometry: &SceneGeometry,
    precision: &Kernel,
    ray: &Ray,
    h: &SceneHit,
    rng: &mut SplitMix64,
    f: &mut Figures,
) {
    if !h.normal.is_finite() {
        f.non_finite_normals += 1;
        return;
    }
    let d = ray.dir.as_dvec3().normalize();
    let n = if h.normal.dot(d) < 0.0 {
        h.normal
    } else {
        -h.normal
    };
    let reflect = d - 2.0 * d.dot(n) * n;
    // A shadow ray towards a random light in the hemisphere above the surface.
    let light = (n + 0.99 * rng.direction()).normalize_or(n);
    let refract = refraction(d, n);
    let n32 = n.as_vec3();
    let above = secondary_origin(&h.leave_box, n32, true, DEFAULT_ULPS);
    let below = secondary_origin(&h.leave_box, n32, false, DEFAULT_ULPS);
    for (origin, dir) in [(above, reflect), (above, light), (below, refract)] {
        let dir = dir.as_vec3();
        if dir == Vec3::ZERO || !dir.is_finite() {
            continue;
        }
        f.secondary_rays += 1;
        let mut stats = QueryStats::default();
        let Some(s) = geometry.intersect(&Ray::new(origin, dir), precision, &mut stats) else {
            continue;
        };
        if !s.normal.is_finite() {
            f.non_finite_normals += 1;
        }
        if s.object == h.object && s.patch == h.patch && overlap(&s.hit_box, &h.hit_box) {
            f.self_hits += 1;
        }
    }
}

/// Snell's law into glass from the side `n` points to (Whitted 1980); the mirror
/// direction's continuation when there is total internal reflection is never needed
/// entering glass, so this always refracts.
fn refraction(d: DVec3, n: DVec3) -> DVec3 {
    let eta = 1.0 / REFRACTION_IOR;
    let cos_i = -d.dot(n);
    let k = 1.0 - eta * eta * (1.0 - cos_i * cos_i);
    eta * d + (eta * cos_i - k.max(0.0).sqrt()) * n
}

fn overlap(a: &Aabb, b: &Aabb) -> bool {
    a.min.cmple(b.max).all() && b.min.cmple(a.max).all()
}

/// Renders the case scene at `size`² with the path and counts pixels with a non-finite
/// channel.
fn nan_pixels(
    case: &Case,
    geometry: &SceneGeometry,
    precision: Kernel,
    size: u32,
) -> (usize, usize) {
    let mut scene = case.scene.clone();
    scene.camera.width = size;
    scene.camera.height = size;
    let integrator = Integrator {
        scene: &scene,
        geometry,
        settings: TraceSettings {
            precision,
            ulps: DEFAULT_ULPS,
            plan: EffectPlan::for_scene(&scene),
        },
    };
    let film = render_image(&integrator, &ProgressBar::hidden()).film;
    let bad = film.pixels.iter().filter(|p| !p.is_finite()).count();
    (film.pixels.len(), bad)
}
