//! Directory Entries (IGES 5.3 §2.3): two records of ten 8-column fields per entity. The
//! fields that matter here: entity type, parameter data pointer and line count, transform
//! pointer, colour, form, and the status number (blank, subordinate, use).

use std::path::Path;

use super::records::Record;
use crate::formats::error::ParseError;

/// How an entity depends on others (status digits 3–4, §2.3.1 field 9).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Subordinate {
    Independent,
    /// Part of another entity (the curves of a 142, the surface of a 144): not drawn alone.
    Physical,
    /// Referenced by a group only: still drawn.
    Logical,
    Both,
}

/// One entity's directory entry.
#[derive(Clone, Debug, PartialEq)]
pub struct DirEntry {
    /// The sequence number of its first record (odd), which pointers name.
    pub sequence: usize,
    /// File line of its first record.
    pub line: usize,
    pub entity_type: i32,
    /// First Parameter Data record (1-based sequence number) and record count.
    pub param_start: usize,
    pub param_count: usize,
    /// Sequence number of a 124 transform, or 0.
    pub transform: usize,
    /// Positive: a predefined colour 1–8; negative: minus the pointer to a 314; 0: none.
    pub colour: i64,
    pub form: i32,
    pub blank: bool,
    pub subordinate: Subordinate,
}

impl DirEntry {
    /// Drawn on its own: not a physical part of another entity (§2.3.1). Blanked
    /// entities are drawn too, as OpenCASCADE reads them (`read.iges.onlyvisible` is off
    /// by default): CATIA V4 blanks every surface of some files.
    pub fn is_drawn(&self) -> bool {
        matches!(
            self.subordinate,
            Subordinate::Independent | Subordinate::Logical
        )
    }
}

/// Field `k` (1-based, 1–10) of a directory record, as an integer (blank is 0).
fn field(path: &Path, r: &Record<'_>, k: usize, name: &str) -> Result<i64, ParseError> {
    let start = (k - 1) * 8;
    let text = r.data.get(start..start + 8).unwrap_or("").trim();
    if text.is_empty() {
        return Ok(0);
    }
    text.parse().map_err(|_| {
        ParseError::new(
            path,
            r.line,
            start + 1,
            format!("expected an integer {name} in directory field {k}, found `{text}`"),
        )
    })
}

/// Reads every entry: pairs of D records.
pub fn entries(path: &Path, records: &[Record<'_>]) -> Result<Vec<DirEntry>, ParseError> {
    if records.len() % 2 == 1 {
        let last = records[records.len() - 1];
        return Err(ParseError::new(
            path,
            last.line,
            1,
            "expected two Directory Entry records per entity, found an odd number",
        ));
    }
    records
        .chunks_exact(2)
        .enumerate()
        .map(|(i, pair)| {
            let (a, b) = (&pair[0], &pair[1]);
            let pointer = |r: &Record<'_>, k: usize, name: &str| -> Result<usize, ParseError> {
                let v = field(path, r, k, name)?;
                usize::try_from(v).map_err(|_| {
                    ParseError::new(
                        path,
                        r.line,
                        (k - 1) * 8 + 1,
                        format!("expected a non-negative {name}, found {v}"),
                    )
                })
            };
            let status = a.data.get(64..72).unwrap_or("").trim();
            // Eight digits, right-justified; missing leading digits are zeros.
            let padded = format!("{status:0>8}");
            let digits_at = |k: usize| {
                padded
                    .get(k..k + 2)
                    .and_then(|s| s.parse::<u8>().ok())
                    .unwrap_or(0)
            };
            Ok(DirEntry {
                sequence: 2 * i + 1,
                line: a.line,
                entity_type: field(path, a, 1, "entity type")? as i32,
                param_start: pointer(a, 2, "parameter data pointer")?,
                transform: pointer(a, 7, "transformation matrix pointer")?,
                blank: digits_at(0) == 1,
                subordinate: match digits_at(2) {
                    1 => Subordinate::Physical,
                    2 => Subordinate::Logical,
                    3 => Subordinate::Both,
                    _ => Subordinate::Independent,
                },
                colour: field(path, b, 3, "colour number")?,
                param_count: pointer(b, 4, "parameter line count")?,
                form: field(path, b, 5, "form number")? as i32,
            })
        })
        .collect()
}
