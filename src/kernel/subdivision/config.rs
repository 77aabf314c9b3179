//! Settings of the subdivision kernel: the split-direction heuristic (Dammertz §2.3.2 and
//! §2.5.2) and the mantissa distance that ends the subdivision of rational patches (§2.7.2).

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
/// (tests/kernel_newton.rs) passes with it, the split savings are unmeasured.
pub const DEFAULT_RATIONAL_DIST: u32 = 16;

/// End-game threshold: a box whose L1 diameter is below this many ulps of the root box's
/// largest coordinate magnitude is final, besides Dammertz's "stops shrinking" (§2.3.3),
/// which alone spends the last splits on rounding noise. Measured with
/// `cargo bench --bench kernel -- size=256 end=K` (teapot primary rays; splits per test,
/// mean / 99th-percentile hit-point distance to the `f64` reference in those ulps):
/// K = 0: 78.2, 4.3 / 33; 4: 72.4, 4.5 / 35; 8: 68.2, 4.9 / 37; 16: 64.3, 6.0 / 44.
/// 8 saves an eighth of the splits for an error still well inside the de Casteljau
/// rounding bound the tests allow (tests/kernel_newton.rs).
pub const DEFAULT_END_ULPS: u32 = 8;

/// Configuration of [`super::intersect`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SubdivisionConfig {
    pub heuristic: SplitHeuristic,
    /// Mantissa distance of §2.7.2 for rational patches; 0 disables it (the L1 criterion
    /// alone then ends the subdivision).
    pub rational_dist: u32,
    /// End-game criterion in ulps of the root box's largest coordinate magnitude; 0
    /// disables it.
    pub end_ulps: u32,
}

impl Default for SubdivisionConfig {
    fn default() -> Self {
        SubdivisionConfig {
            heuristic: SplitHeuristic::Length,
            rational_dist: DEFAULT_RATIONAL_DIST,
            end_ulps: DEFAULT_END_ULPS,
        }
    }
}
