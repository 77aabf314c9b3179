//! `patchtrace convert IN -o OUT`: NURBS → Bézier by knot insertion, with a report.

use std::process::ExitCode;

use crate::cli::args::ConvertArgs;
use crate::scene::convert::convert_scene;
use crate::scene::{load_scene, write::write_scene_as};

pub fn run(args: ConvertArgs) -> anyhow::Result<ExitCode> {
    let scene = load_scene(&args.input)?;
    let (converted, report) = convert_scene(&scene);
    write_scene_as(&args.output, &converted)?;
    if args.json {
        println!("{}", serde_json::to_string_pretty(&report)?);
    } else {
        let kb = |b: usize| b as f64 / 1024.0;
        println!("NURBS surfaces:          {}", report.nurbs_surfaces);
        println!("  control points:        {}", report.nurbs_control_points);
        println!("  size:                  {:.2} kB", kb(report.nurbs_bytes));
        println!(
            "Bézier patches (made):   {}",
            report.bezier_patches_from_nurbs
        );
        println!(
            "  control points:        {}",
            report.bezier_control_points_from_nurbs
        );
        println!("  size:                  {:.2} kB", kb(report.bezier_bytes));
        println!(
            "Bézier patches (as is):  {}",
            report.bezier_patches_unchanged
        );
        println!(
            "memory ratio:            {:.3} (Dammertz Table 2.13)",
            report.memory_ratio
        );
        println!("wrote {}", args.output.display());
    }
    Ok(ExitCode::SUCCESS)
}
