//! Primary-ray throughput through the whole scene query (BVH + kernel), single threaded:
//! the bare teapot (testdata/teapot.bpt, 32 bicubic patches) traced directly, and the same
//! teapot tessellated at 4608 triangles per patch (147,456 triangles, Dammertz Table 2.1's
//! middle row) traced with the watertight triangle kernel. Camera of DESIGN.md's sample
//! scene, 512², one ray per pixel; median of several runs after a warm-up.
//!
//! `cargo bench --bench primary`, or `cargo bench --bench primary -- triangles` (or
//! `-- patches`) for one of the two.

use std::path::Path;
use std::time::Instant;

use patchtrace::accel::scene::{QueryStats, SceneGeometry};
use patchtrace::formats::{bpt::read_bpt, load_scene};
use patchtrace::geom::Ray;
use patchtrace::kernel::Kernel;
use patchtrace::kernel::subdivision::SubdivisionConfig;
use patchtrace::render::camera::CameraRays;
use patchtrace::scene::{Geometry, Object, Scene, Surface};
use patchtrace::tessellate::{TessellationMode, tessellate_scene};

#[path = "support/mod.rs"]
mod support;
use support::{median, thread_cpu_seconds as cpu_seconds};

const RUNS: usize = 5;
const SIZE: u32 = 512;

/// Median wall seconds and median on-CPU seconds (wall where unavailable) to trace `rays`
/// through `geometry`, and the number of hits.
fn time(geometry: &SceneGeometry, rays: &[Ray]) -> (f64, f64, usize) {
    let precision = Kernel::F32(SubdivisionConfig::default());
    let (mut wall, mut cpu) = (Vec::new(), Vec::new());
    let mut hits = 0;
    for run in 0..=RUNS {
        let (start, cpu_start) = (Instant::now(), cpu_seconds());
        let mut stats = QueryStats::default();
        hits = rays
            .iter()
            .filter(|r| geometry.intersect(r, &precision, &mut stats).is_some())
            .count();
        let elapsed = start.elapsed().as_secs_f64();
        if run > 0 {
            wall.push(elapsed);
            cpu.push(cpu_seconds().zip(cpu_start).map_or(elapsed, |(b, a)| b - a));
        }
    }
    (median(wall), median(cpu), hits)
}

fn main() {
    let testdata = Path::new(env!("CARGO_MANIFEST_DIR")).join("testdata");
    let patches = read_bpt(&testdata.join("teapot.bpt")).expect("testdata/teapot.bpt");
    let mut scene = Scene::framing(vec![Object {
        name: "teapot".into(),
        material: 0,
        geometry: Geometry::Surfaces(patches.into_iter().map(Surface::bezier).collect()),
    }]);
    // The sample scene's camera at SIZE², looking at the bare teapot (no floor).
    scene.camera = load_scene(&testdata.join("teapot.ron"))
        .expect("testdata/teapot.ron")
        .camera;
    scene.camera.width = SIZE;
    scene.camera.height = SIZE;
    let cam = CameraRays::new(&scene.camera);
    let rays: Vec<Ray> = (0..SIZE)
        .flat_map(|y| (0..SIZE).map(move |x| (x, y)))
        .map(|(x, y)| cam.ray(x, y))
        .collect();

    let only = std::env::args().skip(1).find(|a| !a.starts_with('-'));
    let run = |name: &str| only.as_deref().is_none_or(|o| o == name);

    if run("patches") {
        let direct = SceneGeometry::build(&scene);
        let (wall, seconds, hits) = time(&direct, &rays);
        println!(
            "patches   {:>7} prims: {:.3} s wall, {:.3} s on CPU, {:.2} M rays/s/core, {} hits, {:.3} M patch hits/s/core",
            direct.patch_count(),
            wall,
            seconds,
            rays.len() as f64 / seconds / 1e6,
            hits,
            hits as f64 / seconds / 1e6
        );
    }
    if !run("triangles") {
        return;
    }
    let (meshes, report) =
        tessellate_scene(&scene, TessellationMode::TrianglesPerPatch(4608)).expect("tessellate");
    let triangles = SceneGeometry::build(&meshes);
    let (wall, seconds, hits) = time(&triangles, &rays);
    println!(
        "triangles {:>7} prims: {:.3} s wall, {:.3} s on CPU, {:.2} M rays/s/core, {} hits",
        report.triangles,
        wall,
        seconds,
        rays.len() as f64 / seconds / 1e6,
        hits
    );
}
