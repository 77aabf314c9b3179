//! USD stages (testdata/usd, written by Pixar's library with make_usd.py there): rays
//! traced through the usda, usdc and usdz forms of one stage hit where an independent
//! `f64` evaluation puts the surfaces — de Boor's algorithm on the NURBS patches (written
//! here), the global Catmull–Clark reference on the cube — and miss what the trim loops
//! cut away; the instanced copies are placed by their xformOps; the camera follows the
//! focal length and apertures.

use glam::{DAffine3, DMat3, DVec3, DVec4};
use patchtrace::formats::load::load_scene_noted;
use patchtrace::formats::{LoadError, LoadOptions};
use patchtrace::scene::model::Geometry;

use crate::common::{testdata, trace_hits};
use crate::subdiv_common::cube;

const FORMATS: [&str; 3] = ["usda", "usdc", "usdz"];

/// Hits are computed in `f32` by the kernels: within this of the `f64` point (the scene
/// spans about 10 units, and f32 spacing there is 2^-20 ≈ 1e-6).
const TOLERANCE: f64 = 2e-5;

/// De Boor's algorithm (The NURBS Book A2.1 + the triangular scheme of §2.3) for a
/// B-spline curve of `degree` over `knots` with homogeneous points, at `t`.
fn de_boor(degree: usize, knots: &[f64], points: &[DVec4], t: f64) -> DVec4 {
    let n = points.len();
    // The span k with knots[k] <= t < knots[k + 1], clamped into [degree, n - 1].
    let k = (degree..n).rev().find(|&k| knots[k] <= t).unwrap_or(degree);
    let mut d: Vec<DVec4> = (0..=degree).map(|j| points[j + k - degree]).collect();
    for r in 1..=degree {
        for j in (r..=degree).rev() {
            let i = j + k - degree;
            let a = (t - knots[i]) / (knots[i + degree + 1 - r] - knots[i]);
            d[j] = d[j - 1] * (1.0 - a) + d[j] * a;
        }
    }
    d[degree]
}

/// A tensor-product surface by de Boor along u on each row, then along v.
struct Patch {
    degree: (usize, usize),
    knots: (Vec<f64>, Vec<f64>),
    count_u: usize,
    /// Homogeneous, u fastest.
    points: Vec<DVec4>,
}

impl Patch {
    fn eval(&self, u: f64, v: f64) -> DVec3 {
        let column: Vec<DVec4> = self
            .points
            .chunks(self.count_u)
            .map(|row| de_boor(self.degree.0, &self.knots.0, row, u))
            .collect();
        let p = de_boor(self.degree.1, &self.knots.1, &column, v);
        p.truncate() / p.w
    }
}

/// USD stores points as `float3`: what the generator's doubles became.
fn f32ed(x: f64) -> f64 {
    x as f32 as f64
}

/// The generator's trimmed bump patch (make_usd.py, `trimmed_patch`).
fn bump() -> Patch {
    let mut points = Vec::new();
    for j in 0..4 {
        for i in 0..4 {
            let z = if (1..=2).contains(&i) && (1..=2).contains(&j) {
                0.6
            } else {
                0.0
            };
            points.push(DVec4::new(
                f32ed(i as f64 / 3.0),
                f32ed(j as f64 / 3.0),
                f32ed(z),
                1.0,
            ));
        }
    }
    let k = vec![0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0];
    Patch {
        degree: (3, 3),
        knots: (k.clone(), k),
        count_u: 4,
        points,
    }
}

/// Parameter points (u, v).
type Samples = Vec<(f64, f64)>;

/// (u, v) samples of the bump's domain kept by its loops (outside the hole of radius
/// 0.25 about (0.5, 0.5) by a margin) and cut away by them (well inside the hole).
fn bump_samples() -> (Samples, Samples) {
    let (mut kept, mut cut) = (Vec::new(), Vec::new());
    for a in 1..10 {
        for b in 1..10 {
            let (u, v) = (a as f64 / 10.0, b as f64 / 10.0);
            let r = ((u - 0.5).powi(2) + (v - 0.5).powi(2)).sqrt();
            if r > 0.3 {
                kept.push((u, v));
            } else if r < 0.2 {
                cut.push((u, v));
            }
        }
    }
    (kept, cut)
}

/// Rays along the bump's placed z axis onto `place`d copies of it at (u, v), from `side`
/// (+1 above, -1 below): every kept sample is hit at its de Boor point, every cut one
/// missed.
fn check_bump(path: &std::path::Path, place: &DAffine3, side: f64, what: &str) {
    let patch = bump();
    let (kept, cut) = bump_samples();
    let up = place.transform_vector3(DVec3::Z).normalize() * side;
    let above = |p: DVec3| (p + up * 20.0, -up);
    let kept_points: Vec<DVec3> = kept
        .iter()
        .map(|&(u, v)| place.transform_point3(patch.eval(u, v)))
        .collect();
    let hits = trace_hits(
        path,
        &kept_points.iter().map(|&p| above(p)).collect::<Vec<_>>(),
    );
    for ((uv, p), hit) in kept.iter().zip(&kept_points).zip(&hits) {
        let (h, _) = hit.unwrap_or_else(|| panic!("{what} {uv:?}: kept point {p} missed"));
        assert!(
            (h - *p).length() < TOLERANCE,
            "{what} {uv:?}: hit {h}, de Boor {p}"
        );
    }
    // A cut sample's ray goes through the hole (and through the hole of the copy it
    // lines up with: /World/Copies/A is /World/Trimmed moved up).
    let cut_rays: Vec<_> = cut
        .iter()
        .map(|&(u, v)| above(place.transform_point3(patch.eval(u, v))))
        .collect();
    for (uv, hit) in cut.iter().zip(trace_hits(path, &cut_rays)) {
        assert!(
            hit.is_none(),
            "{what} {uv:?}: trimmed-away point hit at {hit:?}"
        );
    }
}

#[test]
fn trimmed_patch_and_its_instances_are_hit_on_the_surface_and_missed_in_the_hole() {
    for ext in FORMATS {
        let path = testdata(&format!("usd/stage.{ext}"));
        // From below: /World/Copies/A lies above it.
        check_bump(
            &path,
            &DAffine3::IDENTITY,
            -1.0,
            &format!("{ext} /World/Trimmed"),
        );
        // The copies' ops: translate, then rotateZ (degrees), then scale (make_usd.py).
        for (name, t, turn, s) in [
            ("A", DVec3::new(0.0, 0.0, 3.0), 0.0, 1.0),
            ("B", DVec3::new(2.0, 0.0, 3.0), 90.0_f64, 1.0),
            ("C", DVec3::new(4.0, 0.0, 3.0), 0.0, 2.0),
        ] {
            let place = DAffine3::from_translation(t)
                * DAffine3::from_mat3(DMat3::from_rotation_z(turn.to_radians()))
                * DAffine3::from_scale(DVec3::splat(s));
            check_bump(&path, &place, 1.0, &format!("{ext} /World/Copies/{name}"));
        }
    }
}

#[test]
fn rational_and_periodic_patches_are_hit_at_their_de_boor_points() {
    let s = std::f64::consts::FRAC_1_SQRT_2;
    // Quarter cylinder, premultiplied by its weights (1, √2/2, 1), at x = 3.
    let arc = [(1.0, 0.0, 1.0), (1.0, 1.0, s), (0.0, 1.0, 1.0)];
    let rational = Patch {
        degree: (2, 1),
        knots: (vec![0.0, 0.0, 0.0, 1.0, 1.0, 1.0], vec![0.0, 0.0, 1.0, 1.0]),
        count_u: 3,
        points: [0.0, 1.0]
            .iter()
            .flat_map(|&z| {
                arc.iter()
                    .map(move |&(x, y, w)| DVec4::new(x * w, y * w, z * w, w))
            })
            .collect(),
    };
    // Closed cubic tube: 8 points on the unit circle, the first 3 repeated, at y = 3.
    let ring: Vec<(f64, f64)> = (0..11)
        .map(|k| {
            let a = 2.0 * std::f64::consts::PI * (k % 8) as f64 / 8.0;
            (f32ed(a.cos()), f32ed(a.sin()))
        })
        .collect();
    let periodic = Patch {
        degree: (3, 1),
        knots: ((-3..12).map(f64::from).collect(), vec![0.0, 0.0, 1.0, 1.0]),
        count_u: 11,
        points: [0.0, 1.0]
            .iter()
            .flat_map(|&z| ring.iter().map(move |&(x, y)| DVec4::new(x, y, z, 1.0)))
            .collect(),
    };
    for ext in FORMATS {
        let path = testdata(&format!("usd/stage.{ext}"));
        for (what, patch, offset, u_end) in [
            ("Rational", &rational, DVec3::new(3.0, 0.0, 0.0), 1.0),
            ("Periodic", &periodic, DVec3::new(0.0, 3.0, 0.0), 8.0),
        ] {
            let mut targets = Vec::new();
            for a in 0..=8 {
                for b in 1..4 {
                    let (u, v) = (u_end * (0.02 + 0.96 * a as f64 / 8.0), b as f64 / 4.0);
                    targets.push(patch.eval(u, v) + offset);
                }
            }
            // From the axis outward: both surfaces surround it.
            let rays: Vec<_> = targets
                .iter()
                .map(|&p| {
                    let axis = DVec3::new(offset.x, offset.y, p.z);
                    (axis, p - axis)
                })
                .collect();
            for (p, hit) in targets.iter().zip(trace_hits(&path, &rays)) {
                let (h, _) = hit.unwrap_or_else(|| panic!("{ext} {what}: {p} missed"));
                assert!(
                    (h - *p).length() < TOLERANCE,
                    "{ext} {what}: hit {h}, de Boor {p}"
                );
            }
            if what == "Rational" {
                // The rational quadratic is the exact circle: radius 1 about the axis.
                for p in &targets {
                    let r = (p.truncate() - offset.truncate()).length();
                    assert!((r - 1.0).abs() < 1e-12, "{p} at radius {r}");
                }
            }
        }
    }
}

#[test]
fn the_cube_mesh_is_its_catmull_clark_limit_surface_and_the_none_mesh_is_flat() {
    // The stage's cube has the reference cube's corners and faces, at x = -3.
    let offset = DVec3::new(-3.0, 0.0, 0.0);
    let (m, _) = cube().subdivide(2);
    let limits: Vec<DVec3> = (0..m.p.len())
        .filter_map(|v| m.limit(v, &|_, _| false))
        .map(|p| p + offset)
        .collect();
    assert!(limits.len() > 20);
    for ext in FORMATS {
        let path = testdata(&format!("usd/stage.{ext}"));
        let rays: Vec<_> = limits.iter().map(|&p| (offset, p - offset)).collect();
        for (p, hit) in limits.iter().zip(trace_hits(&path, &rays)) {
            let (h, _) = hit.unwrap_or_else(|| panic!("{ext} cube: limit point {p} missed"));
            assert!(
                (h - *p).length() < TOLERANCE,
                "{ext} cube: hit {h}, limit {p}"
            );
        }
        // Two triangles in the plane y = -3 over x, z in [0, 1].
        let rays = [
            (DVec3::new(0.7, -5.0, 0.2), DVec3::Y),
            (DVec3::new(0.2, -5.0, 0.7), DVec3::Y),
        ];
        for ((o, _), hit) in rays.iter().zip(trace_hits(&path, &rays)) {
            let (h, _) = hit.unwrap_or_else(|| panic!("{ext} triangles missed"));
            assert!(
                (h - DVec3::new(o.x, -3.0, o.z)).length() < 1e-6,
                "{ext}: {h}"
            );
        }
        // The quad beside them, x in [1, 2], is in holeIndices: nothing is hit there.
        let through = [(DVec3::new(1.5, -5.0, 0.5), DVec3::Y)];
        assert_eq!(
            trace_hits(&path, &through),
            vec![None],
            "{ext}: the hole quad"
        );
    }
}

#[test]
fn a_hole_face_is_missed_and_its_neighbours_are_the_whole_cubes_limit_surface() {
    // /World/Holed is the reference cube at (-3, -3, 0) with face 2 (its -y side) a
    // hole. Two global steps of the reference: face f's 16 grandchildren are 16 f ..
    // 16 f + 15 (every face a quad). A vertex whose faces all descend from the hole lies
    // inside it, one with none of them outside; those on its rim are left out.
    let offset = DVec3::new(-3.0, -3.0, 0.0);
    let (m, _) = cube().subdivide(2);
    let in_hole = |f: usize| f / 16 == 2;
    let (mut kept, mut cut) = (Vec::new(), Vec::new());
    for v in 0..m.p.len() {
        let faces: Vec<usize> = (0..m.f.len()).filter(|&f| m.f[f].contains(&v)).collect();
        let Some(p) = m.limit(v, &|_, _| false) else {
            continue;
        };
        if faces.iter().all(|&f| in_hole(f)) {
            cut.push(p + offset);
        } else if !faces.iter().any(|&f| in_hole(f)) {
            kept.push(p + offset);
        }
    }
    assert_eq!(cut.len(), 9, "the hole's inner vertices");
    assert!(kept.len() > 40);
    for ext in FORMATS {
        let path = testdata(&format!("usd/stage.{ext}"));
        let rays: Vec<_> = kept.iter().map(|&p| (offset, p - offset)).collect();
        for (p, hit) in kept.iter().zip(trace_hits(&path, &rays)) {
            let (h, _) = hit.unwrap_or_else(|| panic!("{ext} holed cube: limit point {p} missed"));
            assert!(
                (h - *p).length() < TOLERANCE,
                "{ext} holed cube: hit {h}, limit {p}"
            );
        }
        // Out through the hole, towards -y, where the stage has nothing.
        let rays: Vec<_> = cut.iter().map(|&p| (offset, p - offset)).collect();
        for (p, hit) in cut.iter().zip(trace_hits(&path, &rays)) {
            assert!(
                hit.is_none(),
                "{ext}: the ray through {p} in the hole hit {hit:?}"
            );
        }
    }
}

#[test]
fn a_patch_with_a_narrower_range_is_hit_only_inside_it_at_its_de_boor_points() {
    // /World/Ranged (make_usd.py, `ranged_patch`): x depends on u alone and y on v alone,
    // so a vertical ray at a de Boor point of the whole patch meets the patch there if
    // (u, v) is in uRange x vRange and outside the trimmed hole, and nothing otherwise.
    let heights = [0.0, 0.5, -0.3, 0.4, 0.1];
    let mut points = Vec::new();
    for j in 0..4 {
        for (i, h) in heights.iter().enumerate() {
            points.push(DVec4::new(
                f32ed(-6.0 + 0.5 * i as f64),
                f32ed(2.0 + j as f64 / 3.0),
                f32ed(h * (1.0 + 0.5 * j as f64)),
                1.0,
            ));
        }
    }
    let patch = Patch {
        degree: (3, 3),
        knots: (
            vec![0.0, 0.0, 0.0, 0.0, 1.0, 2.0, 2.0, 2.0, 2.0],
            vec![0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0],
        ),
        count_u: 5,
        points,
    };
    let margin = 0.02;
    let (mut kept, mut cut) = (Vec::new(), Vec::new());
    for a in 0..20 {
        for b in 0..10 {
            let (u, v) = (0.05 + 0.1 * a as f64, 0.05 + 0.1 * b as f64);
            let inside = |x: f64, lo: f64, hi: f64| x > lo + margin && x < hi - margin;
            let outside = |x: f64, lo: f64, hi: f64| x < lo - margin || x > hi + margin;
            let r = ((u - 1.0).powi(2) + (v - 0.5).powi(2)).sqrt();
            if inside(u, 0.5, 1.6) && inside(v, 0.2, 0.9) && r > 0.2 + margin {
                kept.push((u, v));
            } else if outside(u, 0.5, 1.6) || outside(v, 0.2, 0.9) || r < 0.2 - margin {
                cut.push((u, v));
            }
        }
    }
    assert!(kept.len() > 30 && cut.len() > 100);
    let ray = |&(u, v): &(f64, f64)| {
        let p = patch.eval(u, v);
        (DVec3::new(p.x, p.y, 20.0), -DVec3::Z)
    };
    for ext in FORMATS {
        let path = testdata(&format!("usd/stage.{ext}"));
        let hits = trace_hits(&path, &kept.iter().map(ray).collect::<Vec<_>>());
        for (uv, hit) in kept.iter().zip(hits) {
            let p = patch.eval(uv.0, uv.1);
            let (h, _) = hit.unwrap_or_else(|| panic!("{ext} {uv:?}: {p} in range missed"));
            assert!(
                (h - p).length() < TOLERANCE,
                "{ext} {uv:?}: hit {h}, de Boor {p}"
            );
        }
        let hits = trace_hits(&path, &cut.iter().map(ray).collect::<Vec<_>>());
        for (uv, hit) in cut.iter().zip(hits) {
            assert!(
                hit.is_none(),
                "{ext} {uv:?}: outside the range or in the hole, hit {hit:?}"
            );
        }
    }
}

#[test]
fn point_instancer_places_each_prototype_by_its_index_position_orientation_and_scale() {
    // /World/Scatter (make_usd.py, `scatter`): at (0, 8, 0); prototype 1 is the bump
    // raised by its own translate (0, 0, 0.25). Instance i is the instancer's placement,
    // then positions[i], orientations[i], scales[i], then the prototype's own transform.
    // The orientations as the rotations they are: none; 120 degrees about (1, 1, 1),
    // which takes x to y, y to z and z to x; 180 degrees about z.
    let cycle = DMat3::from_cols(DVec3::Y, DVec3::Z, DVec3::X);
    let half_turn = DMat3::from_cols(-DVec3::X, -DVec3::Y, DVec3::Z);
    let raised = DAffine3::from_translation(DVec3::new(0.0, 0.0, 0.25));
    let instances = [
        (DVec3::ZERO, DMat3::IDENTITY, DVec3::ONE, DAffine3::IDENTITY),
        (DVec3::new(3.0, 3.0, 0.0), cycle, DVec3::ONE, raised),
        (
            DVec3::new(6.0, 0.0, 1.0),
            half_turn,
            DVec3::new(2.0, 1.0, 0.5),
            DAffine3::IDENTITY,
        ),
    ];
    for ext in FORMATS {
        let path = testdata(&format!("usd/stage.{ext}"));
        for (i, (position, turn, scale, own)) in instances.iter().enumerate() {
            let place = DAffine3::from_translation(DVec3::new(0.0, 8.0, 0.0))
                * DAffine3::from_translation(*position)
                * DAffine3::from_mat3(*turn)
                * DAffine3::from_scale(*scale)
                * *own;
            check_bump(&path, &place, 1.0, &format!("{ext} /World/Scatter[{i}]"));
        }
        // /World/ScatterF at (0, 14, 0): its orientationsf (the cycle) wins over its
        // orientations (none).
        let place =
            DAffine3::from_translation(DVec3::new(0.0, 14.0, 0.0)) * DAffine3::from_mat3(cycle);
        check_bump(&path, &place, 1.0, &format!("{ext} /World/ScatterF[0]"));
    }
}

#[test]
fn boundary_corners_under_edge_and_corner_are_noted_and_edge_only_is_not() {
    // A 2 x 2 grid of quads: four boundary corner vertices (one face each).
    let dir = tempfile::tempdir().unwrap();
    let grid = |name: &str, rule: &str| {
        format!(
            r#"def Mesh "{name}"
{{
    point3f[] points = [(0,0,0),(1,0,0),(2,0,0),(0,1,0),(1,1,1),(2,1,0),(0,2,0),(1,2,0),(2,2,0)]
    int[] faceVertexCounts = [4, 4, 4, 4]
    int[] faceVertexIndices = [0,1,4,3, 1,2,5,4, 3,4,7,6, 4,5,8,7]
    {rule}
}}
"#
        )
    };
    let text = format!(
        "#usda 1.0\n(\n    upAxis = \"Z\"\n)\n{}{}{}",
        grid("Fallback", ""),
        grid("EdgeOnly", r#"token interpolateBoundary = "edgeOnly""#),
        grid("NoBoundary", r#"token interpolateBoundary = "none""#),
    );
    let path = dir.path().join("grids.usda");
    std::fs::write(&path, text).unwrap();
    let (_, notes) = load_scene_noted(&path, LoadOptions::default()).unwrap();
    let about = |prim: &str| -> Vec<&String> {
        notes
            .iter()
            .filter(|n| n.starts_with(prim) && n.contains("interpolateBoundary"))
            .collect()
    };
    let fallback = about("/Fallback:");
    assert!(
        fallback.len() == 1 && fallback[0].contains("at 4 boundary corner vertices"),
        "{notes:?}"
    );
    assert!(about("/EdgeOnly:").is_empty(), "{notes:?}");
    assert_eq!(about("/NoBoundary:").len(), 1, "{notes:?}");
    assert!(
        !notes.iter().any(|n| n.starts_with("not read")),
        "{notes:?}"
    );
}

#[test]
fn the_stage_unit_is_meters_per_unit_or_usds_centimetre_fallback() {
    let dir = tempfile::tempdir().unwrap();
    for (metadata, millimetres) in [("metersPerUnit = 0.0254", 25.4), ("", 10.0)] {
        let path = dir.path().join("unit.usda");
        std::fs::write(
            &path,
            format!(
                r#"#usda 1.0
(
    {metadata}
)
def Mesh "M"
{{
    point3f[] points = [(0,0,0),(1,0,0),(0,1,0)]
    int[] faceVertexCounts = [3]
    int[] faceVertexIndices = [0,1,2]
    token subdivisionScheme = "none"
}}
"#
            ),
        )
        .unwrap();
        let (scene, _) = load_scene_noted(&path, LoadOptions::default()).unwrap();
        let unit = scene.unit.as_ref().expect("a USD stage has a unit");
        assert!(
            (unit.millimetres - millimetres).abs() < 1e-12,
            "{}",
            unit.words
        );
        // Coordinates stay in stage units.
        assert_eq!(scene.bounds().max.x, 1.0);
    }
}

#[test]
fn stage_reads_the_camera_lights_materials_and_shares_the_instances() {
    for ext in FORMATS {
        let path = testdata(&format!("usd/stage.{ext}"));
        let (scene, notes) = load_scene_noted(&path, LoadOptions::default()).unwrap();
        let c = &scene.camera;
        // 35 mm lens on a 36 x 24 aperture: fov_y = 2 atan(12 / 35); 512 wide, 3:2.
        assert!((c.fov_y - 2.0 * (12.0f64 / 35.0).atan().to_degrees()).abs() < 1e-9);
        assert_eq!((c.width, c.height), (512, 341));
        assert!((c.eye - DVec3::new(0.0, -12.0, 4.0)).length() < 1e-9);
        // Looking at the origin: the forward direction is parallel to -eye.
        let forward = (c.look_at - c.eye).normalize();
        assert!(
            forward.cross(-c.eye.normalize()).length() < 1e-6,
            "{forward}"
        );
        assert_eq!(scene.lights.len(), 2, "{ext}");
        let red = scene
            .materials
            .iter()
            .find(|m| m.name == "/World/Looks/Red")
            .expect("the bound UsdPreviewSurface");
        assert_eq!(red.diffuse, glam::Vec3::new(0.8, 0.1, 0.1));
        assert!((red.specular - 0.7).abs() < 1e-6 && red.transmit == 0.0);
        assert_eq!(
            scene.unit.as_ref().map(|u| u.millimetres),
            Some(1000.0),
            "{ext}: metersPerUnit 1"
        );
        let shared = instanced_geometries(&scene, "/World/Copies/");
        assert_eq!(shared.len(), 3, "{ext}: three instanceable copies");
        assert!(
            shared.iter().all(|&p| p == shared[0]),
            "{ext}: one shared prototype"
        );
        assert!(
            notes
                .iter()
                .any(|n| n.contains("creaseIndices not honoured")),
            "{notes:?}"
        );
        // The PointInstancer's prototype 0 is placed twice, shared; prototype 1 once.
        let scattered = instanced_geometries(&scene, "/World/Scatter[");
        assert_eq!(scattered.len(), 2, "{ext}");
        assert_eq!(scattered[0], scattered[1], "{ext}");
        // What is read is not listed as not read; the closed cubes have no boundary
        // corners to note.
        let unread = notes.iter().find(|n| n.starts_with("not read")).unwrap();
        for read in [
            "holeIndices",
            "uRange",
            "vRange",
            "PointInstancer",
            "orientations",
        ] {
            assert!(!unread.contains(read), "{ext}: {unread}");
        }
        assert!(
            !notes.iter().any(|n| n.contains("interpolateBoundary")),
            "{notes:?}"
        );
    }
}

#[test]
fn a_usda_syntax_error_names_its_line_and_column_and_a_missing_camera_is_refused() {
    match load_scene_noted(&testdata("usd/bad.usda"), LoadOptions::default()) {
        Err(LoadError::Parse(e)) => assert_eq!((e.line, e.column), (6, 1), "{e}"),
        other => panic!(
            "expected a located parse error, found {:?}",
            other.map(|_| ())
        ),
    }
    let options = LoadOptions {
        camera: Some("/World/Nope".into()),
        ..LoadOptions::default()
    };
    let e = load_scene_noted(&testdata("usd/stage.usda"), options).unwrap_err();
    assert!(e.to_string().contains("/World/Cam"), "{e}");
}

#[test]
fn import_to_ron_keeps_the_trims_the_shared_instances_and_the_camera() {
    // A stage of the part layer alone, instanced, with the stage's camera: written
    // beside a copy of the part so that its reference resolves.
    let dir = tempfile::tempdir().unwrap();
    std::fs::copy(testdata("usd/part.usda"), dir.path().join("part.usda")).unwrap();
    let stage = dir.path().join("copies.usda");
    std::fs::write(
        &stage,
        r#"#usda 1.0
(
    upAxis = "Z"
)
def Xform "A" (instanceable = true references = @./part.usda@)
{
    double3 xformOp:translate = (0, 0, 3)
    uniform token[] xformOpOrder = ["xformOp:translate"]
}
def Xform "B" (instanceable = true references = @./part.usda@)
{
    double3 xformOp:translate = (2, 0, 3)
    float xformOp:rotateZ = 90
    uniform token[] xformOpOrder = ["xformOp:translate", "xformOp:rotateZ"]
}
def Camera "Cam"
{
    float focalLength = 35
    double3 xformOp:translate = (0, -12, 4)
    uniform token[] xformOpOrder = ["xformOp:translate"]
}
"#,
    )
    .unwrap();
    let ron = dir.path().join("copies.ron");
    let o = crate::common::run(&[
        "import",
        stage.to_str().unwrap(),
        "-o",
        ron.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", crate::common::stderr(&o));
    let (scene, _) = load_scene_noted(&ron, LoadOptions::default()).unwrap();
    assert_eq!(scene.objects.len(), 2);
    assert_eq!(scene.trim_loop_count(), 4, "two loops on each copy");
    let shared = instanced_geometries(&scene, "");
    assert_eq!(shared.len(), 2);
    assert_eq!(shared[0], shared[1], "one shared copy");
    assert!((scene.camera.eye - DVec3::new(0.0, -12.0, 4.0)).length() < 1e-12);
    // The default vertical aperture (15.2908) behind a 35 mm lens.
    let fov = 2.0 * (15.2908f64 / 70.0).atan().to_degrees();
    assert!(
        (scene.camera.fov_y - fov).abs() < 1e-6,
        "{}",
        scene.camera.fov_y
    );
    // Rays through the copies of the .ron hit where the .usda's do.
    let rays: Vec<_> = [(0.1, 0.1), (1.9, 0.1), (1.5, 0.5), (0.5, 0.5)]
        .iter()
        .map(|&(x, y)| (DVec3::new(x, y, 10.0), -DVec3::Z))
        .collect();
    let a = trace_hits(&stage, &rays);
    assert_eq!(a, trace_hits(&ron, &rays));
    assert!(
        a[0].is_some() && a[1].is_some() && a[2].is_none() && a[3].is_none(),
        "{a:?}"
    );
}

/// The shared geometry each instance object named from `prefix` places, by address:
/// equal addresses are one copy.
fn instanced_geometries(
    scene: &patchtrace::scene::model::Scene,
    prefix: &str,
) -> Vec<*const Geometry> {
    scene
        .objects
        .iter()
        .filter(|o| o.name.starts_with(prefix))
        .filter_map(|o| match &o.geometry {
            Geometry::Instance(i) => Some(std::sync::Arc::as_ptr(&i.geometry)),
            _ => None,
        })
        .collect()
}
