//! `patchtrace tessellate SCENE -o OUT.obj|OUT.gltf|OUT.glb|OUT.stl`: the triangle baseline.

use std::io::Write;
use std::process::ExitCode;
use std::time::Instant;

use serde::Serialize;

use crate::cli::args::TessellateArgs;
use crate::cli::setup::{load, tessellate};
use crate::formats::LoadError;
use crate::tessellate::{MeshFormat, TessellationMode, TessellationReport, write_mesh_scene};

/// Triangles per patch when no mode is given: Dammertz's coarsest table row.
const DEFAULT_TRIANGLES_PER_PATCH: u32 = 512;

#[derive(Serialize)]
struct Report {
    #[serde(flatten)]
    mesh: TessellationReport,
    file_bytes: u64,
    seconds: f64,
}

/// The mode chosen by the flags (clap makes them mutually exclusive).
pub fn mode(args: &TessellateArgs) -> TessellationMode {
    match (args.grid, args.tolerance) {
        (Some((u, v)), _) => TessellationMode::Uniform {
            grid_u: u,
            grid_v: v,
        },
        (_, Some(t)) => TessellationMode::Adaptive { tolerance: t },
        _ => TessellationMode::TrianglesPerPatch(
            args.triangles_per_patch
                .unwrap_or(DEFAULT_TRIANGLES_PER_PATCH),
        ),
    }
}

pub fn run(args: TessellateArgs) -> anyhow::Result<ExitCode> {
    if MeshFormat::of(&args.output).is_none() {
        return Err(LoadError::invalid(
            &args.output,
            "unsupported mesh type: expected .obj, .gltf, .glb or .stl",
        )
        .into());
    }
    let scene = load(&args.scene, &args.mesh, args.quiet)?;
    let start = Instant::now();
    let (meshes, report) = tessellate(&scene, mode(&args), args.quiet, "tessellating")?;
    let seconds = start.elapsed().as_secs_f64();
    let file_bytes = write_mesh_scene(&args.output, &meshes)?;
    let r = Report {
        mesh: report,
        file_bytes,
        seconds,
    };
    let mut out = std::io::stdout().lock();
    if args.json {
        writeln!(out, "{}", serde_json::to_string_pretty(&r)?)?;
    } else {
        writeln!(out, "triangles: {}", r.mesh.triangles)?;
        writeln!(out, "vertices:  {}", r.mesh.vertices)?;
        writeln!(
            out,
            "memory:    {} bytes (f32 positions and normals, u32 indices)",
            r.mesh.bytes
        )?;
        writeln!(
            out,
            "file:      {} bytes, {}",
            r.file_bytes,
            args.output.display()
        )?;
        writeln!(out, "time:      {:.3} s", r.seconds)?;
        let g = &r.mesh.trim_gaps;
        if g.faces > 0 {
            writeln!(
                out,
                "trim gaps: largest {:.3e} between {} trimmed faces; {} of {} shared boundary samples open wider than f32 rounding; {} samples with no other face within {:.3e} (free edges)",
                g.largest, g.faces, g.open_samples, g.shared_samples, g.free_samples, g.radius
            )?;
            writeln!(
                out,
                "surface:   largest distance {:.3e} from the exact surfaces to the mesh (probed in each trimmed face's parameters); shared-edge vertices within {:.3e} of both faces (samples joined within {:.3e})",
                r.mesh.surface_distance, r.mesh.edge_offset, r.mesh.edge_tolerance
            )?;
        }
    }
    Ok(ExitCode::SUCCESS)
}
