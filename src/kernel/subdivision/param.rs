//! The parameter interval of a sub-patch, tracked per stack entry so that a hit reports the
//! centre of the final interval as (u, v) (Dammertz code 2.3.8, `paramStack`).
//!
//! Intervals are dyadic, so they are kept exactly in fixed point: `[u0, u0 + 2^-level_u)`
//! with `u0` in units of 2^-63. The level also bounds the work. Termination: every split
//! raises `level_u + level_v` by one and a direction is never split beyond
//! `T::MAX_LEVEL` (32 for `f32`, 61 for `f64`); a cell at the limit in both directions is
//! final. So a search is at most `2 · MAX_LEVEL` splits deep and its stack holds at most
//! `2 · MAX_LEVEL` entries. No accuracy is lost by the limit: a Bézier patch of degree
//! n ≤ 15 over a parameter interval of width h moves at most `n h D` (D the largest
//! control-net edge), so at 2^-32 a box is below `2^-28 D`, under one `f32` ulp of any
//! coordinate larger than `D / 16`; Dammertz's criterion normally stops the `f32` search
//! after 20–30 levels per direction (measured on the teapot in `benches/kernel.rs`).

/// Which parameter direction a split halves.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Split {
    U,
    V,
}

/// `2^-levels`, the width of a cell `levels` splits deep, exactly: built from its bits (any
/// `u8` is far inside `f64`'s normal exponents) rather than by `exp2`, a library call that
/// took 3% of the glass teapot's render in the jumps' restriction matrices.
pub fn dyadic_width(levels: u8) -> f64 {
    f64::from_bits((1023 - u64::from(levels)) << 52)
}

/// Fixed-point position of 1.0: the cell coordinates are multiples of 2^-63.
const ONE_FIXED: f64 = (1u64 << 63) as f64;

/// A dyadic cell of the parameter square.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct ParamCell {
    u0: u64,
    v0: u64,
    level_u: u8,
    level_v: u8,
}

impl ParamCell {
    /// The whole square [0,1]².
    pub const ROOT: ParamCell = ParamCell {
        u0: 0,
        v0: 0,
        level_u: 0,
        level_v: 0,
    };

    pub fn levels(&self) -> (u8, u8) {
        (self.level_u, self.level_v)
    }

    /// The two halves (lower parameter first).
    #[inline(always)]
    pub fn split(&self, dir: Split) -> (ParamCell, ParamCell) {
        match dir {
            Split::U => {
                let level_u = self.level_u + 1;
                let lo = ParamCell { level_u, ..*self };
                let hi = ParamCell {
                    u0: self.u0 + (1u64 << (63 - level_u)),
                    ..lo
                };
                (lo, hi)
            }
            Split::V => {
                let level_v = self.level_v + 1;
                let lo = ParamCell { level_v, ..*self };
                let hi = ParamCell {
                    v0: self.v0 + (1u64 << (63 - level_v)),
                    ..lo
                };
                (lo, hi)
            }
        }
    }

    /// The sub-cell `levels` deeper in u and v at `index` (in units of the sub-cell's
    /// width, from the cell's lower corner): where a jump ([`super::jump`]) lands.
    pub fn sub_cell(&self, levels: [u8; 2], index: [u64; 2]) -> ParamCell {
        let (level_u, level_v) = (self.level_u + levels[0], self.level_v + levels[1]);
        ParamCell {
            u0: self.u0 + (index[0] << (63 - level_u)),
            v0: self.v0 + (index[1] << (63 - level_v)),
            level_u,
            level_v,
        }
    }

    /// Lower corner and width of the cell in u and v: `(u0, v0, wu, wv)`.
    pub fn bounds(&self) -> (f64, f64, f64, f64) {
        (
            self.u0 as f64 / ONE_FIXED,
            self.v0 as f64 / ONE_FIXED,
            dyadic_width(self.level_u),
            dyadic_width(self.level_v),
        )
    }

    /// Whether `other` lies inside this cell (a dyadic cell is inside another or disjoint
    /// from it unless it contains it).
    #[inline(always)]
    pub fn contains(&self, other: &ParamCell) -> bool {
        // Shifting by 63 clears a coordinate below 2^63: the root holds every cell.
        let same = |a: u64, b: u64, level: u8| (a ^ b) >> (63 - level) == 0;
        other.level_u >= self.level_u
            && other.level_v >= self.level_v
            && same(self.u0, other.u0, self.level_u)
            && same(self.v0, other.v0, self.level_v)
    }

    /// The centre of the cell, the (u, v) a hit reports (Dammertz code 2.3.8).
    pub fn centre(&self) -> (f64, f64) {
        let (u0, v0, wu, wv) = self.bounds();
        (u0 + 0.5 * wu, v0 + 0.5 * wv)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn halves_tile_the_parent() {
        let c = ParamCell::ROOT.split(Split::U).1.split(Split::V).0;
        assert_eq!(c.bounds(), (0.5, 0.0, 0.5, 0.5));
        let (a, b) = c.split(Split::U);
        let (ab, bb) = (a.bounds(), b.bounds());
        assert_eq!(ab.0 + ab.2, bb.0);
        assert_eq!(ab.0, 0.5);
        assert_eq!(bb.0 + bb.2, 1.0);
        assert_eq!(a.centre(), (0.625, 0.25));
    }

    /// Against `exp2`, the library's power of two, for every width a `u8` names.
    #[test]
    fn dyadic_width_is_the_power_of_two() {
        for levels in 0..=u8::MAX {
            assert_eq!(
                dyadic_width(levels),
                (-f64::from(levels)).exp2(),
                "{levels}"
            );
        }
    }

    /// Against the cells' bounds as intervals.
    #[test]
    fn containment_is_interval_inclusion() {
        let mut cells = vec![ParamCell::ROOT];
        for _ in 0..3 {
            let more: Vec<ParamCell> = cells
                .iter()
                .flat_map(|c| {
                    let (a, b) = c.split(Split::U);
                    let (d, e) = c.split(Split::V);
                    [a, b, d, e]
                })
                .collect();
            cells.extend(more);
        }
        for a in &cells {
            for b in &cells {
                let ((au, av, aw, ah), (bu, bv, bw, bh)) = (a.bounds(), b.bounds());
                let inside = bu >= au && bu + bw <= au + aw && bv >= av && bv + bh <= av + ah;
                assert_eq!(a.contains(b), inside, "{a:?} {b:?}");
            }
        }
    }

    #[test]
    fn deepest_cell_is_exact() {
        let mut c = ParamCell::ROOT;
        for _ in 0..61 {
            c = c.split(Split::U).1;
        }
        let (u0, _, wu, _) = c.bounds();
        assert_eq!(wu, (-61f64).exp2());
        assert_eq!(u0, 1.0 - wu);
    }
}
