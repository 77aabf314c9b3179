//! big unique scenes: the BVH build and the `render --bvh` load on 10,000
//! flattened teapots (`scene teapots --count 10000 --flatten`: 320,000 distinct patches),
//! in wall and process CPU seconds (all threads; from /proc/self/stat, 10 ms ticks), three
//! interleaved rounds, so that other work on the machine shows as wall time above CPU time.
//!
//! - build: what `patchtrace bvh` reports as "built in": collecting the patches, their
//!   boxes, the tree and its wide form, and preparing the patches for the kernel;
//! - load: what `render --bvh` does before rendering: mapping the file, reading the scene
//!   (from the parse the file keeps) without its geometry files, keying the inputs and
//!   checking the file.
//!
//! Run: `cargo bench --bench bvh_build` (or `-- COUNT` for another number of teapots).

mod support;

use std::path::Path;
use std::time::Instant;

use support::process_cpu_seconds;

use patchtrace::accel::mapped;
use patchtrace::accel::scene::{FromFile, SceneGeometry};
use patchtrace::formats::ron_format::parsed_scene;
use patchtrace::formats::{LoadOptions, load_scene_keyed};
use patchtrace::scene::generate::{TEAPOT_BPT, TeapotsSpec, teapots_scene};

/// Runs `f`, returning its value and its (wall, CPU) seconds.
fn timed<T>(f: impl FnOnce() -> T) -> (T, f64, f64) {
    let cpu = || process_cpu_seconds().unwrap_or(f64::NAN);
    let (wall, before) = (Instant::now(), cpu());
    let v = f();
    (v, wall.elapsed().as_secs_f64(), cpu() - before)
}

fn main() {
    let count: usize = std::env::args()
        .skip(1)
        .find_map(|a| a.parse().ok())
        .unwrap_or(10_000);
    let dir = std::env::temp_dir().join("patchtrace-bench-bvh-build");
    std::fs::create_dir_all(&dir).expect("bench directory");
    let scene_path = dir.join("teapots.ron");
    let spec = TeapotsSpec {
        count,
        seed: 1,
        reflective: false,
        lights: 1,
        width: 512,
        height: 512,
        flatten: true,
    };
    std::fs::write(&scene_path, teapots_scene(&spec)).expect("scene");
    std::fs::write(dir.join("teapot.bpt"), TEAPOT_BPT).expect("teapot");
    let bvh_path = dir.join("teapots.bvh");
    println!(
        "{count} flattened teapots, {} threads; load average {}",
        rayon::current_num_threads(),
        std::fs::read_to_string("/proc/loadavg")
            .unwrap_or_default()
            .trim()
    );
    for round in 1..=3 {
        let (scene, source) = load_scene_keyed(&scene_path, LoadOptions::default(), false, None)
            .expect("scene loads");
        let (geometry, build_wall, build_cpu) = timed(|| SceneGeometry::build(&scene));
        let key = mapped::key(source, false);
        let parsed = parsed_scene(&scene_path).expect("the scene's parse is kept");
        let with_patches = geometry
            .save_bvh(
                &bvh_path,
                key,
                // The teapots lie around the origin: built where they are.
                (scene.trim_loop_count(), glam::DVec3::ZERO),
                Some((parsed.0, &parsed.1)),
                &|_, _| None,
            )
            .expect("file written");
        assert!(
            with_patches,
            "the teapots are plain bicubics: the file holds them"
        );
        let patches = geometry.patch_count();
        drop((geometry, scene));
        let (mapped, load_wall, load_cpu) = timed(|| load(&scene_path, &bvh_path));
        assert_eq!(mapped, patches);
        println!(
            "round {round}: build {build_wall:.3} s wall, {build_cpu:.2} s CPU; load {load_wall:.3} s wall, {load_cpu:.2} s CPU"
        );
    }
    let bytes = std::fs::metadata(&bvh_path).map_or(0, |m| m.len());
    let patches = (count * 32) as f64;
    println!(
        "file {bytes} bytes: {:.0} bytes per patch ({} of them the patch record)",
        bytes as f64 / patches,
        mapped::RECORD_BYTES
    );
}

/// What `render --bvh` does before it renders; the number of patches mapped.
fn load(scene_path: &Path, bvh_path: &Path) -> usize {
    let opened = mapped::map(bvh_path).expect("file maps");
    let parsed = Some(opened.cached_scene());
    let (scene, source) =
        load_scene_keyed(scene_path, LoadOptions::default(), true, parsed).expect("scene loads");
    let key = mapped::key(source, false);
    let file = opened
        .check(bvh_path, key, scene.objects.len())
        .expect("file fits");
    match SceneGeometry::from_file(file) {
        FromFile::Mapped(geometry, _) => geometry.patch_count(),
        FromFile::TreeOnly(_) => panic!("the file should hold the patches"),
    }
}
