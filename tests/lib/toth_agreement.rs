//! The Toth kernel against the `f64` subdivision reference (`intersect_f64`, an independent
//! algorithm: Dammertz's box subdivision in double precision) on random rays at random
//! bicubic and rational patches, and the ISRT shadow variant against full shadow tests.

use crate::kernel_common;
use crate::toth_common;

use kernel_common::{Rng, min_ray_distance};
use patchtrace::geom::Ray;
use patchtrace::kernel::KernelStats;
use patchtrace::kernel::toth::{TothConfig, intersect, occluded};
use toth_common::{SILHOUETTE, agrees_with_reference, random_patch, random_ray};

#[test]
fn toth_agrees_with_the_f64_reference_on_random_patches() {
    let cfg = TothConfig::default();
    let mut stats = KernelStats::default();
    let a = agrees_with_reference(6, 40, |patch, ray| {
        intersect(patch, None, ray, &cfg, false, &mut stats)
    });
    assert!(
        a.hits > 600 && a.misses > 300,
        "{} hits, {} misses of {}",
        a.hits,
        a.misses,
        a.rays
    );
    let t = stats.toth;
    assert!(t.newton_starts > 0 && t.search_iterations >= t.newton_starts);
    assert_eq!(t.cut_off, 0, "a search hit the iteration bound");
}

/// A shadow test with ISRT answers like the full test: a safe region with its ray
/// parameters inside `[tmin, tmax]` proves a root there.
#[test]
fn isrt_shadow_answers_match_full_shadow_tests() {
    let mut rng = Rng::new(60);
    let full = TothConfig::default();
    let isrt = TothConfig { isrt: true, ..full };
    let (mut s_full, mut s_isrt) = (KernelStats::default(), KernelStats::default());
    let mut blocked = 0;
    for k in 0..30 {
        let patch = random_patch(&mut rng, 3, 3, k % 2 == 1);
        for _ in 0..40 {
            let (mut ray, o, d) = random_ray(&mut rng);
            // A segment that ends somewhere along the ray, as towards a light.
            ray.tmax = rng.range(0.3, 1.3) as f32;
            let a = occluded(&patch, None, &ray, &full, false, &mut s_full);
            let b = occluded(&patch, None, &ray, &isrt, false, &mut s_isrt);
            if a != b {
                // Only a root within f32 precision of the segment's end may differ.
                let h = intersect(
                    &patch,
                    None,
                    &Ray {
                        tmax: f32::INFINITY,
                        ..ray
                    },
                    &full,
                    false,
                    &mut s_full,
                )
                .map(|h| h.t);
                let near_end = h.is_some_and(|t| ((t - ray.tmax) as f64 * d.length()).abs() < 1e-4);
                assert!(
                    near_end || min_ray_distance(&patch, o, d, 24) < SILHOUETTE,
                    "ISRT {b} vs full {a}"
                );
            }
            blocked += a as u32;
        }
    }
    assert!(blocked > 100, "only {blocked} blocked segments");
    assert!(s_isrt.toth.early_outs > 0, "ISRT never stopped early");
    assert!(
        s_isrt.toth.newton_starts < s_full.toth.newton_starts,
        "ISRT started Newton {} times, the full test {}",
        s_isrt.toth.newton_starts,
        s_full.toth.newton_starts
    );
}
