//! Writing a scene by the output's extension: our RON scene, `.bpt`, OBJ free-form or
//! IGES.

use std::path::Path;

use super::iges_writer::{Header, timestamp_now, write_iges};
use super::sheet::{object_colour, scene_sheets};
use crate::io::{OutputError, write_atomic};

/// Writes a scene by the output's extension: `.ron` (geometry inline), `.bpt` (all
/// patches, non-rational and untrimmed only), `.obj` (free-form Bézier patches with their
/// trims) or `.igs`/`.iges` (IGES 5.3: 128 surfaces trimmed by 144, in millimetres, with
/// colours). NURBS surfaces are written as their Bézier patches to `.bpt`, `.obj` and
/// `.igs`; triangle meshes only to `.ron`. A scene read from a file that declared a length
/// unit (CAD files) says which in a comment line opening `.ron` and `.obj` (`.bpt` has no
/// comments; IGES states its unit in its Global section).
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
                    writeln!(w, "// {}", unit.words)?;
                }
                w.write_all(text.as_bytes())
            })
        }
        Some(InputKind::Bpt) if scene.trim_loop_count() > 0 => Err(OutputError::invalid(
            path,
            format!(
                "the scene has {} trim loop(s), which .bpt does not store (the surfaces would come back untrimmed); write .obj, .igs or .ron instead",
                scene.trim_loop_count()
            ),
        )),
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
        Some(InputKind::Obj) => {
            let sheets = scene_sheets(scene).map_err(|m| OutputError::invalid(path, m))?;
            write_atomic(path, |w| {
                if let Some(unit) = &scene.unit {
                    writeln!(w, "# {}", unit.words)?;
                }
                super::obj::write_obj_sheets(w, &sheets)
            })
        }
        Some(InputKind::Iges) => {
            let sheets = scene_sheets(scene).map_err(|m| OutputError::invalid(path, m))?;
            let colours: Vec<_> = (0..scene.objects.len())
                .map(|k| object_colour(scene, k))
                .collect();
            let name = path
                .file_name()
                .map(|n| n.to_string_lossy().into_owned())
                .unwrap_or_default();
            let header = Header {
                file_name: &name,
                timestamp: &timestamp_now(),
            };
            write_atomic(path, |w| write_iges(w, &header, &sheets, &colours))
        }
        _ => Err(OutputError::invalid(
            path,
            "unsupported output type: expected .ron, .bpt, .obj or .igs",
        )),
    }
}
