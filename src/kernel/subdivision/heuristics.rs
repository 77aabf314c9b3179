//! Choice of the split direction from the corner control points `b(0,0)`, `b(n,0)` and
//! `b(0,m)` of the current sub-patch: Dammertz §2.3.2 (length) and §2.5.2 (cross product).

use super::config::SplitHeuristic;
use super::float::KernelFloat;
use super::param::Split;

/// The corner control points the heuristics look at, Euclidean.
#[derive(Clone, Copy, Debug)]
pub struct Corners<T> {
    pub p00: [T; 3],
    pub pn0: [T; 3],
    pub p0m: [T; 3],
}

fn sub<T: KernelFloat>(a: [T; 3], b: [T; 3]) -> [T; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn norm2<T: KernelFloat>(a: [T; 3]) -> T {
    a[0] * a[0] + a[1] * a[1] + a[2] * a[2]
}

fn cross<T: KernelFloat>(a: [T; 3], b: [T; 3]) -> [T; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// The direction to split next. Ties (e.g. both edges collapsed) split in v.
#[inline(always)]
pub fn choose<T: KernelFloat>(h: SplitHeuristic, c: &Corners<T>, dir: [T; 3]) -> Split {
    let du = sub(c.pn0, c.p00);
    let dv = sub(c.p0m, c.p00);
    let (lu, lv) = match h {
        SplitHeuristic::Length => (norm2(du), norm2(dv)),
        SplitHeuristic::CrossProduct => (norm2(cross(du, dir)), norm2(cross(dv, dir))),
    };
    if lu > lv { Split::U } else { Split::V }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn corners(du: [f64; 3], dv: [f64; 3]) -> Corners<f64> {
        Corners {
            p00: [1.0, 2.0, 3.0],
            pn0: [1.0 + du[0], 2.0 + du[1], 3.0 + du[2]],
            p0m: [1.0 + dv[0], 2.0 + dv[1], 3.0 + dv[2]],
        }
    }

    #[test]
    fn length_splits_the_longer_edge() {
        let d = [0.0, 0.0, 1.0];
        let c = corners([2.0, 0.0, 0.0], [0.0, 1.0, 0.0]);
        assert_eq!(choose(SplitHeuristic::Length, &c, d), Split::U);
        let c = corners([0.5, 0.0, 0.0], [0.0, 0.0, 1.0]);
        assert_eq!(choose(SplitHeuristic::Length, &c, d), Split::V);
    }

    #[test]
    fn length_never_splits_a_collapsed_edge() {
        let c = corners([0.0; 3], [0.0, f64::MIN_POSITIVE, 0.0]);
        assert_eq!(
            choose(SplitHeuristic::Length, &c, [1.0, 0.0, 0.0]),
            Split::V
        );
    }

    #[test]
    fn cross_product_cuts_the_direction_parallel_to_the_ray() {
        // du is the longer edge, but the ray runs along it: |du × d| = 0, so the
        // cross-product heuristic splits v where the length heuristic would split u.
        let c = corners([3.0, 0.0, 0.0], [0.0, 1.0, 0.0]);
        let d = [1.0, 0.0, 0.0];
        assert_eq!(choose(SplitHeuristic::Length, &c, d), Split::U);
        assert_eq!(choose(SplitHeuristic::CrossProduct, &c, d), Split::V);
        // A ray across both edges: the longer edge gives the longer cross product.
        assert_eq!(
            choose(SplitHeuristic::CrossProduct, &c, [0.0, 0.0, 1.0]),
            Split::U
        );
    }
}
