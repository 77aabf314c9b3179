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

/// A content error at a byte offset of a binary file (a GLB header or chunk): what a
/// line and column are to a text file.
#[derive(Debug, Error, Clone, PartialEq)]
#[error("byte {offset}: {message}")]
pub struct BinaryError {
    pub offset: usize,
    pub message: String,
}

impl BinaryError {
    pub fn new(offset: usize, message: impl Into<String>) -> Self {
        BinaryError {
            offset,
            message: message.into(),
        }
    }
}

/// Anything that can go wrong loading or saving a scene.
#[derive(Debug, Error)]
pub enum LoadError {
    #[error(transparent)]
    Parse(#[from] ParseError),
    /// An error at a byte offset of a binary file.
    #[error("{}: {source}", path.display())]
    Binary {
        path: PathBuf,
        #[source]
        source: BinaryError,
    },
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

    pub fn binary(path: &Path, source: BinaryError) -> Self {
        LoadError::Binary {
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

/// Reads a whole text file, naming the path on failure; bytes that are not UTF-8 are
/// refused at their line and column.
pub fn read_text(path: &Path) -> Result<String, LoadError> {
    let bytes = std::fs::read(path).map_err(|e| LoadError::io(path, e))?;
    String::from_utf8(bytes).map_err(|e| {
        let good = e.utf8_error().valid_up_to();
        let bytes = e.as_bytes();
        let text = std::str::from_utf8(&bytes[..good]).unwrap_or_default();
        let (line, column) = line_column(text, good);
        ParseError::new(
            path,
            line,
            column,
            format!("expected UTF-8 text, found the byte 0x{:02x}", bytes[good]),
        )
        .into()
    })
}

/// The 1-based line and column (in characters) of byte offset `byte` of `src`, for readers
/// that find a problem by offset (a JSON value, a RON key, a base64 digit); offsets past
/// the end give the end, and an offset inside a character counts as that character.
pub fn line_column(src: &str, byte: usize) -> (usize, usize) {
    let mut end = byte.min(src.len());
    while !src.is_char_boundary(end) {
        end -= 1;
    }
    let before = &src[..end];
    let line_start = before.rfind('\n').map_or(0, |i| i + 1);
    let line = before.matches('\n').count() + 1;
    (line, before[line_start..].chars().count() + 1)
}

impl ParseError {
    /// An error at byte offset `byte` of the text `src` of `path`.
    pub fn at_byte(path: &Path, src: &str, byte: usize, message: impl Into<String>) -> Self {
        let (line, column) = line_column(src, byte);
        ParseError::new(path, line, column, message)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn byte_offsets_become_lines_and_character_columns() {
        let src = "ab\nçd\n";
        assert_eq!(line_column(src, 0), (1, 1));
        assert_eq!(line_column(src, 2), (1, 3));
        assert_eq!(line_column(src, 3), (2, 1));
        // 'ç' is two bytes: 'd' at byte 5 is the second character.
        assert_eq!(line_column(src, 5), (2, 2));
        assert_eq!(line_column(src, 4), (2, 1));
        assert_eq!(line_column(src, 99), (3, 1));
    }
}
