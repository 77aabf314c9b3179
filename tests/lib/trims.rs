//! Trimmed surfaces through the scene query, every kernel and both accelerators (//! Dammertz §2.6), against closed forms: a square plate with a circular hole, nested
//! loops, a hole across the spans of a B-spline plane, and the hammer of a real CAD export
//! against an `f64` point-in-polygon test of the test's own.

use glam::{DVec2, DVec3, DVec4, Vec3};
use patchtrace::accel::scene::{QueryStats, SceneGeometry};
use patchtrace::geom::nurbs::NurbsSurface;
use patchtrace::geom::trim::{ParamCurve, TrimLoop};
use patchtrace::geom::{BezierPatch, Ray};
use patchtrace::kernel::Kernel;
use patchtrace::kernel::cached::CachedConfig;
use patchtrace::kernel::subdivision::SubdivisionConfig;
use patchtrace::kernel::toth::TothConfig;
use patchtrace::scene::{Geometry, Object, Scene, Surface, SurfaceGeometry};

fn circle(c: DVec2, r: f64) -> ParamCurve {
    ParamCurve::circle(c, r)
}

/// A closed polygon through `(u, v)` corners.
fn polygon(corners: &[(f64, f64)]) -> ParamCurve {
    let corners: Vec<DVec2> = corners.iter().map(|&(u, v)| DVec2::new(u, v)).collect();
    ParamCurve::polygon(&corners)
}

fn whole(curve: ParamCurve, hole: bool) -> TrimLoop {
    TrimLoop::closed(curve, hole)
}

/// The plate z = 0 over `offset + scale · [0,1]²` as a bicubic patch with a linear
/// parameterisation, so parameter (u, v) sits at `offset + scale · (u, v)`.
fn plate(scale: f64, offset: f64) -> BezierPatch {
    let pts: Vec<DVec3> = (0..16)
        .map(|k| {
            let (u, v) = ((k % 4) as f64 / 3.0, (k / 4) as f64 / 3.0);
            DVec3::new(offset + scale * u, offset + scale * v, 0.0)
        })
        .collect();
    BezierPatch::from_points(3, 3, &pts).unwrap()
}

fn scene_of(surface: Surface) -> Scene {
    Scene::framing(vec![Object {
        name: "plate".into(),
        material: 0,
        geometry: Geometry::Surfaces(vec![surface]),
    }])
}

fn precisions() -> Vec<(&'static str, Kernel)> {
    vec![
        ("f32", Kernel::F32(SubdivisionConfig::default())),
        ("f64", Kernel::F64(SubdivisionConfig::default())),
        ("toth", Kernel::Toth(TothConfig::default())),
        (
            "cached",
            Kernel::Cached(CachedConfig::new(TothConfig::default(), 1 << 20, 6)),
        ),
    ]
}

/// A ray straight down onto the plane z = 0 at (x, y).
fn down(x: f64, y: f64) -> Ray {
    Ray::new(
        Vec3::new(x as f32, y as f32, 1.0),
        Vec3::new(0.0, 0.0, -1.0),
    )
}

/// Whether every kernel and accelerator hits (and is blocked by) the plate at (x, y).
fn hits(geometries: &[SceneGeometry], x: f64, y: f64) -> Vec<(String, bool, bool)> {
    let ray = down(x, y);
    let mut out = Vec::new();
    for (k, g) in geometries.iter().enumerate() {
        for (name, p) in precisions() {
            let mut s = QueryStats::default();
            let hit = g.intersect(&ray, &p, &mut s).is_some();
            let blocked = g.occluded(&ray, &p, &mut s);
            out.push((format!("{name}, accel {k}"), hit, blocked));
        }
    }
    out
}

#[test]
fn rays_through_a_round_hole_miss_and_rays_beside_it_hit_at_every_scale() {
    // The hole of radius 0.25 about the plate's centre, in the patch's [0,1]² domain.
    let (c, r) = (DVec2::splat(0.5), 0.25);
    for (scale, offset) in [(1e-3, 0.0), (1.0, 0.0), (1e3, 0.0), (1.0, 1e4)] {
        let surface = Surface {
            trims: vec![
                whole(circle(c, r), true),
                whole(polygon(&[(0., 0.), (1., 0.), (1., 1.), (0., 1.)]), false),
            ],
            ..Surface::bezier(plate(scale, offset))
        };
        let scene = scene_of(surface);
        let geometries = [
            SceneGeometry::build(&scene),
            SceneGeometry::build_grid(&scene, 1 << 20),
        ];
        // The bound: a point is classified correctly once its distance from the circle,
        // in parameters, exceeds the hit box's parameter extent. Rays start at f32 points,
        // so the parameter a ray meets is known to an f32 ulp of the coordinates over the
        // plate's size; 8 of those leave room for the final box (end_ulps = 4).
        let coordinate = offset + scale;
        let ulp = (coordinate as f32).next_up() as f64 - coordinate as f32 as f64;
        let margin = 8.0 * ulp / scale;
        for k in 0..24 {
            let a = k as f64 / 24.0 * std::f64::consts::TAU + 0.1;
            let dir = DVec2::new(a.cos(), a.sin());
            for (rho, inside_hole) in [
                (r - margin, true),
                (r + margin, false),
                (0.5 * r, true),
                (1.5 * r, false),
            ] {
                let p = c + dir * rho;
                let (x, y) = (offset + scale * p.x, offset + scale * p.y);
                // The ray's (x, y) rounds to f32: classify what it really aims at.
                let aimed = DVec2::new(
                    ((x as f32) as f64 - offset) / scale,
                    ((y as f32) as f64 - offset) / scale,
                );
                let want = (aimed - c).length() > r;
                assert_eq!(
                    want, !inside_hole,
                    "scale {scale}: the f32 ray moved across the circle"
                );
                for (what, hit, blocked) in hits(&geometries, x, y) {
                    assert_eq!(
                        (hit, blocked),
                        (want, want),
                        "scale {scale}, offset {offset}, {what}: ray at radius {rho} (r = {r})"
                    );
                }
            }
        }
    }
}

#[test]
fn an_island_in_a_hole_and_loops_touching_the_border_follow_parity() {
    // Outer loop = the patch border (touching it), a square hole, an island in it, either
    // orientation.
    let surface = Surface {
        trims: vec![
            whole(polygon(&[(0., 0.), (1., 0.), (1., 1.), (0., 1.)]), false),
            whole(
                polygon(&[(0.2, 0.2), (0.2, 0.8), (0.8, 0.8), (0.8, 0.2)]),
                true,
            ),
            whole(circle(DVec2::splat(0.5), 0.15), false),
        ],
        ..Surface::bezier(plate(2.0, -1.0))
    };
    let scene = scene_of(surface);
    let geometries = [
        SceneGeometry::build(&scene),
        SceneGeometry::build_grid(&scene, 1 << 20),
    ];
    for (u, v, want) in [
        (0.1, 0.1, true),
        (0.9, 0.5, true),
        (0.25, 0.5, false),
        (0.5, 0.75, false),
        (0.5, 0.5, true),
        (0.55, 0.45, true),
    ] {
        for (what, hit, blocked) in hits(&geometries, -1.0 + 2.0 * u, -1.0 + 2.0 * v) {
            assert_eq!((hit, blocked), (want, want), "{what} at ({u}, {v})");
        }
    }
}

#[test]
fn a_hole_across_the_spans_of_a_bspline_plane() {
    // A bicubic B-spline plane over [0, 3]² with three spans each way (9 Bézier patches);
    // the hole about (1.5, 1.2) crosses span boundaries, culling drops nothing and keeps
    // the corner patches trim-free.
    let n = 6;
    let knots = vec![0., 0., 0., 0., 1., 2., 3., 3., 3., 3.];
    // Greville abscissae make the plane's parameterisation the identity: x = u, y = v.
    let greville = |i: usize| (knots[i + 1] + knots[i + 2] + knots[i + 3]) / 3.0;
    let points: Vec<DVec4> = (0..n * n)
        .map(|k| DVec4::new(greville(k % n), greville(k / n), 0.0, 1.0))
        .collect();
    let nurbs = NurbsSurface::new(3, 3, knots.clone(), knots, n, n, points).unwrap();
    let (c, r) = (DVec2::new(1.5, 1.2), 0.9);
    let surface = Surface {
        geometry: SurfaceGeometry::Nurbs(nurbs),
        trims: vec![whole(circle(c, r), true)],
        trim_space: Default::default(),
    };
    let scene = scene_of(surface);
    let geometries = [
        SceneGeometry::build(&scene),
        SceneGeometry::build_grid(&scene, 1 << 20),
    ];
    for i in 0..30 {
        for j in 0..30 {
            let p = DVec2::new((i as f64 + 0.5) / 10.0, (j as f64 + 0.5) / 10.0);
            let d = (p - c).length();
            if (d - r).abs() < 1e-3 {
                continue;
            }
            for (what, hit, blocked) in hits(&geometries, p.x, p.y) {
                assert_eq!((hit, blocked), (d > r, d > r), "{what} at {p}");
            }
        }
    }
}
