//! Writing a scene by the output's extension: our RON scene, `.bpt` or OBJ free-form.

use std::path::Path;

use crate::io::{OutputError, write_atomic};

/// Writes a scene by the output's extension: `.ron` (geometry inline), `.bpt` (all
/// patches, non-rational only) or `.obj` (free-form Bézier patches). NURBS surfaces are
/// written as their Bézier patches to `.bpt` and `.obj`. A scene read from a file that
/// declared a length unit (CAD files) says which in a comment line opening `.ron` and
/// `.obj` (`.bpt` has no comments).
pub fn write_scene_as(path: &Path, scene: &crate::scene::model::Scene) -> Result<(), OutputError> {
    use super::load::InputKind;
    let patches = || -> Vec<crate::geom::BezierPatch> {
        scene
            .objects
            .iter()
            .flat_map(|o| o.bezier_patches())
            .collect()
    };
    match InputKind::of(path) {
        Some(InputKind::Ron) => {
            let text = super::ron_format::scene_to_ron(scene)
                .map_err(|m| OutputError::invalid(path, m))?;
            write_atomic(path, |w| {
                if let Some(unit) = &scene.unit {
                    writeln!(w, "// {unit}")?;
                }
                w.write_all(text.as_bytes())
            })
        }
        Some(InputKind::Bpt | InputKind::Obj) if scene.trim_loop_count() > 0 => {
            Err(OutputError::invalid(
                path,
                format!(
                    "the scene has {} trim loop(s), which patchtrace's .bpt and .obj writers do not store (the surfaces would come back untrimmed); write .ron instead",
                    scene.trim_loop_count()
                ),
            ))
        }
        Some(InputKind::Bpt) => {
            let patches = patches();
            if let Some(i) = patches.iter().position(|p| p.is_rational()) {
                return Err(OutputError::invalid(
                    path,
                    format!(
                        ".bpt cannot store rational patches (patch {i} has weights other than 1); write .obj instead"
                    ),
                ));
            }
            write_atomic(path, |w| super::bpt::write_bpt(w, &patches))
        }
        Some(InputKind::Obj) => write_atomic(path, |w| {
            if let Some(unit) = &scene.unit {
                writeln!(w, "# {unit}")?;
            }
            super::obj::write_obj_freeform(w, &patches())
        }),
        _ => Err(OutputError::invalid(
            path,
            "unsupported output type: expected .ron, .bpt or .obj",
        )),
    }
}
