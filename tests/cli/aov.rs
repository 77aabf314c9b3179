//! `render --aov all` read back by the `exr` crate: every layer under its compositor
//! name, ids as integers, misses marked, and depth, ids, point and normal agreeing with
//! `trace` for the same pixels' centre rays.

use crate::common;

use std::collections::BTreeMap;

use common::{render, run, stderr, testdata, trace_rows};
use exr::prelude::*;

const W: u32 = 24;
const H: u32 = 18;

#[test]
fn aov_layers_open_in_an_exr_reader_and_agree_with_trace() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("a.exr");
    let o = render(
        &testdata("teapot.ron"),
        &out,
        (W, H),
        &["--aov", "all", "--spp", "4"],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let image = read_all_flat_layers_from_file(&out).unwrap();
    let layer = &image.layer_data[0];
    let channels: BTreeMap<String, &FlatSamples> = layer
        .channel_data
        .list
        .iter()
        .map(|c| (c.name.to_string(), &c.sample_data))
        .collect();
    let names: Vec<&str> = channels.keys().map(String::as_str).collect();
    assert_eq!(
        names,
        [
            "A",
            "B",
            "G",
            "N.X",
            "N.Y",
            "N.Z",
            "P.X",
            "P.Y",
            "P.Z",
            "R",
            "UV.U",
            "UV.V",
            "Z",
            "effort",
            "id.object",
            "id.patch"
        ]
    );
    let f32s = |n: &str| match channels[n] {
        FlatSamples::F32(v) => v.clone(),
        _ => panic!("{n} is not f32"),
    };
    let u32s = |n: &str| match channels[n] {
        FlatSamples::U32(v) => v.clone(),
        _ => panic!("{n} is not u32"),
    };
    let (z, object, patch) = (f32s("Z"), u32s("id.object"), u32s("id.patch"));
    let (p, n) = (
        ["P.X", "P.Y", "P.Z"].map(f32s),
        ["N.X", "N.Y", "N.Z"].map(f32s),
    );

    // The centre rays of rows 0 and 9, by the DESIGN.md camera formula for teapot.ron's
    // camera, computed here in f64.
    let eye = [0.0, -8.0, 4.5];
    let f = normalize(sub([0.0, 0.0, 1.2], eye));
    let r = normalize(cross(f, [0.0, 0.0, 1.0]));
    let u = cross(r, f);
    let s = 20f64.to_radians().tan();
    let pixels: Vec<(u32, u32)> = [0, 9]
        .iter()
        .flat_map(|&y| (0..W).map(move |x| (x, y)))
        .collect();
    let mut rays = String::new();
    for &(x, y) in &pixels {
        let a = (2.0 * (x as f64 + 0.5) / W as f64 - 1.0) * s * W as f64 / H as f64;
        let b = (1.0 - 2.0 * (y as f64 + 0.5) / H as f64) * s;
        let d = normalize([0, 1, 2].map(|i| f[i] + a * r[i] + b * u[i]));
        rays += &format!(
            "{:?} {:?} {:?} {:?} {:?} {:?}\n",
            eye[0], eye[1], eye[2], d[0], d[1], d[2]
        );
    }
    let rows = trace_rows(&testdata("teapot.ron"), &rays, &[]);
    assert_eq!(rows.len(), pixels.len());
    let (mut hits, mut misses) = (0, 0);
    for (f, &(x, y)) in rows.iter().zip(&pixels) {
        let i = (y * W + x) as usize;
        if f[1] == "0" {
            misses += 1;
            assert!(
                z[i].is_infinite(),
                "pixel ({x}, {y}) missed in trace, Z {}",
                z[i]
            );
            assert_eq!((object[i], patch[i]), (u32::MAX, u32::MAX));
            continue;
        }
        hits += 1;
        let num = |k: usize| f[k].parse::<f64>().unwrap();
        let close = |a: f64, b: f64, what: &str| {
            assert!(
                (a - b).abs() <= 1e-5 * (1.0 + b.abs()),
                "({x}, {y}) {what}: {a} vs {b}"
            );
        };
        close(z[i] as f64, num(2), "Z vs t");
        assert_eq!(object[i].to_string(), f[3], "({x}, {y}) object");
        assert_eq!(patch[i].to_string(), f[4], "({x}, {y}) patch");
        for k in 0..3 {
            close(p[k][i] as f64, num(7 + k), "P");
            close(n[k][i] as f64, num(10 + k), "N");
        }
    }
    assert!(hits > 10 && misses > 10, "{hits} hits, {misses} misses");

    // Tiles with their layers merge into the same file.
    let mut args = vec!["merge".to_string()];
    for k in 0..3 {
        let piece = dir.path().join(format!("t{k}.exr"));
        let tile = format!("{k}/3");
        let o = render(
            &testdata("teapot.ron"),
            &piece,
            (W, H),
            &["--aov", "all", "--spp", "4", "--tile", &tile],
        );
        assert!(o.status.success(), "{}", stderr(&o));
        args.push(piece.to_str().unwrap().to_string());
    }
    let merged = dir.path().join("m.exr");
    args.extend(["-o".into(), merged.to_str().unwrap().into()]);
    let o = run(&args.iter().map(String::as_str).collect::<Vec<_>>());
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(std::fs::read(&merged).unwrap() == std::fs::read(&out).unwrap());
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn normalize(a: [f64; 3]) -> [f64; 3] {
    let l = (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
    a.map(|c| c / l)
}
