//! Batch rendering through the real binary: antialiased images that do not depend on the
//! threads, the sampling order or the split into tiles, `merge` of pieces, and shell
//! completions.

use crate::common;

use std::path::{Path, PathBuf};

use common::{render, run, stderr, testdata};

const SIZE: (u32, u32) = (40, 30);

fn render_ok(out: &Path, extra: &[&str]) -> Vec<u8> {
    let o = render(&testdata("teapot.ron"), out, SIZE, extra);
    assert!(o.status.success(), "{}", stderr(&o));
    std::fs::read(out).unwrap()
}

fn merge(pieces: &[PathBuf], out: &Path) -> std::process::Output {
    let mut args = vec!["merge".to_string()];
    args.extend(pieces.iter().map(|p| p.to_str().unwrap().to_string()));
    args.extend(["-o".to_string(), out.to_str().unwrap().to_string()]);
    run(&args.iter().map(String::as_str).collect::<Vec<_>>())
}

#[test]
fn spp16_teapot_is_the_same_for_any_threads_order_and_seven_merged_tiles() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let reference = render_ok(&d.join("ref.png"), &["--spp", "16", "--threads", "1"]);
    let centre = render_ok(&d.join("one.png"), &[]);
    // Antialiasing changed the silhouette pixels: the images differ.
    assert_ne!(reference, centre);
    let two = render_ok(&d.join("two.png"), &["--spp", "16", "--threads", "2"]);
    assert!(reference == two, "--threads 2 differs from --threads 1");
    for order in ["scanline", "hilbert", "itembuffer"] {
        let img = render_ok(
            &d.join(format!("{order}.png")),
            &["--spp", "16", "--order", order],
        );
        assert!(reference == img, "--order {order} differs");
    }
    let pieces: Vec<PathBuf> = (0..7)
        .map(|k| {
            let p = d.join(format!("tile{k}.png"));
            render_ok(
                &p,
                &["--spp", "16", "--tile", &format!("{k}/7"), "--threads", "1"],
            );
            p
        })
        .collect();
    // Pieces in any order on the command line.
    let mut shuffled = pieces.clone();
    shuffled.reverse();
    let out = d.join("merged.png");
    let o = merge(&shuffled, &out);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        std::fs::read(&out).unwrap() == reference,
        "7 merged tiles differ"
    );
}

#[test]
fn exr_crops_merge_into_the_single_render_and_keep_their_data_window() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let reference = render_ok(&d.join("ref.exr"), &["--spp", "4"]);
    let crops = ["0,25,0,12", "25,40,0,12", "0,40,12,30"];
    let pieces: Vec<PathBuf> = crops
        .iter()
        .enumerate()
        .map(|(k, c)| {
            let p = d.join(format!("c{k}.exr"));
            render_ok(&p, &["--spp", "4", "--crop", c]);
            p
        })
        .collect();
    // The second piece's data window is its crop inside the 40×30 display window.
    let meta = exr::meta::MetaData::read_from_file(&pieces[1], false).unwrap();
    let h = &meta.headers[0];
    assert_eq!(h.own_attributes.layer_position, exr::math::Vec2(25, 0));
    assert_eq!(h.layer_size, exr::math::Vec2(15, 12));
    assert_eq!(
        h.shared_attributes.display_window.size,
        exr::math::Vec2(40, 30)
    );
    let out = d.join("merged.exr");
    let o = merge(&pieces, &out);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        std::fs::read(&out).unwrap() == reference,
        "merged EXR differs"
    );
    // EXR pieces also merge into the PNG a single render writes.
    let png = render_ok(&d.join("ref.png"), &["--spp", "4"]);
    let out = d.join("merged.png");
    assert!(merge(&pieces, &out).status.success());
    assert!(
        std::fs::read(&out).unwrap() == png,
        "PNG from EXR pieces differs"
    );
}

#[test]
fn merge_refuses_pieces_of_other_renders_gaps_and_overlaps() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let piece = |name: &str, extra: &[&str]| {
        let p = d.join(name);
        render_ok(&p, extra);
        p
    };
    let a = piece("a.png", &["--tile", "0/2"]);
    let b = piece("b.png", &["--tile", "1/2"]);
    let b4 = piece("b4.png", &["--tile", "1/2", "--spp", "4"]);
    let top = piece("top.png", &["--crop", "0,40,0,16"]);
    let out = d.join("m.png");
    let o = merge(&[a.clone(), b4], &out);
    assert!(!o.status.success());
    assert!(stderr(&o).contains("same render"), "{}", stderr(&o));
    let o = merge(std::slice::from_ref(&a), &out);
    assert!(stderr(&o).contains("in no piece"), "{}", stderr(&o));
    let o = merge(&[a.clone(), b.clone(), top], &out);
    assert!(stderr(&o).contains("in two pieces"), "{}", stderr(&o));
    assert!(!out.exists(), "a refused merge wrote {}", out.display());
    // A file that is not a piece is bad input (exit 2).
    let plain = d.join("plain.png");
    image::RgbaImage::new(4, 4).save(&plain).unwrap();
    let o = merge(&[plain, b], &out);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    // Windows outside the image are refused before rendering.
    let o = render(&testdata("teapot.ron"), &out, SIZE, &["--crop", "0,41,0,5"]);
    assert!(stderr(&o).contains("outside"), "{}", stderr(&o));
    let o = render(&testdata("teapot.ron"), &out, SIZE, &["--tile", "3/31"]);
    assert!(!o.status.success());
}

/// Every subcommand of the clap model, nested ones too, as (its parents' names, its name).
fn subcommands(cmd: &clap::Command, parents: &[String], out: &mut Vec<(Vec<String>, String)>) {
    for s in cmd.get_subcommands() {
        out.push((parents.to_vec(), s.get_name().to_string()));
        let mut path = parents.to_vec();
        path.push(s.get_name().to_string());
        subcommands(s, &path, out);
    }
}

#[test]
fn completions_for_bash_and_zsh_name_every_subcommand() {
    use clap::CommandFactory;
    let mut all = Vec::new();
    subcommands(&patchtrace::cli::Cli::command(), &[], &mut all);
    assert!(all.iter().filter(|(p, _)| p.is_empty()).count() >= 12);
    assert!(all.iter().any(|(p, n)| p == &["bench"] && n == "stability"));
    for shell in ["bash", "zsh", "fish", "elvish", "powershell"] {
        let o = run(&["completions", shell]);
        assert!(o.status.success(), "{shell}: {}", stderr(&o));
        let script = String::from_utf8(o.stdout).unwrap();
        // bash dispatches on `PARENT,NAME)` with PARENT `patchtrace__subcmd__bench` for
        // `bench`'s subcommands; zsh lists `'NAME:description'` under its parent.
        let pattern = |parents: &[String], name: &str| match shell {
            "bash" => Some(format!(
                "patchtrace{},{name})",
                parents
                    .iter()
                    .map(|p| format!("__subcmd__{p}"))
                    .collect::<String>()
            )),
            "zsh" => Some(format!("'{name}:")),
            _ => None,
        };
        for (parents, name) in &all {
            if let Some(p) = pattern(parents, name) {
                assert!(
                    script.contains(&p),
                    "{shell} completion does not name `{}`",
                    [parents.join(" "), name.clone()].join(" ")
                );
            }
        }
    }
}

/// The linear RGBA pixels of an EXR render.
fn exr_pixels(path: &Path) -> Vec<[f32; 4]> {
    use exr::prelude::*;
    let img = read_first_rgba_layer_from_file(
        path,
        |size, _| vec![[0f32; 4]; size.0 * size.1],
        |px: &mut Vec<[f32; 4]>, pos, (r, g, b, a): (f32, f32, f32, f32)| {
            px[pos.1 * SIZE.0 as usize + pos.0] = [r, g, b, a]
        },
    )
    .unwrap();
    img.layer_data.channel_data.pixels
}

#[test]
fn adaptive_pixels_are_the_four_sample_or_the_max_sample_pixels_and_are_counted() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let o = render(
        &testdata("teapot.ron"),
        &d.join("ad.exr"),
        SIZE,
        &["--spp", "adaptive:32", "--stats"],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let stats: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    render_ok(&d.join("4.exr"), &["--spp", "4"]);
    render_ok(&d.join("32.exr"), &["--spp", "32"]);
    let [ad, four, full] = ["ad", "4", "32"].map(|n| exr_pixels(&d.join(format!("{n}.exr"))));
    // Adaptive sampling extends the pixel's own sequence: a pixel left alone is the
    // 4-sample pixel, a refined one the 32-sample pixel, bit for bit.
    let mut refined = 0;
    for i in 0..ad.len() {
        if ad[i] != four[i] {
            assert_eq!(ad[i], full[i], "pixel {i} is neither");
            refined += 1;
        }
    }
    let n = ad.len() as u64;
    let counted = stats["samples"]["refined_pixels"].as_u64().unwrap();
    // A refined pixel may happen to equal its 4-sample value, never the other way round.
    assert!(
        refined as u64 <= counted && counted > 0 && counted < n / 2,
        "{counted}"
    );
    assert_eq!(
        stats["samples"]["total"].as_u64().unwrap(),
        4 * (n - counted) + 32 * counted
    );
    assert_eq!(
        stats["rays"]["primary"].as_u64().unwrap(),
        stats["samples"]["total"].as_u64().unwrap()
    );
}

#[test]
fn the_scene_samples_field_is_the_default_spp() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let src = std::fs::read_to_string(testdata("teapot.ron")).unwrap();
    let scene = d.join("s.ron");
    std::fs::write(
        &scene,
        src.replace("background:", "samples: 4,\n    background:")
            .replace(
                "File(\"teapot.bpt\")",
                &format!("File({:?})", testdata("teapot.bpt")),
            ),
    )
    .unwrap();
    let o = render(&scene, &d.join("s.png"), SIZE, &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    let four = render_ok(&d.join("4.png"), &["--spp", "4"]);
    let s = std::fs::read(d.join("s.png")).unwrap();
    // The same pixels; the provenance differs only in the scene fingerprint.
    let decode = |b: &[u8]| image::load_from_memory(b).unwrap().to_rgba8().into_raw();
    assert_eq!(decode(&s), decode(&four));
    assert!(decode(&s) != decode(&render_ok(&d.join("1.png"), &["--spp", "1"])));
}

/// Rows and columns of `png` that hold a pixel other than the top-left (background) one.
fn covered_extent(png: &Path) -> (usize, usize) {
    let img = image::open(png).unwrap().to_rgb8();
    let bg = *img.get_pixel(0, 0);
    let (mut rows, mut cols) = (
        vec![false; img.height() as usize],
        vec![false; img.width() as usize],
    );
    for (x, y, p) in img.enumerate_pixels() {
        if *p != bg {
            rows[y as usize] = true;
            cols[x as usize] = true;
        }
    }
    let count = |v: &[bool]| v.iter().filter(|&&b| b).count();
    (count(&rows), count(&cols))
}

/// A unit cube seen from the y-up and the z-up framing gives the same image (it is
/// symmetric under the quarter turn between them), so the framing is tested on a column
/// three times as long along glTF's up axis, y: upright it is much taller than wide in the
/// image; lying along the view of a z-up camera it is not.
#[test]
fn gltf_is_framed_y_up_by_default_and_up_is_refused_for_scenes() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let mut gltf: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(testdata("quad_mesh.gltf")).unwrap())
            .unwrap();
    gltf["nodes"][0] = serde_json::json!({"name": "column", "mesh": 0, "scale": [1, 3, 1]});
    let column = d.join("column.gltf");
    std::fs::write(&column, gltf.to_string()).unwrap();
    let img = |name: &str, extra: &[&str]| {
        let out = d.join(name);
        let o = render(&column, &out, (48, 48), extra);
        assert!(o.status.success(), "{}", stderr(&o));
        out
    };
    let decode = |p: &Path| image::open(p).unwrap().to_rgba8().into_raw();
    let default = img("d.png", &[]);
    assert!(decode(&default) == decode(&img("y.png", &["--up", "y"])));
    let (rows, cols) = covered_extent(&default);
    assert!(rows > 2 * cols, "y up: {rows} rows, {cols} columns");
    let (rows, cols) = covered_extent(&img("z.png", &["--up", "z"]));
    assert!(rows < cols + cols / 4, "z up: {rows} rows, {cols} columns");
    let o = render(
        &testdata("teapot.ron"),
        &d.join("t.png"),
        SIZE,
        &["--up", "y"],
    );
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("bare geometry"), "{}", stderr(&o));
}

/// `up: Y` on an object turns a y-up model to stand in the z-up scene: y → z, z → -y. The
/// teapot's box after loading is checked against the control points of `teapot.bpt` read
/// here and turned by hand.
#[test]
fn an_up_y_object_stands_its_y_axis_along_z() {
    let text = std::fs::read_to_string(testdata("teapot.bpt")).unwrap();
    let mut tokens = text.split_whitespace().map(|t| t.parse::<f64>().unwrap());
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for _ in 0..tokens.next().unwrap() as usize {
        let (du, dv) = (tokens.next().unwrap(), tokens.next().unwrap());
        for _ in 0..((du + 1.0) * (dv + 1.0)) as usize {
            for k in 0..3 {
                let c = tokens.next().unwrap();
                (lo[k], hi[k]) = (lo[k].min(c), hi[k].max(c));
            }
        }
    }
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("up.ron");
    let src = std::fs::read_to_string(testdata("teapot.ron")).unwrap();
    std::fs::write(
        &scene,
        src.replace(
            "geometry: File(\"teapot.bpt\"),",
            &format!("geometry: File({:?}), up: Y,", testdata("teapot.bpt")),
        ),
    )
    .unwrap();
    let loaded = patchtrace::scene::load_scene(&scene).unwrap();
    let b = loaded.objects[0].bounds();
    let want_min = [lo[0], -hi[2], lo[1]];
    let want_max = [hi[0], -lo[2], hi[1]];
    for k in 0..3 {
        assert!(
            (b.min[k] - want_min[k]).abs() < 1e-12 && (b.max[k] - want_max[k]).abs() < 1e-12,
            "axis {k}: {} {} against {} {}",
            b.min[k],
            b.max[k],
            want_min[k],
            want_max[k]
        );
    }
}
