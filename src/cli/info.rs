//! `patchtrace info SCENE`: describe a scene.

use std::io::Write;
use std::process::ExitCode;

use crate::cli::args::InfoArgs;
use crate::scene::load_scene_with;
use crate::scene::summary::summarize;

pub fn run(args: InfoArgs) -> anyhow::Result<ExitCode> {
    let scene = load_scene_with(&args.scene, args.mesh.load_options())?;
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
    for o in &s.objects {
        writeln!(
            out,
            "  {}: material \"{}\", {} surface(s), {} NURBS, {} patch(es), {} trim loop(s), {} triangle(s)",
            o.name, o.material, o.surfaces, o.nurbs_surfaces, o.patches, o.trim_loops, o.triangles
        )?;
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
    Ok(ExitCode::SUCCESS)
}
