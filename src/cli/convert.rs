//! `patchtrace convert IN -o OUT`: NURBS → Bézier by knot insertion, with a report.

use std::io::Write;
use std::process::ExitCode;

use crate::cli::args::ConvertArgs;
use crate::cli::setup::load;
use crate::formats::load::InputKind;
use crate::formats::write::write_scene_as;
use crate::scene::convert::convert_scene;

pub fn run(args: ConvertArgs) -> anyhow::Result<ExitCode> {
    let scene = load(&args.input, &args.mesh, args.quiet)?;
    let (converted, report) = convert_scene(&scene);
    // RON keeps what it is given, so it gets the patches; the patch formats decompose each
    // surface themselves and write its patches as one sheet with its trims once.
    let keeps_surfaces = matches!(InputKind::of(&args.output), Some(InputKind::Ron));
    write_scene_as(
        &args.output,
        if keeps_surfaces { &converted } else { &scene },
    )?;
    let mut out = std::io::stdout().lock();
    if args.json {
        writeln!(out, "{}", serde_json::to_string_pretty(&report)?)?;
    } else {
        let kb = |b: usize| b as f64 / 1024.0;
        writeln!(out, "NURBS surfaces:          {}", report.nurbs_surfaces)?;
        writeln!(
            out,
            "  control points:        {}",
            report.nurbs_control_points
        )?;
        writeln!(
            out,
            "  size:                  {:.2} kB",
            kb(report.nurbs_bytes)
        )?;
        writeln!(
            out,
            "Bézier patches (made):   {}",
            report.bezier_patches_from_nurbs
        )?;
        writeln!(
            out,
            "  control points:        {}",
            report.bezier_control_points_from_nurbs
        )?;
        writeln!(
            out,
            "  size:                  {:.2} kB",
            kb(report.bezier_bytes)
        )?;
        writeln!(
            out,
            "Bézier patches (as is):  {}",
            report.bezier_patches_unchanged
        )?;
        writeln!(
            out,
            "memory ratio:            {:.3} (Dammertz Table 2.13)",
            report.memory_ratio
        )?;
        writeln!(out, "wrote {}", args.output.display())?;
    }
    Ok(ExitCode::SUCCESS)
}
