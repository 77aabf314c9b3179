//! The bilinear non-rational fast path (Dammertz §2.7.1: "extra optimized code for the
//! most frequently used degrees"; a degree-1×1 patch is the ground plane of most scenes).
//! The net is structure-of-arrays: one SSE register per coordinate holding the corners
//! `b(0,0), b(1,0), b(0,1), b(1,1)` in its lanes. A split at 1/2 averages pairs of lanes
//! (de Casteljau for two points is one average) and blends the averages into the lanes of
//! the corners they replace; the box is one transposed horizontal min/max of the three
//! registers ([`super::register::reduce3`]). The averages are
//! the same operations as `general::split_net`'s, so the search is bit-identical to the
//! general path's on such a patch.

use glam::{BVec4A, Vec3A, Vec4, Vec4Swizzles};

use super::heuristics::Corners;
use super::param::Split;
use super::register::{LaneNet, reduce3};
use crate::geom::BezierPatch;

/// Lanes of the corners a split in u replaces in the lower child: `b(1,0)` and `b(1,1)`.
const U_LOWER_MIDPOINTS: BVec4A = BVec4A::new(false, true, false, true);
/// Lanes a split in v replaces in the lower child: `b(0,1)` and `b(1,1)`.
const V_LOWER_MIDPOINTS: BVec4A = BVec4A::new(false, false, true, true);

/// A bilinear control net: `xyz[c]` holds coordinate `c` of the four corners, u fastest.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BilinearNet {
    pub xyz: [Vec4; 3],
}

impl BilinearNet {
    /// The net of a plain bilinear patch, each coordinate rounded once to `f32`; `None` for
    /// any other patch.
    pub fn from_patch(patch: &BezierPatch) -> Option<BilinearNet> {
        if patch.degree_u() != 1 || patch.degree_v() != 1 || patch.is_rational() {
            return None;
        }
        let mut xyz = [Vec4::ZERO; 3];
        for (k, p) in patch.euclidean_points().enumerate() {
            for (c, v) in p.as_vec3().to_array().into_iter().enumerate() {
                xyz[c][k] = v;
            }
        }
        Some(BilinearNet { xyz })
    }
}

impl LaneNet for BilinearNet {
    #[inline(always)]
    fn split_in_place(&mut self, dir: Split) -> BilinearNet {
        let half = Vec4::splat(0.5);
        let mut upper = [Vec4::ZERO; 3];
        for (a, up) in self.xyz.iter_mut().zip(upper.iter_mut()) {
            // Each lane's partner across the split: the average lands in both lanes.
            let (partner, lower_mid) = match dir {
                Split::U => (a.yxwz(), U_LOWER_MIDPOINTS),
                Split::V => (a.zwxy(), V_LOWER_MIDPOINTS),
            };
            let mid = (*a + partner) * half;
            *up = Vec4::select(lower_mid, *a, mid);
            *a = Vec4::select(lower_mid, mid, *a);
        }
        BilinearNet { xyz: upper }
    }

    #[inline(always)]
    fn bounds_pair(a: &BilinearNet, b: &BilinearNet) -> [(Vec3A, Vec3A); 2] {
        [a, b].map(|n| {
            let [x, y, z] = n.xyz;
            (reduce3(x, y, z, Vec4::min), reduce3(x, y, z, Vec4::max))
        })
    }

    #[inline(always)]
    fn corners(&self) -> Corners<f32> {
        let [x, y, z] = self.xyz;
        Corners {
            p00: [x.x, y.x, z.x],
            pn0: [x.y, y.y, z.y],
            p0m: [x.z, y.z, z.z],
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::Ray;
    use crate::kernel::KernelStats;
    use crate::kernel::subdivision::prepared::Prepared;
    use crate::kernel::subdivision::{PreparedPatch, SubdivisionConfig, intersect, occluded};
    use glam::{DVec3, Vec3};

    /// A twisted (non-planar) bilinear patch with unequal edges, so both split directions
    /// and both heuristics' choices occur.
    fn patch() -> BezierPatch {
        let pts = [
            DVec3::new(-3.0, -0.5, -2.0),
            DVec3::new(4.0, 0.7, -2.5),
            DVec3::new(-2.5, 0.3, 3.0),
            DVec3::new(3.5, -0.9, 2.0),
        ];
        BezierPatch::from_points(1, 1, &pts).unwrap()
    }

    /// xorshift32 mapped to [0, 1): deterministic rays without a dependency.
    fn uniform(state: &mut u32) -> f32 {
        *state ^= *state << 13;
        *state ^= *state >> 17;
        *state ^= *state << 5;
        (*state >> 8) as f32 / (1u32 << 24) as f32
    }

    #[test]
    fn split_matches_general_split_bit_for_bit() {
        let p = patch();
        let net = BilinearNet::from_patch(&p).unwrap();
        let shape = crate::kernel::subdivision::general::NetShape {
            nu: 2,
            nv: 2,
            rational: false,
        };
        for dir in [Split::U, Split::V] {
            let mut lower = net;
            let upper = lower.split_in_place(dir);
            let mut g_lower: Vec<[f32; 4]> = p
                .homogeneous_points()
                .iter()
                .map(|q| q.as_vec4().to_array())
                .collect();
            let mut g_upper = vec![[0.0f32; 4]; 4];
            crate::kernel::subdivision::general::split_net(&mut g_lower, &mut g_upper, shape, dir);
            for (ours, theirs) in [(lower, &g_lower), (upper, &g_upper)] {
                for (k, q) in theirs.iter().enumerate() {
                    assert_eq!([ours.xyz[0][k], ours.xyz[1][k], ours.xyz[2][k]], q[..3]);
                }
            }
        }
    }

    #[test]
    fn hits_match_the_general_path_on_random_rays() {
        let p = patch();
        let fast = PreparedPatch::bilinear(&p).expect("a bilinear patch");
        assert!(matches!(fast.data, Prepared::Bilinear(_)));
        let general = PreparedPatch::general(&p);
        let cfg = SubdivisionConfig::default();
        let mut state = 0x9e37_79b9;
        let (mut hits, mut misses) = (0, 0);
        for _ in 0..400 {
            let mut r = || uniform(&mut state);
            // From above the patch towards a point of the parameter square slightly
            // enlarged, so that rays near and beyond the edges miss.
            let (u, v) = (1.2 * r() - 0.1, 1.2 * r() - 0.1);
            let target = p.eval(u as f64, v as f64).as_vec3();
            let origin = Vec3::new(8.0 * r() - 4.0, 6.0 + 4.0 * r(), 8.0 * r() - 4.0);
            let ray = Ray::new(origin, target - origin);
            let mut stats = KernelStats::default();
            let a = intersect(&fast, None, &ray, &cfg, &mut stats);
            let b = intersect(&general, None, &ray, &cfg, &mut stats);
            assert_eq!(a, b, "ray {ray:?}");
            assert_eq!(
                occluded(&fast, None, &ray, &cfg, &mut stats),
                occluded(&general, None, &ray, &cfg, &mut stats)
            );
            if let Some(h) = a {
                // The final box contains the point of the surface the ray was aimed at
                // whenever that point is the hit (the patch is hit at most once from
                // above, so that is when its parameters lie in the square).
                let inside = (0.0..=1.0).contains(&u) && (0.0..=1.0).contains(&v);
                if inside {
                    // Up to the net's f32 rounding, which the end game leaves in the box's
                    // size class: `end_ulps` ulps of the patch's coordinate scale (4).
                    let b = h.hit_box;
                    let ext = (b.max - b.min).max_element()
                        + (cfg.end_ulps as f64 * crate::geom::ulp::ulp_of(4.0)) as f32;
                    assert!(
                        (target - b.min).min_element() >= -ext
                            && (b.max - target).min_element() >= -ext,
                        "{target:?} outside {b:?}"
                    );
                }
                hits += 1;
            } else {
                misses += 1;
            }
        }
        assert!(hits > 100 && misses > 10, "{hits} hits, {misses} misses");
    }
}
