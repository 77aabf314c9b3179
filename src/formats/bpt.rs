//! `.bpt` Bézier patch files (DESIGN.md contract): a count `N`, then per patch `du dv` and
//! `(du+1)(dv+1)` points `x y z`, u index fastest. Non-rational only.

use std::io::Write;
use std::path::Path;

use glam::DVec3;

use super::error::{LoadError, ParseError};
use super::text::Tokens;
use crate::geom::{BezierPatch, MAX_DEGREE};

/// Parses `.bpt` text; `path` is used in error messages only.
pub fn parse_bpt(path: &Path, src: &str) -> Result<Vec<BezierPatch>, ParseError> {
    let mut t = Tokens::new(path, src, true);
    let count: usize = t.parse("the patch count (a non-negative integer)")?;
    let mut patches = Vec::with_capacity(count.min(1 << 20));
    for index in 0..count {
        let mut degree = || -> Result<usize, ParseError> {
            let tok = t.next(&format!("the degrees of patch {index}"))?;
            match tok.text.parse::<usize>() {
                Ok(d) if (1..=MAX_DEGREE).contains(&d) => Ok(d),
                _ => Err(t.error_at(
                    &tok,
                    format!(
                        "expected a degree from 1 to {MAX_DEGREE} for patch {index}, found `{}`",
                        tok.text
                    ),
                )),
            }
        };
        let du = degree()?;
        let dv = degree()?;
        let n = (du + 1) * (dv + 1);
        let mut points = Vec::with_capacity(n);
        for k in 0..n {
            let what = format!("coordinate of control point {k} of patch {index}");
            points.push(DVec3::new(
                t.finite(&what)?,
                t.finite(&what)?,
                t.finite(&what)?,
            ));
        }
        let patch = BezierPatch::from_points(du, dv, &points)
            .map_err(|e| t.error_here(format!("patch {index}: {e}")))?;
        patches.push(patch);
    }
    t.expect_end()?;
    Ok(patches)
}

/// Reads a `.bpt` file.
pub fn read_bpt(path: &Path) -> Result<Vec<BezierPatch>, LoadError> {
    let src = super::error::read_text(path)?;
    Ok(parse_bpt(path, &src)?)
}

/// Writes patches as `.bpt`; rational patches are refused because the format has no
/// weights.
pub fn write_bpt(w: &mut dyn Write, patches: &[BezierPatch]) -> std::io::Result<()> {
    if let Some(i) = patches.iter().position(|p| p.is_rational()) {
        return Err(std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            format!(
                ".bpt cannot store rational patches (patch {i} has weights other than 1); write OBJ (.obj) instead"
            ),
        ));
    }
    writeln!(w, "{}", patches.len())?;
    for p in patches {
        writeln!(w, "{} {}", p.degree_u(), p.degree_v())?;
        for q in p.euclidean_points() {
            writeln!(w, "{} {} {}", q.x, q.y, q.z)?;
        }
    }
    Ok(())
}
