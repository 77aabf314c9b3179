//! Triangle meshes from polygonal OBJ and glTF: the same cube from both.

use std::path::{Path, PathBuf};

use glam::DVec3;
use patchtrace::scene::TriangleMesh;
use patchtrace::scene::gltf_mesh::read_gltf;
use patchtrace::scene::mesh::read_obj_mesh;

fn testdata(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("testdata")
        .join(name)
}

/// Triangles as corner coordinates, each rotated to start at its smallest corner (keeping
/// orientation), sorted: a form independent of vertex numbering.
fn triangles(m: &TriangleMesh) -> Vec<[[f64; 3]; 3]> {
    let mut tris: Vec<[[f64; 3]; 3]> = m
        .indices
        .iter()
        .map(|t| {
            let c = t.map(|i| m.positions[i as usize].to_array());
            let k = (0..3)
                .min_by(|&a, &b| c[a].partial_cmp(&c[b]).unwrap())
                .unwrap();
            [c[k], c[(k + 1) % 3], c[(k + 2) % 3]]
        })
        .collect();
    tris.sort_by(|a, b| a.partial_cmp(b).unwrap());
    tris
}

/// Surface area and enclosed volume (divergence theorem), computed from the triangles.
fn area_and_volume(m: &TriangleMesh) -> (f64, f64) {
    m.indices.iter().fold((0.0, 0.0), |(a, v), t| {
        let [p, q, r] = t.map(|i| m.positions[i as usize]);
        (
            a + 0.5 * (q - p).cross(r - p).length(),
            v + p.dot(q.cross(r)) / 6.0,
        )
    })
}

#[test]
fn obj_and_gltf_cubes_give_the_same_triangles() {
    let obj = read_obj_mesh(&testdata("quad_mesh.obj")).unwrap_or_else(|e| panic!("{e}"));
    let gltf = read_gltf(&testdata("quad_mesh.gltf")).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(obj.indices.len(), 12, "six quads triangulated");
    assert_eq!(triangles(&obj), triangles(&gltf));
    for m in [&obj, &gltf] {
        // The unit cube [1,2] x [0,1] x [0,1] (the glTF node translates it by x + 1),
        // with outward-facing triangles.
        let (area, volume) = area_and_volume(m);
        assert!((area - 6.0).abs() < 1e-12, "area {area}");
        assert!((volume - 1.0).abs() < 1e-12, "volume {volume}");
        let min = m.positions.iter().fold(DVec3::INFINITY, |a, &p| a.min(p));
        assert_eq!(min, DVec3::new(1.0, 0.0, 0.0));
    }
}

#[test]
fn non_triangle_gltf_primitives_are_refused() {
    let src = std::fs::read_to_string(testdata("quad_mesh.gltf")).unwrap();
    let lines = src.replace("\"mode\": 4", "\"mode\": 1");
    assert_ne!(lines, src);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("lines.gltf");
    std::fs::write(&path, lines).unwrap();
    let e = read_gltf(&path).unwrap_err().to_string();
    // Located at the mesh in the JSON text.
    let place = format!("{}:", path.display());
    assert!(e.starts_with(&place), "{e}");
    assert!(e.contains(": glTF mesh 0 (\""), "{e}");
    assert!(e.contains("expected triangles, found mode Lines"), "{e}");
}

#[test]
fn mesh_errors_name_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let empty = dir.path().join("empty.obj");
    std::fs::write(&empty, "v 0 0 0\nv 1 0 0\n").unwrap();
    let e = read_obj_mesh(&empty).unwrap_err().to_string();
    // At the end of the last line.
    assert!(
        e.starts_with(&format!(
            "{}:2:8: expected at least one face",
            empty.display()
        )),
        "{e}"
    );
    let missing = dir.path().join("missing.gltf");
    let e = read_gltf(&missing).unwrap_err().to_string();
    assert!(
        e.starts_with(&format!("{}: ", missing.display())) && e.contains("No such file"),
        "{e}"
    );
}
