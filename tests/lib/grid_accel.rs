//! The uniform grid (LG90 §3.1) against independent computations: the BVH's nearest hits
//! on the 100-teapot scene, a brute-force slab test of every stored voxel, sampled surface
//! points for the voxel lists, brute-force triangle intersection, and the mailbox counted.

use std::collections::{HashMap, HashSet};

use glam::{DVec3, Vec3};
use patchtrace::accel::grid::{DEFAULT_BUDGET_BYTES, Grid};
use patchtrace::accel::scene::{QueryStats, SceneGeometry};
use patchtrace::formats::load_scene;
use patchtrace::geom::ulp::ulp_distance;
use patchtrace::geom::{BezierPatch, DAabb, Ray};
use patchtrace::kernel::Kernel;
use patchtrace::kernel::subdivision::SubdivisionConfig;
use patchtrace::kernel::triangle::{RayShear, intersect_triangle};
use patchtrace::scene::Scene;
use patchtrace::scene::generate::{SplitMix64, TEAPOT_BPT, TeapotsSpec, teapots_scene};

/// Largest ulp distance between the `t` of two different patches that both hit a ray
/// at a shared edge: both kernels report the entry of a final box, and final boxes stop
/// shrinking within `DEFAULT_END_ULPS` (8) ulps; twice that for the two sides of a seam.
const SEAM_TIE_ULPS: u32 = 16;

fn teapots(count: usize, seed: u64) -> Scene {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("teapot.bpt"), TEAPOT_BPT).unwrap();
    let spec = TeapotsSpec {
        count,
        seed,
        reflective: false,
        lights: 1,
        width: 64,
        height: 64,
        // Copies: the grid prepares instances as placed copies, the BVH would share one
        // teapot whose placed surface differs from a copy's by rounding.
        flatten: true,
    };
    let path = dir.path().join("scene.ron");
    std::fs::write(&path, teapots_scene(&spec)).unwrap();
    load_scene(&path).unwrap()
}

fn all_patches(scene: &Scene) -> Vec<BezierPatch> {
    scene
        .objects
        .iter()
        .flat_map(|o| o.bezier_patches())
        .collect()
}

/// A ray from a random point on a sphere around `b` towards a random point inside `b`.
fn random_ray(rng: &mut SplitMix64, b: &DAabb) -> Ray {
    let c = b.center();
    let r = b.diagonal();
    let origin = c + rng.direction() * r;
    let e = b.extent();
    let target = b.min
        + DVec3::new(
            rng.uniform() * e.x,
            rng.uniform() * e.y,
            rng.uniform() * e.z,
        );
    Ray::new(origin.as_vec3(), (target - origin).normalize().as_vec3())
}

fn scene_box(g: &SceneGeometry) -> DAabb {
    g.bounds().to_f64()
}

#[test]
fn grid_and_bvh_find_the_same_nearest_hits_on_100_teapots() {
    let scene = teapots(100, 11);
    let bvh = SceneGeometry::build(&scene);
    let grid = SceneGeometry::build_grid(&scene, DEFAULT_BUDGET_BYTES);
    assert!(grid.grid().is_some() && bvh.bvh().is_some());
    let precision = Kernel::F32(SubdivisionConfig::default());
    let mut rng = SplitMix64::new(5);
    let bounds = scene_box(&bvh);
    let (mut hits, mut ties) = (0, 0);
    let (mut sb, mut sg) = (QueryStats::default(), QueryStats::default());
    for i in 0..2500 {
        let ray = random_ray(&mut rng, &bounds);
        let a = bvh.intersect(&ray, &precision, &mut sb);
        let b = grid.intersect(&ray, &precision, &mut sg);
        match (a, b) {
            (None, None) => {}
            (Some(a), Some(b)) => {
                hits += 1;
                if (a.object, a.patch) == (b.object, b.patch) {
                    assert_eq!(a.t, b.t, "ray {i}: same patch, different t");
                    assert_eq!((a.u, a.v), (b.u, b.v), "ray {i}");
                } else {
                    ties += 1;
                    let d = ulp_distance(a.t as f32, b.t as f32);
                    assert!(d <= SEAM_TIE_ULPS, "ray {i}: {a:?} vs {b:?}");
                }
            }
            (a, b) => panic!("ray {i}: bvh {a:?}, grid {b:?}"),
        }
        // Shadow queries agree too.
        assert_eq!(
            bvh.occluded(&ray, &precision, &mut sb),
            grid.occluded(&ray, &precision, &mut sg),
            "ray {i}"
        );
    }
    assert!(hits > 1000, "only {hits} of 2500 rays hit");
    assert!(ties * 100 <= hits, "{ties} seam ties of {hits} hits");
    assert!(sg.voxels_visited > 0 && sb.voxels_visited == 0);
}

#[test]
fn mailboxes_test_each_patch_once_per_ray() {
    let scene = teapots(100, 11);
    let geometry = SceneGeometry::build_grid(&scene, DEFAULT_BUDGET_BYTES);
    let grid = geometry.grid().unwrap();
    let mut rng = SplitMix64::new(9);
    let bounds = scene_box(&geometry);
    let mut repeated_registrations = 0;
    for _ in 0..500 {
        let ray = random_ray(&mut rng, &bounds);
        let mut tests: HashMap<u32, u32> = HashMap::new();
        // Never a hit: the walk crosses the whole grid, meeting patches again and again.
        grid.traverse(&ray, |prim, _| {
            *tests.entry(prim).or_default() += 1;
            None
        });
        assert!(tests.values().all(|&n| n == 1), "{tests:?}");
        let mut seen: HashMap<u32, u32> = HashMap::new();
        for v in grid.voxels(&ray) {
            for &p in grid.voxel_prims(v.cell) {
                *seen.entry(p).or_default() += 1;
            }
        }
        repeated_registrations += seen.values().filter(|&&n| n > 1).count();
        // Every patch met along the walk whose box the ray enters was tested.
        for p in seen.keys() {
            let b = grid.prim_box(*p);
            let hit = b.intersect(ray.origin, ray.dir.recip(), ray.tmin, ray.tmax);
            assert_eq!(hit.is_some(), tests.contains_key(p), "patch {p}");
        }
    }
    assert!(
        repeated_registrations > 100,
        "the rays met few patches twice"
    );
}

/// A large flat patch and many small ones: voxels are small, the flat patch spans many.
fn flat_and_small() -> Vec<BezierPatch> {
    let quad = |x0: f64, y0: f64, s: f64, z: f64| {
        let pts: Vec<DVec3> = (0..4)
            .map(|k| DVec3::new(x0 + s * (k % 2) as f64, y0 + s * (k / 2) as f64, z))
            .collect();
        BezierPatch::from_points(1, 1, &pts).unwrap()
    };
    let mut v = vec![quad(0.0, 0.0, 10.0, 0.0)];
    for k in 0..20 {
        v.push(quad(k as f64 * 0.5, 5.0, 0.2, 1.0));
    }
    v
}

#[test]
fn a_ray_through_many_voxels_of_one_patch_tests_it_once() {
    let grid = Grid::build(&flat_and_small(), &[], DEFAULT_BUDGET_BYTES);
    // Just above the flat patch, along it: inside its (padded) voxels all the way.
    let ray = Ray::new(Vec3::new(-1.0, 0.3, 0.0), Vec3::new(1.0, 0.05, 0.0));
    let holding = grid
        .voxels(&ray)
        .filter(|v| grid.voxel_prims(v.cell).contains(&0))
        .count();
    assert!(
        holding >= 10,
        "the ray crossed only {holding} voxels of patch 0"
    );
    let mut calls = 0;
    grid.traverse(&ray, |prim, _| {
        calls += u32::from(prim == 0);
        None
    });
    assert_eq!(calls, 1);
    let (_, _) = grid.traverse_any(&ray, |prim| {
        calls += u32::from(prim == 0);
        false
    });
    assert_eq!(calls, 2);
}

/// Entry and exit of `ray` through `b`, exactly as the slab formulas give them in f64.
fn slab(b: &DAabb, ray: &Ray) -> (f64, f64) {
    let (o, d) = (ray.origin.as_dvec3(), ray.dir.as_dvec3());
    let mut t0 = ray.tmin as f64;
    let mut t1 = ray.tmax as f64;
    for a in 0..3 {
        if d[a] == 0.0 {
            if o[a] < b.min[a] || o[a] > b.max[a] {
                return (1.0, 0.0);
            }
            continue;
        }
        let (p, q) = ((b.min[a] - o[a]) / d[a], (b.max[a] - o[a]) / d[a]);
        t0 = t0.max(p.min(q));
        t1 = t1.min(p.max(q));
    }
    (t0, t1)
}

#[test]
fn dda_visits_exactly_the_stored_voxels_a_slab_test_finds() {
    let scene = teapots(20, 3);
    let grid = Grid::build(&all_patches(&scene), &[], DEFAULT_BUDGET_BYTES);
    let stored: Vec<([u32; 3], DAabb)> = grid
        .non_empty_voxels()
        .map(|(c, _)| (c, grid.voxel_box(c)))
        .collect();
    assert!(stored.len() > 100);
    let slack = 1e-9 * grid.voxel_edge();
    let mut rng = SplitMix64::new(2);
    let mut bounds = DAabb::EMPTY;
    for (_, b) in &stored {
        bounds = bounds.union(b);
    }
    for i in 0..300 {
        let mut ray = random_ray(&mut rng, &bounds);
        if i % 3 == 0 {
            // Some rays start inside the grid and end early.
            ray.origin = bounds.center().as_vec3();
            ray.tmax = (0.3 * bounds.diagonal()) as f32;
        }
        if i % 7 == 0 {
            ray.dir.y = 0.0; // parallel to a family of planes
        }
        let walk: Vec<_> = grid.voxels(&ray).collect();
        for w in walk.windows(2) {
            let step: u32 = (0..3).map(|a| w[0].cell[a].abs_diff(w[1].cell[a])).sum();
            assert_eq!(step, 1, "ray {i}: not face neighbours {w:?}");
            assert!(w[1].t_enter >= w[0].t_enter);
        }
        let visited: HashSet<[u32; 3]> = walk
            .iter()
            .map(|v| v.cell)
            .filter(|c| !grid.voxel_prims(*c).is_empty())
            .collect();
        for (cell, b) in &stored {
            let (t0, t1) = slab(b, &ray);
            if t1 - t0 > slack {
                assert!(visited.contains(cell), "ray {i}: missed {cell:?}");
            } else if t1 - t0 < -slack {
                assert!(!visited.contains(cell), "ray {i}: visited {cell:?}");
            }
        }
    }
}

#[test]
fn every_surface_point_is_in_a_voxel_listing_its_patch() {
    let scene = teapots(5, 4);
    let patches = all_patches(&scene);
    let grid = Grid::build(&patches, &[], DEFAULT_BUDGET_BYTES);
    let d = grid.voxel_edge();
    for (k, p) in patches.iter().enumerate() {
        for a in 0..=8 {
            for b in 0..=8 {
                let q = p.eval(a as f64 / 8.0, b as f64 / 8.0);
                // The voxel holding q, found from its box independently of the grid's index.
                let cell = grid
                    .non_empty_voxels()
                    .map(|(c, _)| c)
                    .find(|c| {
                        let vb = grid.voxel_box(*c);
                        q.cmpge(vb.min).all() && q.cmplt(vb.max).all()
                    })
                    .unwrap_or_else(|| panic!("patch {k}: {q} in no stored voxel"));
                assert!(grid.voxel_prims(cell).contains(&(k as u32)));
                let tb = grid.prim_box(k as u32);
                assert!(
                    tb.contains(q.as_vec3()),
                    "patch {k}: {q} outside its tight box"
                );
            }
        }
        // The tight box is no looser than LG90's one-level box.
        let one = p.tight_box().to_f32_outward();
        let tb = grid.prim_box(k as u32);
        assert!(tb.extent().element_sum() <= one.extent().element_sum() + 1e-3 * d as f32);
    }
}

#[test]
fn voxel_edge_is_a_quarter_of_the_mean_box_edge() {
    let scene = teapots(10, 6);
    let patches = all_patches(&scene);
    let grid = Grid::build(&patches, &[], DEFAULT_BUDGET_BYTES);
    let mean = patches
        .iter()
        .map(|p| p.tight_box().extent().element_sum() / 3.0)
        .sum::<f64>()
        / patches.len() as f64;
    assert!((grid.voxel_edge() - mean / 4.0).abs() < 1e-12 * mean);
}

#[test]
fn a_smaller_memory_budget_makes_the_voxels_coarser() {
    let patches = all_patches(&teapots(10, 6));
    let full = Grid::build(&patches, &[], DEFAULT_BUDGET_BYTES);
    let budget = full.memory_bytes() / 4;
    let small = Grid::build(&patches, &[], budget);
    assert!(small.voxel_edge() > full.voxel_edge());
    assert!(small.memory_bytes() <= budget);
    assert!(small.non_empty_count() < full.non_empty_count());
    // No budget can be met: the grid ends as one voxel holding everything.
    let one = Grid::build(&patches, &[], 1);
    assert_eq!(one.dims(), [1, 1, 1]);
    assert_eq!(one.registration_count(), patches.len());
}

#[test]
fn triangles_are_found_like_by_brute_force() {
    let mut rng = SplitMix64::new(8);
    let tris: Vec<[Vec3; 3]> = (0..400)
        .map(|_| {
            let c = DVec3::new(rng.uniform(), rng.uniform(), rng.uniform()) * 10.0;
            [0, 1, 2].map(|_| (c + rng.direction() * 0.7).as_vec3())
        })
        .collect();
    let grid = Grid::build(&[], &tris, DEFAULT_BUDGET_BYTES);
    let bounds = DAabb {
        min: DVec3::ZERO,
        max: DVec3::splat(10.0),
    };
    let mut hits = 0;
    for i in 0..500 {
        let ray = random_ray(&mut rng, &bounds);
        let shear = RayShear::new(&ray);
        let brute = tris
            .iter()
            .filter_map(|[a, b, c]| intersect_triangle(&shear, *a, *b, *c, ray.tmin, ray.tmax))
            .map(|h| h.t)
            .min_by(f32::total_cmp);
        let mut best: Option<f32> = None;
        grid.traverse(&ray, |prim, tmax| {
            let [a, b, c] = tris[prim as usize];
            let t = intersect_triangle(&shear, a, b, c, ray.tmin, tmax)?.t;
            best = Some(best.map_or(t, |x| x.min(t)));
            Some(t)
        });
        assert_eq!(best, brute, "ray {i}");
        let (any, _) = grid.traverse_any(&ray, |prim| {
            let [a, b, c] = tris[prim as usize];
            intersect_triangle(&shear, a, b, c, ray.tmin, ray.tmax).is_some()
        });
        assert_eq!(any, brute.is_some(), "ray {i}");
        hits += usize::from(brute.is_some());
    }
    assert!(hits > 100);
}

fn patchtrace(args: &[&str]) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_patchtrace"))
        .args(args)
        .output()
        .unwrap()
}

fn testdata(name: &str) -> String {
    format!("{}/testdata/{name}", env!("CARGO_MANIFEST_DIR"))
}

#[test]
fn trace_with_the_grid_prints_the_bvh_rows() {
    let dir = tempfile::tempdir().unwrap();
    let rays = dir.path().join("rays.txt");
    let mut rng = SplitMix64::new(4);
    let mut text = String::new();
    for _ in 0..300 {
        let t = DVec3::new(
            rng.range(-3.0, 3.0),
            rng.range(-2.0, 2.0),
            rng.range(0.0, 3.0),
        );
        let d = t - DVec3::new(0.0, -8.0, 4.5);
        text.push_str(&format!("0 -8 4.5 {} {} {}\n", d.x, d.y, d.z));
    }
    std::fs::write(&rays, text).unwrap();
    let scene = testdata("teapot.ron");
    let rays = rays.to_str().unwrap();
    let bvh = patchtrace(&["trace", &scene, "--rays", rays]);
    let grid = patchtrace(&["trace", &scene, "--rays", rays, "--accel", "grid"]);
    assert!(bvh.status.success() && grid.status.success());
    let bvh = String::from_utf8(bvh.stdout).unwrap();
    assert!(bvh.lines().filter(|l| l.contains(",1,")).count() > 50);
    assert_eq!(String::from_utf8(grid.stdout).unwrap(), bvh);
}

#[test]
fn a_bvh_file_with_the_grid_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("x.png");
    let out = patchtrace(&[
        "render",
        &testdata("teapot.ron"),
        "-o",
        png.to_str().unwrap(),
        "--accel",
        "grid",
        "--bvh",
        "some.bvh",
    ]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("--bvh") && err.contains("--accel grid"),
        "{err}"
    );
}

#[test]
fn render_stats_report_voxels_per_ray_for_the_grid() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("t.png");
    let stats = |accel: &str| {
        let o = patchtrace(&[
            "render",
            &testdata("teapot.ron"),
            "-o",
            out.to_str().unwrap(),
            "-q",
            "--width",
            "24",
            "--height",
            "24",
            "--stats",
            "--accel",
            accel,
        ]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        let rays = &v["rays"];
        rays["voxels_per_ray"]["mean"].as_f64().unwrap()
    };
    assert!(stats("grid") > 0.0);
    assert_eq!(stats("bvh"), 0.0);
}
