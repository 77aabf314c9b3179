//! Termination criteria of the subdivision kernel against the `f64` reference on one
//! strongly distorted bicubic patch (testdata/distorted_patch.ron): the shape of Dammertz
//! Tables 2.1 and 2.9 for float precision and adaptive termination, and what a fixed depth
//! must guarantee.

use crate::common;

use glam::DVec3;
use patchtrace::bench::accuracy::{self, Method, MethodResult};
use patchtrace::geom::{BezierPatch, Ray};
use patchtrace::kernel::KernelStats;
use patchtrace::kernel::subdivision::{
    PreparedPatch, SplitHeuristic, SubdivisionConfig, Termination, intersect, intersect_f64,
};
use patchtrace::progress::ProgressBar;
use patchtrace::render::camera::CameraRays;
use patchtrace::scene::rays::RayQuery;
use patchtrace::scene::{Scene, load_scene};

use common::testdata;

fn scene() -> Scene {
    load_scene(&testdata("distorted_patch.ron")).unwrap()
}

fn the_patch(scene: &Scene) -> BezierPatch {
    let patches = scene.objects[0].bezier_patches();
    assert_eq!(patches.len(), 1);
    patches[0].clone()
}

/// The camera's primary rays at `n`×`n`, in `f64` as `bench accuracy` takes them.
fn camera_rays(scene: &Scene, n: u32) -> Vec<RayQuery> {
    let mut camera = scene.camera.clone();
    camera.width = n;
    camera.height = n;
    let cam = CameraRays::new(&camera);
    (0..n)
        .flat_map(|y| (0..n).map(move |x| (x, y)))
        .map(|(x, y)| {
            let (origin, dir) = cam.ray_f64(x, y, 0.5, 0.5);
            RayQuery {
                origin,
                dir,
                tmin: 0.0,
                tmax: f64::INFINITY,
            }
        })
        .collect()
}

fn with_size(mut scene: Scene, n: u32) -> Scene {
    scene.camera.width = n;
    scene.camera.height = n;
    scene
}

/// Diagonal of the control points' bounding box: the patch size the error is measured in.
fn patch_size(p: &BezierPatch) -> f64 {
    let (lo, hi) = p.euclidean_points().fold(
        (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
        |(lo, hi), q| (lo.min(q), hi.max(q)),
    );
    (hi - lo).length()
}

fn row<'a>(results: &'a [MethodResult], name: &str) -> &'a MethodResult {
    results.iter().find(|r| r.method == name).unwrap()
}

/// Dammertz Table 2.1 and 2.9 at his resolution, 512². The run takes about ten seconds
/// in the dev profile, most of it the `f64` reference and the 131,072-triangle BVH.
#[test]
fn float_precision_beats_the_finest_tessellation_a_hundredfold_and_adaptive_sits_between() {
    const SIZE: u32 = 512;
    let scene = with_size(scene(), SIZE);
    let size = patch_size(&the_patch(&scene));
    let rays = camera_rays(&scene, SIZE);
    let methods = [
        Method::Float(SplitHeuristic::Length),
        Method::Adaptive,
        Method::Tessellated(512),
        Method::Tessellated(131072),
    ];
    let progress = ProgressBar::hidden();
    let results = accuracy::run(&scene, &rays, &methods, &progress).unwrap();
    // The reference and each method counted once.
    assert_eq!((progress.position(), progress.length()), (5, Some(5)));
    let float = row(&results, "float, length heuristic");
    let adaptive = row(&results, "adaptive, half pixel");
    let coarse = row(&results, "512 triangles/patch");
    let fine = row(&results, "131072 triangles/patch");
    let table = accuracy::markdown(&results);
    assert!(float.hit_error.mean > 0.0, "{table}");
    assert_eq!(float.holes, 0, "{table}");
    assert!(float.hit_error.mean <= 1e-6 * size, "size {size}\n{table}");
    assert!(
        100.0 * float.hit_error.mean <= fine.hit_error.mean,
        "{table}"
    );
    // Adaptive stops at half a pixel: far coarser than float precision, but (as in
    // Dammertz Table 2.9, where it lands between 4608 and 131,072 triangles) well inside
    // the coarse tessellation.
    assert!(
        float.hit_error.mean < adaptive.hit_error.mean
            && adaptive.hit_error.mean < coarse.hit_error.mean,
        "{table}"
    );
    assert_eq!(
        adaptive.holes, 0,
        "adaptive boxes are conservative\n{table}"
    );
}

/// The hit of a fixed depth `d`: `None` on a miss.
fn depth_hit(prepared: &PreparedPatch, ray: &Ray, d: u8) -> Option<patchtrace::kernel::PatchHit> {
    let cfg = SubdivisionConfig {
        termination: Termination::Depth(d),
        ..SubdivisionConfig::default()
    };
    intersect(prepared, None, ray, &cfg, &mut KernelStats::default())
}

fn f32_ray(q: &RayQuery) -> Ray {
    Ray {
        origin: q.origin.as_vec3(),
        dir: q.dir.as_vec3(),
        tmin: 0.0,
        tmax: f32::INFINITY,
    }
}

#[test]
fn fixed_depth_error_falls_as_the_depth_grows() {
    let scene = scene();
    let patch = the_patch(&scene);
    let prepared = PreparedPatch::new(&patch);
    let rays = camera_rays(&scene, 64);
    let cfg = SubdivisionConfig::default();
    let depths = [8u8, 12, 16, 20];
    let mut sums = [0.0f64; 4];
    let mut count = 0;
    for q in &rays {
        let ray = f32_ray(q);
        let (o, d) = (ray.origin.as_dvec3(), ray.dir.as_dvec3());
        let Some(reference) = intersect_f64(&patch, o, d, 0.0, f64::INFINITY, &cfg, None) else {
            continue;
        };
        let p_ref = o + d * reference.t;
        let hits: Vec<_> = depths
            .iter()
            .map(|&depth| depth_hit(&prepared, &ray, depth))
            .collect();
        // A fixed depth only ever stops earlier: its boxes contain the finer ones, so
        // every ray the reference hits is hit.
        let hits: Vec<_> = hits.into_iter().map(|h| h.expect("a hole")).collect();
        count += 1;
        for (s, h) in sums.iter_mut().zip(&hits) {
            // The surface point at the reported (u, v) against the reference hit point.
            *s += (patch.eval(h.u as f64, h.v as f64) - p_ref)
                .abs()
                .element_sum();
        }
    }
    assert!(count > 500, "only {count} hits");
    for w in sums.windows(2) {
        // Four more splits halve each direction about twice: the error must fall clearly.
        assert!(
            w[1] < 0.5 * w[0],
            "mean errors by depth {depths:?}: {sums:?}"
        );
    }
}

#[test]
fn a_depth_8_hit_is_a_depth_8_cell_whose_box_holds_the_surface_there() {
    let scene = scene();
    let patch = the_patch(&scene);
    let prepared = PreparedPatch::new(&patch);
    let cfg = SubdivisionConfig::default();
    let scale = patch
        .euclidean_points()
        .map(|p| p.abs().max_element())
        .fold(0.0, f64::max);
    // The f32 de Casteljau net after 8 halvings: a few ulps of the coordinate scale.
    let slack = 8.0 * f64::from(f32::EPSILON) * scale;
    let mut checked = 0;
    for q in camera_rays(&scene, 48) {
        let ray = f32_ray(&q);
        let (o, d) = (ray.origin.as_dvec3(), ray.dir.as_dvec3());
        let Some(h) = depth_hit(&prepared, &ray, 8) else {
            continue;
        };
        // (u, v) is the centre of a cell split lu times in u and 8 - lu in v: u is an odd
        // multiple of 2^-(lu+1) and v of 2^-(9-lu), for one lu.
        let (u, v) = (h.u as f64, h.v as f64);
        let odd = |x: f64, bits: i32| {
            let k = x * 2f64.powi(bits);
            k.fract() == 0.0 && k as i64 % 2 == 1
        };
        assert!(
            (0..=8).any(|lu| odd(u, lu + 1) && odd(v, 9 - lu)),
            "({u}, {v}) is no depth-8 cell centre"
        );
        // The box is the sub-patch's control box, so it holds the surface at the centre.
        let p = patch.eval(u, v);
        let (lo, hi) = (h.hit_box.min.as_dvec3(), h.hit_box.max.as_dvec3());
        assert!(
            (lo - slack).cmple(p).all() && p.cmple(hi + slack).all(),
            "S({u}, {v}) = {p} outside {lo}..{hi}"
        );
        // And the box is entered no later than the exact surface is reached.
        if let Some(r) = intersect_f64(&patch, o, d, 0.0, f64::INFINITY, &cfg, None) {
            assert!(
                h.t as f64 <= r.t * (1.0 + 4.0 * f64::from(f32::EPSILON)),
                "entered at {} after the surface at {}",
                h.t,
                r.t
            );
        }
        checked += 1;
    }
    assert!(checked > 200, "only {checked} hits");
}
