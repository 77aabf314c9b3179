//! Writing output files safely: to a temporary name beside the target, then renamed, so a
//! crash or an error never leaves a half-written file under the real name.

use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use super::error::LoadError;

/// Calls `write` on a buffered temporary file next to `path` and renames it to `path` when
/// `write` succeeds; on failure the temporary file is removed.
pub fn write_atomic<F>(path: &Path, write: F) -> Result<(), LoadError>
where
    F: FnOnce(&mut dyn Write) -> std::io::Result<()>,
{
    let tmp = temporary_name(path);
    let result = (|| {
        let file = std::fs::File::create(&tmp)?;
        let mut w = BufWriter::new(file);
        write(&mut w)?;
        let file = w.into_inner().map_err(|e| e.into_error())?;
        file.sync_all()?;
        std::fs::rename(&tmp, path)
    })();
    result.map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        LoadError::io(path, e)
    })
}

/// `dir/.name.tmp-<pid>`: hidden, in the same directory (so the rename is atomic), and
/// unique per process.
pub fn temporary_name(path: &Path) -> PathBuf {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "output".into());
    path.with_file_name(format!(".{name}.tmp-{}", std::process::id()))
}

/// Writes a scene by the output's extension: `.ron` (geometry inline), `.bpt` (all
/// patches, non-rational only) or `.obj` (free-form Bézier patches). NURBS surfaces are
/// written as their Bézier patches to `.bpt` and `.obj`.
pub fn write_scene_as(path: &Path, scene: &super::model::Scene) -> Result<(), LoadError> {
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
            let text =
                super::ron_format::scene_to_ron(scene).map_err(|m| LoadError::invalid(path, m))?;
            write_atomic(path, |w| w.write_all(text.as_bytes()))
        }
        Some(InputKind::Bpt | InputKind::Obj) if scene.trim_loop_count() > 0 => {
            Err(LoadError::invalid(
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
                return Err(LoadError::invalid(
                    path,
                    format!(
                        ".bpt cannot store rational patches (patch {i} has weights other than 1); write .obj instead"
                    ),
                ));
            }
            write_atomic(path, |w| super::bpt::write_bpt(w, &patches))
        }
        Some(InputKind::Obj) => {
            write_atomic(path, |w| super::obj::write_obj_freeform(w, &patches()))
        }
        _ => Err(LoadError::invalid(
            path,
            "unsupported output type: expected .ron, .bpt or .obj",
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn failed_write_leaves_nothing_behind() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("x.txt");
        let err = write_atomic(&out, |w| {
            w.write_all(b"half")?;
            Err(std::io::Error::other("boom"))
        });
        assert!(err.is_err());
        assert!(!out.exists());
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
    }

    #[test]
    fn successful_write_lands_under_the_real_name() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("x.txt");
        write_atomic(&out, |w| w.write_all(b"whole")).unwrap();
        assert_eq!(std::fs::read(&out).unwrap(), b"whole");
    }
}
