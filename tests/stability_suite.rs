//! The reduced stability suite of issue 7 on the float-precision kernel: 0 holes and 0 false
//! hits outside the final box's extent, 0 self-hits, 0 non-finite normals, 0 NaN pixels,
//! bounded splits and a median hit distance of at most 4 ulps, all against the `f64`
//! reference. Cases that genuinely fail are listed in `EXPECTED_FAILURES` with the reason;
//! the test fails if such a case starts passing (so the list cannot go stale) or if any
//! other criterion fails.

use indicatif::ProgressBar;
use patchtrace::bench::stability::{Criterion, KernelPath, SuiteSize, report, run_suite};

/// Known failures of the `f32` path: (case, criterion, why).
const EXPECTED_FAILURES: &[(&str, Criterion, &str)] = &[
    (
        "patch collapsed to a curve",
        Criterion::SelfHits,
        "a zero-area patch has no normal to offset along: the f32 kernel reports hits within \
         its final box (the reference, correctly, none) and secondary rays from them re-hit the \
         curve",
    ),
    (
        "rational, weights 1e-3..1e3",
        Criterion::Splits,
        "a ray–patch test on a rational patch with weights 1e-3..1e3 takes ~9600 splits",
    ),
    (
        "teapot x1e-6",
        Criterion::Holes,
        "one ray misses that the reference hits; not yet diagnosed",
    ),
    (
        "teapot x1e-35 (subnormal range)",
        Criterion::NanPixels,
        "the integrator normalises f32 vectors ~1e-35 long (squared length underflows); the \
         loader refuses such scenes (MIN_OBJECT_EXTENT), the suite builds them directly",
    ),
    (
        "teapot x1e-35 (subnormal range)",
        Criterion::MedianDistance,
        "final boxes stop shrinking at the subnormal spacing, far above an ulp of the hit",
    ),
    (
        "teapot x1e-40 (subnormal range)",
        Criterion::SelfHits,
        "subnormal control points: the ulp offset of secondary origins is too small",
    ),
    (
        "teapot x1e-40 (subnormal range)",
        Criterion::NanPixels,
        "the integrator normalises f32 vectors ~1e-40 long (squared length underflows)",
    ),
    (
        "teapot x1e-40 (subnormal range)",
        Criterion::MedianDistance,
        "subnormal coordinates carry fewer significant bits than an f32 ulp assumes",
    ),
];

#[test]
fn float_precision_kernel_meets_the_stability_criteria() {
    let results = run_suite(
        SuiteSize::Reduced,
        1,
        &[KernelPath::F32],
        &ProgressBar::hidden(),
    );
    let mut problems = Vec::new();
    for r in &results {
        let fails = r.figures.failures();
        for c in &fails {
            if !EXPECTED_FAILURES
                .iter()
                .any(|(n, e, _)| *n == r.case && e == c)
            {
                problems.push(format!("{}: {c} fails: {:?}", r.case, r.figures));
            }
        }
        for (_, c, why) in EXPECTED_FAILURES.iter().filter(|(n, _, _)| *n == r.case) {
            if !fails.contains(c) {
                problems.push(format!(
                    "{}: {c} now passes; remove it from EXPECTED_FAILURES ({why})",
                    r.case
                ));
            }
        }
    }
    for (name, _, _) in EXPECTED_FAILURES {
        assert!(
            results.iter().any(|r| r.case == *name),
            "no case named {name}"
        );
    }
    assert!(
        problems.is_empty(),
        "{}\n\n{}",
        problems.join("\n"),
        report::markdown(&results)
    );
    // Every primary ray is compared: the reference must hit somewhere in the suite.
    assert!(
        results
            .iter()
            .all(|r| r.figures.rays == SuiteSize::Reduced.rays())
    );
}

#[test]
fn csv_has_one_row_per_result_and_a_cell_per_column() {
    let results = run_suite(SuiteSize::Reduced, 7, &[], &ProgressBar::hidden());
    assert!(results.is_empty());
    let text = report::csv(&results);
    assert_eq!(text.lines().count(), 1, "header only for no results");
    assert_eq!(text.lines().next().map(|h| h.split(',').count()), Some(19));
}
