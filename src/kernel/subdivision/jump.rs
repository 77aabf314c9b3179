//! Newton jumps in ray space: skip the levels of the descent that a linearisation of the
//! sub-patch already decides.
//!
//! Why: the search (Dammertz §2.2) halves one parameter direction per split, so reaching
//! an `f32`-sized box takes ~46 splits on the teapot, each a dependent chain of de
//! Casteljau, box and test whose child choice the branch predictor cannot guess
//! (BENCHMARKS.md, issue 3). Once a sub-patch is nearly linear, where the ray crosses it
//! is known to a small fraction of the cell from its centre point and mean derivatives,
//! and the search can go straight to the dyadic sub-cell holding that fraction: halving
//! towards a known cell needs no box, no test and no branch.
//!
//! The argument, in ray space (the ray is the z-axis, [`super::ray_space`]), with cell
//! parameters `p ∈ [0,1]²` and `F(p)` the sub-patch's (x, y): let `J₀` be the mean of the
//! derivative nets and `E` a bound on how far `∂F/∂p` strays from `J₀` over the cell
//! (by the convex hull property of the derivative nets, Farin, *Curves and Surfaces for
//! CAGD*, §16.5). Then `G(p) = p − J₀⁻¹ F(p)` has Lipschitz constant `q ≤ ‖|J₀⁻¹| E‖∞` on
//! the cell; with `q < 1` it is a contraction, so the ray crosses the sub-patch at most
//! once in the cell (`F` is injective there), and if it does, at `p*` with
//! `‖p* − G(c)‖∞ ≤ q / (1 − q) · ‖J₀⁻¹ F(c)‖∞` for the centre `c` (the Newton–Kantorovich
//! estimate for a simplified Newton step). The jump targets the smallest dyadic sub-cell
//! holding that window, widened by [`WINDOW_SCALE`] for the `f32` rounding of `F(c)` and
//! the net.
//!
//! The jump never decides a hit by itself. Its sub-cell's box is tested like any child;
//! if it is hit, the search continues there with the cell as a fallback, which is searched
//! in full only if the sub-cell yields no hit (the window missed by rounding). Because the
//! crossing in the cell is unique, a hit in the sub-cell is the cell's nearest, and the
//! final box is one the halving search could have produced: the same dyadic cell, split
//! with the same roundings (halving is exact in the split's arithmetic).

use super::param::ParamCell;

/// Largest Lipschitz bound `q` at which a jump is tried: the window grows as `q / (1 − q)`,
/// so above 1/2 it is wider than the step itself and saves little.
const MAX_CONTRACTION: f64 = 0.5;

/// Factor on the Kantorovich window: the bound is exact for exact arithmetic, and the
/// `f32` centre point and net are a few ulps off; doubling covers that wherever the window
/// is wider than the rounding, and [`MIN_WINDOW`] covers the rest.
const WINDOW_SCALE: f64 = 2.0;

/// Smallest half-width of the window, as a fraction of the cell: below it the `f32`
/// centre point's rounding can exceed the Kantorovich bound. 2^-9 lets one jump skip up to
/// eight levels per direction.
const MIN_WINDOW: f64 = 1.0 / 16384.0;

/// Most levels one jump descends per direction (the window's floor allows eight).
pub const MAX_JUMP_LEVELS: u8 = 13;

/// A jump is worth its fixed cost (linearisation, descent, one box test) from this many
/// levels on, in both directions together; a split costs about as much as two descent
/// levels plus the linearisation.
const MIN_JUMP_LEVELS: u8 = 3;

/// What a jump needs of a sub-patch in ray space, over cell parameters `[0,1]²`: its
/// (x, y) at the cell centre, the mean derivatives and the bound on their deviation.
#[derive(Clone, Copy, Debug)]
pub struct Linearization {
    pub centre: [f32; 2],
    /// Mean `∂(x, y)/∂u` and `∂(x, y)/∂v` over the derivative nets.
    pub du: [f32; 2],
    pub dv: [f32; 2],
    /// Largest deviation of the derivative nets from `du`, `dv`, per component.
    pub du_dev: [f32; 2],
    pub dv_dev: [f32; 2],
}

/// The sub-cell a jump goes to: `levels` more levels in u and v, at `index` (in units of
/// the sub-cell's width inside the cell).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Jump {
    pub levels: [u8; 2],
    pub index: [u64; 2],
}

impl Jump {
    /// The jumped-to cell inside `cell`.
    pub fn cell(&self, cell: ParamCell) -> ParamCell {
        cell.sub_cell(self.levels, self.index)
    }
}

/// A bicubic net's linearisation from its points' (x, y), `xy[j][i]` the point `(i, j)`
/// (u index `i`, v index `j`): the definition the register version
/// (`avx512::Net16::linearization`) is tested against.
#[cfg(test)]
pub fn linearize(xy: &[[[f32; 2]; 4]; 4]) -> Linearization {
    // Bernstein weights of degree 3 at 1/2, times 8.
    const HALF: [f32; 4] = [1.0, 3.0, 3.0, 1.0];
    let mut centre = [0f32; 2];
    for (j, row) in xy.iter().enumerate() {
        for (i, p) in row.iter().enumerate() {
            for c in 0..2 {
                centre[c] += HALF[i] * HALF[j] * p[c];
            }
        }
    }
    let centre = centre.map(|s| s / 64.0);
    // Derivative nets (degree 2 × 3 and 3 × 2): 3 × the differences of neighbours.
    let du: [[f32; 2]; 12] = std::array::from_fn(|k| diff(xy[k / 3][k % 3 + 1], xy[k / 3][k % 3]));
    let dv: [[f32; 2]; 12] = std::array::from_fn(|k| diff(xy[k / 4 + 1][k % 4], xy[k / 4][k % 4]));
    let (du, du_dev) = mean_and_deviation(&du);
    let (dv, dv_dev) = mean_and_deviation(&dv);
    Linearization {
        centre,
        du,
        dv,
        du_dev,
        dv_dev,
    }
}

#[cfg(test)]
/// `3 (a − b)`, the derivative-net point of neighbours `a`, `b` of a cubic net.
fn diff(a: [f32; 2], b: [f32; 2]) -> [f32; 2] {
    [3.0 * (a[0] - b[0]), 3.0 * (a[1] - b[1])]
}

#[cfg(test)]
/// Componentwise mean of `d` and the largest distance of an element from it.
fn mean_and_deviation(d: &[[f32; 2]; 12]) -> ([f32; 2], [f32; 2]) {
    let mean = [0, 1].map(|c| d.iter().map(|v| v[c]).sum::<f32>() / 12.0);
    let dev = [0, 1].map(|c| d.iter().fold(0f32, |m, v| m.max((v[c] - mean[c]).abs())));
    (mean, dev)
}

/// The jump for a cell at levels `(lu, lv)` with linearisation `lin`, descending at most
/// `max_levels` per direction, or `None` where the sub-patch is not linear enough, the
/// crossing lies outside the cell, or the jump would save too little.
pub fn plan(lin: &Linearization, max_levels: [u8; 2]) -> Option<Jump> {
    let f = |v: [f32; 2]| v.map(f64::from);
    let (c, du, dv, eu, ev) = (
        f(lin.centre),
        f(lin.du),
        f(lin.dv),
        f(lin.du_dev),
        f(lin.dv_dev),
    );
    // J₀ = [du dv] (columns), its inverse by the adjugate.
    let det = du[0] * dv[1] - dv[0] * du[1];
    if !det.is_normal() {
        return None;
    }
    let inv = [[dv[1] / det, -dv[0] / det], [-du[1] / det, du[0] / det]];
    // q = ‖|J₀⁻¹| E‖∞ with E = [eu ev] (columns).
    let q = (0..2)
        .map(|r| {
            let row = inv[r].map(f64::abs);
            (row[0] * eu[0] + row[1] * eu[1]) + (row[0] * ev[0] + row[1] * ev[1])
        })
        .fold(0f64, f64::max);
    if q.is_nan() || q >= MAX_CONTRACTION {
        return None;
    }
    let step = [0, 1].map(|r| inv[r][0] * c[0] + inv[r][1] * c[1]);
    let half_width =
        (WINDOW_SCALE * q / (1.0 - q) * step[0].abs().max(step[1].abs())).max(MIN_WINDOW);
    let mut levels = [0u8; 2];
    let mut index = [0u64; 2];
    for d in 0..2 {
        let centre = 0.5 - step[d];
        let (lo, hi) = (centre - half_width, centre + half_width);
        if !(hi > 0.0 && lo < 1.0) {
            return None;
        }
        let k = max_levels[d].min(MAX_JUMP_LEVELS);
        let scale = f64::from(1u32 << k);
        let top = (1u64 << k) - 1;
        let (a, b) = ((lo.max(0.0) * scale) as u64, ((hi * scale) as u64).min(top));
        // The deepest level at which both ends of the window fall in the same cell.
        let drop = 64 - (a ^ b).leading_zeros() as u8;
        levels[d] = k - drop;
        index[d] = a >> drop;
    }
    (levels[0] + levels[1] >= MIN_JUMP_LEVELS).then_some(Jump { levels, index })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The net of the bilinear-in-disguise patch `F(u, v) = A (u, v) + b` (degree-elevated
    /// to bicubic): exactly linear, so the window is the floor and must hold the root.
    fn linear_net(a: [[f32; 2]; 2], b: [f32; 2]) -> [[[f32; 2]; 4]; 4] {
        std::array::from_fn(|j| {
            std::array::from_fn(|i| {
                let (u, v) = (i as f32 / 3.0, j as f32 / 3.0);
                [0, 1].map(|c| a[c][0] * u + a[c][1] * v + b[c])
            })
        })
    }

    #[test]
    fn linear_patch_jumps_to_the_cell_of_its_root() {
        // Root where A (u, v) = -b, solved in f64.
        let a = [[1.0f32, 0.25], [-0.5, 2.0]];
        let b = [-0.4f32, -0.9];
        let det = f64::from(a[0][0] * a[1][1] - a[0][1] * a[1][0]);
        let u =
            (f64::from(-b[0]) * f64::from(a[1][1]) - f64::from(a[0][1]) * f64::from(-b[1])) / det;
        let v =
            (f64::from(a[0][0]) * f64::from(-b[1]) - f64::from(-b[0]) * f64::from(a[1][0])) / det;
        let lin = linearize(&linear_net(a, b));
        let jump = plan(&lin, [20, 20]).expect("a linear patch is a contraction");
        for (d, root) in [u, v].into_iter().enumerate() {
            let width = (-f64::from(jump.levels[d])).exp2();
            let lo = jump.index[d] as f64 * width;
            assert!(lo <= root && root < lo + width, "{jump:?} {root}");
        }
        // Exactly linear: the window is the floor, so the jump goes nearly as deep as it may.
        assert!(
            jump.levels.iter().all(|&l| l + 2 >= MAX_JUMP_LEVELS),
            "{jump:?}"
        );
    }

    /// Bernstein basis of degree 3 and its derivative at `t`, in `f64`.
    fn bernstein(t: f64) -> ([f64; 4], [f64; 4]) {
        let s = 1.0 - t;
        (
            [s * s * s, 3.0 * t * s * s, 3.0 * t * t * s, t * t * t],
            [
                -3.0 * s * s,
                3.0 * s * s - 6.0 * t * s,
                6.0 * t * s - 3.0 * t * t,
                3.0 * t * t,
            ],
        )
    }

    /// `F(u, v)` and its Jacobian columns for the net, in `f64`.
    fn eval(xy: &[[[f32; 2]; 4]; 4], u: f64, v: f64) -> [[f64; 2]; 3] {
        let ((bu, du), (bv, dv)) = (bernstein(u), bernstein(v));
        let mut out = [[0f64; 2]; 3];
        for j in 0..4 {
            for i in 0..4 {
                for c in 0..2 {
                    let p = f64::from(xy[j][i][c]);
                    out[0][c] += bu[i] * bv[j] * p;
                    out[1][c] += du[i] * bv[j] * p;
                    out[2][c] += bu[i] * dv[j] * p;
                }
            }
        }
        out
    }

    /// The crossing by Newton's method with the exact Jacobian, in `f64`, from the centre:
    /// an algorithm independent of the jump's simplified step and bound.
    fn newton_root(xy: &[[[f32; 2]; 4]; 4]) -> Option<(f64, f64)> {
        let (mut u, mut v) = (0.5, 0.5);
        for _ in 0..60 {
            let [f, fu, fv] = eval(xy, u, v);
            let det = fu[0] * fv[1] - fv[0] * fu[1];
            u -= (fv[1] * f[0] - fv[0] * f[1]) / det;
            v -= (fu[0] * f[1] - fu[1] * f[0]) / det;
        }
        let [f, ..] = eval(xy, u, v);
        (f[0].abs().max(f[1].abs()) < 1e-12).then_some((u, v))
    }

    /// Random gently curved nets crossing the ray inside their cell: wherever the plan
    /// jumps, the sub-cell holds the crossing; strongly curved nets are refused.
    #[test]
    fn jumps_land_on_the_crossing_of_curved_nets() {
        let mut state = 0x9e37_79b9u32;
        let mut uniform = || {
            state ^= state << 13;
            state ^= state >> 17;
            state ^= state << 5;
            (state >> 8) as f64 / (1u32 << 24) as f64
        };
        let (mut jumped, mut refused) = (0, 0);
        for case in 0..2000 {
            // Control points off a unit-sized linear map by 1e-4 to 0.3 (log-uniform).
            let bend = 1e-4 * 3000f64.powf(case as f64 / 2000.0);
            let a = [
                [0.5 + uniform(), uniform() - 0.5],
                [uniform() - 0.5, 0.5 + uniform()],
            ];
            let (u0, v0) = (0.05 + 0.9 * uniform(), 0.05 + 0.9 * uniform());
            let xy: [[[f32; 2]; 4]; 4] = std::array::from_fn(|j| {
                std::array::from_fn(|i| {
                    let (u, v) = (i as f64 / 3.0 - u0, j as f64 / 3.0 - v0);
                    [0, 1].map(|c| (a[c][0] * u + a[c][1] * v + bend * (uniform() - 0.5)) as f32)
                })
            });
            let Some((u, v)) = newton_root(&xy) else {
                continue;
            };
            if !(0.0..1.0).contains(&u) || !(0.0..1.0).contains(&v) {
                continue;
            }
            match plan(&linearize(&xy), [20, 20]) {
                Some(jump) => {
                    jumped += 1;
                    for (d, root) in [u, v].into_iter().enumerate() {
                        let width = (-f64::from(jump.levels[d])).exp2();
                        let lo = jump.index[d] as f64 * width;
                        assert!(
                            lo <= root && root <= lo + width,
                            "case {case}: {jump:?} misses {root}"
                        );
                    }
                }
                None => refused += 1,
            }
        }
        // Both regimes occur: the test must see jumps and refusals.
        assert!(
            jumped > 200 && refused > 200,
            "{jumped} jumps, {refused} refused"
        );
    }
}
