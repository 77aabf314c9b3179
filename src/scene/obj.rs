//! Wavefront OBJ free-form surfaces (reader and writer). PLACEHOLDER: filled in by the
//! formats work.

use std::io::Write;
use std::path::Path;

use super::error::ParseError;
use super::model::Surface;
use crate::geom::BezierPatch;

/// True when the text holds free-form surface statements (`cstype` or `surf`).
pub fn is_freeform(src: &str) -> bool {
    src.lines().any(|l| {
        let l = l.trim_start();
        l.starts_with("cstype") || l.starts_with("surf")
    })
}

pub fn parse_obj_freeform(path: &Path, _src: &str) -> Result<Vec<Surface>, ParseError> {
    Err(ParseError::new(
        path,
        1,
        1,
        "OBJ free-form reading is not implemented yet",
    ))
}

pub fn write_obj_freeform(_w: &mut dyn Write, _patches: &[BezierPatch]) -> std::io::Result<()> {
    Err(std::io::Error::other(
        "OBJ free-form writing is not implemented yet",
    ))
}
