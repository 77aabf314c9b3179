use glam::{DMat3, DVec2, DVec3, Vec3};

use super::*;
use crate::geom::Ray;
use crate::geom::bezier::ParamRect;
use crate::geom::trim::{Coverage, ParamCurve, TrimLoop, TrimRegion};
use crate::geom::ulp::ulp_of;
use crate::kernel::KernelStats;
use crate::kernel::secondary::{DEFAULT_ULPS, secondary_origin};
use crate::kernel::subdivision::prepared::Prepared;
use crate::kernel::subdivision::{
    PreparedPatch, SubdivisionConfig, intersect, intersect_f64, widen_by_net_rounding,
};

/// xorshift32 mapped to [0, 1): deterministic rays without a dependency.
fn uniform(state: &mut u32) -> f64 {
    *state ^= *state << 13;
    *state ^= *state >> 17;
    *state ^= *state << 5;
    f64::from(*state >> 8) / f64::from(1u32 << 24)
}

/// The Bézier net of degree `du` × `dv` of `O + u A + v B`: the affine image of the grid.
fn affine_net(du: usize, dv: usize, o: DVec3, a: DVec3, b: DVec3) -> BezierPatch {
    let mut pts = Vec::new();
    for j in 0..=dv {
        for i in 0..=du {
            pts.push(o + (i as f64 / du as f64) * a + (j as f64 / dv as f64) * b);
        }
    }
    BezierPatch::from_points(du, dv, &pts).unwrap()
}

/// A tilted parallelogram away from the origin, so no coordinate is trivially exact.
fn tilted() -> (DVec3, DVec3, DVec3) {
    (
        DVec3::new(1.3, -0.7, 2.1),
        DVec3::new(3.1, 0.4, -0.9),
        DVec3::new(-0.6, 2.7, 1.2),
    )
}

/// The crossing of the line `orig + t dir` with `O + u A + v B`, by Cramer's rule on the
/// 3×3 system `u A + v B - t dir = orig - O` (independent of the dual basis the kernel
/// uses): `(t, u, v)`.
fn cramer(o: DVec3, a: DVec3, b: DVec3, orig: DVec3, dir: DVec3) -> (f64, f64, f64) {
    let m = DMat3::from_cols(a, b, -dir);
    let r = orig - o;
    let det = m.determinant();
    let solve = |k: usize| {
        let mut c = m;
        *c.col_mut(k) = r;
        c.determinant() / det
    };
    (solve(2), solve(0), solve(1))
}

fn f32_ray(orig: DVec3, dir: DVec3) -> Ray {
    Ray::new(orig.as_vec3(), dir.as_vec3())
}

fn as_gray(ray: &Ray) -> GRay<f32> {
    GRay::new(
        ray.origin.to_array(),
        ray.dir.to_array(),
        ray.tmin,
        ray.tmax,
    )
}

#[test]
fn affine_nets_of_every_degree_take_the_closed_form() {
    let (o, a, b) = tilted();
    for (du, dv) in [(1, 1), (1, 3), (2, 2), (3, 3), (5, 2)] {
        let p = affine_net(du, dv, o, a, b);
        assert!(AffinePatch::of(&p).is_some(), "{du} × {dv}");
        assert!(matches!(PreparedPatch::new(&p).data, Prepared::Affine(_)));
    }
    // Equal weights other than 1 are the same surface.
    let p = affine_net(1, 1, o, a, b);
    let w: Vec<_> = p
        .euclidean_points()
        .map(|q| (q * 2.5).extend(2.5))
        .collect();
    assert!(AffinePatch::of(&BezierPatch::new(1, 1, w).unwrap()).is_some());
}

#[test]
fn non_affine_patches_keep_the_search() {
    let (o, a, b) = tilted();
    let n = a.cross(b).normalize();
    // A saddle: the fourth corner lifted off the plane of the other three.
    let saddle = BezierPatch::from_points(1, 1, &[o, o + a, o + b, o + a + b + 0.3 * n]).unwrap();
    // Planar but not a parallelogram: a trapezoid, its far edge half as long.
    let trapezoid = BezierPatch::from_points(1, 1, &[o, o + a, o + b, o + b + 0.5 * a]).unwrap();
    // Planar and a parallelogram, but an inner point of the bicubic net moved within the
    // plane: the same outline, parameterised non-uniformly.
    let mut pts: Vec<DVec3> = affine_net(3, 3, o, a, b).euclidean_points().collect();
    pts[5] += 0.1 * a;
    let warped = BezierPatch::from_points(3, 3, &pts).unwrap();
    // A point off the grid by far more than the tolerance, but by less than an f32 ulp.
    let mut pts: Vec<DVec3> = affine_net(1, 1, o, a, b).euclidean_points().collect();
    pts[3] += DVec3::splat(1e-9);
    let nearly = BezierPatch::from_points(1, 1, &pts).unwrap();
    // Unequal weights: a rational parallelogram is not affine in its parameters.
    let mut w: Vec<_> = affine_net(1, 1, o, a, b)
        .euclidean_points()
        .map(|q| q.extend(1.0))
        .collect();
    w[3] *= 2.0;
    let rational = BezierPatch::new(1, 1, w).unwrap();
    // A sliver: A and B almost parallel.
    let sliver = affine_net(1, 1, o, a, a + 1e-6 * b);
    for (name, p) in [
        ("saddle", saddle),
        ("trapezoid", trapezoid),
        ("warped", warped),
        ("nearly", nearly),
        ("rational", rational),
        ("sliver", sliver),
    ] {
        assert!(AffinePatch::of(&p).is_none(), "{name}");
        assert!(
            !matches!(PreparedPatch::new(&p).data, Prepared::Affine(_)),
            "{name}"
        );
    }
}

#[test]
fn closed_form_agrees_with_cramer_and_the_f64_reference_on_random_rays() {
    let (o, a, b) = tilted();
    let n = a.cross(b).normalize();
    let scale = scale(o, a, b) as f32;
    let cfg = SubdivisionConfig::default();
    for p in [affine_net(1, 1, o, a, b), affine_net(3, 2, o, a, b)] {
        let plane = AffinePatch::of(&p).unwrap();
        let prepared = PreparedPatch::new(&p);
        let mut state = 0x2545_f491;
        let (mut hits, mut misses, mut grazing) = (0, 0, 0);
        for k in 0..2000 {
            let mut r = || uniform(&mut state);
            let (tu, tv) = (1.4 * r() - 0.2, 1.4 * r() - 0.2);
            let target = o + tu * a + tv * b;
            // Every fourth ray grazes: it arrives within 1e-3 radians of the plane.
            let lift = if k % 4 == 0 {
                1e-3 * (r() + 0.01)
            } else {
                0.3 + r()
            };
            let side = if k % 2 == 0 { 1.0 } else { -1.0 };
            let along = (r() - 0.5) * a + (r() - 0.5) * b;
            let dir = along.normalize() + side * lift * n;
            let orig = target - (2.0 + 6.0 * r()) * dir;
            let ray = f32_ray(orig, dir);
            let (ro, rd) = (ray.origin.as_dvec3(), ray.dir.as_dvec3());
            let (t, u, v) = cramer(o, a, b, ro, rd);
            let got = plane.hit(&as_gray(&ray), ray.tmax);
            // Away from the edges (where rounding may go either way) the two agree on
            // hit or miss.
            let margin = 1e-9;
            let inside =
                (margin..=1.0 - margin).contains(&u) && (margin..=1.0 - margin).contains(&v);
            let outside =
                !(-margin..=1.0 + margin).contains(&u) || !(-margin..=1.0 + margin).contains(&v);
            match got {
                Some(h) => {
                    assert!(!outside, "hit at ({u}, {v})");
                    let exact = ro + t * rd;
                    assert!(
                        (h.u - u.clamp(0.0, 1.0)).abs() < 1e-9
                            && (h.v - v.clamp(0.0, 1.0)).abs() < 1e-9
                    );
                    let b = h.hit_box.to_f64();
                    assert!(
                        (exact - b.min).min_element() >= -1e-12
                            && (b.max - exact).min_element() >= -1e-12,
                        "{exact:?} outside {b:?}"
                    );
                    // About an ulp of the coordinates wide, grazing rays included (their
                    // box grows by the rounding along the ray, still far below the
                    // search's 8 ulps).
                    let width = (b.max - b.min).max_element();
                    assert!(width <= 4.0 * ulp_of(scale), "box {width} wide");
                    // The f64 reference kernel's hit, in ulps of the patch scale: on every
                    // grazing ray (the hard case) and every eighth other one (the reference's
                    // search is most of this test's time).
                    if k % 4 == 0 || k % 8 == 1 {
                        let reference = intersect_f64(&p, ro, rd, 0.0, f64::INFINITY, &cfg, None)
                            .expect("the f64 reference hits too");
                        let err = (reference.hit_box.center() - (ro + f64::from(h.t) * rd))
                            .abs()
                            .max_element();
                        assert!(err <= 4.0 * ulp_of(scale), "{err} off the f64 reference");
                    }
                    hits += 1;
                    grazing += usize::from(k % 4 == 0);
                }
                None => {
                    assert!(!inside, "missed at ({u}, {v})");
                    misses += 1;
                }
            }
            // The kernel entry gives the same answer as the closed form itself.
            let mut stats = KernelStats::default();
            let via_kernel = intersect(&prepared, None, &ray, &cfg, &mut stats);
            assert_eq!(via_kernel.map(|h| h.t), got.map(|h| h.t));
        }
        assert!(
            hits > 800 && misses > 200 && grazing > 150,
            "{hits} {misses} {grazing}"
        );
    }
}

#[test]
fn rays_leaving_the_patch_never_meet_it_again() {
    // Without the kernel's leaving shortcut: rays from the secondary origin of each hit
    // (the widened box's corner, Dammertz §2.4) into the normal's hemisphere, and rays
    // going in from the opposite corner, find no crossing at t ≥ 0.
    let (o, a, b) = tilted();
    let plane = AffinePatch::new(o, a, b).unwrap();
    let n = a.cross(b).normalize();
    let mut state = 0x1234_5678;
    for k in 0..4000 {
        let mut r = || uniform(&mut state);
        let target = o + r() * a + r() * b;
        let dir = ((r() - 0.5) * a + (r() - 0.5) * b).normalize() - (0.02 + r()) * n;
        let ray = f32_ray(target - 3.0 * dir, dir);
        let Some(h) = plane.hit(&as_gray(&ray), f32::INFINITY) else {
            continue;
        };
        let leave = widen_by_net_rounding(h.hit_box, &plane.bounds());
        // Grazing on every eighth ray: the new direction within 1e-4 of the plane.
        let tilt = if k % 8 == 0 { 1e-4 } else { 0.05 + r() };
        let along = ((r() - 0.5) * a + (r() - 0.5) * b).normalize();
        for (outside, side) in [(true, 1.0), (false, -1.0)] {
            let from = secondary_origin(&leave, n.as_vec3(), outside, DEFAULT_ULPS);
            let out = f32_ray(from.as_dvec3(), along + side * tilt * n);
            assert!(
                plane.hit(&as_gray(&out), f32::INFINITY).is_none(),
                "ray {out:?} leaving {h:?} meets the plane again"
            );
        }
    }
}

#[test]
fn trimmed_planes_honour_their_trim() {
    // A parallelogram with a round hole of radius 0.3 at the centre of its unit square.
    let (o, a, b) = tilted();
    let p = affine_net(1, 1, o, a, b);
    let c = DVec2::splat(0.5);
    let hole = TrimLoop::closed(ParamCurve::circle(c, 0.3), true);
    let region = TrimRegion::new(&[hole], &Default::default())
        .unwrap()
        .unwrap();
    let unit = ParamRect {
        u0: 0.0,
        u1: 1.0,
        v0: 0.0,
        v1: 1.0,
    };
    let Coverage::Partial(trim) = region.coverage(unit) else {
        panic!("the hole cuts the patch");
    };
    let prepared = PreparedPatch::new(&p);
    assert!(matches!(prepared.data, Prepared::Affine(_)));
    let general = PreparedPatch::general(&p);
    let n = a.cross(b).normalize();
    let cfg = SubdivisionConfig::default();
    let mut state = 0xdead_beef;
    let (mut through, mut on) = (0, 0);
    for _ in 0..1000 {
        let mut r = || uniform(&mut state);
        let (u, v) = (r(), r());
        let target = o + u * a + v * b;
        let dir = -(n + 0.5 * (r() - 0.5) * a.normalize());
        let ray = f32_ray(target - 4.0 * dir, dir);
        let mut stats = KernelStats::default();
        let got = intersect(&prepared, Some(&trim), &ray, &cfg, &mut stats);
        let searched = intersect(&general, Some(&trim), &ray, &cfg, &mut stats);
        let d = (DVec2::new(u, v) - c).length();
        // Away from the circle (1e-4 in parameters, far beyond both kernels' (u, v)
        // error) the hole decides alone, and the search agrees.
        if (d - 0.3).abs() < 1e-4 {
            continue;
        }
        assert_eq!(got.is_some(), d > 0.3, "({u}, {v})");
        assert_eq!(got.is_some(), searched.is_some(), "({u}, {v})");
        if let Some(h) = got {
            assert!((f64::from(h.u) - u).abs() < 1e-6 && (f64::from(h.v) - v).abs() < 1e-6);
            on += 1;
        } else {
            through += 1;
        }
    }
    assert!(through > 150 && on > 500, "{through} through, {on} on");
}

#[test]
fn rays_parallel_to_the_plane_miss() {
    // Exactly parallel: a patch in z = 1 and a ray along x, in the plane (0/0) and
    // beside it (±∞, which an infinite tmax would admit).
    let flat = AffinePatch::new(DVec3::new(0.0, 0.0, 1.0), DVec3::X, DVec3::Y).unwrap();
    for z in [1.0f32, 0.5] {
        let ray = Ray::new(Vec3::new(-1.0, 0.5, z), Vec3::X);
        assert!(flat.hit(&as_gray(&ray), f32::INFINITY).is_none(), "z = {z}");
    }
}

#[test]
fn bounds_hold_the_patch() {
    let (o, a, b) = tilted();
    let plane = AffinePatch::new(o, a, b).unwrap();
    let bounds = plane.bounds().to_f64();
    for c in [o, o + a, o + b, o + a + b] {
        assert!((c - bounds.min).min_element() > 0.0 && (bounds.max - c).min_element() > 0.0);
    }
}
