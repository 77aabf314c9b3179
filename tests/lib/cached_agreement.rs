//! The cached surface-tree kernel (LG90 §4.2–4.3) against the `f64` subdivision reference
//! on random rays at random bicubic and rational patches, with the default cache and with
//! a cache too small to keep anything and a depth limit of one level; and the cache at
//! work: a repeated ray finds its tree.

use crate::kernel_common;
use crate::toth_common;

use kernel_common::Rng;
use patchtrace::kernel::KernelStats;
use patchtrace::kernel::cached::{CachedConfig, cached_bytes, intersect};
use patchtrace::kernel::toth::TothConfig;
use toth_common::{HIT_DISTANCE, agrees_with_reference, random_patch, random_ray};

#[test]
fn cached_kernel_agrees_with_the_f64_reference_on_random_patches() {
    let cfg = CachedConfig::default();
    let mut stats = KernelStats::default();
    let a = agrees_with_reference(7, 40, |patch, ray| {
        intersect(patch, None, ray, &cfg, false, &mut stats)
    });
    assert!(
        a.hits > 600 && a.misses > 300,
        "{} hits, {} misses of {}",
        a.hits,
        a.misses,
        a.rays
    );
    let c = stats.cached;
    // Each patch misses once, at its first ray; every later ray finds its tree. (A freed
    // patch's address may be reused by the next one: its tree must not be.)
    assert_eq!(c.misses, 60, "{c:?}");
    assert_eq!(c.hits, a.rays as u64 - 60, "{c:?}");
    assert_eq!(c.evictions, 0);
    assert!(c.nodes_created > 0 && c.subdivisions > 0);
    let t = stats.toth;
    // Rays that miss every leaf of a cached tree are not searched (LG90 §7.1).
    assert!(t.searches < stats.patch_tests, "{t:?}");
    assert!(t.newton_starts > 0);
    assert_eq!(t.cut_off, 0, "a search hit the iteration bound");
}

#[test]
fn without_a_usable_cache_the_answers_are_the_same() {
    // One byte keeps no tree, and depth 1 caches only the root's quarters.
    let cfg = CachedConfig::new(TothConfig::default(), 1, 1);
    let mut stats = KernelStats::default();
    let a = agrees_with_reference(8, 20, |patch, ray| {
        intersect(patch, None, ray, &cfg, false, &mut stats)
    });
    assert!(a.hits > 300 && a.misses > 150);
    let c = stats.cached;
    assert_eq!((c.hits, c.misses), (0, a.rays as u64), "{c:?}");
    assert_eq!(c.evictions, a.rays as u64, "every tree is released at once");
    assert!(c.uncached_subdivisions > 0, "{c:?}");
    assert_eq!(cached_bytes(&cfg), 0);
}

#[test]
fn a_repeated_ray_starts_from_the_cached_tree() {
    let mut rng = Rng::new(9);
    let patch = random_patch(&mut rng, 3, 3, false);
    let rays: Vec<_> = (0..50).map(|_| random_ray(&mut rng).0).collect();
    let cfg = CachedConfig::default();
    let pass = || {
        let mut stats = KernelStats::default();
        let hits: Vec<_> = rays
            .iter()
            .map(|r| intersect(&patch, None, r, &cfg, false, &mut stats))
            .collect();
        (hits, stats)
    };
    let (first, s1) = pass();
    let (second, s2) = pass();
    // The second pass starts Newton from other (smaller) safe regions: the same roots, to
    // the precision Newton stops at; hit boxes may differ.
    for (a, b) in first.iter().zip(&second) {
        assert_eq!(
            a.is_some(),
            b.is_some(),
            "the cached tree changed an answer"
        );
        if let (Some(a), Some(b)) = (a, b) {
            assert!(((a.t - b.t) as f64).abs() <= HIT_DISTANCE, "{a:?} vs {b:?}");
        }
    }
    assert!(first.iter().flatten().count() > 10);
    assert_eq!(s1.cached.misses, 1);
    assert_eq!((s2.cached.hits, s2.cached.misses), (50, 0));
    assert!(s2.cached.hit_ratio() > 0.0);
    // Starting from the leaves skips the Krawczyk tests of the nodes above them.
    assert!(
        s2.toth.search_iterations < s1.toth.search_iterations,
        "second pass {} vs first {} search iterations",
        s2.toth.search_iterations,
        s1.toth.search_iterations
    );
    assert!(cached_bytes(&cfg) > 0);
    // A new configuration starts with an empty cache.
    let fresh = CachedConfig::default();
    assert_eq!(cached_bytes(&fresh), 0);
    let mut s3 = KernelStats::default();
    intersect(&patch, None, &rays[0], &fresh, false, &mut s3);
    assert_eq!(s3.cached.misses, 1);
}
