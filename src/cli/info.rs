//! `patchtrace info SCENE`: describe a scene.

use std::process::ExitCode;

use crate::cli::args::InfoArgs;
use crate::scene::load_scene;
use crate::scene::summary::summarize;

pub fn run(args: InfoArgs) -> anyhow::Result<ExitCode> {
    let scene = load_scene(&args.scene)?;
    let s = summarize(&scene);
    if args.json {
        println!("{}", serde_json::to_string_pretty(&s)?);
        return Ok(ExitCode::SUCCESS);
    }
    println!("scene: {}", args.scene.display());
    let c = &s.camera;
    println!(
        "camera: eye {:?} look_at {:?} up {:?} fov_y {} deg, {}x{}",
        c.eye, c.look_at, c.up, c.fov_y, c.width, c.height
    );
    println!(
        "objects: {}  patches: {} ({} rational)  NURBS surfaces: {}  triangles: {}",
        s.objects.len(),
        s.patches,
        s.rational_patches,
        s.nurbs_surfaces,
        s.triangles
    );
    for o in &s.objects {
        println!(
            "  {}: material \"{}\", {} surface(s), {} NURBS, {} patch(es), {} trim loop(s), {} triangle(s)",
            o.name, o.material, o.surfaces, o.nurbs_surfaces, o.patches, o.trim_loops, o.triangles
        );
    }
    let degrees: Vec<String> = s.degrees.iter().map(|(d, n)| format!("{d}: {n}")).collect();
    println!(
        "degrees: {}",
        if degrees.is_empty() {
            "-".into()
        } else {
            degrees.join(", ")
        }
    );
    println!("bounds: {:?} .. {:?}", s.bounds_min, s.bounds_max);
    println!("materials: {}", s.materials.join(", "));
    println!(
        "lights: {}",
        if s.lights.is_empty() {
            "none".into()
        } else {
            s.lights.join("; ")
        }
    );
    println!("max depth: {}", s.max_depth);
    Ok(ExitCode::SUCCESS)
}
