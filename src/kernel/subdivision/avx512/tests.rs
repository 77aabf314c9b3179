//! The AVX-512 path against the portable one and the `f64` reference: same hits, in ray
//! space and in world space, and the jumps' landing cells.

use super::*;
use crate::kernel::subdivision::SubdivisionConfig;
use crate::kernel::subdivision::bicubic::tests::patch;
use crate::kernel::subdivision::jump::halve;
use crate::kernel::subdivision::register::{LaneNet, search_register};
use crate::kernel::subdivision::search::SearchHit;

/// Random rays from above aimed at the patch's neighbourhood, by a fixed xorshift32.
fn rays() -> Vec<GRay<f32>> {
    let mut state = 0x2545_f491u32;
    let mut uniform = || {
        state ^= state << 13;
        state ^= state >> 17;
        state ^= state << 5;
        (state >> 8) as f32 / (1u32 << 24) as f32
    };
    (0..2000)
        .map(|_| {
            let target = [4.0 * uniform() - 0.5, 4.5 * uniform() - 1.0, 0.0];
            let origin = [
                8.0 * uniform() - 4.0,
                8.0 * uniform() - 4.0,
                6.0 + 4.0 * uniform(),
            ];
            let dir = [0, 1, 2].map(|c| target[c] - origin[c]);
            GRay::new(origin, dir, 0.0, f32::INFINITY)
        })
        .collect()
}

/// The net, its box and the world-space configuration, or `None` (and a note) on a
/// CPU without AVX-512F, where the path cannot run.
fn setup() -> Option<(Net, GBox<f32>, SubdivisionConfig)> {
    if !available() {
        eprintln!("skipped: this CPU has no AVX-512F");
        return None;
    }
    let net = Net::from_patch(&patch());
    let world = SubdivisionConfig {
        ray_space: false,
        ..SubdivisionConfig::default()
    };
    Some((net, net.bounds(), world))
}

/// In world space the AVX-512 net must give exactly the SSE net's search (the same
/// splits, the same boxes, the same hits): the same arithmetic in another layout.
#[test]
fn world_space_search_is_bit_identical_to_the_sse_search() {
    let Some((net, root, cfg)) = setup() else {
        return;
    };
    let (mut hits, mut scratch16, mut scratch) = (0, Default::default(), Default::default());
    for ray in rays() {
        for any_hit in [false, true] {
            let (mut s16, mut s) = (KernelStats::default(), KernelStats::default());
            let q = Query {
                root,
                ray: &ray,
                frame: None,
                cfg: &cfg,
                any_hit,
                trim: None,
                trivial: None,
            };
            let a = search_net16(&net, &mut scratch16, q, &mut s16);
            assert!(a.is_none_or(|h| h.ray_space_scale.is_none()));
            let b = search_register(net, &mut scratch, q, &mut s);
            assert_eq!(
                a.map(|h| (h.hit.t, h.hit.cell, h.hit.bbox)),
                b.map(|h| (h.t, h.cell, h.bbox))
            );
            assert_eq!((s16.splits, s16.box_tests), (s.splits, s.box_tests));
            hits += a.is_some() as usize;
        }
    }
    // Most rays aim at the patch's parameter-space footprint: the test must see hits.
    assert!(hits > 1000, "{hits} hits");
}

/// In ray space the search finds the same crossings as in world space: the same rays
/// hit, the world hit box (from the final cell) holds the ray-space hit point up to the
/// end game, and the two `t` differ by no more than the two final boxes' extents.
#[test]
fn ray_space_search_finds_the_world_space_hits() {
    let Some((net, root, cfg)) = setup() else {
        return;
    };
    let (mut scratch, mut stats) = (Default::default(), KernelStats::default());
    // The hit with its box in world space.
    let mut search = |ray: &GRay<f32>, frame: Option<&RayFrame>| {
        let q = Query {
            root,
            ray,
            frame,
            cfg: &cfg,
            any_hit: false,
            trim: None,
            trivial: None,
        };
        let h = search_net16(&net, &mut scratch, q, &mut stats)?;
        Some(match (h.ray_space_scale, frame) {
            (Some(scale), Some(frame)) => SearchHit {
                bbox: frame.world_box(&h.hit.bbox, scale),
                ..h.hit
            },
            _ => h.hit,
        })
    };
    let mut hits = 0;
    for ray in rays() {
        let frame = RayFrame::new(&ray);
        let (a, b) = (search(&ray, Some(&frame)), search(&ray, None));
        assert_eq!(a.is_some(), b.is_some(), "{ray:?}");
        let (Some(a), Some(b)) = (a, b) else { continue };
        hits += 1;
        // The length of the ray's parameter interval inside a hit box.
        let extent = |h: &SearchHit<f32>| {
            (0..3)
                .map(|c| (h.bbox.max[c] - h.bbox.min[c]) * ray.inv_dir[c].abs())
                .fold(f32::INFINITY, f32::min)
        };
        // 16 ulps of the scale of t, for the end game of both.
        let slack = 16.0 * f32::EPSILON * a.t.max(b.t);
        assert!(
            (a.t - b.t).abs() <= extent(&a) + extent(&b) + slack,
            "{a:?} vs {b:?}"
        );
        let p: [f32; 3] = std::array::from_fn(|c| ray.origin[c] + a.t * ray.dir[c]);
        for c in 0..3 {
            let pad = extent(&a) * ray.dir[c].abs() + slack * 8.0;
            assert!(
                p[c] >= a.bbox.min[c] - pad && p[c] <= a.bbox.max[c] + pad,
                "{a:?}"
            );
        }
    }
    assert!(hits > 500, "{hits} hits");
    // The ray-space searches jumped ([`super::super::jump`]); the world-space ones
    // cannot, so the agreement above covers the jumps.
    assert!(stats.jumps > 0, "no jumps");
}

/// The point `(i, j)`'s (x, y) of a net, read lane by lane (the layout of the module
/// documentation), for the scalar reference.
fn points_xy(net: &Net16) -> [[[f32; 2]; 4]; 4] {
    points(net).map(|row| row.map(|p| [p[0], p[1]]))
}

/// The point `(i, j)` of a net at `[j][i]`, read lane by lane.
fn points(net: &Net16) -> [[[f32; 3]; 4]; 4] {
    let regs = net.regs.map(Net16::lanes);
    std::array::from_fn(|j| {
        std::array::from_fn(|i| {
            let (r, lane) = if net.transposed { (i, j) } else { (j, i) };
            [regs[r][lane], regs[r][4 + lane], regs[r][8 + lane]]
        })
    })
}

/// How far the register linearisation may lie from the scalar one, relative to the
/// value: both sum the same 16 `f32` products in another order, each order's rounding a
/// few ulps (2^-23 each) of the largest term; 1e-5 is about 80 ulps, room for the terms'
/// cancellation on this test patch, and far below a wrong coefficient (order 1).
const LINEARIZATION_AGREEMENT: f32 = 1e-5;

/// The register linearisation is the scalar definition's, in both layouts, up to the
/// rounding of sums taken in another order.
#[test]
fn register_linearization_matches_the_scalar_definition() {
    if !available() {
        return;
    }
    let frame = RayFrame::new(&rays()[0]);
    // SAFETY: AVX-512F is available (checked above).
    let local = unsafe { Net16::from_net(&Net::from_patch(&patch())).in_ray_space(&frame) };
    for transposed in [false, true] {
        let net = if transposed {
            // SAFETY: as above.
            Net16 {
                regs: unsafe { transpose(local.regs) },
                transposed: !local.transposed,
            }
        } else {
            local
        };
        // SAFETY: as above.
        let got = unsafe { net.linearization() };
        let want = crate::kernel::subdivision::jump::linearize(&points_xy(&net));
        let pairs = [
            (got.centre, want.centre),
            (got.du, want.du),
            (got.dv, want.dv),
            (got.du_dev, want.du_dev),
            (got.dv_dev, want.dv_dev),
        ];
        for (g, w) in pairs {
            for c in 0..2 {
                assert!(
                    (g[c] - w[c]).abs() <= LINEARIZATION_AGREEMENT * (1.0 + w[c].abs()),
                    "transposed {transposed}: {got:?} vs {want:?}"
                );
            }
        }
        // A maximum of the same floats: exact.
        assert_eq!(got.magnitude, want.magnitude, "transposed {transposed}");
    }
}

/// A jump's descent is the search's own halvings: the same net, bit for bit, as
/// splitting towards the sub-cell one level at a time.
#[test]
fn descent_is_the_halving_search_bit_for_bit() {
    if !available() {
        return;
    }
    // SAFETY: AVX-512F is available (checked above).
    let root = unsafe { Net16::from_net(&Net::from_patch(&patch())) };
    let ray = Net16::ray_registers(&rays()[0]);
    for (levels, index) in [([3, 2], [5, 1]), ([0, 4], [0, 9]), ([6, 0], [37, 0])] {
        let jump = Jump {
            levels,
            index,
            interior: false,
            holds_near: true,
        };
        // SAFETY: as above.
        let got = unsafe { root.descend(&jump) };
        let mut want = root;
        // The descent's order: the direction the registers run across first.
        for (d, dir) in [(1, Split::V), (0, Split::U)] {
            for level in (0..levels[d]).rev() {
                let (upper, _) = want.split_test(dir, &ray, f32::INFINITY);
                if (index[d] >> level) & 1 == 1 {
                    want = upper;
                }
            }
        }
        assert_eq!(got.transposed, want.transposed, "{jump:?}");
        let bits = |n: &Net16| n.regs.map(|r| Net16::lanes(r).map(f32::to_bits));
        assert_eq!(bits(&got), bits(&want), "{jump:?}");
    }
}

/// A jump's descent where the window lies inside the cell (the [`restriction`]
/// matrices) is the net of the jumped-to sub-cell: against halvings in `f64`, an
/// independent computation, within a few ulps of the net's largest coordinate (the
/// rounding [`super::super::jump`] allows it).
#[test]
fn interior_descent_is_the_sub_net_of_the_cell() {
    if !available() {
        return;
    }
    // SAFETY: AVX-512F is available (checked above).
    let root = unsafe { Net16::from_net(&Net::from_patch(&patch())) };
    let exact = points(&root).map(|row| row.map(|p| p.map(f64::from)));
    let scale = exact
        .iter()
        .flatten()
        .flatten()
        .fold(0f64, |m, c| m.max(c.abs()));
    let jumps = [
        ([3, 2], [5, 1]),
        ([0, 4], [0, 9]),
        ([6, 0], [37, 0]),
        ([12, 9], [1234, 300]),
        ([21, 17], [654_321, 77_777]),
    ];
    for (levels, index) in jumps {
        let jump = Jump {
            levels,
            index,
            interior: true,
            holds_near: true,
        };
        // SAFETY: as above.
        let got = points(&unsafe { root.descend(&jump) });
        let mut want = exact;
        for level in (0..levels[0]).rev() {
            let upper = (index[0] >> level) & 1 == 1;
            for row in want.iter_mut() {
                for c in 0..3 {
                    let h = halve(row.map(|p| p[c]), upper);
                    for (p, v) in row.iter_mut().zip(h) {
                        p[c] = v;
                    }
                }
            }
        }
        for level in (0..levels[1]).rev() {
            let upper = (index[1] >> level) & 1 == 1;
            for i in 0..4 {
                for c in 0..3 {
                    let h = halve(std::array::from_fn(|j| want[j][i][c]), upper);
                    for (j, v) in h.into_iter().enumerate() {
                        want[j][i][c] = v;
                    }
                }
            }
        }
        let tolerance = 8.0 * scale * f64::from(f32::EPSILON);
        for (g, w) in got.iter().flatten().zip(want.iter().flatten()) {
            for c in 0..3 {
                assert!(
                    (f64::from(g[c]) - w[c]).abs() <= tolerance,
                    "{jump:?}: {g:?} vs {w:?}"
                );
            }
        }
    }
}
