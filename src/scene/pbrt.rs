//! pbrt-v3 `Shape "nurbs"` reader. PLACEHOLDER: filled in by the formats work.

use std::path::Path;

use super::error::ParseError;
use super::model::Surface;

pub fn parse_pbrt(path: &Path, _src: &str) -> Result<Vec<Surface>, ParseError> {
    Err(ParseError::new(
        path,
        1,
        1,
        "pbrt reading is not implemented yet",
    ))
}
