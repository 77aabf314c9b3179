//! Tessellation: vertices on the exact surface, crack-free meshes across patch borders,
//! triangle-count rules and the mesh writers.

use std::collections::HashMap;
use std::path::Path;

use glam::DVec3;
use patchtrace::geom::BezierPatch;
use patchtrace::scene::bpt::read_bpt;
use patchtrace::tessellate::{PatchMesh, TessellationMode, grid_for_triangles, tessellate_patches};

fn teapot() -> Vec<BezierPatch> {
    read_bpt(Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/testdata/teapot.bpt"
    )))
    .unwrap()
}

fn box_diagonal(patches: &[BezierPatch]) -> f64 {
    patches
        .iter()
        .map(|p| p.control_box())
        .reduce(|a, b| a.union(&b))
        .unwrap()
        .diagonal()
}

/// A patch side as (u, v) at position t, counter-clockwise: bottom, right, top, left.
fn side_param(side: usize, t: f64) -> (f64, f64) {
    match side {
        0 => (t, 0.0),
        1 => (1.0, t),
        2 => (1.0 - t, 1.0),
        _ => (0.0, 1.0 - t),
    }
}

fn side_point(p: &BezierPatch, side: usize, t: f64) -> DVec3 {
    let (u, v) = side_param(side, t);
    p.eval(u, v)
}

/// Sides that no other patch side covers, found by geometry alone (end points and
/// mid-points evaluated with `BezierPatch::eval`), and sides collapsed to a point.
fn open_sides(patches: &[BezierPatch], tol: f64) -> Vec<(usize, usize)> {
    let close = |a: DVec3, b: DVec3| a.distance(b) <= tol;
    let mut open = Vec::new();
    for (pi, p) in patches.iter().enumerate() {
        for s in 0..4 {
            let (a, m, b) = (
                side_point(p, s, 0.0),
                side_point(p, s, 0.5),
                side_point(p, s, 1.0),
            );
            if close(a, m) && close(m, b) {
                continue; // collapsed to a point (the lid's knob and the bottom's centre)
            }
            let shared = patches.iter().enumerate().any(|(qi, q)| {
                (0..4).any(|r| {
                    if (qi, r) == (pi, s) {
                        return false;
                    }
                    let (c, n, d) = (
                        side_point(q, r, 0.0),
                        side_point(q, r, 0.5),
                        side_point(q, r, 1.0),
                    );
                    close(m, n) && ((close(a, c) && close(b, d)) || (close(a, d) && close(b, c)))
                })
            });
            if !shared {
                open.push((pi, s));
            }
        }
    }
    open
}

/// Edges (sorted vertex pairs) and how many triangles use each.
fn edge_uses(mesh: &PatchMesh) -> HashMap<(u32, u32), u32> {
    let mut uses = HashMap::new();
    for t in &mesh.mesh.indices {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            *uses.entry((a.min(b), a.max(b))).or_insert(0) += 1;
        }
    }
    uses
}

/// A side curve as a dense polyline (`samples` segments).
fn polyline(p: &BezierPatch, side: usize, samples: usize) -> Vec<DVec3> {
    (0..=samples)
        .map(|k| side_point(p, side, k as f64 / samples as f64))
        .collect()
}

/// Distance from `q` to a polyline.
fn distance_to_polyline(line: &[DVec3], q: DVec3) -> f64 {
    line.windows(2)
        .map(|w| {
            let (a, ab) = (w[0], w[1] - w[0]);
            let t = ((q - a).dot(ab) / ab.length_squared().max(f64::MIN_POSITIVE)).clamp(0.0, 1.0);
            q.distance(a + ab * t)
        })
        .fold(f64::INFINITY, f64::min)
}

/// The teapot's true boundary curves as (patch, side 0..4 = v=0, u=1, v=1, u=0). The
/// Utah teapot is not closed: the body's upper rim (patches 0–3, the circle r = 1.4 at
/// z = 2.4) and the lid's outer rim (24–27, r = 1.3 at z = 2.4) are open edges where lid
/// and body merely sit on each other; the handle's two ends (12–13 at x ≈ −1.55,
/// 14–15 at x ≈ −1.95) and the spout's base (16–17, x = 1.7) end inside the body without
/// meeting it; the spout's tip (18–19, x = 2.8…3.2, z = 2.4) is an open mouth.
const TEAPOT_OPEN_SIDES: [(usize, usize); 16] = [
    (0, 0),
    (1, 0),
    (2, 0),
    (3, 0),
    (12, 0),
    (13, 0),
    (14, 2),
    (15, 2),
    (16, 0),
    (17, 0),
    (18, 2),
    (19, 2),
    (24, 2),
    (25, 2),
    (26, 2),
    (27, 2),
];

#[test]
fn teapot_open_boundaries_are_the_known_ones() {
    let patches = teapot();
    let open = open_sides(&patches, 1e-9 * box_diagonal(&patches));
    assert_eq!(open, TEAPOT_OPEN_SIDES.to_vec());
}

/// Every vertex is the exact surface point at its (u, v), evaluated again in f64.
fn assert_on_surface(patches: &[BezierPatch], mesh: &PatchMesh) {
    let tol = 1e-12 * box_diagonal(patches);
    assert_eq!(mesh.params.len(), mesh.mesh.positions.len());
    for (p, q) in mesh.params.iter().zip(&mesh.mesh.positions) {
        let exact = patches[p.patch as usize].eval(p.u, p.v);
        assert!(
            exact.distance(*q) <= tol,
            "vertex {q} is {} from the surface",
            exact.distance(*q)
        );
    }
    for n in &mesh.mesh.normals {
        assert!((n.length() - 1.0).abs() < 1e-12, "normal {n} not unit");
    }
}

/// Crack-freeness: every edge is used by exactly two triangles, except edges on the
/// model's true boundary curves, which are used once. Returns the number of boundary edges.
fn assert_crack_free(patches: &[BezierPatch], mesh: &PatchMesh) -> usize {
    let diag = box_diagonal(patches);
    // 2048 segments approximate each curve to ~1e-7 of the model's size.
    let open: Vec<Vec<DVec3>> = TEAPOT_OPEN_SIDES
        .iter()
        .map(|&(p, s)| polyline(&patches[p], s, 2048))
        .collect();
    let mut boundary = 0;
    for ((a, b), n) in edge_uses(mesh) {
        assert!(n <= 2, "edge ({a},{b}) used by {n} triangles");
        if n == 1 {
            boundary += 1;
            let (pa, pb) = (
                mesh.mesh.positions[a as usize],
                mesh.mesh.positions[b as usize],
            );
            // Both ends on the same open curve, and the chord's mid-point near it (off by
            // no more than the chord height).
            let on_open_side = open.iter().any(|line| {
                distance_to_polyline(line, pa) <= 1e-6 * diag
                    && distance_to_polyline(line, pb) <= 1e-6 * diag
                    && distance_to_polyline(line, 0.5 * (pa + pb)) <= 1e-2 * diag
            });
            assert!(
                on_open_side,
                "crack: edge {pa} – {pb} is used once but is not on a true boundary"
            );
        }
    }
    boundary
}

#[test]
fn uniform_teapot_is_on_surface_and_crack_free() {
    let patches = teapot();
    let mesh = tessellate_patches(&patches, TessellationMode::TrianglesPerPatch(512)).unwrap();
    assert_on_surface(&patches, &mesh);
    // 16 segments on each of the 16 open sides.
    assert_eq!(
        assert_crack_free(&patches, &mesh),
        16 * TEAPOT_OPEN_SIDES.len()
    );
    // 512 per patch, less the triangles that collapse to a line at the lid's knob and the
    // bottom's centre (one per grid column at each collapsed side, 16 columns).
    let collapsed_sides = count_collapsed_sides(&patches);
    assert_eq!(mesh.mesh.indices.len(), 32 * 512 - 16 * collapsed_sides);
}

fn count_collapsed_sides(patches: &[BezierPatch]) -> usize {
    patches
        .iter()
        .map(|p| {
            (0..4)
                .filter(|&s| {
                    side_point(p, s, 0.0) == side_point(p, s, 1.0)
                        && side_point(p, s, 0.0) == side_point(p, s, 0.5)
                })
                .count()
        })
        .sum()
}

#[test]
fn adaptive_teapot_is_on_surface_and_crack_free() {
    let patches = teapot();
    let tolerance = 1e-3 * box_diagonal(&patches);
    let mesh = tessellate_patches(&patches, TessellationMode::Adaptive { tolerance }).unwrap();
    assert_on_surface(&patches, &mesh);
    assert!(assert_crack_free(&patches, &mesh) > 0);
}

#[test]
fn adaptive_mixed_rates_stitch_crack_free() {
    // Two patches sharing one edge: a flat one (few segments) and a strongly bent one
    // (many), so the shared edge and the grids differ and the ring stitch is used.
    let flat: Vec<DVec3> = (0..16)
        .map(|k| DVec3::new((k % 4) as f64, (k / 4) as f64, 0.0))
        .collect();
    let bent: Vec<DVec3> = (0..16)
        .map(|k| {
            let (i, j) = ((k % 4) as f64, (k / 4) as f64);
            DVec3::new(i, -j, if j > 0.0 { (i * 1.7).sin() * j } else { 0.0 })
        })
        .collect();
    let patches = vec![
        BezierPatch::from_points(3, 3, &flat).unwrap(),
        BezierPatch::from_points(3, 3, &bent).unwrap(),
    ];
    let mesh =
        tessellate_patches(&patches, TessellationMode::Adaptive { tolerance: 1e-3 }).unwrap();
    assert_on_surface(&patches, &mesh);
    let open_ids: Vec<(usize, usize)> = open_sides(&patches, 1e-12);
    assert_eq!(
        open_ids.len(),
        6,
        "two patches sharing one side leave six open sides"
    );
    let open: Vec<Vec<DVec3>> = open_ids
        .iter()
        .map(|&(p, s)| polyline(&patches[p], s, 4096))
        .collect();
    for ((a, b), n) in edge_uses(&mesh) {
        assert!(n <= 2);
        if n == 1 {
            let (pa, pb) = (
                mesh.mesh.positions[a as usize],
                mesh.mesh.positions[b as usize],
            );
            let on_open = open.iter().any(|line| {
                distance_to_polyline(line, pa) <= 1e-6
                    && distance_to_polyline(line, pb) <= 1e-6
                    && distance_to_polyline(line, 0.5 * (pa + pb)) <= 1e-2
            });
            assert!(on_open, "crack at {pa} – {pb}");
        }
    }
}

#[test]
fn triangle_counts_map_to_grids() {
    assert_eq!(grid_for_triangles(512).unwrap(), (16, 16));
    assert_eq!(grid_for_triangles(4608).unwrap(), (48, 48));
    assert_eq!(grid_for_triangles(131072).unwrap(), (256, 256));
    assert_eq!(grid_for_triangles(12).unwrap(), (3, 2));
    for bad in [0, 7, 513] {
        let e = grid_for_triangles(bad).unwrap_err().to_string();
        assert!(
            e.contains(&bad.to_string()) && e.contains("2·g_u·g_v"),
            "{e}"
        );
    }
    assert!(tessellate_patches(&teapot(), TessellationMode::Adaptive { tolerance: -1.0 }).is_err());
    assert!(
        tessellate_patches(
            &teapot(),
            TessellationMode::Uniform {
                grid_u: 0,
                grid_v: 3
            }
        )
        .is_err()
    );
}

#[test]
fn gltf_glb_and_obj_round_trip() {
    use patchtrace::scene::model::{Geometry, Object, Scene};
    let patches = teapot();
    let mesh = tessellate_patches(
        &patches[..4],
        TessellationMode::Uniform {
            grid_u: 4,
            grid_v: 3,
        },
    )
    .unwrap()
    .mesh;
    let scene = Scene::framing(vec![Object {
        name: "rim".into(),
        material: 0,
        geometry: Geometry::Mesh(mesh.clone()),
    }]);
    let dir = tempfile::tempdir().unwrap();
    for name in ["m.gltf", "m.glb"] {
        let path = dir.path().join(name);
        let bytes = patchtrace::tessellate::write_mesh_scene(&path, &scene).unwrap();
        assert_eq!(bytes, std::fs::metadata(&path).unwrap().len());
        let (doc, buffers, _) = gltf::import(&path).unwrap();
        let prim = doc.meshes().next().unwrap().primitives().next().unwrap();
        let reader = prim.reader(|b| Some(&buffers[b.index()]));
        let pos: Vec<[f32; 3]> = reader.read_positions().unwrap().collect();
        let nrm: Vec<[f32; 3]> = reader.read_normals().unwrap().collect();
        let idx: Vec<u32> = reader.read_indices().unwrap().into_u32().collect();
        assert_eq!(
            pos,
            mesh.positions
                .iter()
                .map(|p| p.as_vec3().to_array())
                .collect::<Vec<_>>()
        );
        assert_eq!(
            nrm,
            mesh.normals
                .iter()
                .map(|p| p.as_vec3().to_array())
                .collect::<Vec<_>>()
        );
        assert_eq!(
            idx,
            mesh.indices.iter().flatten().copied().collect::<Vec<_>>()
        );
    }
    let path = dir.path().join("m.obj");
    patchtrace::tessellate::write_mesh_scene(&path, &scene).unwrap();
    let (models, _) = tobj::load_obj(
        &path,
        &tobj::LoadOptions {
            single_index: false,
            ..Default::default()
        },
    )
    .unwrap();
    let m = &models[0].mesh;
    // tobj renumbers vertices, so compare each triangle's corner positions (written with
    // full f64 precision, read back as f64 by tobj: bit-exact).
    assert_eq!(m.indices.len(), mesh.indices.len() * 3);
    for (k, &i) in m.indices.iter().enumerate() {
        let read = glam::DVec3::from_slice(&m.positions[3 * i as usize..3 * i as usize + 3]);
        let ours = mesh.positions[mesh.indices[k / 3][k % 3] as usize];
        assert_eq!(read, ours);
    }
}
