//! LG90's three triviality tests (§6) on the surface a secondary ray leaves, in the Toth
//! and cached kernels, against the full search of the same kernel (the tests switched off)
//! and the `f64` subdivision reference (`intersect_f64`, an independent algorithm).
//!
//! The surface is a half-pipe: rays leaving its floor either escape (every root on the
//! patch is the trivial one, behind the ray's start: the tests must fire) or hit its wall
//! (a real second root: the tests must not drop it).

use crate::kernel_common;
use crate::toth_common;

use glam::DVec3;
use kernel_common::{Rng, min_ray_distance};
use patchtrace::geom::{BezierPatch, Ray};
use patchtrace::kernel::cached::{self, CachedConfig};
use patchtrace::kernel::secondary::{DEFAULT_ULPS, secondary_origin};
use patchtrace::kernel::subdivision::{SubdivisionConfig, intersect_f64};
use patchtrace::kernel::toth::{self, TothConfig};
use patchtrace::kernel::{KernelStats, PatchHit};
use toth_common::{HIT_DISTANCE, SILHOUETTE};

/// A bicubic half-pipe along y: a U in x–z (floor at z ≈ −0.5, walls up to z = 1), normal
/// `∂u × ∂v` up on the floor.
fn half_pipe() -> BezierPatch {
    let section = [(-1.0, 1.0), (-1.0, -1.0), (1.0, -1.0), (1.0, 1.0)];
    let pts: Vec<DVec3> = (0..4)
        .flat_map(|j| section.map(|(x, z)| DVec3::new(x, j as f64, z)))
        .collect();
    BezierPatch::from_points(3, 3, &pts).unwrap()
}

/// A secondary ray leaving the floor near (x, y) the way the renderer makes one: the
/// primary hit from above, the origin at the hit box corner of the normal's octant
/// (Dammertz §2.4), the direction `dir(n)` from the normal.
fn leaving(patch: &BezierPatch, x: f64, y: f64, dir: impl Fn(DVec3) -> DVec3) -> (Ray, DVec3) {
    let down = Ray::new(
        glam::Vec3::new(x as f32, y as f32, 5.0),
        glam::Vec3::new(0.0, 0.0, -1.0),
    );
    let cfg = TothConfig::default();
    let hit = toth::intersect(patch, None, &down, &cfg, false, &mut KernelStats::default())
        .expect("the primary ray hits the floor");
    let n = patch.normal(hit.u as f64, hit.v as f64);
    let o = secondary_origin(&hit.hit_box, n.as_vec3(), true, DEFAULT_ULPS);
    let d = dir(n);
    (Ray::new(o, d.as_vec3()), d)
}

/// Checks one secondary ray: the kernel with the tests (`fast`) answers like the kernel
/// without them (`full`), and both like the `f64` reference up to grazing rays. Returns
/// whether the ray hits the patch again.
fn agree(patch: &BezierPatch, ray: &Ray, mut kernel: impl FnMut(bool) -> Option<PatchHit>) -> bool {
    let (fast, full) = (kernel(true), kernel(false));
    let (o, d) = (ray.origin.as_dvec3(), ray.dir.as_dvec3());
    match (fast, full) {
        (Some(a), Some(b)) => assert!(
            (a.t - b.t).abs() as f64 * d.length() <= HIT_DISTANCE,
            "t {} with the tests, {} without",
            a.t,
            b.t
        ),
        (None, None) => {}
        (a, b) => panic!("with the tests {a:?}, without {b:?}"),
    }
    let reference = intersect_f64(
        patch,
        o,
        d,
        0.0,
        f64::INFINITY,
        &SubdivisionConfig::default(),
        None,
    );
    match (fast, reference) {
        (Some(a), Some(r)) => assert!((a.t as f64 - r.t).abs() * d.length() <= HIT_DISTANCE),
        (None, None) => {}
        (a, r) => assert!(
            min_ray_distance(patch, o, d, 24) < SILHOUETTE,
            "kernel {a:?} vs reference {r:?}"
        ),
    }
    fast.is_some()
}

/// Rays leaving the floor in random directions of the upper hemisphere, through both
/// kernels; returns the counters of the Toth and the cached kernel with the tests on and
/// off, and the counts of rays that hit the wall and that escape. (The cached kernel's
/// work is not comparable between on and off: both share one cache of trees.)
fn random_rays(seed: u64, rays: usize) -> ([[KernelStats; 2]; 2], u32, u32) {
    let patch = half_pipe();
    let mut rng = Rng::new(seed);
    let mut stats = [[KernelStats::default(); 2]; 2];
    let (mut again, mut escaped) = (0, 0);
    let toth_cfg = TothConfig::default();
    let cached_cfg = CachedConfig::default();
    for _ in 0..rays {
        let (x, y) = (rng.range(-0.5, 0.5), rng.range(0.3, 2.7));
        let w = rng.direction();
        let (ray, _) = leaving(&patch, x, y, |n| {
            let d = n + w * 0.95;
            if d.dot(n) > 0.05 { d } else { n }
        });
        let hit = agree(&patch, &ray, |on| {
            toth::intersect(
                &patch,
                None,
                &ray,
                &toth_cfg,
                on,
                &mut stats[0][!on as usize],
            )
        });
        agree(&patch, &ray, |on| {
            cached::intersect(
                &patch,
                None,
                &ray,
                &cached_cfg,
                on,
                &mut stats[1][!on as usize],
            )
        });
        if hit {
            again += 1;
        } else {
            escaped += 1;
        }
    }
    (stats, again, escaped)
}

/// Random rays leaving the floor: each of the three tests fires in one of the kernels
/// (test 1 in the cached kernel's tree descent, where quarters of a box can lie wholly
/// before the ray's start; tests 2 and 3 on safe regions), every answer matches the full
/// search and the reference, and rays that meet the wall still find it.
#[test]
fn triviality_tests_fire_and_agree_with_the_full_search() {
    let ([[toth_on, toth_off], [cached_on, cached_off]], again, escaped) = random_rays(61, 150);
    assert!(
        again >= 20 && escaped >= 20,
        "{again} hits, {escaped} escapes"
    );
    for k in 0..3 {
        assert!(
            toth_on.toth.trivial[k] + cached_on.toth.trivial[k] > 0,
            "test {} never fired: {:?} {:?}",
            k + 1,
            toth_on.toth,
            cached_on.toth
        );
    }
    assert_eq!(toth_off.toth.trivial, [0; 3]);
    assert_eq!(cached_off.toth.trivial, [0; 3]);
    // Test 3 stops Newton early: the same safe regions, fewer iterations.
    assert!(
        toth_on.toth.newton_iterations < toth_off.toth.newton_iterations,
        "the tests saved no Newton iterations: {} vs {}",
        toth_on.toth.newton_iterations,
        toth_off.toth.newton_iterations
    );
}

/// A ray that does not leave the patch (a primary ray, `origin` true by mistake) is
/// answered like the full search: the tests only drop roots before `tmin`.
#[test]
fn tests_never_drop_a_root_after_the_ray_start() {
    let patch = half_pipe();
    let mut rng = Rng::new(62);
    let cfg = TothConfig::default();
    let mut s = KernelStats::default();
    for _ in 0..80 {
        let o = DVec3::new(
            rng.range(-3.0, 3.0),
            rng.range(-1.0, 4.0),
            rng.range(2.0, 4.0),
        );
        let target = DVec3::new(
            rng.range(-1.2, 1.2),
            rng.range(-0.2, 3.2),
            rng.range(-1.0, 1.0),
        );
        let ray = Ray::new(o.as_vec3(), (target - o).as_vec3());
        agree(&patch, &ray, |on| {
            toth::intersect(&patch, None, &ray, &cfg, on, &mut s)
        });
    }
}
