//! The stability table: Markdown for people, CSV for tools. One row per case and kernel
//! path, with the criteria the row fails in the last column.

use std::fmt::Write;

use super::CaseResult;

/// Column headers, shared by both formats.
const HEADERS: [&str; 17] = [
    "case",
    "kernel",
    "rays",
    "ref hits",
    "hits",
    "holes",
    "false hits",
    "within box",
    "secondary",
    "self-hits",
    "non-finite normals",
    "dist median (ulps)",
    "dist max (ulps)",
    "dist across median (ulps)",
    "splits mean",
    "splits max (per patch)",
    "NaN px",
];

/// The cells of one row, without the failure column.
fn cells(r: &CaseResult) -> Vec<String> {
    let f = &r.figures;
    let splits = match f.splits {
        Some(s) => [
            format!("{:.1}", s.mean),
            format!("{} ({})", s.max, s.max_per_patch),
        ],
        None => ["n/a".to_string(), "n/a".to_string()],
    };
    let [splits_mean, splits_max] = splits;
    vec![
        r.case.clone(),
        r.path.name().to_string(),
        f.rays.to_string(),
        f.reference_hits.to_string(),
        f.hits.to_string(),
        f.holes.to_string(),
        f.false_hits.to_string(),
        f.within_box.to_string(),
        f.secondary_rays.to_string(),
        f.self_hits.to_string(),
        f.non_finite_normals.to_string(),
        format!("{:.2}", f.distance_median),
        format!("{:.3e}", f.distance_max),
        format!("{:.2}", f.normal_distance_median),
        splits_mean,
        splits_max,
        format!("{}/{}", f.nan_pixels, f.pixels),
    ]
}

fn failures(r: &CaseResult) -> String {
    let fails = r.figures.failures();
    if let Some(message) = &r.figures.refused {
        format!("refused: {message}")
    } else if fails.is_empty() {
        "ok".to_string()
    } else {
        fails
            .iter()
            .map(|c| c.to_string())
            .collect::<Vec<_>>()
            .join("; ")
    }
}

/// A Markdown table of the results.
pub fn markdown(results: &[CaseResult]) -> String {
    let mut out = String::new();
    let header: Vec<&str> = HEADERS.iter().copied().chain(["fails"]).collect();
    let _ = writeln!(out, "| {} |", header.join(" | "));
    let _ = writeln!(out, "|{}", "---|".repeat(header.len()));
    for r in results {
        let mut row = cells(r);
        row.push(failures(r));
        let _ = writeln!(out, "| {} |", row.join(" | "));
    }
    out
}

/// A CSV table of the results; the split columns are empty where a path does not count
/// splits, the failures column lists criteria separated by `;`.
pub fn csv(results: &[CaseResult]) -> String {
    let mut out = String::new();
    let _ = writeln!(
        out,
        "case,kernel,rays,ref_hits,hits,holes,false_hits,within_box,secondary,self_hits,\
         non_finite_normals,dist_median_ulps,dist_max_ulps,dist_across_median_ulps,\
         splits_mean,splits_max,\
         splits_max_per_patch,nan_pixels,pixels,fails"
    );
    for r in results {
        let f = &r.figures;
        let (mean, max, per) = match f.splits {
            Some(s) => (
                s.mean.to_string(),
                s.max.to_string(),
                s.max_per_patch.to_string(),
            ),
            None => Default::default(),
        };
        let fails = match &r.figures.refused {
            Some(_) => vec!["refused".to_string()],
            None => r.figures.failures().iter().map(|c| c.to_string()).collect(),
        };
        let _ = writeln!(
            out,
            "\"{}\",{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},\"{}\"",
            r.case.replace('"', "\"\""),
            r.path.name(),
            f.rays,
            f.reference_hits,
            f.hits,
            f.holes,
            f.false_hits,
            f.within_box,
            f.secondary_rays,
            f.self_hits,
            f.non_finite_normals,
            f.distance_median,
            f.distance_max,
            f.normal_distance_median,
            mean,
            max,
            per,
            f.nan_pixels,
            f.pixels,
            fails.join(";"),
        );
    }
    out
}
