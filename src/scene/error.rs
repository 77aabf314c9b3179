//! Errors from reading and writing scene and geometry files. Parse errors carry the file,
//! line and column (1-based) and say what was expected.

use std::path::{Path, PathBuf};

use thiserror::Error;

/// A syntax or content error at a place in a file.
#[derive(Debug, Error, Clone, PartialEq)]
#[error("{}:{line}:{column}: {message}", path.display())]
pub struct ParseError {
    pub path: PathBuf,
    pub line: usize,
    pub column: usize,
    pub message: String,
}

impl ParseError {
    pub fn new(path: &Path, line: usize, column: usize, message: impl Into<String>) -> Self {
        ParseError {
            path: path.to_path_buf(),
            line,
            column,
            message: message.into(),
        }
    }
}

/// Anything that can go wrong loading or saving a scene.
#[derive(Debug, Error)]
pub enum LoadError {
    #[error(transparent)]
    Parse(#[from] ParseError),
    #[error("{}: {source}", path.display())]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    /// Valid syntax, but content the scene cannot use (an unknown material, coordinates
    /// that overflow f32, a format we do not support).
    #[error("{}: {message}", path.display())]
    Invalid { path: PathBuf, message: String },
}

impl LoadError {
    pub fn io(path: &Path, source: std::io::Error) -> Self {
        LoadError::Io {
            path: path.to_path_buf(),
            source,
        }
    }

    pub fn invalid(path: &Path, message: impl Into<String>) -> Self {
        LoadError::Invalid {
            path: path.to_path_buf(),
            message: message.into(),
        }
    }
}

/// Reads a whole text file, naming the path on failure.
pub fn read_text(path: &Path) -> Result<String, LoadError> {
    std::fs::read_to_string(path).map_err(|e| LoadError::io(path, e))
}
