//! The bicubic non-rational fast path (Dammertz §2.3.3, §2.7.1: "extra optimized code for
//! the most frequently used degrees"). The net is structure-of-arrays: per coordinate a
//! 4×4 block of `f32` whose rows (fixed v, u = 0..3) are one SSE register each (glam's
//! `Vec4` is `__m128` on x86_64 with SSE2). A split in v is de Casteljau across the four
//! rows, 4 lanes at a time (Dammertz code 2.3.6 does the same on AoS points). A split
//! along the rows instead transposes each block once and leaves the children transposed
//! (the net records its orientation), so alternating split directions cost one transpose
//! per split rather than three. The box is a lane-wise min/max over the rows followed by
//! one transposed horizontal reduction for all three coordinates
//! ([`super::register::reduce3`]); it does not depend on the orientation.

use glam::{DVec3, Mat4, Vec3A, Vec4};

use super::heuristics::Corners;
use super::param::Split;
use super::register::{LaneNet, reduce3};
use crate::geom::BezierPatch;

/// One coordinate of the net: `rows[j]` holds the points (0..4, j), or when the net is
/// transposed `rows[i]` holds the points (i, 0..4).
type Block = [Vec4; 4];

/// A bicubic control net in structure-of-arrays form.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Net {
    pub xyz: [Block; 3],
    /// Whether the registers hold columns (fixed u) rather than rows (fixed v).
    pub transposed: bool,
}

/// De Casteljau at 1/2 across four registers: the same operations in the same order as
/// `geom::bezier::split_curve_half`, so the shared middle row is bit-identical in both
/// children.
#[inline(always)]
fn split4(r: Block) -> (Block, Block) {
    let h = Vec4::splat(0.5);
    let a01 = (r[0] + r[1]) * h;
    let a12 = (r[1] + r[2]) * h;
    let a23 = (r[2] + r[3]) * h;
    let b0 = (a01 + a12) * h;
    let b1 = (a12 + a23) * h;
    let c = (b0 + b1) * h;
    ([r[0], a01, b0, c], [c, b1, a23, r[3]])
}

#[inline(always)]
fn transpose(b: Block) -> Block {
    let m = Mat4::from_cols(b[0], b[1], b[2], b[3]).transpose();
    [m.x_axis, m.y_axis, m.z_axis, m.w_axis]
}

/// Lane-wise minimum and maximum over the four registers of a block.
#[inline(always)]
fn block_range(b: &Block) -> (Vec4, Vec4) {
    let lo = b[0].min(b[1]).min(b[2].min(b[3]));
    let hi = b[0].max(b[1]).max(b[2].max(b[3]));
    (lo, hi)
}

impl Net {
    /// The net of a plain bicubic patch, each coordinate rounded once to `f32`.
    pub fn from_patch(patch: &BezierPatch) -> Net {
        let mut xyz = [[Vec4::ZERO; 4]; 3];
        for (k, p) in patch.euclidean_points().enumerate() {
            let (i, j) = (k % 4, k / 4);
            for (c, v) in p.as_vec3().to_array().into_iter().enumerate() {
                xyz[c][j][i] = v;
            }
        }
        Net {
            xyz,
            transposed: false,
        }
    }

    /// A bilinear integral patch degree-elevated to bicubic (Farin, *Curves and Surfaces
    /// for CAGD*, §5.1: the control points at 1/3 and 2/3 of each edge and the tensor
    /// product inside), so that it takes the AVX-512 path's ray space and Newton jumps: a
    /// flat patch is exactly linear there and a jump lands next to its crossing, where
    /// the bilinear search spent ~44 splits a hit on the teapot's 40-unit floor. Elevation
    /// keeps the parameterisation, so (u, v) and the normal are those of the patch.
    ///
    /// Computed in `f64` and rounded once. Crack freedom (Dammertz §2.3.3): an edge's
    /// points come from that edge's two corners alone, `((3 - i) a + i b) / 3` for
    /// `i = 1, 2` and the corners themselves at the ends, and addition commutes, so a
    /// neighbour that runs the shared edge the other way (`i` and `3 - i` swapped) gets
    /// the same bits. `None` unless the patch is bilinear and integral.
    pub fn elevated_bilinear(patch: &BezierPatch) -> Option<Net> {
        if patch.degree_u() != 1 || patch.degree_v() != 1 || patch.is_rational() {
            return None;
        }
        let c: Vec<DVec3> = patch.euclidean_points().collect();
        // Degree elevation of the segment a..b, point `i` of 4.
        let third = |a: DVec3, b: DVec3, i: usize| match i {
            0 => a,
            3 => b,
            _ => ((3 - i) as f64 * a + i as f64 * b) / 3.0,
        };
        let mut xyz = [[Vec4::ZERO; 4]; 3];
        for i in 0..4 {
            // Corner k = 2 j + i' of the bilinear net: u index i' fastest.
            let (low, high) = (third(c[0], c[1], i), third(c[2], c[3], i));
            for j in 0..4 {
                let p = third(low, high, j).as_vec3().to_array();
                for (coordinate, v) in xyz.iter_mut().zip(p) {
                    coordinate[j][i] = v;
                }
            }
        }
        Some(Net {
            xyz,
            transposed: false,
        })
    }

    /// Point (i, j) of the net.
    pub fn point(&self, i: usize, j: usize) -> [f32; 3] {
        let (r, l) = if self.transposed { (i, j) } else { (j, i) };
        [self.xyz[0][r][l], self.xyz[1][r][l], self.xyz[2][r][l]]
    }
}

impl LaneNet for Net {
    #[inline(always)]
    fn bounds_pair(a: &Net, b: &Net) -> [(Vec3A, Vec3A); 2] {
        [a, b].map(|n| {
            let [(x0, x1), (y0, y1), (z0, z1)] = n.xyz.each_ref().map(block_range);
            (
                reduce3(x0, y0, z0, Vec4::min),
                reduce3(x1, y1, z1, Vec4::max),
            )
        })
    }

    #[inline(always)]
    fn split_in_place(&mut self, dir: Split) -> Net {
        // The registers run across the split direction: split them as they are.
        // Otherwise transpose first, which leaves both children transposed.
        let across_registers = (dir == Split::V) != self.transposed;
        if !across_registers {
            self.transposed = !self.transposed;
        }
        let mut upper = [[Vec4::ZERO; 4]; 3];
        for (b, up) in self.xyz.iter_mut().zip(upper.iter_mut()) {
            let rows = if across_registers { *b } else { transpose(*b) };
            (*b, *up) = split4(rows);
        }
        Net {
            xyz: upper,
            transposed: self.transposed,
        }
    }

    #[inline(always)]
    fn corners(&self) -> Corners<f32> {
        let [x, y, z] = &self.xyz;
        // Points (0,0), (3,0) and (0,3): lane 3 of register 0 and lane 0 of register 3
        // swap roles in a transposed net.
        let first_lane_end = [x[0].w, y[0].w, z[0].w];
        let last_register = [x[3].x, y[3].x, z[3].x];
        let (pn0, p0m) = if self.transposed {
            (last_register, first_lane_end)
        } else {
            (first_lane_end, last_register)
        };
        Corners {
            p00: [x[0].x, y[0].x, z[0].x],
            pn0,
            p0m,
        }
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// A curved bicubic patch with unequal edges, so both split directions (and so both
    /// orientations of the registers) occur.
    pub(crate) fn patch() -> BezierPatch {
        let pts: Vec<DVec3> = (0..16)
            .map(|k| {
                let (i, j) = ((k % 4) as f64, (k / 4) as f64);
                DVec3::new(
                    i + 0.3 * (j * 1.7).sin(),
                    j * 1.1 - 0.1 * i * i,
                    (i * 0.9 - j).cos(),
                )
            })
            .collect();
        BezierPatch::from_points(3, 3, &pts).unwrap()
    }

    /// The elevated net is the bilinear surface: evaluated by its Bernstein form in `f64`
    /// at random (u, v) it agrees with the bilinear interpolation of the corners up to the
    /// `f32` rounding of its points; and a neighbour running a shared edge the other way
    /// gets the same edge points bit for bit.
    #[test]
    fn elevated_bilinear_net_is_the_bilinear_surface_with_symmetric_edges() {
        let corners = [
            DVec3::new(-20.0, -20.0, 0.1),
            DVec3::new(20.0, -19.0, 0.7),
            DVec3::new(-21.0, 20.0, -0.3),
            DVec3::new(20.0, 20.0, 1.0 / 3.0),
        ];
        let bilinear = |c: [DVec3; 4]| BezierPatch::from_points(1, 1, &c).unwrap();
        let net = Net::elevated_bilinear(&bilinear(corners)).expect("bilinear");
        let bernstein = |t: f64| {
            let s = 1.0 - t;
            [s * s * s, 3.0 * t * s * s, 3.0 * t * t * s, t * t * t]
        };
        let mut state = 0x1234_5678u32;
        for _ in 0..200 {
            let mut uniform = || {
                state ^= state << 13;
                state ^= state >> 17;
                state ^= state << 5;
                f64::from(state >> 8) / f64::from(1u32 << 24)
            };
            let (u, v) = (uniform(), uniform());
            let (bu, bv) = (bernstein(u), bernstein(v));
            let mut got = DVec3::ZERO;
            for j in 0..4 {
                for i in 0..4 {
                    got += bu[i] * bv[j] * DVec3::from_array(net.point(i, j).map(f64::from));
                }
            }
            let want = (1.0 - v) * ((1.0 - u) * corners[0] + u * corners[1])
                + v * ((1.0 - u) * corners[2] + u * corners[3]);
            // Half an f32 ulp of the coordinates (below 32) per point, and convexity.
            assert!((got - want).abs().max_element() <= 32.0 * f64::from(f32::EPSILON));
        }
        // The same patch with u reversed: its edges v = 0 and v = 1 run the other way.
        let [a, b, c, d] = corners;
        let flipped = Net::elevated_bilinear(&bilinear([b, a, d, c])).expect("bilinear");
        for i in 0..4 {
            for j in [0, 3] {
                assert_eq!(net.point(i, j), flipped.point(3 - i, j));
            }
        }
        // And with u and v swapped: its edge u = 0 is the edge v = 0.
        let swapped = Net::elevated_bilinear(&bilinear([a, c, b, d])).expect("bilinear");
        for i in 0..4 {
            assert_eq!(net.point(i, 0), swapped.point(0, i));
        }
        let rational = BezierPatch::new(1, 1, corners.map(|p| p.extend(2.0)).to_vec()).unwrap();
        assert!(Net::elevated_bilinear(&rational).is_none());
    }

    #[test]
    fn in_place_split_matches_bezier_split_within_f32_rounding() {
        let p = patch();
        for (dir, (lo, hi)) in [(Split::U, p.split_u()), (Split::V, p.split_v())] {
            let mut net = Net::from_patch(&p);
            let upper = net.split_in_place(dir);
            for (got, want) in [(net, lo), (upper, hi)] {
                for j in 0..4 {
                    for i in 0..4 {
                        let g = got.point(i, j);
                        let w = want.point(i, j);
                        for c in 0..3 {
                            // ½ ulp input rounding + ½ ulp per de Casteljau level (3).
                            let tol = 2.0 * crate::geom::ulp::ulp_of(w[c].abs().max(4.0) as f32);
                            assert!((g[c] as f64 - w[c]).abs() <= tol, "{g:?} vs {w:?}");
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn transposed_nets_match_bezier_splits() {
        // u twice: the first split leaves the net transposed, the second splits it as it
        // is; points and corners must still be those of the de Casteljau sub-patch.
        let p = patch();
        let want = p.split_u().1.split_u().0;
        let mut net = Net::from_patch(&p);
        let mut upper = net.split_in_place(Split::U);
        assert!(upper.transposed);
        upper.split_in_place(Split::U);
        assert!(upper.transposed);
        for j in 0..4 {
            for i in 0..4 {
                let (g, w) = (upper.point(i, j), want.point(i, j));
                for c in 0..3 {
                    let tol = 4.0 * crate::geom::ulp::ulp_of(w[c].abs().max(4.0) as f32);
                    assert!((g[c] as f64 - w[c]).abs() <= tol, "{g:?} vs {w:?}");
                }
            }
        }
        let c = upper.corners();
        assert_eq!(c.pn0, upper.point(3, 0));
        assert_eq!(c.p0m, upper.point(0, 3));
    }

    #[test]
    fn bounds_are_the_control_box() {
        let p = patch();
        let b = Net::from_patch(&p).bounds().to_aabb();
        let want: crate::geom::Aabb = p.euclidean_points().map(|q| q.as_vec3()).collect();
        assert_eq!(b, want);
    }

    #[test]
    fn shared_edge_is_bit_identical() {
        let mut net = Net::from_patch(&patch());
        let upper = net.split_in_place(Split::U);
        for j in 0..4 {
            assert_eq!(net.point(3, j), upper.point(0, j));
        }
    }
}
