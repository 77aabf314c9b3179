//! Settings of the subdivision kernel: the split-direction heuristic (Dammertz §2.3.2 and
//! §2.5.2), the termination criterion (float precision §2.3.3, a fixed depth as in his
//! Table 2.5, adaptive screen-space §2.5.3) and the mantissa distance that ends the
//! subdivision of rational patches (§2.7.2).

use crate::kernel::SurfaceOrigin;

/// How the next split direction is chosen from the corner control points.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum SplitHeuristic {
    /// Split across the longer of the edges `b(n,0) - b(0,0)` and `b(0,m) - b(0,0)`
    /// (Dammertz §2.3.2, used in his code 2.3.8).
    #[default]
    Length,
    /// Split in u when `|du × d|² > |dv × d|²` for the ray direction `d`, so the direction
    /// more parallel to the ray is cut first (Dammertz §2.5.2, eq. 2.8).
    CrossProduct,
}

/// Mantissa distance (in ulps, per box coordinate) below which a rational patch's box counts
/// as final (Dammertz §2.7.2). Dammertz needed 64 with directed-rounding division (code
/// 2.7.3) and 2048 without; our boxes are rounded outward after a correctly rounded
/// division, so crack freedom does not depend on it and it only ends the end game early.
/// 16 keeps the box within 16 ulps per coordinate (Dammertz Table 2.12: mean error about
/// twice that of dist 0). Not yet tuned by measurement: the Newton test
/// (tests/lib/kernel_newton.rs) passes with it, the split savings are unmeasured.
pub const DEFAULT_RATIONAL_DIST: u32 = 16;

/// End-game threshold of the float-precision criterion: where it is measured and why 8,
/// see the definition (kept in `geom::ulp`, as load-time refinement measures by it too).
pub use crate::geom::ulp::DEFAULT_END_ULPS;

/// Splits a ray–patch test takes at full precision before its end game coarsens
/// ([`SubdivisionConfig::full_precision_splits`]). A ray that runs at a small angle θ to the
/// surface over a stretch hits about 1/θ boxes on every level, each of which must be split
/// before the nearest-first search can reject it (BENCHMARKS.md, stability), so
/// without a budget the work has no bound in θ. A coarsened box is entered where the ray
/// runs within that box's size above the surface, which on a grazing ray can be far along
/// it from the crossing, so the budget is set above what ordinary rays need: the teapot's
/// primary rays take at most 3786 splits per test (`cargo bench --bench kernel`); with
/// 2560 the few pairs above that coarsened and moved the mean hit error from 13.8 to 27
/// ulps (max 1.15e6, along a grazing ray). Rational patches converge more slowly (their
/// boxes come from homogeneous division, §2.7.2): a ray of tests/lib/kernel_newton.rs at a
/// random rational patch needs 7150 splits, and a budget of 4096 moved its hit 1e-3 off
/// the crossing. 16384 leaves a factor of two above that; the stability suite's worst
/// unbudgeted test (15251 splits, a folded patch) stays just below it.
pub const DEFAULT_FULL_PRECISION_SPLITS: u32 = 16384;

/// After the full-precision budget, the diameter below which a box is final doubles every
/// this many splits, starting from [`COARSEN_BASE_ULPS`] ulps of the patch scale.
pub const COARSEN_STEP_SPLITS: u32 = 64;

/// Start of the coarsened end game, in ulps of the root box's largest coordinate
/// magnitude: the default end game ([`DEFAULT_END_ULPS`]), whatever `end_ulps` is set to.
pub const COARSEN_BASE_ULPS: u32 = 8;

/// Doublings after which the coarsened end game exceeds every box: the root box's L1
/// diameter is at most 6 times its largest coordinate magnitude `s` (with outward
/// rounding, below 8 s), and `COARSEN_BASE_ULPS` ulps of `s` are more than `8 s 2^-24`
/// (an `f32` ulp of `s` exceeds `s 2^-24`), so 24 doublings reach `8 s`.
pub const COARSEN_DOUBLINGS: u32 = 24;

/// The most splits one ray–patch test of the default configuration can take: every node
/// is final once the coarsened end game exceeds every box, so no split follows the last
/// doubling ([`super::search`]).
pub const MAX_SPLITS_PER_TEST: u64 =
    DEFAULT_FULL_PRECISION_SPLITS as u64 + (COARSEN_DOUBLINGS * COARSEN_STEP_SPLITS) as u64;

/// When a box is final, besides the guards every criterion keeps: the box stopped
/// shrinking (§2.3.3), its L1 diameter fell below the end game ([`DEFAULT_END_ULPS`]), its
/// parameter cell reached the per-direction limit ([`super::param`]), or, for rational
/// patches, its corners are within the mantissa distance (§2.7.2). The guards keep every
/// criterion terminating and crack free; with [`Termination::Float`] they are the whole test.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum Termination {
    /// Float precision (Dammertz §2.3.3): only the guards, i.e. subdivide until the box
    /// stops shrinking in the kernel's float type.
    #[default]
    Float,
    /// Fixed depth: a box is final once its parameter cell has been split this many times
    /// in total (u and v splits together). This is the recursion depth of Dammertz's
    /// algorithm 2.2.1, one split per step in the direction the heuristic picks, and the
    /// "fixed termination criterion" of his Table 2.5.
    Depth(u8),
    /// Adaptive screen-space termination for primary rays (§2.5.3): a box is final when
    /// its projection onto the image plane is at most half a pixel. Secondary rays must
    /// not use it ([`SubdivisionConfig::for_secondary_rays`]).
    Adaptive(ScreenFootprint),
}

/// What the adaptive criterion needs to know about the camera
/// (`render::camera::CameraRays::footprint`). By the intercept theorem
/// (§2.5.3, Fig. 2.22), a box of size `d` at distance `b` along a ray through a pixel at
/// distance `a` from the eye projects to at most `a d / b`, which must not exceed `c`, half
/// the pixel size. With the image plane at distance 1 along the view direction `f`, a ray
/// `t ↦ eye + t dir` meets it at `a = |dir| / (dir · f)` and the box at `b = t |dir|`, so the
/// test is `d ≤ c t (dir · f)`: no square root, one product per ray. `d` is the box's L1
/// diameter, an upper bound on its Euclidean size, so the test stays conservative.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ScreenFootprint {
    /// Unit view direction `f` of the camera.
    pub forward: [f32; 3],
    /// Half a pixel's edge on the image plane at distance 1: `tan(fov_y / 2) / height`.
    pub half_pixel: f32,
}

/// Configuration of [`super::intersect`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SubdivisionConfig {
    pub heuristic: SplitHeuristic,
    pub termination: Termination,
    /// Mantissa distance of §2.7.2 for rational patches; 0 disables it (the L1 criterion
    /// alone then ends the subdivision).
    pub rational_dist: u32,
    /// End-game criterion in ulps of the root box's largest coordinate magnitude; 0
    /// disables it.
    pub end_ulps: u32,
    /// Search bicubic patches in the ray's own frame ([`super::ray_space`]) where the
    /// fast path supports it. A property of the ray, so that every patch a ray meets is
    /// searched in the same space; on by default for primary and secondary rays alike
    /// (each ray has its own frame, from its own origin and direction).
    pub ray_space: bool,
    /// The work budget: after this many splits of one ray–patch test the end game doubles
    /// every [`COARSEN_STEP_SPLITS`] splits, so a test takes at most this plus
    /// `COARSEN_DOUBLINGS · COARSEN_STEP_SPLITS` splits. A box final only by the budget is
    /// still a box of the sub-patch hit by the ray, so its hit stays within the box's own
    /// extent of the surface; only its size grows. `None` (the `f64` reference) never
    /// coarsens.
    pub full_precision_splits: Option<u32>,
    /// For a secondary ray, the surface it leaves and where: the search of that patch
    /// skips the region around the origin that the ray provably does not cross
    /// ([`super::trivial`]). Set by [`crate::kernel::Kernel::leaving`].
    pub surface_of_origin: Option<SurfaceOrigin>,
}

impl Default for SubdivisionConfig {
    fn default() -> Self {
        SubdivisionConfig {
            heuristic: SplitHeuristic::Length,
            termination: Termination::Float,
            rational_dist: DEFAULT_RATIONAL_DIST,
            end_ulps: DEFAULT_END_ULPS,
            ray_space: true,
            full_precision_splits: Some(DEFAULT_FULL_PRECISION_SPLITS),
            surface_of_origin: None,
        }
    }
}

impl SubdivisionConfig {
    /// The configuration for secondary rays: adaptive termination is defined by the
    /// camera's pixels and so only for primary rays (§2.5.3, "this simple projection does
    /// not work for secondary rays"); they fall back to float precision. The search space
    /// ([`SubdivisionConfig::ray_space`]) stays the primary rays': a secondary ray's frame
    /// is built from its own origin and direction like a primary ray's.
    pub fn for_secondary_rays(self) -> SubdivisionConfig {
        let termination = match self.termination {
            Termination::Adaptive(_) => Termination::Float,
            other => other,
        };
        SubdivisionConfig {
            termination,
            ..self
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Any camera's half-pixel angle will do here: the test is about which rays keep it.
    const SOME_HALF_PIXEL: f32 = 1e-3;

    #[test]
    fn secondary_rays_fall_back_to_float_precision_only_from_adaptive() {
        let adaptive = SubdivisionConfig {
            termination: Termination::Adaptive(ScreenFootprint {
                forward: [0.0, 1.0, 0.0],
                half_pixel: SOME_HALF_PIXEL,
            }),
            rational_dist: 64,
            ..SubdivisionConfig::default()
        };
        let secondary = adaptive.for_secondary_rays();
        assert_eq!(secondary.termination, Termination::Float);
        assert_eq!(secondary.rational_dist, 64);
        let depth = SubdivisionConfig {
            termination: Termination::Depth(12),
            ..SubdivisionConfig::default()
        };
        assert_eq!(depth.for_secondary_rays().termination, depth.termination);
        assert!(depth.ray_space && depth.for_secondary_rays().ray_space);
    }
}
