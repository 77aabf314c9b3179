//! The report of `bench lg90`: one Markdown table per test case, our value beside the
//! paper's for every statistic of Tables 2–6, and the same as CSV.

use std::fmt::Write;

use super::{CaseResult, METHODS, Run, paper};

/// The rows of Tables 2–6 (§7.1), plus the total ray count of Table 1.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Statistic {
    NormalizedTime,
    SurfacesTested,
    SurfacesSearched,
    RayBoxTests,
    SearchIterations,
    NewtonStarts,
    NewtonIterationsPerCall,
    SafeRegionWidth,
    CacheMissesPerSurface,
    CacheHitRatio,
    /// LG90's triviality tests (§6), tests 1–3: not in the paper's tables.
    Trivial(usize),
    TotalRays,
}

impl Statistic {
    /// The rows of [`paper::PaperTable::rows`], in order.
    pub const PAPER_ROWS: [Statistic; 8] = [
        Statistic::NormalizedTime,
        Statistic::SurfacesTested,
        Statistic::SurfacesSearched,
        Statistic::RayBoxTests,
        Statistic::SearchIterations,
        Statistic::NewtonStarts,
        Statistic::NewtonIterationsPerCall,
        Statistic::SafeRegionWidth,
    ];

    /// Every row of the report, in order.
    pub const ALL: [Statistic; 14] = [
        Statistic::NormalizedTime,
        Statistic::SurfacesTested,
        Statistic::SurfacesSearched,
        Statistic::RayBoxTests,
        Statistic::SearchIterations,
        Statistic::NewtonStarts,
        Statistic::NewtonIterationsPerCall,
        Statistic::SafeRegionWidth,
        Statistic::CacheMissesPerSurface,
        Statistic::CacheHitRatio,
        Statistic::Trivial(0),
        Statistic::Trivial(1),
        Statistic::Trivial(2),
        Statistic::TotalRays,
    ];

    /// The row label, as in the paper.
    pub fn label(self) -> &'static str {
        match self {
            Statistic::NormalizedTime => "normalized time",
            Statistic::SurfacesTested => "surfaces tested / ray",
            Statistic::SurfacesSearched => "surfaces searched / ray",
            Statistic::RayBoxTests => "ray-box tests / ray",
            Statistic::SearchIterations => "search iterations / ray",
            Statistic::NewtonStarts => "Newton starts / ray",
            Statistic::NewtonIterationsPerCall => "Newton iterations / call",
            Statistic::SafeRegionWidth => "av. width of safe regions",
            Statistic::CacheMissesPerSurface => "cache misses / surface",
            Statistic::CacheHitRatio => "cache hit ratio",
            Statistic::Trivial(0) => "triviality test 1 (box) / ray",
            Statistic::Trivial(1) => "triviality test 2 (K) / ray",
            Statistic::Trivial(_) => "triviality test 3 (safe region) / ray",
            Statistic::TotalRays => "total num. of rays",
        }
    }

    fn decimals(self) -> usize {
        match self {
            Statistic::SafeRegionWidth => 3,
            Statistic::TotalRays => 0,
            _ => 2,
        }
    }
}

/// Our value of `stat` for `run` on a scene of `patches` patches, `toth_seconds` being
/// TOTH's time on the same case. `None` where we have no such number: the time without a
/// TOTH run, and the cache rows of kernels that cache nothing.
pub fn ours(stat: Statistic, run: &Run, patches: usize, toth_seconds: Option<f64>) -> Option<f64> {
    let r = &run.report;
    let toth = r.toth.as_ref();
    let t = |f: fn(&crate::render::stats::TothReport) -> f64| Some(toth.map_or(0.0, f));
    match stat {
        Statistic::NormalizedTime => toth_seconds.map(|s| run.seconds / s),
        Statistic::SurfacesTested => Some(r.surfaces_tested_per_ray.mean),
        Statistic::SurfacesSearched => t(|x| x.surfaces_searched_per_ray),
        Statistic::RayBoxTests => Some(r.box_tests_per_ray.mean),
        Statistic::SearchIterations => t(|x| x.search_iterations_per_ray),
        Statistic::NewtonStarts => t(|x| x.newton_starts_per_ray),
        Statistic::NewtonIterationsPerCall => t(|x| x.newton_iterations_per_call),
        Statistic::SafeRegionWidth => t(|x| x.mean_safe_region_width),
        Statistic::CacheMissesPerSurface => r
            .cache
            .as_ref()
            .map(|c| c.misses as f64 / patches.max(1) as f64),
        // The paper prints percent.
        Statistic::CacheHitRatio => r.cache.as_ref().map(|c| 100.0 * c.hit_ratio),
        Statistic::Trivial(k) => toth.map(|x| x.trivial_per_ray[k]),
        Statistic::TotalRays => Some(r.total as f64),
    }
}

/// The paper's value of `stat` for the method named `name` on `result`'s case.
pub fn papers(stat: Statistic, name: &str, result: &CaseResult) -> Option<f64> {
    let column = METHODS.iter().position(|m| m.name == name)?;
    let table = result.case.table;
    if let Some(row) = Statistic::PAPER_ROWS.iter().position(|&s| s == stat) {
        return Some(table.rows[row][column]);
    }
    if stat == Statistic::TotalRays {
        return Some(paper::TOTAL_RAYS[result.case.number - 1] as f64);
    }
    let cached = column.checked_sub(2)?;
    match stat {
        Statistic::CacheMissesPerSurface => Some(table.cache[0][cached]),
        Statistic::CacheHitRatio => Some(table.cache[1][cached]),
        _ => None,
    }
}

/// TOTH's render seconds on this case, when TOTH ran.
fn toth_seconds(result: &CaseResult) -> Option<f64> {
    result
        .runs
        .iter()
        .find(|r| r.method.name == METHODS[0].name)
        .map(|r| r.seconds)
}

fn cell(v: Option<f64>, decimals: usize) -> String {
    v.map_or_else(|| "—".to_string(), |x| format!("{x:.decimals$}"))
}

/// One Markdown table per case: a column for us and one for the paper per method.
pub fn markdown(results: &[CaseResult]) -> String {
    let mut s = String::new();
    for result in results {
        let case = result.case;
        let _ = writeln!(
            s,
            "### Table {}: test case {} ({} {} teapot{}, {} light{}, depth {}; {} patches, {}², seed {})\n",
            case.number + 1,
            case.number,
            case.teapots,
            if case.reflective {
                "reflective"
            } else {
                "plain"
            },
            if case.teapots == 1 { "" } else { "s" },
            case.lights,
            if case.lights == 1 { "" } else { "s" },
            case.depth,
            result.patches,
            result.size,
            super::SCENE_SEED,
        );
        s.push_str("| statistic |");
        for run in &result.runs {
            let _ = write!(s, " {} | paper |", run.method.name);
        }
        s.push_str("\n|---|");
        s.push_str(&"---:|---:|".repeat(result.runs.len()));
        s.push('\n');
        let toth = toth_seconds(result);
        for stat in Statistic::ALL {
            let _ = write!(s, "| {} |", stat.label());
            for run in &result.runs {
                let d = stat.decimals();
                let _ = write!(
                    s,
                    " {} | {} |",
                    cell(ours(stat, run, result.patches, toth), d),
                    cell(papers(stat, run.method.name, result), d)
                );
            }
            s.push('\n');
        }
        let clock = if result.runs.iter().all(|r| r.cpu) {
            "CPU time of all threads"
        } else {
            "wall-clock time"
        };
        let _ = write!(
            s,
            "\nTimes are {clock}. Per-ray rows are over all rays (the paper counts some only over rays that meet the scene's box or a surface); the paper's total rays are at 512².\n\n",
        );
    }
    s
}

/// The same numbers as CSV, one line per case, method and statistic.
pub fn csv(results: &[CaseResult]) -> String {
    let mut s = String::from("case,table,method,order,statistic,ours,paper\n");
    for result in results {
        let toth = toth_seconds(result);
        for run in &result.runs {
            for stat in Statistic::ALL {
                let v = |x: Option<f64>| x.map_or(String::new(), |x| x.to_string());
                let _ = writeln!(
                    s,
                    "{},{},{},{},{},{},{}",
                    result.case.number,
                    result.case.number + 1,
                    run.method.name,
                    format!("{:?}", run.method.order).to_lowercase(),
                    stat.label(),
                    v(ours(stat, run, result.patches, toth)),
                    v(papers(stat, run.method.name, result)),
                );
            }
        }
    }
    s
}
