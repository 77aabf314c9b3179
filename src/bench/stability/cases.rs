//! The hard cases of the stability suite: each a scene and a ray set built
//! deterministically from a seed. The geometry is rounded to `f32` once here (the precision
//! scenes are stored in for rendering, DESIGN.md conventions), so every kernel path and the
//! `f64` reference see the same surface and a disagreement measures a kernel, not the
//! storage format. Rays are `f32` for the same reason.

use std::f64::consts::{FRAC_PI_2, TAU};
use std::path::Path;

use glam::{DAffine3, DQuat, DVec2, DVec3, Vec3};

use crate::geom::nurbs::shapes::sphere;
use crate::geom::trim::{ParamCurve, TrimLoop};
use crate::geom::ulp::step_ulps;
use crate::geom::{BezierPatch, Ray};
use crate::scene::bpt::parse_bpt;
use crate::scene::generate::{SplitMix64, TEAPOT_BPT};
use crate::scene::{Geometry, Instance, Material, Object, Scene, Surface};

/// How many rays each case traces: the reduced set runs in `cargo test`, the full one in
/// `patchtrace bench stability --full`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SuiteSize {
    Reduced,
    Full,
}

impl SuiteSize {
    /// Rays per case.
    pub fn rays(self) -> usize {
        match self {
            SuiteSize::Reduced => 48,
            SuiteSize::Full => 2000,
        }
    }

    /// Edge of the square image rendered per case to look for NaN pixels.
    pub fn image_size(self) -> u32 {
        match self {
            SuiteSize::Reduced => 16,
            SuiteSize::Full => 64,
        }
    }
}

/// One hard case: a scene (geometry already in `f32`) and the rays shot at it.
pub struct Case {
    pub name: String,
    pub scene: Scene,
    pub rays: Vec<Ray>,
}

/// Scale factors of the teapot (1e-6 to 1e6).
const TEAPOT_SCALES: [f64; 5] = [1e-6, 1e-3, 1.0, 1e3, 1e6];
/// Distances of the moved teapot from the origin ("up to 1e5").
const TEAPOT_OFFSETS: [f64; 2] = [1e3, 1e5];
/// Smallest grazing angle in radians; angles are spread log-uniformly up to
/// [`GRAZING_MAX`].
const GRAZING_MIN: f64 = 1e-6;
const GRAZING_MAX: f64 = 1e-1;
/// Silhouette rays pass this many `f32` ulps inside or outside the outline.
const SILHOUETTE_ULPS: i32 = 4;
/// Weights of the rational case span this range.
const WEIGHT_MIN: f64 = 1e-3;
const WEIGHT_MAX: f64 = 1e3;
/// Scale and offset of the plates with a round hole (scales 1e-3, 1, 1e3 and an
/// offset of 1e4).
const HOLED_PLATES: [(f64, f64); 4] = [(1e-3, 0.0), (1.0, 0.0), (1e3, 0.0), (1.0, 1e4)];
/// The hole's radius in the plate's [0,1]² parameters, about its centre.
const HOLE_RADIUS: f64 = 0.3;
/// Rays aimed beside the hole pass within this range of parameter distances from its
/// circle, log-uniformly, on both sides: from about the final box's parameter extent at
/// the plate with the largest coordinates (1e4 + 1: an f32 ulp of 1e-3) to 1e-2.
const HOLE_DISTANCE_MIN: f64 = 1e-5;
const HOLE_DISTANCE_MAX: f64 = 1e-2;
/// Size ratio of the tiny and the huge patch.
const TINY_HUGE_RATIO: f64 = 1e6;
/// A scale that puts the teapot's control points at ~1e-40, below `f32::MIN_POSITIVE`
/// (1.18e-38): its coordinates are subnormal in `f32`.
const SUBNORMAL_SCALE: f64 = 1e-40;
/// A scale just above the normal range: boxes of sub-patches shrink into subnormals.
const NEAR_SUBNORMAL_SCALE: f64 = 1e-35;
/// The smallest scale the loader accepts, rounded to a power of ten: the teapot (about 6
/// across) stays above `scene::load::MIN_OBJECT_EXTENT` (2^-60 ≈ 8.7e-19).
const SMALLEST_ACCEPTED_SCALE: f64 = 1e-18;

/// Every case of the suite, in report order.
pub fn all_cases(size: SuiteSize, seed: u64) -> Vec<Case> {
    let n = size.rays();
    let mut rng = SplitMix64::new(seed);
    let teapot = teapot();
    let sphere = sphere_patches();
    let mut cases = vec![
        case(
            "sphere grazing",
            &sphere,
            grazing_rays(&sphere, n, &mut rng),
        ),
        case(
            "sphere tangent",
            &sphere,
            tangent_rays(&sphere, n, &mut rng),
        ),
        case("sphere silhouette", &sphere, silhouette_rays(n, &mut rng)),
        case(
            "grid 2x2 corners+edges",
            &grid_2x2(),
            seam_rays(&grid_2x2(), n, &mut rng),
        ),
        case(
            "teapot corners+edges",
            &teapot,
            seam_rays(&teapot, n, &mut rng),
        ),
        case(
            "teapot collapsed edges",
            &teapot,
            collapsed_rays(&teapot, n, &mut rng),
        ),
    ];
    let curve = vec![curve_patch()];
    cases.push(case(
        "patch collapsed to a curve",
        &curve,
        curve_rays(&curve[0], n, &mut rng),
    ));
    let planar = nearly_planar(&mut rng);
    cases.push(case(
        "nearly planar, any orientation",
        &planar,
        random_rays(&planar, n, &mut rng),
    ));
    let folded = folded_patches();
    cases.push(case(
        "self-intersecting + folded",
        &folded,
        random_rays(&folded, n, &mut rng),
    ));
    let high = vec![degree_10x7(&mut rng)];
    cases.push(case("degree 10x7", &high, random_rays(&high, n, &mut rng)));
    let rational = rational_patches(&mut rng);
    cases.push(case(
        "rational, weights 1e-3..1e3",
        &rational,
        random_rays(&rational, n, &mut rng),
    ));
    for s in TEAPOT_SCALES {
        let p = transformed(&teapot, DAffine3::from_scale(DVec3::splat(s)));
        cases.push(case(
            &format!("teapot x{s:e}"),
            &p,
            random_rays(&p, n, &mut rng),
        ));
    }
    for d in TEAPOT_OFFSETS {
        let offset = DVec3::new(1.0, 0.6, 0.3).normalize() * d;
        let p = transformed(&teapot, DAffine3::from_translation(offset));
        cases.push(case(
            &format!("teapot at {d:e} from origin"),
            &p,
            random_rays(&p, n, &mut rng),
        ));
    }
    let pair = tiny_beside_huge();
    cases.push(case(
        "tiny beside huge (1e6)",
        &pair,
        random_rays(&pair, n, &mut rng),
    ));
    let p = transformed(
        &teapot,
        DAffine3::from_scale(DVec3::splat(SMALLEST_ACCEPTED_SCALE)),
    );
    cases.push(case(
        &format!("teapot x{SMALLEST_ACCEPTED_SCALE:e} (smallest accepted)"),
        &p,
        random_rays(&p, n, &mut rng),
    ));
    for (scale, offset) in HOLED_PLATES {
        let p = plate(scale, offset);
        cases.push(holed_case(
            &format!("round hole x{scale:e} at {offset:e}"),
            &p,
            hole_rays(&p, n, &mut rng),
        ));
    }
    let p = plate(1.0, 0.0);
    cases.push(holed_case(
        "grazing along a trim curve",
        &p,
        trim_grazing_rays(&p, n, &mut rng),
    ));
    for (name, placements) in instance_placements() {
        let rounded: Vec<BezierPatch> = teapot.iter().map(round_to_f32).collect();
        let copies: Vec<BezierPatch> = placements
            .iter()
            .flat_map(|m| transformed(&rounded, *m))
            .collect();
        cases.push(instanced_case(
            name,
            &rounded,
            &placements,
            random_rays(&copies, n, &mut rng),
        ));
    }
    for s in [NEAR_SUBNORMAL_SCALE, SUBNORMAL_SCALE] {
        let p = transformed(&teapot, DAffine3::from_scale(DVec3::splat(s)));
        cases.push(case(
            &format!("teapot x{s:e} (subnormal range)"),
            &p,
            random_rays(&p, n, &mut rng),
        ));
    }
    cases
}

/// A case scene: the patches rounded to `f32`, framed by the default camera and light, with
/// a material that reflects and refracts so that renders trace every kind of ray.
fn case(name: &str, patches: &[BezierPatch], rays: Vec<Ray>) -> Case {
    let surfaces = patches
        .iter()
        .map(|p| Surface::bezier(round_to_f32(p)))
        .collect();
    case_of_surfaces(name, surfaces, rays)
}

/// A case of `plate` with a round hole of [`HOLE_RADIUS`] about its parameter centre, the
/// patch rounded to `f32` like [`case`]'s.
fn holed_case(name: &str, plate: &BezierPatch, rays: Vec<Ray>) -> Case {
    let surface = Surface {
        trims: vec![TrimLoop::closed(
            ParamCurve::circle(DVec2::splat(0.5), HOLE_RADIUS),
            true,
        )],
        ..Surface::bezier(round_to_f32(plate))
    };
    case_of_surfaces(name, vec![surface], rays)
}

/// Instances of the teapot (Dammertz §3.3) placed so that the transforms round: rotated
/// about a skew axis and scaled, mirrored, stretched unevenly, and far from the origin
/// at a large scale. Secondary rays leave each through the world leave box
/// ([`crate::accel`]'s instance module) and re-enter their own instance rounded again.
fn instance_placements() -> Vec<(&'static str, Vec<DAffine3>)> {
    let skew = DQuat::from_axis_angle(DVec3::new(1.0, 2.0, 3.0).normalize(), 0.7);
    let near = vec![
        DAffine3::from_scale_rotation_translation(
            DVec3::splat(0.7),
            skew,
            DVec3::new(3.0, 1.0, 0.0),
        ),
        DAffine3::from_scale(DVec3::new(-1.0, 1.0, 1.0)),
        DAffine3::from_scale_rotation_translation(
            DVec3::new(1.0, 2.0, 0.5),
            skew.inverse(),
            DVec3::new(-3.0, 0.5, 1.0),
        ),
    ];
    let far = near
        .iter()
        .map(|m| {
            DAffine3::from_translation(DVec3::splat(1e3))
                * DAffine3::from_scale(DVec3::splat(1e2))
                * *m
        })
        .collect();
    vec![
        ("teapot instances: rotated, mirrored, stretched", near),
        ("teapot instances x1e2 at 1e3", far),
    ]
}

/// A case of instances of `patches` (already in `f32`) placed by `placements`.
fn instanced_case(
    name: &str,
    patches: &[BezierPatch],
    placements: &[DAffine3],
    rays: Vec<Ray>,
) -> Case {
    let shared = std::sync::Arc::new(Geometry::Surfaces(
        patches.iter().cloned().map(Surface::bezier).collect(),
    ));
    let objects = placements
        .iter()
        .enumerate()
        .map(|(k, m)| Object {
            name: format!("{name} {k}"),
            material: 0,
            geometry: Geometry::Instance(Instance::new(shared.clone(), *m)),
        })
        .collect();
    case_of_objects(name, objects, rays)
}

fn case_of_surfaces(name: &str, surfaces: Vec<Surface>, rays: Vec<Ray>) -> Case {
    let object = Object {
        name: name.to_string(),
        material: 0,
        geometry: Geometry::Surfaces(surfaces),
    };
    case_of_objects(name, vec![object], rays)
}

fn case_of_objects(name: &str, objects: Vec<Object>, rays: Vec<Ray>) -> Case {
    let mut scene = Scene::framing(objects);
    scene.materials[0] = Material {
        specular: 0.5,
        reflect: 0.3,
        transmit: 0.3,
        ..Material::default_named("stress")
    };
    Case {
        name: name.to_string(),
        scene,
        rays,
    }
}

/// The patch with every homogeneous coordinate rounded to the nearest `f32`, as the kernel
/// stores it. Rounding keeps weights positive for the weights used here; a coordinate that
/// overflows `f32` would fail [`BezierPatch::new`], and the patch is then kept unrounded so
/// the kernel's own handling shows in the figures.
fn round_to_f32(p: &BezierPatch) -> BezierPatch {
    let points = p
        .homogeneous_points()
        .iter()
        .map(|q| q.as_vec4().as_dvec4())
        .collect();
    BezierPatch::new(p.degree_u(), p.degree_v(), points).unwrap_or_else(|_| p.clone())
}

fn transformed(patches: &[BezierPatch], m: DAffine3) -> Vec<BezierPatch> {
    patches
        .iter()
        .map(|p| {
            let mut p = p.clone();
            p.transform(&m);
            p
        })
        .collect()
}

// ---------------------------------------------------------------------------------------
// Geometry
// ---------------------------------------------------------------------------------------

/// The Utah teapot shipped with the crate.
fn teapot() -> Vec<BezierPatch> {
    parse_bpt(Path::new("teapot.bpt"), TEAPOT_BPT).unwrap_or_default()
}

/// The 8 rational biquadratic patches of the unit sphere: convex, with collapsed edges at
/// the poles.
fn sphere_patches() -> Vec<BezierPatch> {
    sphere(1.0)
        .map(|s| s.to_bezier_patches())
        .unwrap_or_default()
}

/// A patch of degree (du, dv) whose control point (i, j) is `f(i / du, j / dv)`.
fn net(du: usize, dv: usize, f: impl Fn(f64, f64) -> DVec3) -> BezierPatch {
    let points: Vec<DVec3> = (0..=dv)
        .flat_map(|j| (0..=du).map(move |i| (i, j)))
        .map(|(i, j)| f(i as f64 / du as f64, j as f64 / dv as f64))
        .collect();
    BezierPatch::from_points(du, dv, &points).expect("degrees and points are valid")
}

/// Four bicubic patches over [-1, 1]² sharing edges and the corner at the origin, on a
/// smooth height field so that the shared control points coincide exactly.
fn grid_2x2() -> Vec<BezierPatch> {
    let height = |x: f64, y: f64| 0.3 * (1.7 * x).sin() * (1.3 * y + 0.4).cos();
    let mut patches = Vec::new();
    for (x0, y0) in [(-1.0, -1.0), (0.0, -1.0), (-1.0, 0.0), (0.0, 0.0)] {
        patches.push(net(3, 3, |s, t| {
            let (x, y) = (x0 + s, y0 + t);
            DVec3::new(x, y, height(x, y))
        }));
    }
    patches
}

/// A bicubic patch whose net is one curve repeated: the surface is that space curve.
fn curve_patch() -> BezierPatch {
    net(3, 3, |s, _| {
        DVec3::new(2.0 * s - 1.0, 0.5 * (3.0 * s).sin(), 0.3 * s * s)
    })
}

/// Four bicubic patches with control points on a plane, displaced off it by 1e-7 of their
/// size (the "nearly planar" patches of Dammertz Table 2.4), each in a random orientation.
fn nearly_planar(rng: &mut SplitMix64) -> Vec<BezierPatch> {
    /// Out-of-plane displacement relative to the patch size: below one `f32` ulp of 1.
    const BUMP: f64 = 1e-7;
    (0..4)
        .map(|k| {
            let bumps: Vec<f64> = (0..16).map(|_| rng.range(-BUMP, BUMP)).collect();
            let mut p = net(3, 3, |s, t| {
                let idx = (t * 3.0).round() as usize * 4 + (s * 3.0).round() as usize;
                DVec3::new(s, t, bumps[idx])
            });
            let rot = DQuat::from_axis_angle(rng.direction(), rng.range(0.0, TAU));
            let shift = DVec3::new(1.5 * k as f64, 0.0, 0.0);
            p.transform(&DAffine3::from_rotation_translation(rot, shift));
            p
        })
        .collect()
}

/// A self-intersecting patch (the middle control rows cross each other) and a patch folded
/// back over itself along v.
fn folded_patches() -> Vec<BezierPatch> {
    let crossing = net(3, 3, |s, t| {
        let twist = [0.0, 1.0, -1.0, 0.0][(t * 3.0).round() as usize];
        DVec3::new(s, t + 0.8 * twist * (s - 0.5), 0.6 * twist * (0.5 - s))
    });
    let fold = net(3, 3, |s, t| {
        let y = [0.0, 1.5, -0.5, 1.0][(t * 3.0).round() as usize];
        DVec3::new(s + 1.5, y, 0.4 * t + 0.1 * s)
    });
    vec![crossing, fold]
}

/// A degree 10 × 7 patch on a wavy height field with random control-point jitter.
fn degree_10x7(rng: &mut SplitMix64) -> BezierPatch {
    let jitter: Vec<f64> = (0..11 * 8).map(|_| rng.range(-0.2, 0.2)).collect();
    net(10, 7, |s, t| {
        let k = (t * 7.0).round() as usize * 11 + (s * 10.0).round() as usize;
        DVec3::new(s, t, 0.4 * (6.0 * s).sin() * (5.0 * t).cos() + jitter[k])
    })
}

/// Bicubic rational patches with weights spread log-uniformly over 1e-3..1e3.
fn rational_patches(rng: &mut SplitMix64) -> Vec<BezierPatch> {
    (0..3)
        .map(|k| {
            let base = net(3, 3, |s, t| {
                DVec3::new(s + 1.2 * k as f64, t, 0.5 * s * (1.0 - t))
            });
            let points: Vec<DVec3> = base.euclidean_points().collect();
            let (lo, hi) = (WEIGHT_MIN.ln(), WEIGHT_MAX.ln());
            let weights: Vec<f64> = points.iter().map(|_| rng.range(lo, hi).exp()).collect();
            BezierPatch::from_weighted(3, 3, &points, &weights).expect("weights are positive")
        })
        .collect()
}

/// A bicubic patch of size 1e-3 resting just beside one of size 1e3.
fn tiny_beside_huge() -> Vec<BezierPatch> {
    let huge = 1e3;
    let tiny = huge / TINY_HUGE_RATIO;
    let dome = |size: f64, x0: f64| {
        net(3, 3, move |s, t| {
            DVec3::new(x0 + size * s, size * t, 0.3 * size * s * (1.0 - t))
        })
    };
    vec![dome(huge, 0.0), dome(tiny, huge + tiny)]
}

// ---------------------------------------------------------------------------------------
// Rays
// ---------------------------------------------------------------------------------------

/// Centre and radius of the patches' control boxes.
/// The plate z = 0 over `offset + scale · [0,1]²`, a bicubic patch with a linear
/// parameterisation.
fn plate(scale: f64, offset: f64) -> BezierPatch {
    net(3, 3, |u, v| {
        DVec3::new(offset + scale * u, offset + scale * v, 0.0)
    })
}

/// The point of `plate` at parameter distance `rho` from its centre at `angle`.
fn around_centre(plate: &BezierPatch, rho: f64, angle: f64) -> DVec3 {
    plate.eval(0.5 + rho * angle.cos(), 0.5 + rho * angle.sin())
}

/// Rays from random directions of the upper half-space through points at log-uniform
/// parameter distances from the hole's circle, inside and outside it.
fn hole_rays(plate: &BezierPatch, n: usize, rng: &mut SplitMix64) -> Vec<Ray> {
    let (lo, hi) = (HOLE_DISTANCE_MIN.ln(), HOLE_DISTANCE_MAX.ln());
    let (_, radius) = extent(std::slice::from_ref(plate));
    (0..n)
        .map(|i| {
            let side = if i % 2 == 0 { 1.0 } else { -1.0 };
            let rho = HOLE_RADIUS + side * rng.range(lo, hi).exp();
            let target = around_centre(plate, rho, rng.range(0.0, TAU));
            let mut dir = rng.direction();
            dir.z = -dir.z.abs().max(0.05);
            aimed(target, dir, 3.0 * radius)
        })
        .collect()
}

/// Rays at 1e-6..1e-1 rad to the plate, crossing it near the hole's circle while running
/// along its tangent there: they graze the surface and the trim curve at once.
fn trim_grazing_rays(plate: &BezierPatch, n: usize, rng: &mut SplitMix64) -> Vec<Ray> {
    let (lo, hi) = (GRAZING_MIN.ln(), GRAZING_MAX.ln());
    (0..n)
        .map(|i| {
            let angle = rng.range(0.0, TAU);
            let side = if i % 2 == 0 { 1.0 } else { -1.0 };
            let target = around_centre(plate, HOLE_RADIUS * (1.0 + side * 1e-3), angle);
            let tangent = DVec3::new(-angle.sin(), angle.cos(), 0.0);
            let a = rng.range(lo, hi).exp();
            let dir = tangent * a.cos() - DVec3::Z * a.sin();
            aimed(target, dir, 0.5)
        })
        .collect()
}

fn extent(patches: &[BezierPatch]) -> (DVec3, f64) {
    let b = patches.iter().fold(crate::geom::DAabb::EMPTY, |acc, p| {
        acc.union(&p.control_box())
    });
    (b.center(), 0.5 * b.diagonal())
}

/// A ray through `target` along `dir`, starting `reach` before it, rounded to `f32`.
fn aimed(target: DVec3, dir: DVec3, reach: f64) -> Ray {
    let d = dir.normalize();
    Ray::new((target - d * reach).as_vec3(), d.as_vec3())
}

/// Rays through random points of random patches from random directions.
fn random_rays(patches: &[BezierPatch], n: usize, rng: &mut SplitMix64) -> Vec<Ray> {
    let (_, radius) = extent(patches);
    (0..n)
        .map(|_| {
            let p = &patches[rng.next_u64() as usize % patches.len()];
            let target = p.eval(rng.uniform(), rng.uniform());
            aimed(target, rng.direction(), 3.0 * radius)
        })
        .collect()
}

/// A unit tangent at (u, v) and the unit normal, in `f64`.
fn frame(p: &BezierPatch, u: f64, v: f64, rng: &mut SplitMix64) -> (DVec3, DVec3) {
    let n = p.normal(u, v);
    let a = n.any_orthonormal_vector();
    let b = n.cross(a);
    let phi = rng.range(0.0, TAU);
    (a * phi.cos() + b * phi.sin(), n)
}

/// Rays meeting the sphere at an interior point at angles of 1e-6..1e-1 rad below the
/// tangent plane, coming from outside.
fn grazing_rays(patches: &[BezierPatch], n: usize, rng: &mut SplitMix64) -> Vec<Ray> {
    let (lo, hi) = (GRAZING_MIN.ln(), GRAZING_MAX.ln());
    (0..n)
        .map(|_| {
            let p = &patches[rng.next_u64() as usize % patches.len()];
            let (u, v) = (rng.range(0.1, 0.9), rng.range(0.1, 0.9));
            let (t, nrm) = frame(p, u, v, rng);
            let angle = rng.range(lo, hi).exp();
            let dir = t * angle.cos() - nrm * angle.sin();
            aimed(p.eval(u, v), dir, 1.0)
        })
        .collect()
}

/// Rays along the tangent plane of an interior point of a convex patch: they touch it.
fn tangent_rays(patches: &[BezierPatch], n: usize, rng: &mut SplitMix64) -> Vec<Ray> {
    (0..n)
        .map(|_| {
            let p = &patches[rng.next_u64() as usize % patches.len()];
            let (u, v) = (rng.range(0.05, 0.95), rng.range(0.05, 0.95));
            let (t, _) = frame(p, u, v, rng);
            aimed(p.eval(u, v), t, 1.0)
        })
        .collect()
}

/// Axis-parallel rays past the unit sphere's outline, within ±[`SILHOUETTE_ULPS`] `f32`
/// ulps of it: the ray is exact in `f32`, so the offset is exactly what it says.
fn silhouette_rays(n: usize, rng: &mut SplitMix64) -> Vec<Ray> {
    (0..n)
        .map(|k| {
            let phi = rng.range(0.0, TAU);
            let steps = (k as i32 % (2 * SILHOUETTE_ULPS + 1)) - SILHOUETTE_ULPS;
            let (a, b) = (phi.cos() as f32, phi.sin() as f32);
            // Moving the larger lateral coordinate by k ulps moves the ray across the
            // outline by about k ulps of the radius.
            let (a, b) = if a.abs() > b.abs() {
                (step_ulps(a, steps * a.signum() as i32), b)
            } else {
                (a, step_ulps(b, steps * b.signum() as i32))
            };
            match k % 3 {
                0 => Ray::new(Vec3::new(a, b, 3.0), Vec3::NEG_Z),
                1 => Ray::new(Vec3::new(3.0, a, b), Vec3::NEG_X),
                _ => Ray::new(Vec3::new(a, -3.0, b), Vec3::Y),
            }
        })
        .collect()
}

/// Rays through patch corners and points on patch edges, from both sides.
fn seam_rays(patches: &[BezierPatch], n: usize, rng: &mut SplitMix64) -> Vec<Ray> {
    let (_, radius) = extent(patches);
    (0..n)
        .map(|k| {
            let p = &patches[rng.next_u64() as usize % patches.len()];
            let corner = |r: &mut SplitMix64| {
                if r.next_u64().is_multiple_of(2) {
                    0.0
                } else {
                    1.0
                }
            };
            let (u, v) = match k % 3 {
                0 => (corner(rng), corner(rng)),
                1 => (corner(rng), rng.uniform()),
                _ => (rng.uniform(), corner(rng)),
            };
            aimed(p.eval(u, v), rng.direction(), 3.0 * radius)
        })
        .collect()
}

/// Which boundary of a patch, if any, has all its control points coincident.
fn collapsed_side(p: &BezierPatch) -> Option<(bool, f64)> {
    let (nu, nv) = (p.degree_u() + 1, p.degree_v() + 1);
    let row_collapsed = |j: usize| (1..nu).all(|i| p.point(i, j) == p.point(0, j));
    let col_collapsed = |i: usize| (1..nv).all(|j| p.point(i, j) == p.point(i, 0));
    if row_collapsed(0) {
        Some((true, 0.0))
    } else if row_collapsed(nv - 1) {
        Some((true, 1.0))
    } else if col_collapsed(0) {
        Some((false, 0.0))
    } else if col_collapsed(nu - 1) {
        Some((false, 1.0))
    } else {
        None
    }
}

/// Rays at the teapot's collapsed edges (lid knob and bottom): exactly at the apex and at
/// parameter distances 1e-9..1e-1 from it.
fn collapsed_rays(patches: &[BezierPatch], n: usize, rng: &mut SplitMix64) -> Vec<Ray> {
    let degenerate: Vec<(&BezierPatch, (bool, f64))> = patches
        .iter()
        .filter_map(|p| collapsed_side(p).map(|s| (p, s)))
        .collect();
    if degenerate.is_empty() {
        return random_rays(patches, n, rng);
    }
    let (_, radius) = extent(patches);
    (0..n)
        .map(|k| {
            let (p, (along_v, side)) = degenerate[rng.next_u64() as usize % degenerate.len()];
            let gap = if k % 4 == 0 {
                0.0
            } else {
                10f64.powf(rng.range(-9.0, -1.0))
            };
            let near = (side - gap).abs().min(1.0);
            let free = rng.uniform();
            let (u, v) = if along_v { (free, near) } else { (near, free) };
            aimed(p.eval(u, v), rng.direction(), 3.0 * radius)
        })
        .collect()
}

/// Rays through points of the curve a collapsed patch degenerates to, across it.
fn curve_rays(p: &BezierPatch, n: usize, rng: &mut SplitMix64) -> Vec<Ray> {
    (0..n)
        .map(|_| {
            let s = rng.uniform();
            let (_, du, _) = p.derivatives(s, 0.5);
            let across = du.any_orthonormal_vector();
            let tilt = rng.range(-FRAC_PI_2, FRAC_PI_2) * 0.5;
            let dir = across * tilt.cos() + du.normalize() * tilt.sin();
            aimed(p.eval(s, 0.5), dir, 3.0)
        })
        .collect()
}
