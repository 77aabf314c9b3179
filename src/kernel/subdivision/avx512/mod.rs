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
//!   the SSE path's;
//! - for primary rays the net is first moved into ray space ([`super::ray_space`]), where
//!   both children's box tests are one comparison of the register against the ray's
//!   bounds (exact, no rounding).
//!
//! The net is re-laid out from the SSE one ([`super::bicubic::Net`], kept per patch) at
//! the start of each search: a dozen loads against the ~55 splits of a search.
//!
//! The arithmetic of the split is the same sequence of roundings as
//! `geom::bezier::split_curve_half`, so neighbouring patches' shared edges stay
//! bit-identical whichever path splits them (Dammertz §2.3.3).

use std::arch::x86_64::*;

use super::bicubic::Net;
use super::float::{GBox, GRay, KernelFloat};
use super::heuristics::Corners;
use super::jump::{Jump, JumpOutcome, Linearization, plan, restriction};
use super::param::{ParamCell, Split};
use super::ray_space::{MIN_RAY_SPACE_SCALE, RayFrame, SpacedHit};
use super::register::{ChildTests, Query, RegisterNet, RegisterStack, Scratch};
use super::search::{end_game_diameter, search};
use crate::geom::bbox::SLAB_FAR_SCALE;
use crate::kernel::KernelStats;

/// Whether this CPU runs the AVX-512 path: it has AVX-512F, and the environment does not
/// set `PATCHTRACE_NO_AVX512` (to anything but `0`), which makes an AVX-512 machine
/// render, trace and test as one without it does (the portable world-space search and
/// bilinear patches as such), to check or measure that path. Decided once per process.
#[inline(always)]
pub fn available() -> bool {
    static AVAILABLE: std::sync::OnceLock<bool> = std::sync::OnceLock::new();
    *AVAILABLE.get_or_init(|| {
        let refused = std::env::var_os("PATCHTRACE_NO_AVX512").is_some_and(|v| v != "0");
        is_x86_feature_detected!("avx512f") && !refused
    })
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

/// The ray as the box tests need it.
#[derive(Clone, Copy, Debug)]
pub enum Ray16 {
    /// World space: the slab test, with origin and reciprocal direction repeated in every
    /// quarter (x, y, z, 0).
    Slab {
        origin: __m512,
        inv_dir: __m512,
        tmin: f32,
    },
    /// Ray space ([`super::ray_space`]), the ray the z-axis: a box is hit when its x and
    /// y ranges hold 0 and its z range meets `[tmin, tmax]`. `bounds` is what the boxes
    /// of [`slab_pair`]'s regrouped layout, maxima negated, must not exceed: x, y 0, z
    /// `tmax` (filled in per test) for the minima, `-tmin` for the negated maxima.
    Axis { bounds: __m512, tmin: f32 },
}

/// Lanes of the minima's z, where [`Ray16::Axis`] takes `tmax`.
const MIN_Z: __mmask16 = 0x0044;

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

    /// The net with every point in the ray space of `frame`: `(p - o)` and then the three
    /// axes' dot products, the same operations for every point, so shared edge points
    /// stay bit-identical (see [`super::ray_space`]).
    #[target_feature(enable = "avx512f")]
    fn in_ray_space(&self, frame: &RayFrame) -> Net16 {
        // Quarter r of the result holds v[r] in every lane (coordinate r of four points).
        let per_quarter = |v: [f32; 3]| {
            _mm512_setr_ps(
                v[0], v[0], v[0], v[0], v[1], v[1], v[1], v[1], v[2], v[2], v[2], v[2], 0.0, 0.0,
                0.0, 0.0,
            )
        };
        let origin = per_quarter(frame.origin);
        let a = frame.axes;
        let (ax, ay, az) = (
            per_quarter([a[0][0], a[1][0], a[2][0]]),
            per_quarter([a[0][1], a[1][1], a[2][1]]),
            per_quarter([a[0][2], a[1][2], a[2][2]]),
        );
        let regs = self.regs.map(|r| {
            let d = _mm512_sub_ps(r, origin);
            let x = _mm512_shuffle_f32x4::<0x00>(d, d);
            let y = _mm512_shuffle_f32x4::<0x55>(d, d);
            let z = _mm512_shuffle_f32x4::<0xAA>(d, d);
            _mm512_add_ps(
                _mm512_add_ps(_mm512_mul_ps(ax, x), _mm512_mul_ps(ay, y)),
                _mm512_mul_ps(az, z),
            )
        });
        Net16 { regs, ..*self }
    }

    /// The control box of the net.
    #[target_feature(enable = "avx512f")]
    fn bounds(&self) -> GBox<f32> {
        child_boxes(by_bound(boxes(&self.regs, &self.regs)))[0]
    }

    /// The net's [`Linearization`] (its definition is [`super::jump::linearize`]), from the
    /// registers: register r holds row r (v = r) or, transposed, column r (u = r), so the
    /// differences across registers are one parameter's derivative net and those across
    /// the lanes of a quarter the other's. The means telescope to the end rows' sums.
    #[target_feature(enable = "avx512f")]
    fn linearization(&self) -> Linearization {
        let r = self.regs;
        let (add, sub, mul) = (_mm512_add_ps, _mm512_sub_ps, _mm512_mul_ps);
        let splat = _mm512_set1_ps;
        // Sums and maxima within each quarter, left in every lane of it.
        let hsum = |v| {
            let v = add(v, _mm512_shuffle_ps::<0xB1>(v, v));
            add(v, _mm512_shuffle_ps::<0x4E>(v, v))
        };
        let hmax = |v| {
            let v = _mm512_max_ps(v, _mm512_shuffle_ps::<0xB1>(v, v));
            _mm512_max_ps(v, _mm512_shuffle_ps::<0x4E>(v, v))
        };
        let abs = |v| _mm512_abs_ps(v);
        // Bernstein weights of degree 3 at 1/2, times 8, along the lanes.
        let half = _mm512_setr_ps(
            1.0, 3.0, 3.0, 1.0, 1.0, 3.0, 3.0, 1.0, 1.0, 3.0, 3.0, 1.0, 1.0, 3.0, 3.0, 1.0,
        );
        let rows = add(add(r[0], r[3]), mul(splat(3.0), add(r[1], r[2])));
        let centre = mul(hsum(mul(rows, half)), splat(1.0 / 64.0));
        let magnitude = hmax(_mm512_max_ps(
            _mm512_max_ps(abs(r[0]), abs(r[1])),
            _mm512_max_ps(abs(r[2]), abs(r[3])),
        ));
        // Across the registers: 3 (r[k+1] - r[k]), mean 3 Σ (r[3] - r[0]) / 12.
        let across: [__m512; 3] = std::array::from_fn(|k| mul(splat(3.0), sub(r[k + 1], r[k])));
        let across_mean = mul(hsum(sub(r[3], r[0])), splat(0.25));
        let across_dev = hmax(_mm512_max_ps(
            _mm512_max_ps(
                abs(sub(across[0], across_mean)),
                abs(sub(across[1], across_mean)),
            ),
            abs(sub(across[2], across_mean)),
        ));
        // Along the lanes: 3 (p[i+1] - p[i]) in lanes 0..3 of each quarter, lane 3 unused.
        let next = |v| _mm512_shuffle_ps::<0xF9>(v, v);
        let along: [__m512; 4] = std::array::from_fn(|k| mul(splat(3.0), sub(next(r[k]), r[k])));
        let ends = |v| {
            sub(
                _mm512_shuffle_ps::<0xFF>(v, v),
                _mm512_shuffle_ps::<0x00>(v, v),
            )
        };
        let along_mean = mul(
            add(add(ends(r[0]), ends(r[1])), add(ends(r[2]), ends(r[3]))),
            splat(0.25),
        );
        let dev = |v| abs(sub(v, along_mean));
        let along_dev = _mm512_max_ps(
            _mm512_max_ps(dev(along[0]), dev(along[1])),
            _mm512_max_ps(dev(along[2]), dev(along[3])),
        );
        // Lane 3 of each quarter is not a difference.
        let along_dev = hmax(_mm512_maskz_mov_ps(0x7777, along_dev));
        let xy = |v| {
            let l = Net16::lanes(v);
            [l[0], l[4]]
        };
        let (across, along) = (
            (xy(across_mean), xy(across_dev)),
            (xy(along_mean), xy(along_dev)),
        );
        // Not transposed, the registers run across v.
        let ((du, du_dev), (dv, dv_dev)) = if self.transposed {
            (across, along)
        } else {
            (along, across)
        };
        let [mx, my] = xy(magnitude);
        Linearization {
            centre: xy(centre),
            magnitude: mx.max(my),
            du,
            dv,
            du_dev,
            dv_dev,
        }
    }

    /// The sub-net of a jump, with no box or test, the direction the registers run across
    /// first, so at most one transpose. Where the window lies inside the cell, one product
    /// with the [`restriction`] matrix per direction; elsewhere the search's own halvings
    /// ([`split4`]) towards the jumped-to cell, each choosing its half by the index bit, so
    /// that the sub-net's border is the one a neighbour made by halving has.
    #[target_feature(enable = "avx512f")]
    fn descend(&self, jump: &Jump) -> Net16 {
        let mut net = *self;
        let first = if self.transposed { Split::U } else { Split::V };
        let second = if first == Split::U {
            Split::V
        } else {
            Split::U
        };
        for dir in [first, second] {
            let d = usize::from(dir == Split::V);
            let levels = jump.levels[d];
            if levels == 0 {
                continue;
            }
            if (dir == Split::V) == net.transposed {
                net.regs = transpose(net.regs);
                net.transposed = !net.transposed;
            }
            if jump.interior {
                let m = restriction(levels, jump.index[d]);
                let r = net.regs;
                net.regs = m.map(|w| {
                    let term = |j: usize| _mm512_mul_ps(_mm512_set1_ps(w[j]), r[j]);
                    _mm512_add_ps(
                        _mm512_add_ps(term(0), term(1)),
                        _mm512_add_ps(term(2), term(3)),
                    )
                });
                continue;
            }
            for level in (0..levels).rev() {
                let (lo, hi) = split4(net.regs);
                // All lanes from the upper half where the index bit is set.
                let upper = 0u16.wrapping_sub(((jump.index[d] >> level) & 1) as u16);
                net.regs = std::array::from_fn(|r| _mm512_mask_blend_ps(upper, lo[r], hi[r]));
            }
        }
        net
    }

    fn lanes(v: __m512) -> [f32; 16] {
        // SAFETY: __m512 and [f32; 16] have the same size, and every bit pattern is an f32.
        unsafe { std::mem::transmute(v) }
    }
}

/// `v` in lanes 0..3 of every quarter, `pad` in lane 3.
#[target_feature(enable = "avx512f")]
#[inline]
fn quarters(v: [f32; 3], pad: f32) -> __m512 {
    let mut l = [pad; 16];
    for q in 0..4 {
        l[4 * q..4 * q + 3].copy_from_slice(&v);
    }
    // SAFETY: 16 f32s, read unaligned.
    unsafe { _mm512_loadu_ps(l.as_ptr()) }
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

/// De Casteljau at 1/2 across four registers, with the roundings of `split_curve_half`.
///
/// Each level of `split_curve_half` is a sum and a halving. Halving is exact in binary
/// floating point, so it commutes with the rounding of the sums: summing level by level
/// and scaling once by 1/2, 1/4 or 1/8 gives the same bits with one multiplication
/// instead of three on the longest chain, which is the latency the search waits for
/// before it can tell which child the ray hits (measured: 4 % of the teapot kernel
/// bench). The exceptions are the ends of the range, where neighbouring patches still
/// agree because they all run this code: sums of subnormal coordinates keep a bit the
/// halvings would round, and coordinates above `f32::MAX / 8` overflow here first.
#[target_feature(enable = "avx512f")]
#[inline]
fn split4(r: [__m512; 4]) -> ([__m512; 4], [__m512; 4]) {
    let sum = |a, b| _mm512_add_ps(a, b);
    let scale = |a, s: f32| _mm512_mul_ps(a, _mm512_set1_ps(s));
    let (s01, s12, s23) = (sum(r[0], r[1]), sum(r[1], r[2]), sum(r[2], r[3]));
    let (s012, s123) = (sum(s01, s12), sum(s12, s23));
    let c = scale(sum(s012, s123), 0.125);
    (
        [r[0], scale(s01, 0.5), scale(s012, 0.25), c],
        [c, scale(s123, 0.25), scale(s23, 0.5), r[3]],
    )
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

/// The boxes of [`boxes`] regrouped to quarters `[lower min, upper min, lower max, upper
/// max]`, lanes x, y, z, 0.
#[target_feature(enable = "avx512f")]
#[inline]
fn by_bound(b: __m512) -> __m512 {
    _mm512_permutexvar_ps(
        _mm512_setr_epi32(0, 4, 8, 12, 1, 5, 9, 13, 2, 6, 10, 14, 3, 7, 11, 15),
        b,
    )
}

/// The two children's boxes from the regrouped layout of [`by_bound`].
fn child_boxes(by_bound: __m512) -> [GBox<f32>; 2] {
    let l = Net16::lanes(by_bound);
    std::array::from_fn(|k| GBox {
        min: [l[4 * k], l[4 * k + 1], l[4 * k + 2]],
        max: [l[8 + 4 * k], l[9 + 4 * k], l[10 + 4 * k]],
    })
}

/// The ray-space test of [`Ray16::Axis`] for both boxes of [`by_bound`]'s layout. Exact:
/// comparisons only, no rounding.
#[target_feature(enable = "avx512f")]
#[inline]
fn axis_pair(by_bound: __m512, bounds: __m512, tmin: f32, tmax: f32) -> ChildTests {
    let negated_max = _mm512_mask_sub_ps(by_bound, UPPER_HALF, _mm512_setzero_ps(), by_bound);
    let bounds = _mm512_mask_blend_ps(MIN_Z, bounds, _mm512_set1_ps(tmax));
    // A child is hit when its six bounds pass: its minima in lanes 0..3 (lower child) or
    // 4..7 (upper), its negated maxima eight lanes higher. The mask is folded in a
    // general-purpose register: tested as a 16-bit vector, the compiler went through
    // memory (a store-forwarding stall that cost a sixth of the search's time), and two
    // masked tests side by side it vectorised into a broadcast-and-compare chain three
    // times as long as the shifts.
    let passed = u32::from(_mm512_cmp_ps_mask::<_CMP_LE_OQ>(negated_max, bounds));
    let passed = passed & (passed >> 8);
    let passed = passed & (passed >> 1) & (passed >> 2);
    let l = Net16::lanes(by_bound);
    let [lower, upper] = child_boxes(by_bound);
    let lower_hit = passed & 0x01 != 0;
    let upper_hit = passed & 0x10 != 0;
    [
        (lower, lower_hit.then(|| l[2].max(tmin))),
        (upper, upper_hit.then(|| l[6].max(tmin))),
    ]
}

/// The slab test of [`crate::geom::bbox::slab`] for both boxes of [`by_bound`]'s layout:
/// the entry parameters `[lower, upper]` where the ray hits, and the boxes.
#[target_feature(enable = "avx512f")]
#[inline]
fn slab_pair(
    by_bound: __m512,
    origin: __m512,
    inv_dir: __m512,
    tmin: f32,
    tmax: f32,
) -> ChildTests {
    let t = _mm512_mul_ps(_mm512_sub_ps(by_bound, origin), inv_dir);
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
    let boxes = child_boxes(by_bound);
    std::array::from_fn(|k| {
        let enter = l[4 * k].max(tmin);
        let exit = (-l[8 + 4 * k]).min(tmax);
        (boxes[k], (enter <= exit).then_some(enter))
    })
}

impl RegisterNet for Net16 {
    type RayRegisters = Ray16;

    #[inline(always)]
    fn ray_registers(ray: &GRay<f32>) -> Ray16 {
        // SAFETY: AVX-512 is available wherever a Net16 exists (one is only built by
        // `search_net16`, behind `available`).
        unsafe {
            Ray16::Slab {
                origin: quarters(ray.origin, 0.0),
                inv_dir: quarters(ray.inv_dir, 0.0),
                tmin: ray.tmin,
            }
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
            let b = by_bound(boxes(&lo, &hi));
            let tests = match *ray {
                Ray16::Slab {
                    origin,
                    inv_dir,
                    tmin,
                } => slab_pair(b, origin, inv_dir, tmin, tmax),
                Ray16::Axis { bounds, tmin } => axis_pair(b, bounds, tmin, tmax),
            };
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
    fn jump(
        &self,
        cell: ParamCell,
        ray: &Ray16,
        tmax: f32,
        near: f32,
    ) -> JumpOutcome<(Net16, ParamCell, GBox<f32>, f32)> {
        let Ray16::Axis { bounds, tmin } = *ray else {
            return JumpOutcome::Undecided;
        };
        let (lu, lv) = cell.levels();
        // SAFETY: a Net16 exists only where AVX-512 is available (see `ray_registers`).
        unsafe {
            let max_levels = [lu, lv].map(|l| f32::MAX_LEVEL - l);
            let (u0, v0, wu, wv) = cell.bounds();
            let borders = [[u0 == 0.0, u0 + wu == 1.0], [v0 == 0.0, v0 + wv == 1.0]];
            plan(&self.linearization(), max_levels, near, borders).and_then(|jump| {
                let net = self.descend(&jump);
                let b = by_bound(boxes(&net.regs, &net.regs));
                match axis_pair(b, bounds, tmin, tmax) {
                    [(bbox, Some(t)), _] => JumpOutcome::Landed((net, jump.cell(cell), bbox, t)),
                    _ if jump.holds_near => JumpOutcome::Empty,
                    // A near miss outside the sub-cell may still end in a final box.
                    _ => JumpOutcome::Undecided,
                }
            })
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

/// The search of [`super::search`] on the AVX-512 net, in the ray space of the query's
/// frame where it has one (the hit's box then stays in ray space, see [`SpacedHit`]).
///
/// # Panics
/// Never on a CPU where [`available`] is true; callers check it first.
pub fn search_net16(
    net: &Net,
    scratch: &mut Scratch<Net16>,
    q: Query,
    stats: &mut KernelStats,
) -> Option<SpacedHit> {
    assert!(available(), "the AVX-512 kernel path needs AVX-512F");
    // SAFETY: the CPU has AVX-512F (asserted above).
    unsafe { search_avx512(net, scratch, q, stats) }
}

#[target_feature(enable = "avx512f")]
fn search_avx512(
    net: &Net,
    (slots, nodes): &mut Scratch<Net16>,
    Query {
        root,
        ray,
        frame,
        cfg,
        any_hit,
        trim,
        trivial,
    }: Query,
    stats: &mut KernelStats,
) -> Option<SpacedHit> {
    let world = Net16::from_net(net);
    if let Some(frame) = frame {
        let local = world.in_ray_space(frame);
        let local_root = local.bounds();
        let scale = (0..3).fold(0f32, |a, i| {
            a.max(-local_root.min[i]).max(local_root.max[i])
        });
        if scale >= MIN_RAY_SPACE_SCALE {
            let axis = frame.axis_ray(ray);
            let (inf, lo) = (f32::INFINITY, -ray.tmin);
            let registers = Ray16::Axis {
                bounds: _mm512_setr_ps(
                    0.0, 0.0, 0.0, inf, 0.0, 0.0, 0.0, inf, 0.0, 0.0, lo, inf, 0.0, 0.0, lo, inf,
                ),
                tmin: ray.tmin,
            };
            let floor = frame.world_length(end_game_diameter(&root, cfg.end_ulps));
            let mut nets = RegisterStack::with_registers(local, registers, floor, slots);
            let hit = search(
                &mut nets, nodes, local_root, &axis, false, cfg, any_hit, trim, trivial, stats,
            )?;
            return Some(SpacedHit {
                hit,
                ray_space_scale: Some(scale),
            });
        }
    }
    let mut nets = RegisterStack::new(world, ray, slots);
    search(
        &mut nets, nodes, root, ray, false, cfg, any_hit, trim, trivial, stats,
    )
    .map(SpacedHit::world)
}

#[cfg(test)]
mod tests;
