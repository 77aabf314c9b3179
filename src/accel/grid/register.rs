//! The voxel list `l_a(S)` of a patch (LG90 §3.1): quarter the patch in parameter space
//! until every edge of a sub-patch's control box is shorter than `D / k`, and register the
//! voxels each final box overlaps. The union of the final boxes is the patch's tight box
//! (LG90 §3.1, Fig. 2: the sub-patches are computed anyway, so the box costs nothing).

use crate::geom::{BezierPatch, DAabb};

/// `k` of LG90 §3.1: boxes are compared with `D / k`; the paper found k = 2 sufficient
/// ("higher values for k did not significantly reduce l_a(S)").
pub const K: f64 = 2.0;

/// Quartering depth after which a sub-patch is registered whatever its box: a rational
/// patch with extreme weights may shrink slowly, and 4^12 leaves per patch already exceed
/// any memory budget (the build gives up on that voxel size well before).
const MAX_DEPTH: u32 = 12;

/// Calls `leaf(box)` for each final box of the recursion on `patch` and returns their union.
/// The patch is quartered at least once, so the result is never looser than
/// [`BezierPatch::tight_box`]. `leaf` returns `false` to abandon the recursion (over
/// budget); the union is then partial.
pub fn quarter_boxes(
    patch: &BezierPatch,
    target: f64,
    leaf: &mut impl FnMut(&DAabb) -> bool,
) -> DAabb {
    let mut union = DAabb::EMPTY;
    recurse(patch, target, 0, leaf, &mut union);
    union
}

/// Returns `false` once `leaf` has asked to stop.
fn recurse(
    patch: &BezierPatch,
    target: f64,
    depth: u32,
    leaf: &mut impl FnMut(&DAabb) -> bool,
    union: &mut DAabb,
) -> bool {
    let b = patch.control_box();
    let small = b.extent().max_element() < target;
    if depth > 0 && (small || depth >= MAX_DEPTH) {
        *union = union.union(&b);
        return leaf(&b);
    }
    let (a, c) = patch.split_u();
    for half in [a, c] {
        let (lo, hi) = half.split_v();
        for q in [lo, hi] {
            if !recurse(&q, target, depth + 1, leaf, union) {
                return false;
            }
        }
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    fn wavy() -> BezierPatch {
        let pts: Vec<DVec3> = (0..16)
            .map(|k| {
                let (i, j) = ((k % 4) as f64, (k / 4) as f64);
                DVec3::new(i, j, ((i + 2.0 * j) * 1.3).sin() * 2.0)
            })
            .collect();
        BezierPatch::from_points(3, 3, &pts).unwrap()
    }

    #[test]
    fn leaves_are_below_target_and_cover_sampled_points() {
        let p = wavy();
        let target = 0.4;
        let mut leaves = Vec::new();
        let union = quarter_boxes(&p, target, &mut |b| {
            leaves.push(*b);
            true
        });
        assert!(leaves.iter().all(|b| b.extent().max_element() < target));
        // Every sampled surface point lies in some leaf box (convex hull of the sub-net).
        for a in 0..=20 {
            for c in 0..=20 {
                let q = p.eval(a as f64 / 20.0, c as f64 / 20.0);
                let inside = |b: &DAabb| {
                    let slack = 1e-12 * (1.0 + q.abs().max_element());
                    q.cmpge(b.min - slack).all() && q.cmple(b.max + slack).all()
                };
                assert!(leaves.iter().any(inside), "{q} in no leaf");
            }
        }
        // The union is inside the one-level tight box, which is inside the control box.
        let tight = p.tight_box();
        assert!(union.min.cmpge(tight.min).all() && union.max.cmple(tight.max).all());
        assert!(union.extent().element_sum() < tight.extent().element_sum());
    }

    #[test]
    fn stopping_early_is_reported() {
        let mut n = 0;
        quarter_boxes(&wavy(), 0.01, &mut |_| {
            n += 1;
            n < 5
        });
        assert_eq!(n, 5);
    }
}
