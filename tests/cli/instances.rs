//! Instances (Dammertz §3.3) against the same scene flattened into copies: one prepared
//! copy shared, the same hits as the copies' `f64` reference, the same pixels, the same
//! image for any thread count, and the RON form's errors.

use crate::common;

use std::path::Path;
use std::sync::Arc;

use glam::DVec3;
use patchtrace::accel::scene::{QueryStats, SceneGeometry, SceneHit};
use patchtrace::formats::load_scene;
use patchtrace::geom::{DAabb, Ray};
use patchtrace::kernel::Kernel;
use patchtrace::kernel::subdivision::SubdivisionConfig;
use patchtrace::scene::generate::{SplitMix64, TEAPOT_BPT, TeapotsSpec, teapots_scene};
use patchtrace::scene::{Geometry, Scene};

/// The generated teapot scene written into `dir`, instanced or flattened.
fn teapots(dir: &Path, count: usize, flatten: bool) -> std::path::PathBuf {
    std::fs::write(dir.join("teapot.bpt"), TEAPOT_BPT).unwrap();
    let spec = TeapotsSpec {
        count,
        seed: 5,
        reflective: true,
        lights: 1,
        width: 48,
        height: 48,
        flatten,
    };
    let path = dir.join(if flatten { "flat.ron" } else { "inst.ron" });
    std::fs::write(&path, teapots_scene(&spec)).unwrap();
    path
}

fn both(count: usize) -> (Scene, Scene) {
    let dir = tempfile::tempdir().unwrap();
    let inst = load_scene(&teapots(dir.path(), count, false)).unwrap();
    let flat = load_scene(&teapots(dir.path(), count, true)).unwrap();
    (inst, flat)
}

#[test]
fn generated_instances_share_one_prepared_teapot() {
    let (inst, flat) = both(12);
    let shared: Vec<_> = inst
        .objects
        .iter()
        .map(|o| match &o.geometry {
            Geometry::Instance(i) => Arc::as_ptr(&i.geometry),
            other => panic!("{} is not an instance: {other:?}", o.name),
        })
        .collect();
    assert!(shared.iter().all(|&p| p == shared[0]));
    assert!(
        flat.objects
            .iter()
            .all(|o| matches!(o.geometry, Geometry::Surfaces(_)))
    );
    let (gi, gf) = (SceneGeometry::build(&inst), SceneGeometry::build(&flat));
    assert_eq!((gi.instance_count(), gi.prepared_patch_count()), (12, 32));
    assert_eq!(gi.patch_count(), 12 * 32);
    assert_eq!(
        (gf.instance_count(), gf.prepared_patch_count()),
        (0, 12 * 32)
    );
    // The placed copies are the flattened scene's geometry, to rounding of the transform.
    for (a, b) in inst.objects.iter().zip(&flat.objects) {
        for (p, q) in a.bezier_patches().iter().zip(&b.bezier_patches()) {
            for (x, y) in p.euclidean_points().zip(q.euclidean_points()) {
                assert!((x - y).abs().max_element() <= 1e-12 * (1.0 + y.abs().max_element()));
            }
        }
    }
}

/// A ray from a random point on a sphere around `b` towards a random point inside it.
fn random_ray(rng: &mut SplitMix64, b: &DAabb) -> Ray {
    let origin = b.center() + rng.direction() * b.diagonal();
    let e = b.extent();
    let target = b.min + DVec3::new(rng.uniform(), rng.uniform(), rng.uniform()) * e;
    Ray::new(origin.as_vec3(), (target - origin).normalize().as_vec3())
}

fn point(ray: &Ray, h: &SceneHit) -> DVec3 {
    ray.origin.as_dvec3() + ray.dir.as_dvec3() * h.t
}

/// Largest distance across the surface, in ulps of the hit point's largest coordinate,
/// between a hit point through an instance and the `f64` reference's on the flattened copy. The `f32` kernel
/// ends within a few ulps of the rounded surface; the instance adds the rounding of the
/// ray into object space and of the prototype's control points (each half an ulp of the
/// object's coordinates, scaled by the teapots' 0.6 to 1.4 back to world space).
const POINT_ULPS: f64 = 64.0;

#[test]
fn trace_through_instances_hits_what_the_copies_hit_in_f64() {
    let (inst, flat) = both(40);
    let (gi, gf) = (SceneGeometry::build(&inst), SceneGeometry::build(&flat));
    let f32_path = Kernel::F32(SubdivisionConfig::default());
    let cfg = SubdivisionConfig::default();
    let mut rng = SplitMix64::new(17);
    let bounds = gi.bounds().to_f64();
    let mut q = QueryStats::default();
    let (mut hits, mut ties, mut disagree, mut shadow_disagree) = (0, 0, 0, 0);
    let mut worst = 0.0f64;
    for i in 0..1500 {
        let ray = random_ray(&mut rng, &bounds);
        let (o, d) = (ray.origin.as_dvec3(), ray.dir.as_dvec3());
        let reference = gf.intersect_f64(o, d, 0.0, f64::INFINITY, &cfg, &mut q);
        let through = gi.intersect_f64(o, d, 0.0, f64::INFINITY, &cfg, &mut q);
        let hit = gi.intersect(&ray, &f32_path, &mut q);
        // The instance's f64 path is the copy's f64 path: the same surface to 1e-12.
        match (&through, &reference) {
            (Some(a), Some(r)) => {
                assert_eq!((a.object, a.patch), (r.object, r.patch), "ray {i}");
                assert!((a.t - r.t).abs() <= 1e-9 * r.t, "ray {i}: {a:?} {r:?}");
                assert!(a.normal.dot(r.normal) > 1.0 - 1e-9, "ray {i}");
            }
            (None, None) => {}
            _ => panic!("ray {i}: f64 through instances {through:?}, copies {reference:?}"),
        }
        match (&hit, &reference) {
            (Some(a), Some(r)) => {
                hits += 1;
                if (a.object, a.patch) != (r.object, r.patch) {
                    ties += 1;
                    continue;
                }
                let (p, pr) = (point(&ray, a), point(&ray, r));
                let ulp =
                    f64::from(pr.abs().max_element() as f32).max(1.0) * f64::from(f32::EPSILON);
                // A surface moved by e along its normal moves the crossing of a ray at
                // angle theta to that normal by e / |cos theta| along the ray: grazing
                // rays amplify the control points' rounding, so the bound is on the
                // distance across the surface, and along the ray it is divided by the
                // reference's |cos theta|.
                let cos = r.normal.dot(ray.dir.as_dvec3().normalize()).abs();
                worst = worst.max((p - pr).abs().max_element() * cos / ulp);
                assert!(a.normal.dot(r.normal) > 0.999, "ray {i}: {a:?} vs {r:?}");
                // The world hit box holds the reference point, to the rounding of the
                // prototype's control points.
                let grow = POINT_ULPS * ulp / cos;
                let hb = &a.hit_box;
                assert!(
                    (0..3)
                        .all(|k| pr[k] >= hb.min[k] as f64 - grow
                            && pr[k] <= hb.max[k] as f64 + grow),
                    "ray {i}: {pr} outside {hb:?}"
                );
            }
            (None, None) => {}
            _ => disagree += 1,
        }
        if gi.occluded(&ray, &f32_path, &mut q) != reference.is_some() {
            shadow_disagree += 1;
        }
    }
    assert!(hits > 300, "only {hits} hits");
    assert!(worst <= POINT_ULPS, "worst hit point {worst} ulps away");
    // Silhouette and seam rays may fall either way: a handful in 1500.
    assert!(ties * 100 <= hits, "{ties} seam ties in {hits}");
    assert!(
        disagree <= 5 && shadow_disagree <= 5,
        "{disagree} {shadow_disagree}"
    );
}

/// A scene with a mirrored and a stretched instance of an inline patch, and the same
/// scene with copies: `Instance(of:)` in RON.
fn ron_scenes(dir: &Path) -> (std::path::PathBuf, std::path::PathBuf) {
    let patch = "Bezier(degree: (2, 2), points: [(-1, -1, 0), (0, -1, 0.5), (1, -1, 0), (-1, 0, 0.5), (0, 0, 1.5), (1, 0, 0.5), (-1, 1, 0), (0, 1, 0.5), (1, 1, 0)])";
    let placements = [
        "[RotateX(-60), Translate(-1.2, 0, 0)]",
        "[ScaleXyz(-1, 1, 1), RotateX(-50), Translate(1.1, 0, 0.2)]",
        "[ScaleXyz(0.5, 1.5, 1), RotateY(20), RotateX(-70), Translate(0, 0, -1.3)]",
    ];
    let head = "Scene(camera: (eye: (0, -6, 2), look_at: (0, 0, 0), up: (0, 0, 1), fov_y: 45, width: 40, height: 40), lights: [Point(position: (3, -5, 6))], materials: {\"m\": (diffuse: (0.8, 0.6, 0.4), specular: 0.5, reflect: 0.4)}, objects: [";
    let mut inst = String::from(head);
    let mut flat = String::from(head);
    for (k, m) in placements.iter().enumerate() {
        let geometry = if k == 0 {
            format!("Surfaces([{patch}])")
        } else {
            "Instance(of: \"p0\")".to_string()
        };
        inst.push_str(&format!(
            "(name: \"p{k}\", geometry: {geometry}, material: \"m\", transform: {m}),\n"
        ));
        flat.push_str(&format!(
            "(geometry: Surfaces([{patch}]), material: \"m\", transform: {m}),\n"
        ));
    }
    inst.push_str("])\n");
    flat.push_str("])\n");
    let (a, b) = (dir.join("inst.ron"), dir.join("flat.ron"));
    std::fs::write(&a, inst).unwrap();
    std::fs::write(&b, flat).unwrap();
    (a, b)
}

fn pixels(path: &Path) -> Vec<u8> {
    image::open(path).unwrap().to_rgb8().into_raw()
}

#[test]
fn instanced_renders_match_copies_and_any_thread_count() {
    let dir = tempfile::tempdir().unwrap();
    let (inst, flat) = ron_scenes(dir.path());
    let out = |name: &str| dir.path().join(name);
    for (scene, png, threads) in [
        (&inst, "i1.png", "1"),
        (&inst, "i2.png", "2"),
        (&flat, "f1.png", "1"),
    ] {
        let o = common::render(scene, &out(png), (40, 40), &["--threads", threads]);
        assert!(o.status.success(), "{}", common::stderr(&o));
    }
    let (i1, i2, f1) = (
        pixels(&out("i1.png")),
        pixels(&out("i2.png")),
        pixels(&out("f1.png")),
    );
    assert_eq!(i1, i2, "instanced render differs between 1 and 2 threads");
    let lit = f1.chunks(3).filter(|p| p.iter().any(|&c| c > 40)).count();
    assert!(lit > 200, "only {lit} lit pixels");
    // The placed surfaces differ from the copies only by rounding: silhouette pixels at most.
    let differing = i1
        .chunks(3)
        .zip(f1.chunks(3))
        .filter(|(a, b)| a.iter().zip(*b).any(|(x, y)| x.abs_diff(*y) > 2))
        .count();
    assert!(
        differing <= 4,
        "{differing} pixels differ from the flattened scene"
    );
}

#[test]
fn an_instance_of_an_unknown_or_later_object_is_refused_with_its_place() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bad.ron");
    std::fs::write(
        &path,
        "Scene(camera: (eye: (0, -6, 2), look_at: (0, 0, 0), up: (0, 0, 1), fov_y: 45, width: 8, height: 8),\n objects: [\n  (geometry: Instance(of: \"later\")),\n  (name: \"later\", geometry: Surfaces([Bezier(degree: (1, 1), points: [(0, 0, 0), (1, 0, 0), (0, 1, 0), (1, 1, 0)])])),\n ])\n",
    )
    .unwrap();
    let o = common::run(&["info", path.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2), "{}", common::stderr(&o));
    let e = common::stderr(&o);
    assert!(
        e.contains("bad.ron:3:") && e.contains("earlier object"),
        "{e}"
    );
}

/// The shared geometry of an instance is prepared in `f32` before its transform, so its
/// own coordinates must fit `f32` even where the placed instance does (range
/// check, applied to shared geometry).
#[test]
fn an_instance_whose_shared_geometry_overflows_f32_is_refused_though_placed_in_range() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("huge.ron");
    let patch =
        "Bezier(degree: (1, 1), points: [(0, 0, 0), (1e39, 0, 0), (0, 1e39, 0), (1e39, 1e39, 0)])";
    std::fs::write(
        &path,
        format!("Scene(camera: (eye: (0.5, 0.5, 3), look_at: (0.5, 0.5, 0), up: (0, 1, 0), fov_y: 45, width: 8, height: 8),\n objects: [\n  (name: \"big\", geometry: Surfaces([{patch}]), transform: [Scale(1e-39)]),\n  (geometry: Instance(of: \"big\"), transform: [Scale(1e-39), Translate(2, 0, 0)]),\n ])\n"),
    )
    .unwrap();
    // The placed boxes are about 1 across: only the shared geometry is out of range.
    let o = common::run(&["info", path.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2), "{}", common::stderr(&o));
    let e = common::stderr(&o);
    assert!(
        e.contains("\"big\"") && e.contains("before its transform") && e.contains("f32 range"),
        "{e}"
    );
}

#[test]
fn mirrored_and_stretched_instances_report_the_copies_hits_and_normals() {
    let dir = tempfile::tempdir().unwrap();
    let (inst, flat) = ron_scenes(dir.path());
    let (si, sf) = (load_scene(&inst).unwrap(), load_scene(&flat).unwrap());
    let (gi, gf) = (SceneGeometry::build(&si), SceneGeometry::build(&sf));
    assert_eq!((gi.instance_count(), gi.prepared_patch_count()), (3, 1));
    let cfg = SubdivisionConfig::default();
    let f32_path = Kernel::F32(cfg);
    let eye = si.camera.eye;
    let mut q = QueryStats::default();
    let mut hits = [0; 3];
    for y in 0..24 {
        for x in 0..24 {
            let target = DVec3::new(-2.4 + 0.2 * x as f64, 0.0, -2.2 + 0.2 * y as f64);
            let d = target - eye;
            let reference = gf.intersect_f64(eye, d, 0.0, f64::INFINITY, &cfg, &mut q);
            let through = gi.intersect_f64(eye, d, 0.0, f64::INFINITY, &cfg, &mut q);
            let ray = Ray::new(eye.as_vec3(), d.as_vec3());
            let hit = gi.intersect(&ray, &f32_path, &mut q);
            match (&through, &reference, &hit) {
                (Some(a), Some(r), Some(h)) => {
                    hits[r.object as usize] += 1;
                    assert_eq!((a.object, a.patch), (r.object, r.patch));
                    assert!((a.t - r.t).abs() <= 1e-9 * r.t, "{a:?} {r:?}");
                    assert!((a.u - r.u).abs() < 1e-6 && (a.v - r.v).abs() < 1e-6);
                    // The mirrored instance's normal too is ∂S/∂u × ∂S/∂v of the copy.
                    assert!(a.normal.dot(r.normal) > 1.0 - 1e-9, "{a:?} {r:?}");
                    assert!(h.normal.dot(r.normal) > 0.999, "{h:?} {r:?}");
                    assert_eq!(h.object, r.object);
                }
                (None, None, None) => {}
                // A ray through a silhouette may fall either way in f32.
                (Some(_), Some(_), None) | (None, None, Some(_)) => {}
                other => panic!("({x}, {y}): {other:?}"),
            }
        }
    }
    assert!(hits.iter().all(|&n| n > 10), "hits per object {hits:?}");
}
