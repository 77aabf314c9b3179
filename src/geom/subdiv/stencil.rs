//! Control points as integer-weighted sums of mesh points ("stencils"), evaluated in
//! ascending point order.
//!
//! Why: two patches that share an edge must produce the same bits along it (Dammertz
//! §2.9.1: "exactly the same operations are applied to connected boundaries"). Each
//! side builds its edge's Bézier points from its own 4×4 B-spline net, in its own
//! orientation; as formal sums over mesh points the two results are the same, and with
//! integer weights (the B-spline-to-Bézier matrix scaled by 6, phantom points as
//! `2 a - b`) and one fixed summation order they are the same in floating point too.

use glam::DVec3;

/// A sum `Σ w_i p_i` over mesh points, sorted by point index, without zero weights.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Stencil(Vec<(u32, i64)>);

impl Stencil {
    pub fn point(index: u32) -> Stencil {
        Stencil(vec![(index, 1)])
    }

    /// `Σ c_k s_k`, merged and sorted.
    pub fn combine<'a>(terms: impl IntoIterator<Item = (i64, &'a Stencil)>) -> Stencil {
        let mut all: Vec<(u32, i64)> = terms
            .into_iter()
            .flat_map(|(c, s)| s.0.iter().map(move |&(i, w)| (i, c * w)))
            .collect();
        all.sort_unstable_by_key(|&(i, _)| i);
        let mut out: Vec<(u32, i64)> = Vec::with_capacity(all.len());
        for (i, w) in all {
            match out.last_mut() {
                Some((j, acc)) if *j == i => *acc += w,
                _ => out.push((i, w)),
            }
        }
        out.retain(|&(_, w)| w != 0);
        Stencil(out)
    }

    /// `2 a - b`: the reflection of `b` through `a`, the phantom point of a sharp boundary.
    pub fn reflect(a: &Stencil, b: &Stencil) -> Stencil {
        Stencil::combine([(2, a), (-1, b)])
    }

    /// `Σ w_i p_i / denominator`, summed in ascending index order.
    pub fn eval(&self, points: &[DVec3], denominator: f64) -> DVec3 {
        self.0.iter().fold(DVec3::ZERO, |acc, &(i, w)| {
            acc + points[i as usize] * w as f64
        }) / denominator
    }

    /// The points the stencil reads.
    pub fn indices(&self) -> impl Iterator<Item = u32> + '_ {
        self.0.iter().map(|&(i, _)| i)
    }
}

/// The uniform cubic B-spline segment's Bézier points times 6: `b_a = Σ_i M6[a][i] P_i / 6`.
pub const BSPLINE_TO_BEZIER_6: [[i64; 4]; 4] =
    [[1, 4, 1, 0], [0, 4, 2, 0], [0, 2, 4, 0], [0, 1, 4, 1]];

/// The 16 Bézier points (`[a][b]`, a along u) of the bicubic B-spline net `grid`
/// (`[i][j]`, i along u), as stencils over 36.
pub fn bezier_stencils(grid: &[[Stencil; 4]; 4]) -> [[Stencil; 4]; 4] {
    let m = BSPLINE_TO_BEZIER_6;
    std::array::from_fn(|a| {
        std::array::from_fn(|b| {
            Stencil::combine((0..16).map(|k| {
                let (i, j) = (k % 4, k / 4);
                (m[a][i] * m[b][j], &grid[i][j])
            }))
        })
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn combine_merges_and_drops_zero_weights() {
        let (a, b) = (Stencil::point(3), Stencil::point(1));
        let s = Stencil::combine([(2, &a), (1, &b), (-2, &a)]);
        assert_eq!(s, Stencil(vec![(1, 1)]));
    }

    #[test]
    fn summation_order_does_not_depend_on_term_order() {
        // The same formal sum built in two orders evaluates to the same bits.
        let pts: Vec<DVec3> = (0..5)
            .map(|i| DVec3::splat(0.1 + i as f64 * 1e-3).powf(i as f64 + 0.5))
            .collect();
        let p: Vec<Stencil> = (0..5).map(Stencil::point).collect();
        let s1 = Stencil::combine([(1, &p[0]), (4, &p[3]), (1, &p[4])]);
        let s2 = Stencil::combine([(1, &p[4]), (4, &p[3]), (1, &p[0])]);
        assert_eq!(s1.eval(&pts, 6.0).to_array(), s2.eval(&pts, 6.0).to_array());
    }

    #[test]
    fn bezier_of_a_planar_grid_is_the_b_spline_patch() {
        // An affine grid P_ij = (i, j, 0) is reproduced: Bézier points (1 + a/3, 1 + b/3).
        let pts: Vec<DVec3> = (0..16)
            .map(|k| DVec3::new((k % 4) as f64, (k / 4) as f64, 0.0))
            .collect();
        let grid =
            std::array::from_fn(|i| std::array::from_fn(|j| Stencil::point((j * 4 + i) as u32)));
        let b = bezier_stencils(&grid);
        for a in 0..4 {
            for c in 0..4 {
                let p = b[a][c].eval(&pts, 36.0);
                let want = DVec3::new(1.0 + a as f64 / 3.0, 1.0 + c as f64 / 3.0, 0.0);
                assert!((p - want).length() < 1e-15, "{a},{c}: {p} vs {want}");
            }
        }
    }
}
