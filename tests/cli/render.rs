//! `render`, `bvh` and the effect plan, driven through the real binary on small images.

use crate::common;

use common::{render, run, stderr, stdout, testdata};

fn stats(scene: &str, extra: &[&str]) -> serde_json::Value {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("x.png");
    let scene = testdata(scene);
    let mut args = vec!["--stats"];
    args.extend_from_slice(extra);
    let o = render(&scene, &out, (24, 24), &args);
    assert!(o.status.success(), "{}", stderr(&o));
    serde_json::from_str(&stdout(&o)).expect("stats JSON")
}

/// Whether this machine runs the AVX-512 bicubic path, the one that searches in ray space.
fn ray_space_kernel() -> bool {
    #[cfg(target_arch = "x86_64")]
    return patchtrace::kernel::subdivision::avx512::available();
    #[cfg(not(target_arch = "x86_64"))]
    false
}

#[test]
fn ray_counts_by_type_follow_the_effect_plan() {
    // Reflective teapot, one light: shadows and reflection, no refraction.
    let s = stats("teapot.ron", &[]);
    assert_eq!(s["rays"]["primary"], 24 * 24);
    assert!(s["rays"]["shadow"].as_u64().unwrap() > 0);
    assert!(s["rays"]["reflection"].as_u64().unwrap() > 0);
    assert_eq!(s["rays"]["refraction"], 0);
    assert_eq!(s["plan"]["refraction"], false);
    // On AVX-512 primary rays search the bicubic patches in ray space, where the kernel
    // jumps; the portable path searches in world space and never jumps.
    let jumps = s["rays"]["jumps_per_ray"]["mean"].as_f64().unwrap();
    assert_eq!(jumps > 0.0, ray_space_kernel(), "jumps per ray {jumps}");

    // Glass: refraction rays appear.
    let s = stats("glass_teapot.ron", &[]);
    assert!(s["rays"]["refraction"].as_u64().unwrap() > 0);
    assert_eq!(s["plan"]["refraction"], true);

    // Diffuse: primary and shadow rays only, depth 1.
    let s = stats("diffuse.ron", &[]);
    assert_eq!(s["plan"]["max_depth"], 1);
    assert_eq!(s["rays"]["reflection"], 0);
    assert_eq!(s["rays"]["refraction"], 0);
    assert!(s["rays"]["shadow"].as_u64().unwrap() > 0);
    assert_eq!(
        s["rays"]["total"].as_u64().unwrap(),
        s["rays"]["primary"].as_u64().unwrap() + s["rays"]["shadow"].as_u64().unwrap()
    );
}

#[test]
fn a_scene_without_lights_traces_no_shadow_rays() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("dark.ron");
    let src = std::fs::read_to_string(testdata("diffuse.ron")).unwrap();
    let start = src.find("lights: [").unwrap();
    let end = start + src[start..].find("],").unwrap() + 2;
    let src = format!("{}{}", &src[..start], &src[end..]).replace(
        "File(\"teapot.bpt\")",
        &format!("File({:?})", testdata("teapot.bpt")),
    );
    std::fs::write(&scene, src).unwrap();
    let out = dir.path().join("x.png");
    let o = render(&scene, &out, (16, 16), &["--stats"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let s: serde_json::Value = serde_json::from_str(&stdout(&o)).unwrap();
    assert_eq!(s["plan"]["shadows"], false);
    assert_eq!(s["rays"]["shadow"], 0);
    assert!(stderr(&o).contains("no shadows"), "{}", stderr(&o));
}

#[test]
fn image_bytes_do_not_depend_on_the_thread_count() {
    let dir = tempfile::tempdir().unwrap();
    let scene = testdata("teapot.ron");
    let mut images = Vec::new();
    for threads in ["1", "2", "3"] {
        let out = dir.path().join(format!("t{threads}.png"));
        let o = render(&scene, &out, (40, 30), &["--threads", threads]);
        assert!(o.status.success(), "{}", stderr(&o));
        images.push(std::fs::read(&out).unwrap());
    }
    assert_eq!(images[0], images[1]);
    assert_eq!(images[0], images[2]);
}

#[test]
fn a_saved_bvh_renders_the_same_bytes_and_a_stale_one_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let scene = testdata("teapot.ron");
    let bvh = dir.path().join("teapot.bvh");
    let o = run(&["bvh", scene.to_str().unwrap(), "-o", bvh.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let render = |extra: &[&str], name: &str| {
        let out = dir.path().join(name);
        let o = render(&scene, &out, (32, 32), extra);
        assert!(o.status.success(), "{}", stderr(&o));
        std::fs::read(out).unwrap()
    };
    assert_eq!(
        render(&[], "built.png"),
        render(&["--bvh", bvh.to_str().unwrap()], "loaded.png")
    );

    // The diffuse scene rotates the teapot: different geometry, so the file is stale.
    let other = testdata("diffuse.ron");
    let out = dir.path().join("stale.png");
    let o = run(&[
        "render",
        other.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "-q",
        "--bvh",
        bvh.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("rebuild"), "{}", stderr(&o));
    assert!(!out.exists());

    // Not a BVH file at all.
    let o = run(&[
        "render",
        scene.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "-q",
        "--bvh",
        scene.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
}

#[test]
fn exr_output_is_linear_rgba_with_coverage_alpha() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("x.exr");
    let scene = testdata("teapot.ron");
    let o = render(&scene, &out, (20, 20), &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    use exr::prelude::*;
    let img = read_first_rgba_layer_from_file(
        &out,
        |res, _| vec![vec![(0f32, 0f32, 0f32, 0f32); res.width()]; res.height()],
        |px: &mut Vec<Vec<(f32, f32, f32, f32)>>, pos, (r, g, b, a): (f32, f32, f32, f32)| {
            px[pos.y()][pos.x()] = (r, g, b, a)
        },
    )
    .unwrap();
    let px = &img.layer_data.channel_data.pixels;
    // Top row looks over the floor's far edge into the background; the centre sees the teapot.
    assert_eq!(px[0][10].3, 0.0);
    assert_eq!(px[12][10].3, 1.0);
}

#[test]
fn effort_aov_counts_every_split_of_the_render() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("e.png");
    let scene = testdata("teapot.ron");
    let o = render(&scene, &out, (24, 24), &["--aov", "effort", "--stats"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let s: serde_json::Value = serde_json::from_str(&stdout(&o)).unwrap();
    let total_splits = s["rays"]["splits_per_ray"]["mean"].as_f64().unwrap()
        * s["rays"]["total"].as_f64().unwrap();
    use exr::prelude::*;
    // Beside a PNG, the layers are one EXR, <name>-aov.exr.
    let img = read_first_flat_layer_from_file(dir.path().join("e-aov.exr")).unwrap();
    let channel = &img.layer_data.channel_data.list[0];
    assert_eq!(channel.name.to_string(), "effort");
    let values: Vec<f32> = channel.sample_data.values_as_f32().collect();
    assert_eq!(values.len(), 24 * 24);
    let sum: f64 = values.iter().map(|&v| v as f64).sum();
    assert!(
        (sum - total_splits).abs() <= 1e-6 * total_splits,
        "{sum} vs {total_splits}"
    );
    // The top-left pixel sees only background: no patch, no split.
    assert_eq!(values[0], 0.0);
    assert!(dir.path().join("e-effort.png").exists());
}

/// A flag the command cannot honour is bad input: exit status 2, the flag named, no image.
#[test]
fn flags_the_command_cannot_honour_exit_2() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("x.png");
    let scene = testdata("teapot.ron");
    for (extra, named) in [
        (&["--crop", "0,4000,0,10"][..], "--crop"),
        (&["--tile", "3/2"][..], "tile"),
        (&["--bvh", "absent.bvh", "--accel", "grid"][..], "--bvh"),
        (&["--isrt"][..], "--isrt"),
    ] {
        let o = render(&scene, &out, (16, 16), extra);
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{extra:?}: {err}");
        assert!(err.contains(named), "{extra:?}: {err}");
        assert!(!out.exists(), "{extra:?} wrote an image");
    }
}
