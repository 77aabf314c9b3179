//! `patchtrace diff A B`: image metrics, an optional heat map, and limits for CI.

use std::io::Write;
use std::process::ExitCode;

use serde::Serialize;

use crate::cli::EXIT_FAILURE;
use crate::cli::args::{DiffArgs, HeatmapChoice};
use crate::diff::{DiffError, DiffOptions, DiffReport, Exceeded, Space, diff_images, read_image};
use crate::formats::LoadError;
use crate::render::heatmap::heat_map;

/// The JSON document: the report plus the inputs and the limits exceeded.
#[derive(Serialize)]
struct JsonOutput<'a> {
    a: &'a std::path::Path,
    b: &'a std::path::Path,
    #[serde(flatten)]
    report: &'a DiffReport,
    exceeded: &'a [Exceeded],
}

pub fn run(args: DiffArgs) -> anyhow::Result<ExitCode> {
    let a = read_image(&args.a)?;
    let b = read_image(&args.b)?;
    let opts = DiffOptions {
        threshold: args.threshold,
    };
    let report = diff_images(&a, &b, opts).map_err(|e| match e {
        // Bad input: the second image does not fit the first.
        DiffError::SizeMismatch { .. } => anyhow::Error::new(LoadError::invalid(
            &args.b,
            format!("{e} ({} is {}x{})", args.a.display(), a.width, a.height),
        )),
        other => other.into(),
    })?;
    let exceeded = report.exceeded(&args.fail_above).map_err(|limit| {
        let without = if a.has_alpha { &args.b } else { &args.a };
        LoadError::invalid(
            without,
            format!(
                "no alpha channel, so --fail-above {}={} cannot be checked",
                limit.metric.name(),
                limit.max
            ),
        )
    })?;
    if let Some(path) = &args.heatmap {
        let values = match args.heatmap_metric {
            HeatmapChoice::Flip => &report.maps.flip,
            HeatmapChoice::Abs => &report.maps.abs,
        };
        heat_map(values, report.width, report.height).write_png(path)?;
    }

    let mut out = std::io::stdout().lock();
    if args.json {
        let doc = JsonOutput {
            a: &args.a,
            b: &args.b,
            report: &report,
            exceeded: &exceeded,
        };
        writeln!(out, "{}", serde_json::to_string_pretty(&doc)?)?;
    } else {
        print_table(&mut out, &args, &report)?;
    }
    for e in &exceeded {
        eprintln!(
            "patchtrace: {} = {} exceeds the limit {}",
            e.metric.name(),
            e.value,
            e.max
        );
    }
    Ok(if exceeded.is_empty() {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(EXIT_FAILURE)
    })
}

fn print_table(out: &mut impl Write, args: &DiffArgs, r: &DiffReport) -> std::io::Result<()> {
    let space = match r.space {
        Space::Srgb => "sRGB-encoded values",
        Space::Linear => "linear values clamped to [0, 1]",
    };
    writeln!(out, "A: {}", args.a.display())?;
    writeln!(out, "B: {}", args.b.display())?;
    writeln!(
        out,
        "{}x{} pixels; metrics on RGB {space}",
        r.width, r.height
    )?;
    let psnr = if r.psnr.is_finite() {
        format!("{:.2} dB", r.psnr)
    } else {
        "inf (identical)".into()
    };
    let pixels = u64::from(r.width) * u64::from(r.height);
    let coverage = match r.coverage_mismatch {
        Some(n) => format!("{n} pixels"),
        None => "n/a (needs alpha in both images)".into(),
    };
    let rows = [
        ("RMSE", format!("{:.6}", r.rmse)),
        ("PSNR", psnr),
        ("MAE", format!("{:.6}", r.mae)),
        ("max abs error", format!("{:.6}", r.max_abs)),
        (
            "above threshold",
            format!(
                "{} of {pixels} pixels ({:.3}%) above {}",
                r.above_count,
                100.0 * r.above_share,
                r.threshold
            ),
        ),
        ("FLIP mean", format!("{:.6}", r.flip.mean)),
        (
            "FLIP weighted median",
            format!("{:.6}", r.flip.weighted_median),
        ),
        ("FLIP max", format!("{:.6}", r.flip.max)),
        ("coverage mismatch", coverage),
    ];
    for (name, value) in rows {
        writeln!(out, "  {name:<22}{value}")?;
    }
    if let Some(path) = &args.heatmap {
        writeln!(out, "wrote {}", path.display())?;
    }
    Ok(())
}
