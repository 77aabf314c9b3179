//! Random NURBS for the property tests: degrees 1–5, knots on the domain [0, 1] with
//! interior multiplicities 1..=p + 1 (p + 1: a break), clamped or with uniform unclamped ends, weights in
//! [0.1, 10] and control points in [-1, 1]³.

use glam::{DVec3, DVec4};
use proptest::prelude::*;

use super::NurbsSurface;

/// Interior knots lie on a grid of this many steps, so spans are never so short that the
/// local-parameter comparison measures cancellation rather than the algorithm.
const KNOT_GRID: u32 = 40;
/// Spacing of the unclamped end knots outside [0, 1].
const END_SPACING: f64 = 0.15;

/// A knot vector of degree `p` on the domain [0, 1]: up to 4 distinct interior knots, each
/// repeated 1..=p + 1 times, and clamped ends or `p` extra uniformly spaced knots at each end.
pub fn knot_vector(p: usize, clamped: bool) -> impl Strategy<Value = Vec<f64>> {
    prop::collection::vec((1..KNOT_GRID, 1..=p + 1), 0..=4).prop_map(move |mut interior| {
        interior.sort_by_key(|&(k, _)| k);
        interior.dedup_by_key(|&mut (k, _)| k);
        let mut knots: Vec<f64> = (0..=p)
            .map(|i| {
                if clamped {
                    0.0
                } else {
                    -END_SPACING * (p - i) as f64
                }
            })
            .collect();
        for (k, m) in interior {
            knots.extend(std::iter::repeat_n(f64::from(k) / f64::from(KNOT_GRID), m));
        }
        knots.extend((0..=p).map(|i| {
            if clamped {
                1.0
            } else {
                1.0 + END_SPACING * i as f64
            }
        }));
        knots
    })
}

fn weighted_point() -> impl Strategy<Value = DVec4> {
    (-1.0..1.0f64, -1.0..1.0f64, -1.0..1.0f64, 0.1..=10.0f64)
        .prop_map(|(x, y, z, w)| (DVec3::new(x, y, z) * w).extend(w))
}

/// A random valid surface.
pub fn surface() -> impl Strategy<Value = NurbsSurface> {
    (1usize..=5, 1usize..=5, any::<bool>(), any::<bool>())
        .prop_flat_map(|(pu, pv, cu, cv)| {
            (Just(pu), Just(pv), knot_vector(pu, cu), knot_vector(pv, cv))
        })
        .prop_flat_map(|(pu, pv, ku, kv)| {
            let (nu, nv) = (ku.len() - pu - 1, kv.len() - pv - 1);
            let points = prop::collection::vec(weighted_point(), nu * nv);
            (Just((pu, pv, ku, kv, nu, nv)), points)
        })
        .prop_map(|((pu, pv, ku, kv, nu, nv), points)| {
            NurbsSurface::new(pu, pv, ku, kv, nu, nv, points).expect("generated surface is valid")
        })
}

/// The distinct knot values inside the domain: the breakpoints between non-empty spans,
/// counted independently of the decomposition code.
pub fn breakpoints(p: usize, knots: &[f64]) -> Vec<f64> {
    let (a, b) = (knots[p], knots[knots.len() - p - 1]);
    let mut v: Vec<f64> = knots
        .iter()
        .copied()
        .filter(|&k| k >= a && k <= b)
        .collect();
    v.dedup();
    v
}
