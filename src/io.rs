//! Writing output files safely: to a temporary name beside the target, then renamed, so a
//! crash or an error never leaves a half-written file under the real name. Every command
//! that writes a file goes through here, whatever the format.

use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use thiserror::Error;

/// Anything that can go wrong writing an output file.
#[derive(Debug, Error)]
pub enum OutputError {
    /// The file system refused (no such directory, no permission, disk full).
    #[error("{}: cannot write: {source}", path.display())]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    /// The output cannot hold what was asked (an unknown extension, content the format has
    /// no place for).
    #[error("{}: {message}", path.display())]
    Invalid { path: PathBuf, message: String },
}

impl OutputError {
    pub fn io(path: &Path, source: std::io::Error) -> Self {
        OutputError::Io {
            path: path.to_path_buf(),
            source,
        }
    }

    pub fn invalid(path: &Path, message: impl Into<String>) -> Self {
        OutputError::Invalid {
            path: path.to_path_buf(),
            message: message.into(),
        }
    }
}

/// Calls `write` on a buffered temporary file next to `path` and renames it to `path` when
/// `write` succeeds; on failure the temporary file is removed.
pub fn write_atomic<F>(path: &Path, write: F) -> Result<(), OutputError>
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
        OutputError::io(path, e)
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
