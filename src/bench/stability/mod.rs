//! The numerical stability suite: hard cases ([`cases`]) run against every kernel
//! path and compared ray by ray with the `f64` reference ([`run`]), summarised as a
//! Markdown or CSV table ([`report`]). The acceptance criteria of the float-precision
//! kernel are [`Criterion`]s, checked by `tests/lib/stability_suite.rs` on the reduced suite.

pub mod cases;
pub mod report;
pub mod run;

use std::fmt;

use indicatif::ProgressBar;

pub use cases::{Case, SuiteSize, all_cases};
pub use run::{BOX_TOLERANCE_ULPS, Figures, KernelPath, SplitFigures, run_case};

/// Largest median distance from the reference hit across the surface (along its normal), in
/// ulps of the hit's largest coordinate (the suite's acceptance criterion).
pub const MAX_MEDIAN_ULPS: f64 = 4.0;

/// Largest number of de Casteljau splits one ray–patch test may take: the kernel's proven
/// bound (src/kernel/subdivision/search.rs), 4096 at full precision and 24 doublings of a
/// coarsening end game 64 splits apart. Without that budget the work has no bound: a
/// grazing ray hits about 1/θ boxes per level (BENCHMARKS.md, stability).
pub const MAX_SPLITS_PER_PATCH_TEST: u64 = crate::kernel::subdivision::MAX_SPLITS_PER_TEST;

/// One acceptance criterion for the float-precision kernel.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Criterion {
    Holes,
    FalseHits,
    SelfHits,
    NonFiniteNormals,
    NanPixels,
    Splits,
    MedianDistance,
}

impl fmt::Display for Criterion {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Criterion::Holes => "holes",
            Criterion::FalseHits => "false hits",
            Criterion::SelfHits => "self-hits",
            Criterion::NonFiniteNormals => "non-finite normals",
            Criterion::NanPixels => "NaN pixels",
            Criterion::Splits => "splits",
            Criterion::MedianDistance => "median distance",
        })
    }
}

impl Figures {
    /// The criteria these figures fail.
    pub fn failures(&self) -> Vec<Criterion> {
        if self.refused.is_some() {
            // Refusing with a clear message is the accepted answer for such input.
            return Vec::new();
        }
        let splits_unbounded = self
            .splits
            .is_some_and(|s| s.max_per_patch > MAX_SPLITS_PER_PATCH_TEST);
        [
            (self.holes > 0, Criterion::Holes),
            (self.false_hits > 0, Criterion::FalseHits),
            (self.self_hits > 0, Criterion::SelfHits),
            (self.non_finite_normals > 0, Criterion::NonFiniteNormals),
            (self.nan_pixels > 0, Criterion::NanPixels),
            (splits_unbounded, Criterion::Splits),
            (
                self.normal_distance_median > MAX_MEDIAN_ULPS,
                Criterion::MedianDistance,
            ),
        ]
        .into_iter()
        .filter_map(|(failed, c)| failed.then_some(c))
        .collect()
    }
}

/// The figures of one case on one kernel path.
#[derive(Clone, Debug)]
pub struct CaseResult {
    pub case: String,
    pub path: KernelPath,
    pub figures: Figures,
}

/// Runs every case on every path in `paths`, advancing `progress` once per (case, path).
pub fn run_suite(
    size: SuiteSize,
    seed: u64,
    paths: &[KernelPath],
    progress: &ProgressBar,
) -> Vec<CaseResult> {
    let cases = all_cases(size, seed);
    progress.set_length((cases.len() * paths.len()) as u64);
    let mut results = Vec::new();
    for (k, case) in cases.iter().enumerate() {
        for &path in paths {
            progress.set_message(format!("{} ({})", case.name, path.name()));
            let figures = run_case(case, path, size.image_size(), seed ^ k as u64);
            results.push(CaseResult {
                case: case.name.clone(),
                path,
                figures,
            });
            progress.inc(1);
        }
    }
    progress.finish_and_clear();
    results
}
