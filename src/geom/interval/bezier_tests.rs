use super::*;
use crate::geom::BezierPatch;
use glam::DVec3;
use proptest::prelude::*;

/// A random patch of degree 1..=4 in each direction, rational when `rational`.
fn patch() -> impl Strategy<Value = BezierPatch> {
    (1usize..=4, 1usize..=4, any::<bool>()).prop_flat_map(|(du, dv, rational)| {
        let n = (du + 1) * (dv + 1);
        let w = if rational {
            0.25..4.0
        } else {
            1.0..1.0 + f64::EPSILON
        };
        (
            prop::collection::vec(prop::array::uniform3(-10.0..10.0f64), n),
            prop::collection::vec(w, n),
        )
            .prop_map(move |(p, w)| {
                let pts: Vec<DVec3> = p.into_iter().map(DVec3::from_array).collect();
                BezierPatch::from_weighted(du, dv, &pts, &w).unwrap()
            })
    })
}

fn param_box() -> impl Strategy<Value = ParamBox> {
    (0.0..1.0f64, 0.0..1.0f64, 0.0..1.0f64, 0.0..1.0f64).prop_map(|(a, b, c, d)| ParamBox {
        u: Interval::spanning(a, b),
        v: Interval::spanning(c, d),
    })
}

/// The sampled `f64` value is itself rounded (by far less than this relative amount), so
/// containment is checked up to it: the enclosure is rigorous for the exact value.
const SAMPLE_ROUNDING: f64 = 1e-12;

fn holds(iv: Interval, x: f64, scale: f64) -> bool {
    let slack = SAMPLE_ROUNDING * scale.max(1.0);
    iv.lo() - slack <= x && x <= iv.hi() + slack
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    /// The patch and its Euclidean partial derivatives at points sampled in a box lie in
    /// the enclosures over that box (values from `BezierPatch::derivatives`, independent
    /// `f64` de Casteljau and the quotient rule).
    #[test]
    fn enclosures_contain_sampled_values(
        p in patch(),
        b in param_box(),
        samples in prop::collection::vec((0.0..=1.0f64, 0.0..=1.0f64), 8),
    ) {
        let s = enclose_patch(&p, &b);
        let (eu, ev) = enclose_derivatives(&p, &b);
        for (a, c) in samples {
            let u = b.u.lo() + a * (b.u.hi() - b.u.lo());
            let v = b.v.lo() + c * (b.v.hi() - b.v.lo());
            let (u, v) = (u.min(b.u.hi()), v.min(b.v.hi()));
            let (x, xu, xv) = p.derivatives(u, v);
            for k in 0..3 {
                prop_assert!(holds(s[k], x[k], x.abs().max_element()), "S{k} {} outside {:?}", x[k], s[k]);
                prop_assert!(holds(eu[k], xu[k], xu.abs().max_element()), "Su{k} {} outside {:?}", xu[k], eu[k]);
                prop_assert!(holds(ev[k], xv[k], xv.abs().max_element()), "Sv{k} {} outside {:?}", xv[k], ev[k]);
            }
        }
    }

    /// Point evaluation of the net encloses the `f64` homogeneous point and derivatives.
    #[test]
    fn point_evaluation_encloses_f64_evaluation(p in patch(), u in 0.0..=1.0f64, v in 0.0..=1.0f64) {
        let net = IntervalNet::from_patch(&p);
        let (h, hu, hv) = net.eval(u, v);
        let exact = p.eval_homogeneous(u, v);
        for k in 0..4 {
            prop_assert!(holds(h[k], exact[k], exact.abs().max_element()));
        }
        // Euclidean derivatives by the quotient rule on the interval results.
        let (_, su, sv) = p.derivatives(u, v);
        for k in 0..3 {
            let s = h[k].checked_div(h[3]).unwrap();
            let qu = (hu[k] - s * hu[3]).checked_div(h[3]).unwrap();
            let qv = (hv[k] - s * hv[3]).checked_div(h[3]).unwrap();
            prop_assert!(holds(qu, su[k], su.abs().max_element()));
            prop_assert!(holds(qv, sv[k], sv.abs().max_element()));
        }
    }
}

/// Over a small box the enclosures are tight: the sub-patch hull shrinks with the box,
/// which is what lets Krawczyk's test succeed on small regions.
#[test]
fn enclosures_shrink_with_the_box() {
    let pts: Vec<DVec3> = (0..16)
        .map(|k| {
            let (i, j) = ((k % 4) as f64, (k / 4) as f64);
            DVec3::new(i, j, (i * j).sin())
        })
        .collect();
    let p = BezierPatch::from_points(3, 3, &pts).unwrap();
    let h = 1e-6;
    let b = ParamBox {
        u: Interval::new(0.4, 0.4 + h).unwrap(),
        v: Interval::new(0.7, 0.7 + h).unwrap(),
    };
    let s = enclose_patch(&p, &b);
    let (su, sv) = enclose_derivatives(&p, &b);
    let (_, du, dv) = p.derivatives(0.4, 0.7);
    for k in 0..3 {
        // A first-order move over the box, plus rounding: a few times |S_u| h.
        assert!(
            s[k].width() < 10.0 * (du.length() + dv.length()) * h,
            "{:?}",
            s[k]
        );
        // Derivatives vary by O(h) times the second derivative (control net scale ~10).
        assert!(su[k].width() < 1e3 * h && sv[k].width() < 1e3 * h);
    }
}

#[test]
fn bisection_halves_the_wider_side() {
    let b = ParamBox {
        u: Interval::new(0.0, 0.5).unwrap(),
        v: Interval::new(0.0, 1.0).unwrap(),
    };
    let (l, r) = b.bisect().unwrap();
    assert_eq!(l.v, Interval::new(0.0, 0.5).unwrap());
    assert_eq!(r.v, Interval::new(0.5, 1.0).unwrap());
    assert_eq!(l.u, b.u);
    let tiny = ParamBox {
        u: Interval::new(0.5, 0.5f64.next_up()).unwrap(),
        v: Interval::point(0.5),
    };
    assert!(tiny.bisect().is_none());
}
