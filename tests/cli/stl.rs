//! STL meshes, ASCII and binary, read everywhere a scene goes and written by `tessellate`:
//! the unit cube's twelve facets in both forms, traced against its closed form, located
//! errors, and a tessellation written as STL read back as the same triangles.

use crate::common;

use std::path::Path;

use common::{run, stderr, testdata, trace_rows};
use glam::DVec3;

/// The unit cube [0, 1]³ as twelve outward-facing triangles.
fn cube() -> Vec<[DVec3; 3]> {
    let v = |i: u32| DVec3::new((i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64);
    // Each face as a quad of corner numbers (bit 0 x, bit 1 y, bit 2 z), counter-clockwise
    // seen from outside.
    let quads = [
        [0, 2, 3, 1], // z = 0
        [4, 5, 7, 6], // z = 1
        [0, 1, 5, 4], // y = 0
        [2, 6, 7, 3], // y = 1
        [0, 4, 6, 2], // x = 0
        [1, 3, 7, 5], // x = 1
    ];
    quads
        .iter()
        .flat_map(|q| [[v(q[0]), v(q[1]), v(q[2])], [v(q[0]), v(q[2]), v(q[3])]])
        .collect()
}

/// ASCII STL of `triangles` in two solids (exporters write one per body), names with
/// spaces, a zero normal as many exporters write.
fn ascii(triangles: &[[DVec3; 3]]) -> String {
    let mut s = String::new();
    for (k, half) in triangles.chunks(triangles.len() / 2).enumerate() {
        s.push_str(&format!("solid body {k} of the cube\n"));
        for t in half {
            s.push_str("  facet normal 0 0 0\n    outer loop\n");
            for p in t {
                s.push_str(&format!("      vertex {:e} {} {}\n", p.x, p.y, p.z));
            }
            s.push_str("    endloop\n  endfacet\n");
        }
        s.push_str(&format!("endsolid body {k} of the cube\n"));
    }
    s
}

/// Binary STL whose header starts with `solid`, as several exporters write it.
fn binary(triangles: &[[DVec3; 3]]) -> Vec<u8> {
    let mut b = b"solid exported by a CAD system".to_vec();
    b.resize(80, 0);
    b.extend((triangles.len() as u32).to_le_bytes());
    for t in triangles {
        b.extend([0f32; 3].iter().flat_map(|x| x.to_le_bytes()));
        for p in t {
            b.extend(p.to_array().iter().flat_map(|&x| (x as f32).to_le_bytes()));
        }
        b.extend(0u16.to_le_bytes());
    }
    b
}

fn write(dir: &Path, name: &str, bytes: &[u8]) -> std::path::PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, bytes).unwrap();
    path
}

#[test]
fn ascii_and_binary_cubes_trace_as_the_closed_form() {
    let dir = tempfile::tempdir().unwrap();
    let a = write(dir.path(), "cube.STL", ascii(&cube()).as_bytes());
    let b = write(dir.path(), "cube-binary.stl", &binary(&cube()));
    // Rays down onto the top face, and through the side x = 1 from outside, and one that
    // passes beside the cube.
    let rays = "0.25 0.5 5 0 0 -1\n0.9 0.1 3 0 0 -2\n4 0.5 0.5 -1 0 0\n2 2 5 0 0 -1\n";
    for path in [&a, &b] {
        let rows = trace_rows(path, rays, &[]);
        let t = |k: usize| rows[k][2].parse::<f64>().unwrap();
        assert_eq!(rows[0][1], "1", "{rows:?}");
        assert!((t(0) - 4.0).abs() < 1e-6, "{rows:?}");
        assert!((t(1) - 1.0).abs() < 1e-6, "{rows:?}");
        assert!((t(2) - 3.0).abs() < 1e-6, "{rows:?}");
        assert_eq!(rows[3][1], "0", "{rows:?}");
        // The geometric normal of the top face, whatever the file's facet normal said.
        let nz: f64 = rows[0][12].parse().unwrap();
        assert!((nz.abs() - 1.0).abs() < 1e-12, "{rows:?}");
    }
    // Shared corners are merged: `info` counts 8 vertices and 12 triangles for both.
    for path in [&a, &b] {
        let o = run(&["info", path.to_str().unwrap(), "--json"]);
        assert!(o.status.success(), "{}", stderr(&o));
        let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        let text = v.to_string();
        assert!(text.contains("\"triangles\":12"), "{text}");
    }
}

#[test]
fn damaged_stl_files_are_refused_where_they_go_wrong() {
    let dir = tempfile::tempdir().unwrap();
    let text = ascii(&cube()).replacen("vertex 1e0 0 0", "vertex 1e0 0 endloop", 1);
    let cut = binary(&cube());
    let mut nan = binary(&cube());
    // Triangle 2, vertex 1, y: 84 + 2·50 + 12 (normal) + 12 (vertex 0) + 4.
    nan[84 + 100 + 28..84 + 100 + 32].copy_from_slice(&f32::NAN.to_le_bytes());
    let cases = [
        (
            write(dir.path(), "a.stl", text.as_bytes()),
            "expected a finite number, found `endloop`",
        ),
        (
            write(dir.path(), "b.stl", &cut[..cut.len() - 7]),
            "byte 80: the binary STL header announces 12 triangles",
        ),
        (
            write(dir.path(), "c.stl", &nan),
            "byte 212: triangle 2, vertex 1",
        ),
        (
            write(dir.path(), "d.stl", b"solid empty\nendsolid empty\n"),
            "expected at least one triangle",
        ),
        (
            write(dir.path(), "e.stl", b"\x00\x01"),
            "byte 2: expected ASCII STL",
        ),
    ];
    for (path, expected) in cases {
        let o = run(&["info", path.to_str().unwrap()]);
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{err}");
        assert!(err.contains(expected), "{}: {err}", path.display());
    }
    // The ASCII error names its line and column: the `endloop` that stands for a number.
    let o = run(&["info", dir.path().join("a.stl").to_str().unwrap()]);
    let line = text
        .lines()
        .position(|l| l.contains("vertex 1e0 0 endloop"))
        .unwrap()
        + 1;
    let column = text.lines().nth(line - 1).unwrap().find("endloop").unwrap() + 1;
    assert!(
        stderr(&o).contains(&format!("a.stl:{line}:{column}:")),
        "{}",
        stderr(&o)
    );
}

#[test]
fn a_tessellation_written_as_stl_reads_back_as_its_triangles() {
    let dir = tempfile::tempdir().unwrap();
    let teapot = testdata("teapot.bpt");
    let (stl, obj) = (dir.path().join("t.stl"), dir.path().join("t.obj"));
    let mut reported = Vec::new();
    for out in [&stl, &obj] {
        let o = run(&[
            "tessellate",
            teapot.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
            "--grid",
            "4,4",
            "-q",
            "--json",
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        reported.push(v["triangles"].as_u64().unwrap());
    }
    // Every triangle the tessellation reports, 84 + 50 bytes each.
    assert_eq!(reported[0], reported[1]);
    assert_eq!(
        std::fs::metadata(&stl).unwrap().len(),
        84 + 50 * reported[0]
    );
    // The same rays hit the STL and the OBJ of the same tessellation at the same t, to the
    // f32 rounding STL stores coordinates with.
    let rays: String = (0..40)
        .map(|k| format!("{} -8 1.2 0 1 0.02\n", -2.0 + 0.1 * k as f64))
        .collect();
    let (a, b) = (trace_rows(&stl, &rays, &[]), trace_rows(&obj, &rays, &[]));
    let mut hits = 0;
    for (x, y) in a.iter().zip(&b) {
        assert_eq!(x[1], y[1], "{x:?} {y:?}");
        if x[1] == "1" {
            hits += 1;
            let (tx, ty): (f64, f64) = (x[2].parse().unwrap(), y[2].parse().unwrap());
            assert!((tx - ty).abs() < 1e-5, "{x:?} {y:?}");
        }
    }
    assert!(hits > 20, "{hits}");
}
