//! `patchtrace info SCENE`: describe a scene.

use std::io::Write;
use std::process::ExitCode;

use crate::cli::args::InfoArgs;
use crate::formats::load::load_scene_noted;
use crate::scene::summary::summarize;

pub fn run(args: InfoArgs) -> anyhow::Result<ExitCode> {
    let (scene, notes) = crate::progress::while_reading(args.quiet, &args.scene, || {
        load_scene_noted(&args.scene, args.mesh.load_options())
    })?;
    crate::cli::setup::print_warnings(&scene);
    let s = summarize(&scene);
    let mut out = std::io::stdout().lock();
    if args.json {
        writeln!(out, "{}", serde_json::to_string_pretty(&s)?)?;
        return Ok(ExitCode::SUCCESS);
    }
    writeln!(out, "scene: {}", args.scene.display())?;
    let c = &s.camera;
    writeln!(
        out,
        "camera: eye {:?} look_at {:?} up {:?} fov_y {} deg, {}x{}",
        c.eye, c.look_at, c.up, c.fov_y, c.width, c.height
    )?;
    writeln!(
        out,
        "objects: {}  patches: {} ({} rational)  NURBS surfaces: {}  triangles: {}",
        s.objects.len(),
        s.patches,
        s.rational_patches,
        s.nurbs_surfaces,
        s.triangles
    )?;
    for (index, o) in s.objects.iter().enumerate() {
        let shared = match o.shares_geometry_of {
            Some(k) if k < index => format!(" (an instance of object {k}'s geometry)"),
            Some(_) => " (an instance: its geometry is shared)".to_string(),
            None => String::new(),
        };
        writeln!(
            out,
            "  {}{shared}: material \"{}\", {} surface(s), {} NURBS, {} patch(es), {} trim loop(s), {} triangle(s)",
            o.name, o.material, o.surfaces, o.nurbs_surfaces, o.patches, o.trim_loops, o.triangles
        )?;
        // A shared geometry's trims were listed with its first instance.
        let listed = o.shares_geometry_of.is_some_and(|k| k < index);
        for t in o.trimmed_surfaces.iter().filter(|_| !listed) {
            writeln!(
                out,
                "    surface {}: {} trim loop(s) ({} hole(s)), {} curve(s) as {} Bézier piece(s); patches: {} cut, {} whole, {} cut away",
                t.surface,
                t.loops,
                t.holes,
                t.curves,
                t.pieces,
                t.patches_cut,
                t.patches_whole,
                t.patches_culled
            )?;
        }
        if let Some(sd) = &o.subdivision {
            writeln!(
                out,
                "    Catmull–Clark cage: {} vertices, {} faces{} -> {} quads; {} regular patches, {} extraordinary ends, {} T-junctions, {} levels",
                sd.cage_vertices,
                sd.cage_faces,
                if sd.holes > 0 {
                    format!(" ({} holes)", sd.holes)
                } else {
                    String::new()
                },
                sd.quads,
                sd.regular_patches,
                sd.extraordinary_ends,
                sd.t_junctions,
                sd.levels
            )?;
        }
    }
    let degrees: Vec<String> = s.degrees.iter().map(|(d, n)| format!("{d}: {n}")).collect();
    writeln!(
        out,
        "degrees: {}",
        if degrees.is_empty() {
            "-".into()
        } else {
            degrees.join(", ")
        }
    )?;
    writeln!(out, "bounds: {:?} .. {:?}", s.bounds_min, s.bounds_max)?;
    if let Some(unit) = &s.unit {
        writeln!(out, "unit: {unit}")?;
    }
    writeln!(out, "materials: {}", s.materials.join(", "))?;
    writeln!(
        out,
        "lights: {}",
        if s.lights.is_empty() {
            "none".into()
        } else {
            s.lights.join("; ")
        }
    )?;
    writeln!(out, "max depth: {}", s.max_depth)?;
    for note in notes {
        writeln!(out, "{note}")?;
    }
    Ok(ExitCode::SUCCESS)
}
