//! The `f64` reference path against a closed form: a ray against a planar bilinear patch
//! that is a parallelogram, `S(u, v) = p + u a + v b`, solved by Cramer's rule.

use crate::kernel_common;

use glam::DVec3;
use kernel_common::Rng;
use patchtrace::geom::BezierPatch;
use patchtrace::kernel::subdivision::{SubdivisionConfig, intersect_f64};

#[test]
fn f64_path_matches_the_closed_form_on_a_parallelogram() {
    let mut rng = Rng::new(21);
    let cfg = SubdivisionConfig::default();
    let mut hits = 0;
    for _ in 0..300 {
        let p = DVec3::new(
            rng.range(-3.0, 3.0),
            rng.range(-3.0, 3.0),
            rng.range(-3.0, 3.0),
        );
        let a = rng.direction() * rng.range(0.5, 2.0);
        let b =
            (rng.direction().cross(a).normalize() + 0.3 * rng.direction()) * rng.range(0.5, 2.0);
        let patch = BezierPatch::from_points(1, 1, &[p, p + a, p + b, p + a + b]).unwrap();
        let (u0, v0) = (rng.range(-0.2, 1.2), rng.range(-0.2, 1.2));
        let target = p + u0 * a + v0 * b;
        let o = target + rng.direction() * rng.range(2.0, 5.0);
        let d = (target - o) * rng.range(0.5, 2.0);
        // Closed form: o + t d = p + u a + v b, i.e. [a b -d](u v t)ᵀ = o - p.
        let r = o - p;
        let det = a.dot(b.cross(-d));
        if det.abs() < 0.05 * a.length() * b.length() * d.length() {
            continue; // grazing: the closed form itself is ill-conditioned
        }
        let u = r.dot(b.cross(-d)) / det;
        let v = a.dot(r.cross(-d)) / det;
        let t = a.dot(b.cross(r)) / det;
        let margin = 1e-9;
        let inside = |x: f64| x > margin && x < 1.0 - margin;
        let got = intersect_f64(&patch, o, d, 0.0, f64::INFINITY, &cfg, None);
        if !(inside(u) && inside(v)) {
            let outside = |x: f64| x < -margin || x > 1.0 + margin;
            if outside(u) || outside(v) {
                assert!(
                    got.is_none(),
                    "hit outside the patch: {got:?} vs uv {u} {v}"
                );
            }
            continue;
        }
        let h = got.expect("ray through the parallelogram must hit");
        hits += 1;
        let scale = 1.0 + t.abs();
        assert!((h.t - t).abs() < 1e-12 * scale, "t {} vs {t}", h.t);
        assert!(
            (h.u - u).abs() < 1e-12 && (h.v - v).abs() < 1e-12,
            "uv {} {} vs {u} {v}",
            h.u,
            h.v
        );
        let q = o + t * d;
        let grown = 1e-12 * (1.0 + q.abs().max_element());
        assert!(
            (0..3).all(|i| q[i] >= h.hit_box.min[i] - grown && q[i] <= h.hit_box.max[i] + grown),
            "closed-form point outside the hit box"
        );
    }
    assert!(hits > 100, "only {hits} hits tested");
}

/// Regression (found by the stability suite): an axis-parallel ray whose origin lies in the
/// plane of a box face gave 0 · inf = NaN in the kernel's own f64 slab test, which reported
/// t = 0 (a silhouette "hole" in the reference). The ray x = 0 runs along the patch's edge
/// plane and must hit at t = 5.
#[test]
fn f64_reference_handles_rays_in_a_box_face_plane() {
    use glam::DVec3;
    use patchtrace::geom::BezierPatch;
    use patchtrace::kernel::subdivision::{
        PreparedPatch, SubdivisionConfig, intersect, intersect_f64,
    };
    let corners = [
        DVec3::new(0.0, 0.0, 0.0),
        DVec3::new(1.0, 0.0, 0.0),
        DVec3::new(0.0, 1.0, 0.0),
        DVec3::new(1.0, 1.0, 0.0),
    ];
    let patch = BezierPatch::from_points(1, 1, &corners).unwrap();
    let cfg = SubdivisionConfig::default();
    for (o, d) in [
        (DVec3::new(0.0, 0.5, 5.0), DVec3::NEG_Z),
        (DVec3::new(0.3, 1.0, 5.0), DVec3::NEG_Z),
    ] {
        let h = intersect_f64(&patch, o, d, 0.0, f64::INFINITY, &cfg, None).expect("hit");
        assert!((h.t - 5.0).abs() < 1e-12, "t = {}", h.t);
        let mut stats = Default::default();
        let ray = patchtrace::geom::Ray::new(o.as_vec3(), d.as_vec3());
        let h =
            intersect(&PreparedPatch::new(&patch), None, &ray, &cfg, &mut stats).expect("f32 hit");
        assert!((h.t - 5.0).abs() < 1e-5, "t = {}", h.t);
    }
}
