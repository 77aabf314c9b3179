//! The bicubic fast path on AVX-512: the whole 4×4 net in four 16-lane registers, one per
//! row, each holding the row's x, y and z coordinates in its first three 128-bit quarters
//! (the fourth is zero padding). Compared with [`super::bicubic`]'s one SSE register per
//! coordinate row, every step works on all three coordinates at once:
//!
//! - a split across the registers is de Casteljau on four registers (Dammertz code 2.3.6),
//!   six additions and six multiplications for both children;
//! - a split along the rows first transposes the four 4×4 blocks in one 8-shuffle 4×4
//!   transpose (the shuffles work within 128-bit quarters) and leaves the children
//!   transposed, as the SSE net does;
//! - both children's boxes are two lane-wise reductions over their rows and one shared
//!   butterfly within the quarters;
//! - both slab tests run in one register (both children, both bounds, three axes), with
//!   exactly the operations of [`crate::geom::bbox::slab`], so hits are bit-identical to
//!   the SSE path's.
//!
//! The arithmetic of the split is the same sequence of roundings as
//! `geom::bezier::split_curve_half`, so neighbouring patches' shared edges stay
//! bit-identical whichever path splits them (Dammertz §2.3.3).

use std::arch::x86_64::*;

use super::bicubic::Net;
use super::config::SubdivisionConfig;
use super::float::{GBox, GRay};
use super::heuristics::Corners;
use super::param::Split;
use super::register::{ChildTests, RegisterNet, RegisterStack};
use super::search::{Node, SearchHit, search};
use crate::geom::bbox::SLAB_FAR_SCALE;
use crate::kernel::KernelStats;

/// Whether this CPU runs the AVX-512 path (detected once and cached by the standard
/// library).
#[inline(always)]
pub fn available() -> bool {
    is_x86_feature_detected!("avx512f")
}

/// A bicubic net, one row of points per register (see the module documentation).
#[derive(Clone, Copy, Debug)]
pub struct Net16 {
    /// Register `r` holds row `r` (points (0..4, r)) or, transposed, column `r`.
    regs: [__m512; 4],
    transposed: bool,
}

/// Lane masks of the padding lanes (lane 3 of every quarter, after regrouping by bound)
/// and of the upper two quarters.
const PAD_LANES: __mmask16 = 0x8888;
const UPPER_HALF: __mmask16 = 0xFF00;

/// The ray as the slab test needs it: origin and reciprocal direction repeated in every
/// quarter (x, y, z, 0), and `tmin`.
#[derive(Clone, Copy, Debug)]
pub struct Ray16 {
    origin: __m512,
    inv_dir: __m512,
    tmin: f32,
}

impl Net16 {
    /// The SSE net's points, re-laid out.
    #[target_feature(enable = "avx512f")]
    fn from_net(net: &Net) -> Net16 {
        let mut rows = [[0f32; 16]; 4];
        for (r, row) in rows.iter_mut().enumerate() {
            for c in 0..3 {
                row[4 * c..4 * c + 4].copy_from_slice(&net.xyz[c][r].to_array());
            }
        }
        Net16 {
            // SAFETY: each row is 16 f32s, read unaligned.
            regs: rows.map(|r| unsafe { _mm512_loadu_ps(r.as_ptr()) }),
            transposed: net.transposed,
        }
    }

    fn lanes(v: __m512) -> [f32; 16] {
        // SAFETY: __m512 and [f32; 16] have the same size, and every bit pattern is an f32.
        unsafe { std::mem::transmute(v) }
    }
}

/// Transposes the four 4×4 blocks (one per quarter) of four registers: the SSE 4×4
/// transpose, which AVX-512 applies to every 128-bit quarter at once.
#[target_feature(enable = "avx512f")]
#[inline]
fn transpose(r: [__m512; 4]) -> [__m512; 4] {
    let t0 = _mm512_unpacklo_ps(r[0], r[1]);
    let t1 = _mm512_unpacklo_ps(r[2], r[3]);
    let t2 = _mm512_unpackhi_ps(r[0], r[1]);
    let t3 = _mm512_unpackhi_ps(r[2], r[3]);
    [
        _mm512_shuffle_ps::<0x44>(t0, t1),
        _mm512_shuffle_ps::<0xEE>(t0, t1),
        _mm512_shuffle_ps::<0x44>(t2, t3),
        _mm512_shuffle_ps::<0xEE>(t2, t3),
    ]
}

/// De Casteljau at 1/2 across four registers, in the order of `split_curve_half`.
#[target_feature(enable = "avx512f")]
#[inline]
fn split4(r: [__m512; 4]) -> ([__m512; 4], [__m512; 4]) {
    let h = _mm512_set1_ps(0.5);
    let avg = |a, b| _mm512_mul_ps(_mm512_add_ps(a, b), h);
    let a01 = avg(r[0], r[1]);
    let a12 = avg(r[1], r[2]);
    let a23 = avg(r[2], r[3]);
    let b0 = avg(a01, a12);
    let b1 = avg(a12, a23);
    let c = avg(b0, b1);
    ([r[0], a01, b0, c], [c, b1, a23, r[3]])
}

/// Both nets' boxes: in quarter `c` (coordinate c), lanes `[lower min, upper min, lower
/// max, upper max]`.
#[target_feature(enable = "avx512f")]
#[inline]
fn boxes(lo: &[__m512; 4], hi: &[__m512; 4]) -> __m512 {
    let min4 =
        |r: &[__m512; 4]| _mm512_min_ps(_mm512_min_ps(r[0], r[1]), _mm512_min_ps(r[2], r[3]));
    let max4 =
        |r: &[__m512; 4]| _mm512_max_ps(_mm512_max_ps(r[0], r[1]), _mm512_max_ps(r[2], r[3]));
    let (lo_min, hi_min, lo_max, hi_max) = (min4(lo), min4(hi), max4(lo), max4(hi));
    // Butterfly within the quarters, both nets together: [l0,l1,h0,h1] against
    // [l2,l3,h2,h3], then against the neighbouring lane.
    let r = _mm512_min_ps(
        _mm512_shuffle_ps::<0x44>(lo_min, hi_min),
        _mm512_shuffle_ps::<0xEE>(lo_min, hi_min),
    );
    let mins = _mm512_min_ps(r, _mm512_shuffle_ps::<0xB1>(r, r));
    let r = _mm512_max_ps(
        _mm512_shuffle_ps::<0x44>(lo_max, hi_max),
        _mm512_shuffle_ps::<0xEE>(lo_max, hi_max),
    );
    let maxs = _mm512_max_ps(r, _mm512_shuffle_ps::<0xB1>(r, r));
    _mm512_shuffle_ps::<0x88>(mins, maxs)
}

/// The slab test of [`crate::geom::bbox::slab`] for both boxes of `b` (the layout of
/// [`boxes`]): the entry parameters `[lower, upper]` where the ray hits, and the boxes.
#[target_feature(enable = "avx512f")]
#[inline]
fn slab_pair(b: __m512, ray: &Ray16, tmax: f32) -> ChildTests {
    // Regroup to quarters [lower min, upper min, lower max, upper max], lanes x, y, z, 0.
    let by_bound = _mm512_permutexvar_ps(
        _mm512_setr_epi32(0, 4, 8, 12, 1, 5, 9, 13, 2, 6, 10, 14, 3, 7, 11, 15),
        b,
    );
    let t = _mm512_mul_ps(_mm512_sub_ps(by_bound, ray.origin), ray.inv_dir);
    // Each min against its max: quarters swapped pairwise.
    let other = _mm512_shuffle_f32x4::<0x4E>(t, t);
    let nan = _mm512_cmp_ps_mask::<_CMP_UNORD_Q>(t, other);
    let near = _mm512_mask_blend_ps(
        nan | PAD_LANES,
        _mm512_min_ps(t, other),
        _mm512_set1_ps(f32::NEG_INFINITY),
    );
    let far = _mm512_mask_blend_ps(
        nan | PAD_LANES,
        _mm512_mul_ps(_mm512_max_ps(t, other), _mm512_set1_ps(SLAB_FAR_SCALE)),
        _mm512_set1_ps(f32::INFINITY),
    );
    // Entries in the lower quarters, negated exits in the upper ones: one maximum
    // reduction within the quarters serves both.
    let neg_far = _mm512_sub_ps(_mm512_setzero_ps(), far);
    let m = _mm512_mask_blend_ps(UPPER_HALF, near, neg_far);
    let m = _mm512_max_ps(m, _mm512_shuffle_ps::<0xB1>(m, m));
    let m = _mm512_max_ps(m, _mm512_shuffle_ps::<0x4E>(m, m));
    let l = Net16::lanes(m);
    let bounds = Net16::lanes(by_bound);
    std::array::from_fn(|k| {
        let enter = l[4 * k].max(ray.tmin);
        let exit = (-l[8 + 4 * k]).min(tmax);
        let gbox = GBox {
            min: [bounds[4 * k], bounds[4 * k + 1], bounds[4 * k + 2]],
            max: [bounds[8 + 4 * k], bounds[9 + 4 * k], bounds[10 + 4 * k]],
        };
        (gbox, (enter <= exit).then_some(enter))
    })
}

impl RegisterNet for Net16 {
    type RayRegisters = Ray16;

    #[inline(always)]
    fn ray_registers(ray: &GRay<f32>) -> Ray16 {
        let quarters = |v: [f32; 3]| {
            let mut l = [0f32; 16];
            for q in 0..4 {
                l[4 * q..4 * q + 3].copy_from_slice(&v);
            }
            // SAFETY: 16 f32s, read unaligned; AVX-512 is available wherever a Net16
            // exists (it is only built by `search`, behind `available`).
            unsafe { _mm512_loadu_ps(l.as_ptr()) }
        };
        Ray16 {
            origin: quarters(ray.origin),
            inv_dir: quarters(ray.inv_dir),
            tmin: ray.tmin,
        }
    }

    #[inline(always)]
    fn split_test(&mut self, dir: Split, ray: &Ray16, tmax: f32) -> (Net16, ChildTests) {
        // The registers run across the split direction: split them as they are.
        // Otherwise transpose first, which leaves both children transposed.
        let across_registers = (dir == Split::V) != self.transposed;
        // SAFETY: a Net16 exists only where AVX-512 is available (see `ray_registers`).
        unsafe {
            let regs = if across_registers {
                self.regs
            } else {
                self.transposed = !self.transposed;
                transpose(self.regs)
            };
            let (lo, hi) = split4(regs);
            self.regs = lo;
            let tests = slab_pair(boxes(&lo, &hi), ray, tmax);
            (
                Net16 {
                    regs: hi,
                    transposed: self.transposed,
                },
                tests,
            )
        }
    }

    #[inline(always)]
    fn corners(&self) -> Corners<f32> {
        let first = Net16::lanes(self.regs[0]);
        let last = Net16::lanes(self.regs[3]);
        let point = |l: &[f32; 16], i: usize| [l[i], l[4 + i], l[8 + i]];
        // Points (0,0), (3,0) and (0,3): lane 3 of register 0 and lane 0 of register 3
        // swap roles in a transposed net.
        let (pn0, p0m) = if self.transposed {
            (point(&last, 0), point(&first, 3))
        } else {
            (point(&first, 3), point(&last, 0))
        };
        Corners {
            p00: point(&first, 0),
            pn0,
            p0m,
        }
    }
}

/// The search of [`super::search`] on the AVX-512 net.
///
/// # Panics
/// Never on a CPU where [`available`] is true; callers check it first.
#[allow(clippy::too_many_arguments)]
pub fn search_net16(
    net: &Net,
    slots: &mut Vec<Net16>,
    nodes: &mut Vec<Node<f32>>,
    root: GBox<f32>,
    ray: &GRay<f32>,
    cfg: &SubdivisionConfig,
    any_hit: bool,
    stats: &mut KernelStats,
) -> Option<SearchHit<f32>> {
    assert!(available(), "the AVX-512 kernel path needs AVX-512F");
    // SAFETY: the CPU has AVX-512F (asserted above).
    unsafe { search_avx512(net, slots, nodes, root, ray, cfg, any_hit, stats) }
}

#[allow(clippy::too_many_arguments)]
#[target_feature(enable = "avx512f")]
fn search_avx512(
    net: &Net,
    slots: &mut Vec<Net16>,
    nodes: &mut Vec<Node<f32>>,
    root: GBox<f32>,
    ray: &GRay<f32>,
    cfg: &SubdivisionConfig,
    any_hit: bool,
    stats: &mut KernelStats,
) -> Option<SearchHit<f32>> {
    let mut nets = RegisterStack::new(Net16::from_net(net), ray, slots);
    search(&mut nets, nodes, root, ray, false, cfg, any_hit, stats)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::BezierPatch;
    use crate::kernel::subdivision::register::search_register;
    use glam::DVec3;

    /// A curved bicubic patch with unequal edges, so both split directions (and so both
    /// orientations of the registers) occur.
    fn patch() -> BezierPatch {
        let pts: Vec<DVec3> = (0..16)
            .map(|k| {
                let (i, j) = ((k % 4) as f64, (k / 4) as f64);
                DVec3::new(
                    1.6 * i + 0.3 * (j * 1.7).sin(),
                    j * 1.1 - 0.2 * i * i,
                    (i * 0.9 - j).cos(),
                )
            })
            .collect();
        BezierPatch::from_points(3, 3, &pts).unwrap()
    }

    /// The AVX-512 net must give exactly the SSE net's search (the same splits, the same
    /// boxes, the same hits): both are the same arithmetic in another register layout.
    #[test]
    fn avx512_search_is_bit_identical_to_the_sse_search() {
        if !available() {
            eprintln!("skipped: this CPU has no AVX-512F");
            return;
        }
        let net = Net::from_patch(&patch());
        let root = GBox {
            min: [-1.0, -2.5, -1.5],
            max: [5.5, 3.5, 1.5],
        };
        let cfg = SubdivisionConfig::default();
        let mut state = 0x2545_f491u32;
        let mut uniform = || {
            state ^= state << 13;
            state ^= state >> 17;
            state ^= state << 5;
            (state >> 8) as f32 / (1u32 << 24) as f32
        };
        let (mut hits, mut slots16, mut slots, mut nodes) = (0, Vec::new(), Vec::new(), Vec::new());
        for _ in 0..2000 {
            let target = [6.0 * uniform() - 0.5, 5.0 * uniform() - 2.0, 0.0];
            let origin = [
                8.0 * uniform() - 4.0,
                8.0 * uniform() - 4.0,
                6.0 + 4.0 * uniform(),
            ];
            let dir = [0, 1, 2].map(|c| target[c] - origin[c]);
            for any_hit in [false, true] {
                let ray = GRay::new(origin, dir, 0.0, f32::INFINITY);
                let (mut s16, mut s) = (KernelStats::default(), KernelStats::default());
                let a = search_net16(
                    &net,
                    &mut slots16,
                    &mut nodes,
                    root,
                    &ray,
                    &cfg,
                    any_hit,
                    &mut s16,
                );
                let b = search_register(
                    net, &mut slots, &mut nodes, root, &ray, &cfg, any_hit, &mut s,
                );
                assert_eq!(
                    a.map(|h| (h.t, h.cell, h.bbox)),
                    b.map(|h| (h.t, h.cell, h.bbox))
                );
                assert_eq!((s16.splits, s16.box_tests), (s.splits, s.box_tests));
                hits += a.is_some() as usize;
            }
        }
        // Most rays aim at the patch's parameter-space footprint: the test must see hits.
        assert!(hits > 1000, "{hits} hits");
    }
}
