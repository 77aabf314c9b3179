//! big unique scenes: the BVH file with the prepared patches, mapped by
//! `render --bvh`, renders the bytes a fresh build renders; it is refused as stale when an
//! input file's bytes or a transform change (and not when only a material does), refused
//! with a byte offset when truncated or damaged, never with a panic; and the parallel
//! build gives a valid tree, the same for one thread as for two. `trace --bvh` reports
//! what `trace` reports, a subdivision surface's quads included.

use crate::bvh_support;
use crate::common;

use std::path::{Path, PathBuf};

use bvh_support::{Rng, random_boxes};
use common::{render, run, stderr, testdata, trace_rows};
use glam::Vec3;
use patchtrace::accel::bvh::{Bvh, checksum};
use patchtrace::accel::mapped;
use patchtrace::accel::scene::{FromFile, QueryStats, SceneGeometry};
use patchtrace::formats::ron_format::parsed_scene;
use patchtrace::formats::{LoadOptions, load_scene_keyed};
use patchtrace::geom::{Aabb, Ray};
use patchtrace::kernel::Kernel;
use patchtrace::kernel::subdivision::SubdivisionConfig;

/// Three teapots from one `.bpt` file, each placed by its own transform (so 96 distinct
/// patches in world space), and a bilinear floor written inline.
fn scene(dir: &Path, scale: &str, material: &str) -> PathBuf {
    std::fs::copy(testdata("teapot.bpt"), dir.join("teapot.bpt")).unwrap();
    let ron = format!(
        r#"Scene(
    camera: (eye: (0, -12, 6), look_at: (0, 0, 1), up: (0, 0, 1), fov_y: 40, width: 32, height: 32),
    lights: [Point(position: (6, -6, 10), intensity: (1, 1, 1))],
    materials: {{ "pink": (diffuse: ({material}, 0.5, 0.6), specular: 0.6, shininess: 40) }},
    objects: [
        (geometry: File("teapot.bpt"), material: "pink", transform: [Translate(-3, 0, 0)]),
        (geometry: File("teapot.bpt"), material: "pink", transform: [Scale({scale}), Rotate((0, 0, 1), 40)]),
        (geometry: File("teapot.bpt"), material: "pink", transform: [Translate(3, 1, 0)]),
        (geometry: Surfaces([Bezier(degree: (1, 1), points: [(-9, -9, 0), (9, -9, 0), (-9, 9, 0), (9, 9, 0)])]), material: "pink"),
    ],
)"#
    );
    let path = dir.join("three.ron");
    std::fs::write(&path, ron).unwrap();
    path
}

fn build(scene: &Path, bvh: &Path) -> String {
    let o = run(&["bvh", scene.to_str().unwrap(), "-o", bvh.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    stderr(&o)
}

fn render_bytes(scene: &Path, out: &Path, extra: &[&str]) -> Vec<u8> {
    let o = render(scene, out, (32, 32), extra);
    assert!(o.status.success(), "{}", stderr(&o));
    std::fs::read(out).unwrap()
}

/// `render --bvh` on `scene` with `bvh`, expected to be refused: exit code 2, no image,
/// no panic; returns stderr.
fn refused(scene: &Path, bvh: &Path) -> String {
    let out = scene.with_extension("refused.png");
    let o = render(scene, &out, (32, 32), &["--bvh", bvh.to_str().unwrap()]);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    assert!(!out.exists());
    err
}

#[test]
fn the_mapped_file_renders_the_bytes_of_a_fresh_build() {
    let dir = tempfile::tempdir().unwrap();
    let scene = scene(dir.path(), "1.2", "0.9");
    let bvh = dir.path().join("three.bvh");
    let said = build(&scene, &bvh);
    assert!(said.contains("with the prepared patches"), "{said}");
    let fresh = render_bytes(&scene, &dir.path().join("fresh.png"), &[]);
    let mapped = render_bytes(
        &scene,
        &dir.path().join("mapped.png"),
        &["--bvh", bvh.to_str().unwrap()],
    );
    assert_eq!(fresh, mapped);
    // The file holds every patch: 3 × 32 teapot patches and the floor.
    let len = std::fs::metadata(&bvh).unwrap().len() as usize;
    assert!(len > 97 * mapped::RECORD_BYTES, "{len} bytes");
}

#[test]
fn with_defer_the_geometry_files_are_keyed_but_not_read() {
    let dir = tempfile::tempdir().unwrap();
    let scene = scene(dir.path(), "1.2", "0.9");
    let (full, key) = load_scene_keyed(&scene, LoadOptions::default(), false, None).unwrap();
    let (deferred, deferred_key) =
        load_scene_keyed(&scene, LoadOptions::default(), true, None).unwrap();
    assert_eq!(key, deferred_key);
    assert_eq!(full.objects.len(), deferred.objects.len());
    assert_eq!(full.objects[0].bezier_patches().len(), 32);
    // The file objects have no geometry; the inline floor keeps its patch.
    let counts: Vec<usize> = deferred
        .objects
        .iter()
        .map(|o| o.bezier_patches().len())
        .collect();
    assert_eq!(counts, [0, 0, 0, 1]);
}

#[test]
fn a_changed_byte_or_transform_makes_the_file_stale_a_material_does_not() {
    let dir = tempfile::tempdir().unwrap();
    let scene = scene(dir.path(), "1.2", "0.9");
    let bvh = dir.path().join("three.bvh");
    build(&scene, &bvh);

    // A material is not geometry: the file still serves.
    let recoloured = self::scene(dir.path(), "1.2", "0.3");
    render_bytes(
        &recoloured,
        &dir.path().join("ok.png"),
        &["--bvh", bvh.to_str().unwrap()],
    );

    // A transform: stale.
    let moved = self::scene(dir.path(), "1.25", "0.9");
    assert!(refused(&moved, &bvh).contains("rebuild"));

    // One byte of the geometry file, same size: stale.
    let scene = self::scene(dir.path(), "1.2", "0.9");
    let bpt = dir.path().join("teapot.bpt");
    let mut bytes = std::fs::read(&bpt).unwrap();
    let at = bytes
        .iter()
        .rposition(|b| b.is_ascii_digit() && *b != b'9')
        .unwrap();
    bytes[at] += 1;
    std::fs::write(&bpt, &bytes).unwrap();
    let err = refused(&scene, &bvh);
    assert!(
        err.contains("rebuild") && err.contains("different inputs"),
        "{err}"
    );
}

#[test]
fn an_old_version_file_is_refused_with_rebuild_advice() {
    let dir = tempfile::tempdir().unwrap();
    let scene = scene(dir.path(), "1.2", "0.9");
    let bvh = dir.path().join("three.bvh");
    build(&scene, &bvh);
    let mut bytes = std::fs::read(&bvh).unwrap();
    bytes[8..12].copy_from_slice(&1u32.to_le_bytes());
    std::fs::write(&bvh, &bytes).unwrap();
    let err = refused(&scene, &bvh);
    assert!(
        err.contains("version 1") && err.contains("rebuild"),
        "{err}"
    );
}

/// Where the parts of a scene's BVH file start: (patch section, records, its checksum,
/// scene section), and the file's length by the layout in `accel::mapped`.
fn layout(bytes: &[u8]) -> (usize, usize, usize, usize, usize) {
    let word = |at: usize| u64::from_le_bytes(bytes[at..at + 8].try_into().unwrap()) as usize;
    let (nodes, prims) = (word(20), word(28));
    let section = (36 + 32 * nodes + 4 * prims + 8).next_multiple_of(8);
    let records = section + 56;
    let end = records + word(section + 8) * mapped::RECORD_BYTES;
    let scene = end + 8;
    (
        section,
        records,
        end,
        scene,
        scene + 16 + word(scene + 8) + 8,
    )
}

#[test]
fn truncated_and_damaged_files_are_refused_with_the_byte_offset() {
    let dir = tempfile::tempdir().unwrap();
    let scene = scene(dir.path(), "1.2", "0.9");
    let bvh = dir.path().join("three.bvh");
    build(&scene, &bvh);
    let (loaded, source) = load_scene_keyed(&scene, LoadOptions::default(), true, None).unwrap();
    let key = mapped::key(source, false);
    let objects = loaded.objects.len();
    let good = std::fs::read(&bvh).unwrap();
    let open = |bytes: &[u8]| {
        let path = dir.path().join("damaged.bvh");
        std::fs::write(&path, bytes).unwrap();
        mapped::map(&path)
            .and_then(|o| o.check(&path, key, objects))
            .map(|f| f.patches.is_some())
    };
    assert!(open(&good).unwrap());
    let (section, records, end, scene_section, len) = layout(&good);
    assert_eq!(len, good.len());

    // Every cut, in steps that land in every part of the file, names where the file ends.
    let parts = [
        section,
        records,
        end,
        end + 7,
        scene_section,
        scene_section + 16,
    ];
    for len in (0..good.len()).step_by(37).chain(parts) {
        let err = open(&good[..len]).unwrap_err().to_string();
        let names_it =
            err.contains(&format!("byte {len}:")) || (len == 0 && err.contains("byte 0"));
        assert!(names_it, "length {len}: {err}");
    }
    // A flipped byte in a record fails the section's checksum, at the checksum's offset.
    let mut flipped = good.clone();
    flipped[records + 100] ^= 0x40;
    let err = open(&flipped).unwrap_err().to_string();
    assert!(
        err.contains(&format!("byte {end}: patch section checksum")),
        "{err}"
    );

    // A record naming an object the scene does not have, resealed: refused at the record.
    let mut forged = good.clone();
    let object_field = records + 4 * 48 + 4 * 6 + 4;
    forged[object_field..object_field + 4].copy_from_slice(&99u32.to_le_bytes());
    let sum = checksum(&forged[section..end]);
    forged[end..end + 8].copy_from_slice(&sum.to_le_bytes());
    let err = open(&forged).unwrap_err().to_string();
    assert!(
        err.contains(&format!("byte {records}: patch record 0: object 99")),
        "{err}"
    );

    // Random damage to the patch section, resealed: never a panic, and geometry from a
    // file that is accepted answers queries without one (in-process, so a panic fails).
    let mut rng = Rng::new(19);
    let precision = Kernel::F32(SubdivisionConfig::default());
    let path = dir.path().join("forged.bvh");
    for _ in 0..40 {
        let mut bytes = good.clone();
        for _ in 0..1 + rng.next_u64() % 8 {
            let at = section + (rng.next_u64() as usize) % (end - section);
            bytes[at] = rng.next_u64() as u8;
        }
        let sum = checksum(&bytes[section..end]);
        bytes[end..end + 8].copy_from_slice(&sum.to_le_bytes());
        std::fs::write(&path, &bytes).unwrap();
        let opened = mapped::map(&path).and_then(|o| o.check(&path, key, objects));
        if let Ok(FromFile::Mapped(geometry, _)) = opened.map(SceneGeometry::from_file) {
            for k in 0..64 {
                let ray = Ray {
                    origin: Vec3::new(-6.0 + 0.2 * k as f32, -12.0, 6.0),
                    dir: Vec3::new(0.0, 12.0, -5.0),
                    tmin: 0.0,
                    tmax: f32::INFINITY,
                };
                let mut stats = QueryStats::default();
                let _ = geometry.intersect(&ray, &precision, &mut stats);
                let _ = geometry.occluded(&ray, &precision, &mut stats);
            }
        }
    }
}

#[test]
fn the_file_keeps_the_scene_parse_and_uses_it_only_for_unchanged_text() {
    let dir = tempfile::tempdir().unwrap();
    let scene = scene(dir.path(), "1.2", "0.9");
    let (hash, json) = parsed_scene(&scene).expect("the scene's parse is kept");
    let read = |parsed: Option<(u64, &[u8])>| {
        let (s, key) = load_scene_keyed(&scene, LoadOptions::default(), true, parsed).unwrap();
        (
            format!("{:?}", (&s.camera, &s.lights, &s.materials, &s.objects)),
            key,
        )
    };
    // The kept parse gives the scene the text gives.
    assert_eq!(read(Some((hash, &json))), read(None));
    // It is what is read when the text's hash matches: a parse with another field of view
    // shows through...
    let text = String::from_utf8(json.clone()).unwrap();
    assert!(text.contains("\"fov_y\":40.0"), "{text}");
    let other = text.replace("\"fov_y\":40.0", "\"fov_y\":30.0");
    let (s, _) = load_scene_keyed(
        &scene,
        LoadOptions::default(),
        true,
        Some((hash, other.as_bytes())),
    )
    .unwrap();
    assert_eq!(s.camera.fov_y, 30.0);
    // ...but not once the text changed, and JSON that does not parse is ignored.
    let (s, _) = load_scene_keyed(
        &scene,
        LoadOptions::default(),
        true,
        Some((hash ^ 1, other.as_bytes())),
    )
    .unwrap();
    assert_eq!(s.camera.fov_y, 40.0);
    assert_eq!(read(Some((hash, b"{not json"))), read(None));
}

fn contains(outer: &Aabb, inner: &Aabb) -> bool {
    outer.min.cmple(inner.min).all() && outer.max.cmpge(inner.max).all()
}

/// Every primitive in exactly one leaf, every child inside its parent's box, and each
/// leaf's box the union of its primitives' boxes.
fn assert_valid(bvh: &Bvh, boxes: &[Aabb]) {
    let mut seen = vec![0u32; boxes.len()];
    for n in bvh.nodes() {
        if n.is_leaf() {
            let prims = &bvh.prim_indices()[n.first as usize..(n.first + n.count) as usize];
            let union = prims
                .iter()
                .fold(Aabb::EMPTY, |b, &p| b.union(&boxes[p as usize]));
            assert_eq!(n.bounds, union);
            prims.iter().for_each(|&p| seen[p as usize] += 1);
        } else {
            for c in [n.first, n.first + 1] {
                assert!(contains(&n.bounds, &bvh.nodes()[c as usize].bounds));
            }
        }
    }
    assert!(seen.iter().all(|&s| s == 1));
}

#[test]
fn the_parallel_build_is_valid_and_the_same_on_one_thread_and_two() {
    // Enough boxes that the root range bins in parallel chunks (2^15) and the upper levels
    // build their subtrees as parallel tasks (2^12).
    let boxes = random_boxes(&mut Rng::new(7), 70_000);
    let on = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| Bvh::build(&boxes))
    };
    let (one, two) = (on(1), on(2));
    assert_valid(&two, &boxes);
    assert_eq!(one.nodes(), two.nodes());
    assert_eq!(one.prim_indices(), two.prim_indices());
}

/// A subdivision surface's patches come from the file, but `trace` reports the quad after
/// the first Catmull–Clark step and (u, v) in it (DESIGN.md via README): the file keeps
/// where each patch lies, so `trace --bvh` prints the rows `trace` prints, and every
/// reported patch of the cube is one of its 24 quads (its 1320 patches are not).
#[test]
fn trace_with_the_file_reports_the_quads_of_a_subdivision_surface() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::copy(
        testdata("opensubdiv/catmark_cube.obj"),
        dir.path().join("cube.obj"),
    )
    .unwrap();
    std::fs::copy(testdata("teapot.bpt"), dir.path().join("teapot.bpt")).unwrap();
    let scene = dir.path().join("cage.ron");
    std::fs::write(
        &scene,
        r#"Scene(
    camera: (eye: (0, -9, 3), look_at: (0, 0, 0), up: (0, 0, 1), fov_y: 40, width: 32, height: 32),
    lights: [Point(position: (6, -6, 10), intensity: (1, 1, 1))],
    materials: { "grey": (diffuse: (0.7, 0.7, 0.7)) },
    objects: [
        (geometry: Subdivision(File("cube.obj")), material: "grey"),
        (geometry: File("teapot.bpt"), material: "grey", transform: [Translate(4, 0, 0)]),
    ],
)"#,
    )
    .unwrap();
    let bvh = dir.path().join("cage.bvh");
    assert!(build(&scene, &bvh).contains("with the prepared patches"));
    let rays = rays_at_the_cube(2000);
    let fresh = trace_rows(&scene, &rays, &[]);
    let mapped = trace_rows(&scene, &rays, &["--bvh", bvh.to_str().unwrap()]);
    assert_eq!(fresh, mapped);
    let cube_hits: Vec<u32> = fresh
        .iter()
        .filter(|r| r[1] == "1" && r[3] == "0")
        .map(|r| r[4].parse().unwrap())
        .collect();
    assert!(cube_hits.len() > 1500, "{} hits", cube_hits.len());
    assert!(cube_hits.iter().all(|&q| q < 24), "{cube_hits:?}");
    // Pieces beyond the whole quads were reported through the file: some hit patches lie
    // near the extraordinary vertices, inside a quad's corner.
    let near_corner = fresh.iter().filter(|r| {
        r[1] == "1" && r[3] == "0" && {
            let (u, v): (f64, f64) = (r[5].parse().unwrap(), r[6].parse().unwrap());
            u.min(1.0 - u).max(v.min(1.0 - v)) < 0.05
        }
    });
    assert!(near_corner.count() > 0);
}

/// Rays from a sphere of radius 6 around the cube cage towards points near its centre.
fn rays_at_the_cube(count: usize) -> String {
    let mut rng = Rng::new(77);
    let mut rays = String::new();
    for _ in 0..count {
        let d = loop {
            let v = Vec3::new(
                rng.range(-1.0, 1.0),
                rng.range(-1.0, 1.0),
                rng.range(-1.0, 1.0),
            );
            if (0.1..1.0).contains(&v.length_squared()) {
                break v.normalize();
            }
        };
        let aim = Vec3::new(
            rng.range(-0.6, 0.6),
            rng.range(-0.6, 0.6),
            rng.range(-0.6, 0.6),
        );
        let o = d * 6.0;
        let dir = aim - o;
        rays.push_str(&format!(
            "{} {} {} {} {} {}\n",
            o.x, o.y, o.z, dir.x, dir.y, dir.z
        ));
    }
    rays
}

/// The BVH file of a bare geometry file keeps its scene without the geometry (the framing
/// camera and light, the geometry's bounds for framing again at another size, the object
/// names): `render --bvh` and `trace --bvh` on a bare cage read no geometry (the deferred
/// load has no patches) and give a fresh run's bytes and rows, at an overridden size too.
#[test]
fn a_bare_file_renders_from_its_bvh_file_without_reading_its_geometry() {
    let dir = tempfile::tempdir().unwrap();
    let cage = dir.path().join("cube.obj");
    std::fs::copy(testdata("opensubdiv/catmark_cube.obj"), &cage).unwrap();
    let bvh = dir.path().join("cube.bvh");
    let (cage_arg, bvh_arg) = (cage.to_str().unwrap(), bvh.to_str().unwrap());
    let subdivide = ["--subdivide", "catmull-clark"];
    let o = run(&[
        "bvh",
        cage_arg,
        "--subdivide",
        "catmull-clark",
        "-o",
        bvh_arg,
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stderr(&o).contains("with the prepared patches"));
    let options = LoadOptions {
        subdivide: true,
        ..LoadOptions::default()
    };
    let opened = mapped::map(&bvh).unwrap();
    let (deferred, key) =
        load_scene_keyed(&cage, options.clone(), true, Some(opened.cached_scene())).unwrap();
    let (full, full_key) = load_scene_keyed(&cage, options, false, None).unwrap();
    assert_eq!(key, full_key);
    assert_eq!(deferred.objects.len(), full.objects.len());
    assert_eq!(deferred.objects[0].bezier_patches().len(), 0);
    assert_eq!(full.objects[0].bezier_patches().len(), 1320);
    assert_eq!(deferred.camera, full.camera);
    assert_eq!(deferred.bounds(), full.bounds());
    let with_file = [subdivide[0], subdivide[1], "--bvh", bvh_arg];
    for (w, h) in [(32, 32), (40, 24)] {
        let image = |name: &str, extra: &[&str]| {
            let out = dir.path().join(name);
            let o = render(&cage, &out, (w, h), extra);
            assert!(o.status.success(), "{}", stderr(&o));
            std::fs::read(out).unwrap()
        };
        assert_eq!(
            image("fresh.png", &subdivide),
            image("mapped.png", &with_file),
            "{w}x{h}"
        );
    }
    let rays = rays_at_the_cube(500);
    let fresh = trace_rows(&cage, &rays, &subdivide);
    let mapped = trace_rows(
        &cage,
        &rays,
        &[subdivide[0], subdivide[1], "--bvh", bvh_arg],
    );
    assert_eq!(fresh, mapped);
    assert!(fresh.iter().filter(|r| r[1] == "1").count() > 400);
}
