//! Newton jumps in ray space: skip the levels of the descent that a linearisation of the
//! sub-patch already decides.
//!
//! Why: the search (Dammertz §2.2) halves one parameter direction per split, so reaching
//! an `f32`-sized box takes ~46 splits on the teapot, each a dependent chain of de
//! Casteljau, box and test whose child choice the branch predictor cannot guess
//! (BENCHMARKS.md, kernel). Once a sub-patch is nearly linear, where the ray crosses it
//! is known to a small fraction of the cell from its centre point and mean derivatives,
//! and the search can go straight to the dyadic sub-cell holding that fraction: halving
//! towards a known cell needs no box, no test and no branch.
//!
//! The argument, in ray space (the ray is the z-axis, [`super::ray_space`]), with cell
//! parameters `p ∈ [0,1]²` and `F(p)` the sub-patch's (x, y): let `J₀` be the mean of the
//! derivative nets and `E` a bound on how far `∂F/∂p` strays from `J₀` over the cell
//! (by the convex hull property of the derivative nets, Farin, *Curves and Surfaces for
//! CAGD*, §16.5). Then `G(p) = p − J₀⁻¹ F(p)` has Lipschitz constant `q ≤ ‖W⁻¹|J₀⁻¹| E W‖∞`
//! on the cell in the norm `‖x‖ = max_r |x_r| / w_r`, `W = diag(w)`, `w_r` the 1-norm of
//! row `r` of `J₀⁻¹`. With `q < 1`, `G` is a contraction, so the ray crosses the
//! sub-patch at most once in the cell (`F` is injective there). For every `p` in the cell,
//! `p − G(p) = J₀⁻¹ F(p)`, so `‖p − G(p)‖ ≤ ‖F(p)‖∞` in that norm, and
//! `‖p − G(c)‖ ≤ ‖p − G(p)‖ + q ‖p − c‖` gives, for the centre `c`,
//!
//! `‖p − G(c)‖ ≤ (q ‖J₀⁻¹ F(c)‖ + ‖F(p)‖∞) / (1 − q)`
//!
//! (the Newton–Kantorovich estimate for a simplified Newton step where `F(p) = 0`). The
//! window is the set of `p` this allows for `‖F(p)‖∞ ≤ η`, with `η` [`ROUNDING_ULPS`] ulps
//! of the net's largest `|x|`, `|y|`: the rounding of the `f32` centre point, and of a ray
//! through a cell border or an edge shared with a neighbour, whose crossing the roundings
//! of the two sides can put a few ulps outside both. The norm's weights keep the window
//! tight on cells that are several levels deeper in one direction than in the other,
//! where the plain max norm applies the wider direction's bound to both.
//!
//! What follows:
//! - A window that misses the cell proves that the ray does not cross the cell's surface:
//!   the cell is dropped ([`JumpOutcome::Empty`]).
//! - Otherwise the search halves straight to the smallest dyadic sub-cell holding the
//!   window (halving towards a known cell needs no box, no test and no branch) and tests
//!   that sub-cell's box, which is the box the halving search would have tested there (the
//!   same dyadic cell split with the same roundings: halving is exact in the split's
//!   arithmetic). A missed box drops the cell as well. A hit box replaces the cell: the
//!   crossing is unique, so the sub-cell's hit is the cell's nearest.
//!
//! The jump never decides a hit by itself: the final box is still found by the halving
//! search (Dammertz §2.2), inside the sub-cell. What a jump can change is a ray that
//! passes within a final box's size of a patch's boundary without crossing the patch,
//! which the halving search may report as a hit and a dropped cell does not (the accuracy criterion asks
//! hit and miss to agree with `f64` only away from a few ulps of the silhouette); at a
//! fold silhouette `J₀` is near singular and no jump is tried.

use super::param::{ParamCell, dyadic_width};

/// Largest Lipschitz bound `q` at which a jump is tried: the window grows as `q / (1 − q)`,
/// so above 1/2 it is wider than the step itself and saves little.
const MAX_CONTRACTION: f64 = 0.5;

/// Ulps of the net's largest `|x|`, `|y|` within which a point counts as a crossing, `η`
/// of the module documentation: more than the rounding of the `f32` centre point (a sum
/// of 16 products) and of a sub-net made by [`restriction`] (two matrix products of
/// rounded weights, about 8 ulps), each a few ulps of that magnitude. The jumps' counts on
/// the teapot are the same from 4 to 128 (BENCHMARKS.md, kernel).
const ROUNDING_ULPS: f64 = 32.0;

/// A jump is taken from this many levels on, in both directions together. Once the plan is
/// made, even one level of descent and a box test cost less than the split they replace
/// (measured from 1 to 6, BENCHMARKS.md, kernel).
const MIN_JUMP_LEVELS: u8 = 1;

/// What a jump needs of a sub-patch in ray space, over cell parameters `[0,1]²`: its
/// (x, y) at the cell centre, the mean derivatives and the bound on their deviation.
#[derive(Clone, Copy, Debug)]
pub struct Linearization {
    pub centre: [f32; 2],
    /// The largest `|x|` or `|y|` of the net's points, the scale of its rounding.
    pub magnitude: f32,
    /// Mean `∂(x, y)/∂u` and `∂(x, y)/∂v` over the derivative nets.
    pub du: [f32; 2],
    pub dv: [f32; 2],
    /// Largest deviation of the derivative nets from `du`, `dv`, per component.
    pub du_dev: [f32; 2],
    pub dv_dev: [f32; 2],
}

/// What a jump decides about a cell, carrying `L`: the [`Jump`] of [`plan`], or what the
/// search continues with after descending to it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum JumpOutcome<L> {
    /// Every final box the search could find in the cell lies in the jumped-to sub-cell.
    Landed(L),
    /// The search can find no final box in the cell (see the module documentation).
    Empty,
    /// Not linear enough to tell, or too little to gain: search the cell by halving.
    Undecided,
}

impl<L> JumpOutcome<L> {
    /// `f` of the landing; the other outcomes as they are.
    #[inline(always)]
    pub fn and_then<M>(self, f: impl FnOnce(L) -> JumpOutcome<M>) -> JumpOutcome<M> {
        match self {
            JumpOutcome::Landed(l) => f(l),
            JumpOutcome::Empty => JumpOutcome::Empty,
            JumpOutcome::Undecided => JumpOutcome::Undecided,
        }
    }
}

/// The sub-cell a jump goes to: `levels` more levels in u and v, at `index` (in units of
/// the sub-cell's width inside the cell).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Jump {
    pub levels: [u8; 2],
    pub index: [u64; 2],
    /// Whether the window lies inside the cell, away from its border: then the sub-net may
    /// be computed by [`restriction`] (see there).
    pub interior: bool,
    /// Whether the window of points within [`plan`]'s `near` of the ray stays inside the
    /// patch: only then does a sub-cell box that misses the ray prove that the halving
    /// search would find nothing in the cell.
    pub holds_near: bool,
}

impl Jump {
    /// The jumped-to cell inside `cell`.
    pub fn cell(&self, cell: ParamCell) -> ParamCell {
        cell.sub_cell(self.levels, self.index)
    }
}

/// The matrix taking a cubic Bézier curve's control points over `[0, 1]` to those of its
/// piece over the dyadic interval `[a, b]`, `a = index 2^-levels`, `b = a + 2^-levels`: row
/// `i` holds the weights of new point `i`, the cubic Bernstein polynomials' blossoms at
/// `(a, a, a)`, `(a, a, b)`, `(a, b, b)` and `(b, b, b)` (Farin, *Curves and Surfaces for
/// CAGD*, §4.2 and §5.5). Computed in `f64` and rounded once.
///
/// Why it may replace the halvings: the weights are non-negative and sum to 1, so the new
/// points are convex combinations, rounded by a few ulps of the net's largest coordinate,
/// as the halvings' points are, but in one matrix product instead of one dependent
/// de Casteljau step per level. Their roundings differ from the halvings', so a sub-net
/// made this way does not share its border bit for bit with a neighbour made by halving,
/// which Dammertz §2.3.3's crack freedom needs. A window inside the cell makes that moot:
/// every point of the cell with `‖F‖∞ ≤ η` lies in the window (module documentation), so
/// on the sub-cell's border the surface stays more than `η` from the ray, farther than
/// either net's rounding can move it ([`ROUNDING_ULPS`]), and the search never needs the
/// sub-cell's neighbours.
pub fn restriction(levels: u8, index: u64) -> [[f32; 4]; 4] {
    let width = dyadic_width(levels);
    let a = index as f64 * width;
    let b = a + width;
    let (s, t) = (1.0 - a, 1.0 - b);
    [
        [s * s * s, 3.0 * a * s * s, 3.0 * a * a * s, a * a * a],
        [
            s * s * t,
            2.0 * a * s * t + s * s * b,
            a * a * t + 2.0 * a * s * b,
            a * a * b,
        ],
        [
            s * t * t,
            a * t * t + 2.0 * s * b * t,
            2.0 * a * b * t + s * b * b,
            a * b * b,
        ],
        [t * t * t, 3.0 * b * t * t, 3.0 * b * b * t, b * b * b],
    ]
    .map(|row| row.map(|w| w as f32))
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
    let magnitude = xy
        .iter()
        .flatten()
        .flatten()
        .fold(0f32, |m, c| m.max(c.abs()));
    // Derivative nets (degree 2 × 3 and 3 × 2): 3 × the differences of neighbours.
    let du: [[f32; 2]; 12] = std::array::from_fn(|k| diff(xy[k / 3][k % 3 + 1], xy[k / 3][k % 3]));
    let dv: [[f32; 2]; 12] = std::array::from_fn(|k| diff(xy[k / 4 + 1][k % 4], xy[k / 4][k % 4]));
    let (du, du_dev) = mean_and_deviation(&du);
    let (dv, dv_dev) = mean_and_deviation(&dv);
    Linearization {
        centre,
        magnitude,
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

/// The jump for a cell with linearisation `lin`, descending at most `max_levels` per
/// direction. `near` is the end game's floor: surfaces within it of the ray are not
/// dropped (see the comment in the body). `borders[d]` says whether the cell's low and
/// high side in direction `d` lie on the patch's border, where a sub-cell's missed box
/// proves nothing if the window of such near points reaches beyond.
pub fn plan(
    lin: &Linearization,
    max_levels: [u8; 2],
    near: f32,
    borders: [[bool; 2]; 2],
) -> JumpOutcome<Jump> {
    let f = |v: [f32; 2]| v.map(f64::from);
    let (c, du, dv, eu, ev) = (
        f(lin.centre),
        f(lin.du),
        f(lin.dv),
        f(lin.du_dev),
        f(lin.dv_dev),
    );
    // J₀ = [du dv] (columns), J₀⁻¹ = A / det with A the adjugate. The plan is written in
    // terms of A with three independent divisions and one more for 1 / (1 − q), as the
    // search waits for it (nine divisions in a chain of three measured slower,
    // BENCHMARKS.md).
    let det = du[0] * dv[1] - dv[0] * du[1];
    if !det.is_normal() {
        return JumpOutcome::Undecided;
    }
    let adj = [[dv[1], -dv[0]], [-du[1], du[0]]];
    let abs_adj = adj.map(|row| row.map(f64::abs));
    // The weights of the norm (module documentation) times |det|.
    let a = abs_adj.map(|row| row[0] + row[1]);
    let (inv_det, inv_a) = (1.0 / det.abs(), [1.0 / a[0], 1.0 / a[1]]);
    // The Lipschitz bound q = ‖W⁻¹ |J₀⁻¹| E W‖∞ with E = [eu ev] (columns).
    let m = abs_adj.map(|row| {
        [
            row[0] * eu[0] + row[1] * eu[1],
            row[0] * ev[0] + row[1] * ev[1],
        ]
    });
    let q = (0..2)
        .map(|r| (m[r][0] * a[0] + m[r][1] * a[1]) * inv_a[r] * inv_det)
        .fold(0f64, f64::max);
    if q.is_nan() || q >= MAX_CONTRACTION {
        return JumpOutcome::Undecided;
    }
    // The simplified Newton step J₀⁻¹ F(c), and its norm (where det cancels).
    let adj_c = [0, 1].map(|r| adj[r][0] * c[0] + adj[r][1] * c[1]);
    let step = adj_c.map(|x| x * inv_det.copysign(det));
    let step_norm = (adj_c[0] * inv_a[0]).abs().max((adj_c[1] * inv_a[1]).abs());
    let rounding = ROUNDING_ULPS * f64::from(f32::EPSILON) * f64::from(lin.magnitude);
    let radius = (q * step_norm + rounding) / (1.0 - q);
    // The same window for points within `near` of the ray. The halving search reports a
    // final box that holds the ray, and at the end game's floor such a box may hold a
    // surface that misses the ray by up to its diameter. The ray-space transform rounds
    // the net by a few ulps of its distance from the ray origin, so a ray crossing the
    // exact surface a few ulps inside an open edge, or grazing it twice a few ulps apart,
    // can miss the rounded net that the halving search still reports as hit; a jump that
    // dropped the cell left a hole (`bench stability --full`: 2 on grid 2x2
    // corners+edges, 1 on teapot corners+edges). So a cell is dropped only when this
    // window misses it too; where only the narrow one does, the halving search decides.
    // A crossing is still landed on with the narrow window: near misses beside it are
    // within a final box of it, except beyond the patch's border (`holds_near`).
    let near_radius = (q * step_norm + rounding.max(f64::from(near))) / (1.0 - q);
    let w = a.map(|x| x * inv_det);
    let centres = [0, 1].map(|d| 0.5 - step[d]);
    let window = |d: usize, r: f64| (centres[d] - w[d] * r, centres[d] + w[d] * r);
    let misses = |r: f64| {
        (0..2).any(|d| {
            let (lo, hi) = window(d, r);
            !(hi >= 0.0 && lo <= 1.0)
        })
    };
    if misses(near_radius) {
        return JumpOutcome::Empty;
    }
    if misses(radius) {
        return JumpOutcome::Undecided;
    }
    let mut levels = [0u8; 2];
    let mut index = [0u64; 2];
    let mut interior = true;
    let mut holds_near = true;
    for d in 0..2 {
        let half_width = w[d] * radius;
        let (lo, hi) = (centres[d] - half_width, centres[d] + half_width);
        interior &= lo > 0.0 && hi < 1.0;
        let k = max_levels[d];
        let scale = (1u64 << k) as f64;
        let top = (1u64 << k) - 1;
        let (a, b) = (
            ((lo.max(0.0) * scale) as u64).min(top),
            ((hi * scale) as u64).min(top),
        );
        // The deepest level at which both ends of the window fall in the same cell.
        let drop = 64 - (a ^ b).leading_zeros() as u8;
        levels[d] = k - drop;
        index[d] = a >> drop;
        let (near_lo, near_hi) = window(d, near_radius);
        holds_near &= !((borders[d][0] && near_lo < 0.0) || (borders[d][1] && near_hi > 1.0));
    }
    if levels[0] + levels[1] >= MIN_JUMP_LEVELS {
        JumpOutcome::Landed(Jump {
            levels,
            index,
            interior,
            holds_near,
        })
    } else {
        JumpOutcome::Undecided
    }
}

/// One halving of a cubic's control values in `f64` (de Casteljau at 1/2), the lower or
/// the upper half: the reference the restriction matrices and the descents are tested
/// against.
#[cfg(test)]
pub fn halve(c: [f64; 4], upper: bool) -> [f64; 4] {
    let mid = |a: f64, b: f64| 0.5 * (a + b);
    let (c01, c12, c23) = (mid(c[0], c[1]), mid(c[1], c[2]), mid(c[2], c[3]));
    let (c012, c123) = (mid(c01, c12), mid(c12, c23));
    let centre = mid(c012, c123);
    if upper {
        [centre, c123, c23, c[3]]
    } else {
        [c[0], c01, c012, centre]
    }
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

    /// A linear patch whose crossing lies just beyond its u = 0 edge, by less than the end
    /// game's floor: the halving search may end in a final box holding the ray there, so
    /// the jump leaves the cell to it; farther out than the floor the cell is dropped.
    #[test]
    fn a_near_miss_within_the_end_game_floor_is_left_to_the_halving_search() {
        // Distances in units of the rounding allowance η (ROUNDING_ULPS ulps of the net's
        // magnitude, 1 here), so the cases sit where the plan's arithmetic puts them.
        let eta = ROUNDING_ULPS as f32 * f32::EPSILON;
        let net = |offset: f32| linearize(&linear_net([[1.0, 0.0], [0.0, 1.0]], [offset, -0.5]));
        // F(u, v) = (u + 5η, v - 0.5): the crossing is at u = -5η, beyond the u = 0 edge.
        let beyond = net(5.0 * eta);
        let border = [[true, false], [false, false]];
        assert_eq!(
            plan(&beyond, [20, 20], 10.0 * eta, border),
            JumpOutcome::Undecided
        );
        assert_eq!(
            plan(&beyond, [20, 20], 2.0 * eta, border),
            JumpOutcome::Empty
        );
        assert_eq!(plan(&beyond, [20, 20], 0.0, border), JumpOutcome::Empty);
        // A crossing 3η inside lands, but a miss of its sub-cell's box may not drop the
        // cell: the window of near points reaches beyond the border.
        let inside = net(-3.0 * eta);
        let JumpOutcome::Landed(jump) = plan(&inside, [20, 20], 10.0 * eta, border) else {
            panic!("the crossing is inside the cell");
        };
        assert!(!jump.holds_near);
        let JumpOutcome::Landed(jump) = plan(&inside, [20, 20], 10.0 * eta, [[false; 2]; 2]) else {
            panic!("the crossing is inside the cell");
        };
        assert!(jump.holds_near);
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
        let JumpOutcome::Landed(jump) = plan(&lin, [20, 20], 0.0, [[false; 2]; 2]) else {
            panic!("a linear patch is a contraction with its root inside");
        };
        assert!(holds(&jump, [u, v]), "{jump:?} {u} {v}");
        // Exactly linear (q = 0): the window is the rounding allowance, about 2^-17 of the
        // cell here, so the jump goes deep unless the window straddles a coarse boundary.
        assert!(jump.levels.iter().all(|&l| l >= 10), "{jump:?}");
    }

    /// Whether the jump's sub-cell holds the point `p` of the cell (closed bounds).
    fn holds(jump: &Jump, p: [f64; 2]) -> bool {
        (0..2).all(|d| {
            let width = (-f64::from(jump.levels[d])).exp2();
            let lo = jump.index[d] as f64 * width;
            lo <= p[d] && p[d] <= lo + width
        })
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
    fn newton_root(xy: &[[[f32; 2]; 4]; 4]) -> Option<[f64; 2]> {
        let (mut u, mut v) = (0.5, 0.5);
        for _ in 0..60 {
            let [f, fu, fv] = eval(xy, u, v);
            let det = fu[0] * fv[1] - fv[0] * fu[1];
            u -= (fv[1] * f[0] - fv[0] * f[1]) / det;
            v -= (fu[0] * f[1] - fu[1] * f[0]) / det;
        }
        let [f, ..] = eval(xy, u, v);
        (f[0].abs().max(f[1].abs()) < 1e-12).then_some([u, v])
    }

    /// Random gently curved nets whose crossing lies inside or outside their cell:
    /// wherever the plan jumps, the sub-cell holds the crossing; it drops only cells whose
    /// crossing lies outside; strongly curved nets are refused.
    #[test]
    fn jumps_land_on_the_crossing_of_curved_nets() {
        let mut state = 0x9e37_79b9u32;
        let mut uniform = || {
            state ^= state << 13;
            state ^= state >> 17;
            state ^= state << 5;
            (state >> 8) as f64 / (1u32 << 24) as f64
        };
        let (mut jumped, mut dropped, mut refused) = (0, 0, 0);
        const CASES: usize = 4000;
        for case in 0..CASES {
            // Control points off a unit-sized linear map by 1e-4 to 0.3 (log-uniform).
            let bend = 1e-4 * 3000f64.powf(case as f64 / CASES as f64);
            let a = [
                [0.5 + uniform(), uniform() - 0.5],
                [uniform() - 0.5, 0.5 + uniform()],
            ];
            // The linear part's root, inside the cell in about half of the cases.
            let (u0, v0) = (1.4 * uniform() - 0.2, 1.4 * uniform() - 0.2);
            let xy: [[[f32; 2]; 4]; 4] = std::array::from_fn(|j| {
                std::array::from_fn(|i| {
                    let (u, v) = (i as f64 / 3.0 - u0, j as f64 / 3.0 - v0);
                    [0, 1].map(|c| (a[c][0] * u + a[c][1] * v + bend * (uniform() - 0.5)) as f32)
                })
            });
            let Some(root) = newton_root(&xy) else {
                continue;
            };
            let inside = root.iter().all(|r| (0.0..=1.0).contains(r));
            match plan(&linearize(&xy), [20, 20], 0.0, [[false; 2]; 2]) {
                JumpOutcome::Landed(jump) => {
                    jumped += 1;
                    assert!(
                        !inside || holds(&jump, root),
                        "case {case}: {jump:?} misses {root:?}"
                    );
                }
                JumpOutcome::Empty => {
                    dropped += 1;
                    assert!(
                        !inside,
                        "case {case}: dropped with its root {root:?} inside"
                    );
                }
                JumpOutcome::Undecided => refused += 1,
            }
        }
        // Every regime occurs: the test must see jumps, dropped cells and refusals.
        assert!(
            jumped > 500 && dropped > 200 && refused > 200,
            "{jumped} jumps, {dropped} dropped, {refused} refused"
        );
    }

    /// The restriction matrices against the piece's control points by halvings in `f64`:
    /// an independent computation of the same sub-curve.
    #[test]
    fn restriction_is_repeated_halving() {
        let curve = [0.3, -1.7, 2.25, 0.9];
        for (levels, index) in [(0, 0), (1, 1), (3, 5), (10, 700), (24, 12_345_678)] {
            let m = restriction(levels, index);
            let mut want = curve;
            for level in (0..levels).rev() {
                want = halve(want, (index >> level) & 1 == 1);
            }
            for (row, w) in m.iter().zip(want) {
                let got: f64 = row.iter().zip(curve).map(|(&a, b)| f64::from(a) * b).sum();
                // The weights are rounded to f32: a few ulps of the largest control value.
                assert!(
                    (got - w).abs() <= 4.0 * 2.25 * f64::from(f32::EPSILON),
                    "{levels} {index}: {got} vs {w}"
                );
                // Convex combinations: non-negative weights summing to 1.
                assert!(row.iter().all(|&a| a >= 0.0));
                let sum: f64 = row.iter().map(|&a| f64::from(a)).sum();
                assert!((sum - 1.0).abs() <= 4.0 * f64::from(f32::EPSILON));
            }
        }
    }
}
