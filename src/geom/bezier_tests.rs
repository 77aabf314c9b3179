//! Bézier patch tests against independent computations: the explicit Bernstein sum, closed
//! forms, and the teapot's known degenerate points.

use glam::{DVec3, DVec4};
use proptest::prelude::*;

use super::*;
use crate::geom::bicubic::BicubicPatch;

fn binomial(n: usize, k: usize) -> f64 {
    (0..k).fold(1.0, |acc, i| acc * (n - i) as f64 / (i + 1) as f64)
}

fn bernstein(n: usize, i: usize, t: f64) -> f64 {
    binomial(n, i) * t.powi(i as i32) * (1.0 - t).powi((n - i) as i32)
}

/// The rational patch by its definition: Σ B_i(u) B_j(v) w_ij P_ij / Σ B_i(u) B_j(v) w_ij.
fn explicit_eval(p: &BezierPatch, u: f64, v: f64) -> DVec3 {
    let mut num = DVec4::ZERO;
    for j in 0..=p.degree_v() {
        for i in 0..=p.degree_u() {
            num +=
                p.homogeneous(i, j) * bernstein(p.degree_u(), i, u) * bernstein(p.degree_v(), j, v);
        }
    }
    num.truncate() / num.w
}

fn random_patch() -> impl Strategy<Value = BezierPatch> {
    (1usize..=6, 1usize..=6).prop_flat_map(|(du, dv)| {
        let n = (du + 1) * (dv + 1);
        (
            Just((du, dv)),
            prop::collection::vec(
                (-10.0f64..10.0, -10.0f64..10.0, -10.0f64..10.0, 0.1f64..10.0),
                n,
            ),
        )
            .prop_map(|((du, dv), pts)| {
                let pts = pts
                    .into_iter()
                    .map(|(x, y, z, w)| DVec4::new(x * w, y * w, z * w, w))
                    .collect();
                BezierPatch::new(du, dv, pts).unwrap()
            })
    })
}

fn teapot() -> Vec<BezierPatch> {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("testdata/teapot.bpt");
    crate::formats::bpt::read_bpt(&path).unwrap()
}

proptest! {
    #[test]
    fn transposed_exchanges_the_parameters(p in random_patch(), u in 0.0f64..=1.0, v in 0.0f64..=1.0) {
        let t = p.transposed();
        let (a, b) = (t.eval(v, u), explicit_eval(&p, u, v));
        prop_assert!((a - b).length() <= 1e-12 * (1.0 + b.length()), "{a} vs {b}");
        prop_assert_eq!((t.degree_u(), t.degree_v()), (p.degree_v(), p.degree_u()));
    }

    #[test]
    fn de_casteljau_equals_the_bernstein_sum(p in random_patch(), u in 0.0f64..=1.0, v in 0.0f64..=1.0) {
        let a = p.eval(u, v);
        let b = explicit_eval(&p, u, v);
        prop_assert!((a - b).length() <= 1e-12 * (1.0 + b.length()), "{a} vs {b}");
    }

    #[test]
    fn derivatives_match_central_differences(p in random_patch(), u in 0.05f64..0.95, v in 0.05f64..0.95) {
        let (_, su, sv) = p.derivatives(u, v);
        let h = 1e-6;
        let du = (explicit_eval(&p, u + h, v) - explicit_eval(&p, u - h, v)) / (2.0 * h);
        let dv = (explicit_eval(&p, u, v + h) - explicit_eval(&p, u, v - h)) / (2.0 * h);
        let scale = 1.0 + du.length().max(dv.length());
        prop_assert!((su - du).length() <= 1e-5 * scale, "{su} vs {du}");
        prop_assert!((sv - dv).length() <= 1e-5 * scale, "{sv} vs {dv}");
    }

    #[test]
    fn halves_reproduce_the_patch(p in random_patch(), s in 0.0f64..=1.0, t in 0.0f64..=1.0) {
        let (a, b) = p.split_u();
        let whole = p.eval(s * 0.5, t);
        prop_assert!((a.eval(s, t) - whole).length() <= 1e-11 * (1.0 + whole.length()));
        let whole = p.eval(0.5 + s * 0.5, t);
        prop_assert!((b.eval(s, t) - whole).length() <= 1e-11 * (1.0 + whole.length()));
        let (c, d) = p.split_v();
        let whole = p.eval(s, t * 0.5);
        prop_assert!((c.eval(s, t) - whole).length() <= 1e-11 * (1.0 + whole.length()));
        let whole = p.eval(s, 0.5 + t * 0.5);
        prop_assert!((d.eval(s, t) - whole).length() <= 1e-11 * (1.0 + whole.length()));
        prop_assert_eq!(d.domain(), ParamRect { u0: 0.0, u1: 1.0, v0: 0.5, v1: 1.0 });
    }

    #[test]
    fn tight_box_is_inside_the_control_box_and_holds_the_surface(p in random_patch()) {
        let (tight, control) = (p.tight_box(), p.control_box());
        for k in 0..3 {
            prop_assert!(tight.min[k] >= control.min[k] && tight.max[k] <= control.max[k]);
        }
        for i in 0..=10 {
            for j in 0..=10 {
                let q = p.eval(i as f64 / 10.0, j as f64 / 10.0);
                let slack = 1e-12 * (1.0 + q.length());
                for k in 0..3 {
                    prop_assert!(q[k] >= tight.min[k] - slack && q[k] <= tight.max[k] + slack);
                }
            }
        }
    }

    #[test]
    fn normal_is_unit_and_orthogonal_to_both_tangents(p in random_patch(), u in 0.0f64..=1.0, v in 0.0f64..=1.0) {
        let n = p.normal(u, v);
        prop_assert!((n.length() - 1.0).abs() < 1e-12);
        let (_, su, sv) = p.derivatives(u, v);
        // Where the tangents are well defined, the normal is orthogonal to them.
        if su.cross(sv).length() > 1e-6 * su.length() * sv.length() {
            prop_assert!(n.dot(su.normalize()).abs() < 1e-9);
            prop_assert!(n.dot(sv.normalize()).abs() < 1e-9);
        }
    }
}

#[test]
fn f32_evaluation_is_within_f32_rounding_of_f64() {
    for p in teapot() {
        for (u, v) in [(0.0, 0.0), (0.3, 0.7), (1.0, 0.5), (0.25, 1.0)] {
            let a = p.eval(u, v);
            let b = p.eval_f32(u as f32, v as f32).as_dvec3();
            assert!(
                (a - b).length() <= 64.0 * f32::EPSILON as f64 * (1.0 + a.length()),
                "{a} vs {b}"
            );
        }
    }
}

#[test]
fn bicubic_fast_path_agrees_with_the_general_path() {
    for p in teapot() {
        let fast = BicubicPatch::from_patch(&p).expect("teapot patches are plain bicubic");
        for (u, v) in [(0.0, 0.0), (0.1, 0.9), (0.5, 0.5), (1.0, 0.3)] {
            let (s, su, sv) = p.derivatives(u, v);
            let (fs, fsu, fsv) = fast.derivatives(u, v);
            assert!((s - fs).length() < 1e-12 && (fast.eval(u, v) - s).length() < 1e-12);
            assert!((su - fsu).length() < 1e-11 && (sv - fsv).length() < 1e-11);
        }
    }
}

#[test]
fn rational_quarter_circle_is_exact() {
    // The classic quadratic rational arc: (1,0), (1,1) with weight √2/2, (0,1), extruded
    // linearly in z. Every point lies on the unit cylinder.
    let w = std::f64::consts::FRAC_1_SQRT_2;
    let pts = [
        DVec3::new(1.0, 0.0, 0.0),
        DVec3::new(1.0, 1.0, 0.0),
        DVec3::new(0.0, 1.0, 0.0),
        DVec3::new(1.0, 0.0, 1.0),
        DVec3::new(1.0, 1.0, 1.0),
        DVec3::new(0.0, 1.0, 1.0),
    ];
    let p = BezierPatch::from_weighted(2, 1, &pts, &[1.0, w, 1.0, 1.0, w, 1.0]).unwrap();
    assert!(p.is_rational());
    for k in 0..=20 {
        let q = p.eval(k as f64 / 20.0, 0.3);
        assert!((q.truncate().length() - 1.0).abs() < 1e-15, "{q}");
        // The cylinder's normal is radial.
        let n = p.normal(k as f64 / 20.0, 0.3);
        assert!((n.truncate().normalize().dot(q.truncate().normalize()).abs() - 1.0).abs() < 1e-12);
    }
}

#[test]
fn teapot_collapsed_edges_have_the_axis_normal() {
    // The lid's top (patches 20..24 at v = 0... by inspection of the data, the points that
    // coincide lie on the z axis) and the bottom: wherever a whole patch edge collapses to a
    // point on the z axis, the surface is rotationally symmetric there, so the normal is
    // ±z. The cross product of the first derivatives vanishes at those points.
    let mut checked = 0;
    for p in teapot() {
        for (edge_v, v) in [(0usize, 0.0), (3, 1.0)] {
            let row: Vec<DVec3> = (0..4).map(|i| p.point(i, edge_v)).collect();
            if row.iter().all(|q| *q == row[0]) && row[0].x == 0.0 && row[0].y == 0.0 {
                for u in [0.0, 0.3, 0.5, 1.0] {
                    let (_, su, sv) = p.derivatives(u, v);
                    assert!(su.cross(sv).length() < 1e-12, "not degenerate");
                    let n = p.normal(u, v);
                    assert!(n.is_finite());
                    assert!(
                        (n.z.abs() - 1.0).abs() < 1e-6,
                        "normal {n} at a collapsed edge"
                    );
                }
                checked += 1;
            }
        }
    }
    assert!(
        checked >= 8,
        "expected the lid and bottom collapsed edges, found {checked}"
    );
}

#[test]
fn invalid_patches_are_refused() {
    let p = |n| vec![DVec4::new(0.0, 0.0, 0.0, 1.0); n];
    assert_eq!(BezierPatch::new(0, 1, p(2)), Err(GeomError::Degree(0)));
    assert_eq!(BezierPatch::new(16, 1, p(34)), Err(GeomError::Degree(16)));
    assert_eq!(
        BezierPatch::new(1, 1, p(3)),
        Err(GeomError::PointCount {
            expected: 4,
            found: 3
        })
    );
    let mut bad = p(4);
    bad[2].y = f64::NAN;
    assert_eq!(
        BezierPatch::new(1, 1, bad),
        Err(GeomError::NonFinite { index: 2 })
    );
    let mut bad = p(4);
    bad[3].w = 0.0;
    assert_eq!(
        BezierPatch::new(1, 1, bad),
        Err(GeomError::Weight {
            index: 3,
            weight: 0.0
        })
    );
}

#[test]
fn zero_area_means_the_surface_ignores_a_parameter() {
    // Independent check: the cross product of the exact derivatives vanishes everywhere
    // exactly when the patch is reported as having no area.
    let curve = |transposed: bool| {
        let pts: Vec<DVec3> = (0..12)
            .map(|k| {
                let (i, j) = (k % 4, k / 4);
                let s = if transposed {
                    j as f64 / 2.0
                } else {
                    i as f64 / 3.0
                };
                DVec3::new(2.0 * s - 1.0, (3.0 * s).sin(), 0.3 * s * s)
            })
            .collect();
        BezierPatch::from_points(3, 2, &pts).unwrap()
    };
    let point = BezierPatch::from_points(1, 1, &[DVec3::ONE; 4]).unwrap();
    for p in [curve(false), curve(true), point] {
        assert!(p.has_zero_area());
        for (u, v) in [(0.2, 0.7), (0.5, 0.5), (0.9, 0.1)] {
            let (_, su, sv) = p.derivatives(u, v);
            assert!(su.cross(sv).length() < 1e-12);
        }
    }
    // The teapot's patches with one collapsed edge keep their area.
    for p in teapot() {
        assert!(!p.has_zero_area());
        let (_, su, sv) = p.derivatives(0.5, 0.5);
        assert!(su.cross(sv).length() > 1e-6);
    }
}
