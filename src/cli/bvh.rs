//! `patchtrace bvh SCENE -o FILE`: build and write the acceleration structure, with the
//! prepared patches where the scene's geometry allows (`render --bvh` maps them).

use std::process::ExitCode;
use std::time::Instant;

use crate::cli::args::BvhArgs;
use crate::cli::setup::{build_bvh, load_keyed};

pub fn run(args: BvhArgs) -> anyhow::Result<ExitCode> {
    let (scene, source) = load_keyed(&args.scene, &args.mesh, args.quiet, (false, None))?;
    // What "built in" covers: collecting the patches (NURBS to Bézier, trims), their boxes,
    // the tree and its wide form, and preparing the patches for the kernel; built where
    // `render` builds it, at the scene's floating origin.
    let start = Instant::now();
    let origin = scene.floating_origin();
    let mut moved = scene.clone();
    moved.translate(-origin);
    let geometry = build_bvh(&moved, args.quiet);
    drop(moved);
    let build = start.elapsed().as_secs_f64();
    let key = crate::accel::mapped::key(source, false);
    let parsed = match crate::formats::load::InputKind::of(&args.scene) {
        Some(crate::formats::load::InputKind::Ron) => {
            crate::formats::ron_format::parsed_scene(&args.scene)
        }
        // A bare file's shell, under the key of its inputs.
        _ => crate::scene::bare_shell::BareShell::json_of(&scene).map(|json| (source, json)),
    };
    let parsed = parsed.as_ref().map(|(hash, json)| (*hash, json.as_slice()));
    let piece_of = |object: u32, patch: u32| {
        let object = scene.objects.get(object as usize)?;
        object.subdivision_piece(patch)
    };
    let with_patches = geometry.save_bvh(
        &args.output,
        key,
        (scene.trim_loop_count(), origin),
        parsed,
        &piece_of,
    )?;
    eprintln!(
        "wrote {}: {} patches, {} nodes, built in {:.3} s{}",
        args.output.display(),
        geometry.patch_count(),
        geometry.bvh().map_or(0, |b| b.node_count()),
        build,
        if with_patches {
            ", with the prepared patches"
        } else {
            ", tree only (triangles, instances, trimmed or rational patches are prepared from the scene)"
        }
    );
    Ok(ExitCode::SUCCESS)
}
