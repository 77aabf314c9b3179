//! STL triangle meshes, the mesh every CAD system exports: ASCII (`solid` … `facet normal`
//! … `outer loop` … three `vertex` lines … `endloop` `endfacet` … `endsolid`) and binary
//! (an 80-byte header, a `u32` triangle count, then per triangle a normal, three vertices,
//! twelve little-endian `f32` in all, and a `u16` attribute count).
//!
//! Both forms are read; a binary file whose header happens to begin with `solid` (several
//! exporters write that) is told apart by its size, which a binary file announces exactly
//! (84 + 50 bytes per triangle). Facet normals are not kept: exporters write them
//! inconsistently (zero, unnormalized, or flipped), and the renderer takes the geometric
//! normal of each triangle. Vertices equal to the bit are merged, so a closed mesh shares
//! its corners the way an indexed mesh does. `tessellate` writes binary STL.

use std::collections::HashMap;
use std::io::Write;
use std::path::Path;

use glam::DVec3;

use super::error::{BinaryError, LoadError, ParseError};
use crate::scene::model::TriangleMesh;

/// Bytes before the first binary triangle: the header and the count.
const BINARY_HEADER: usize = 84;
/// Bytes per binary triangle: normal and vertices (12 `f32`) and the attribute count.
const BINARY_TRIANGLE: usize = 50;

/// Reads an ASCII or binary STL file as one mesh.
pub fn read_stl(path: &Path) -> Result<TriangleMesh, LoadError> {
    let bytes = std::fs::read(path).map_err(|e| LoadError::io(path, e))?;
    let mut mesh = Welded::default();
    match (binary_count(&bytes), std::str::from_utf8(&bytes)) {
        (Some(count), _) => read_binary(path, &bytes, count, &mut mesh)?,
        (None, Ok(text)) if starts_with_solid(&bytes) => read_ascii(path, text, &mut mesh)?,
        // Text with a stray byte, told from a binary file of the wrong size (whose header
        // may begin with `solid` too) by a facet before the byte.
        (None, Err(e)) if starts_with_solid(&bytes) && has_facet(&bytes[..e.valid_up_to()]) => {
            let good = e.valid_up_to();
            let text = String::from_utf8_lossy(&bytes[..good]);
            let message = format!(
                "expected ASCII STL text, found the byte 0x{:02x}",
                bytes[good]
            );
            return Err(ParseError::at_byte(path, &text, good, message).into());
        }
        _ => return Err(not_binary(path, &bytes)),
    }
    super::mesh::finish(path, mesh.mesh, "STL facets")
}

/// The triangle count of a binary STL, when the file's size is exactly what its header
/// announces.
fn binary_count(bytes: &[u8]) -> Option<u32> {
    let count = u32::from_le_bytes(bytes.get(80..BINARY_HEADER)?.try_into().ok()?);
    let size = BINARY_HEADER as u64 + BINARY_TRIANGLE as u64 * u64::from(count);
    (size == bytes.len() as u64).then_some(count)
}

fn starts_with_solid(bytes: &[u8]) -> bool {
    let start = bytes.iter().position(|b| !b.is_ascii_whitespace());
    start.is_some_and(|s| {
        bytes[s..]
            .get(..5)
            .is_some_and(|w| w.eq_ignore_ascii_case(b"solid"))
    })
}

fn has_facet(bytes: &[u8]) -> bool {
    bytes.windows(5).any(|w| w.eq_ignore_ascii_case(b"facet"))
}

/// Why a file that is not ASCII STL is not binary STL either, at the byte concerned.
fn not_binary(path: &Path, bytes: &[u8]) -> LoadError {
    let source = if bytes.len() < BINARY_HEADER {
        BinaryError::new(
            bytes.len(),
            format!(
                "expected ASCII STL (starting with `solid`) or a binary STL's {BINARY_HEADER}-byte header, found {} bytes",
                bytes.len()
            ),
        )
    } else {
        let count = u32::from_le_bytes(bytes[80..BINARY_HEADER].try_into().unwrap_or_default());
        BinaryError::new(
            80,
            format!(
                "the binary STL header announces {count} triangles, {} bytes, but the file has {} bytes",
                BINARY_HEADER as u64 + BINARY_TRIANGLE as u64 * u64::from(count),
                bytes.len()
            ),
        )
    };
    LoadError::Binary {
        path: path.to_path_buf(),
        source,
    }
}

fn read_binary(path: &Path, bytes: &[u8], count: u32, mesh: &mut Welded) -> Result<(), LoadError> {
    for k in 0..count as usize {
        let at = BINARY_HEADER + k * BINARY_TRIANGLE;
        let float = |i: usize| {
            let o = at + 4 * i;
            f32::from_le_bytes([bytes[o], bytes[o + 1], bytes[o + 2], bytes[o + 3]])
        };
        let mut corners = [DVec3::ZERO; 3];
        for (c, corner) in corners.iter_mut().enumerate() {
            // Floats 0..3 are the facet normal; vertex c is floats 3 + 3c ..
            let first = 3 + 3 * c;
            let p = DVec3::new(
                float(first).into(),
                float(first + 1).into(),
                float(first + 2).into(),
            );
            if let Some(axis) = (0..3).find(|&i| !p[i].is_finite()) {
                return Err(LoadError::Binary {
                    path: path.to_path_buf(),
                    source: BinaryError::new(
                        at + 4 * (first + axis),
                        format!(
                            "triangle {k}, vertex {c}: expected a finite {} coordinate, found {}",
                            ["x", "y", "z"][axis],
                            p[axis]
                        ),
                    ),
                });
            }
            *corner = p;
        }
        mesh.push(corners);
    }
    Ok(())
}

/// The whitespace-separated words of ASCII STL with their byte offsets.
struct Words<'a> {
    text: &'a str,
    at: usize,
}

impl<'a> Words<'a> {
    fn next(&mut self) -> Option<(usize, &'a str)> {
        let rest = &self.text[self.at..];
        let start = self.at + rest.find(|c: char| !c.is_whitespace())?;
        let len = self.text[start..]
            .find(char::is_whitespace)
            .unwrap_or(self.text.len() - start);
        self.at = start + len;
        Some((start, &self.text[start..start + len]))
    }

    /// Skips the rest of the current line (a solid's name may hold spaces).
    fn skip_line(&mut self) {
        self.at = self.text[self.at..]
            .find('\n')
            .map_or(self.text.len(), |i| self.at + i);
    }
}

fn read_ascii(path: &Path, text: &str, mesh: &mut Welded) -> Result<(), LoadError> {
    let mut words = Words { text, at: 0 };
    let error = |at: usize, message: String| -> LoadError {
        ParseError::at_byte(path, text, at, message).into()
    };
    let expect = |words: &mut Words, keyword: &str| -> Result<(), LoadError> {
        match words.next() {
            Some((_, w)) if w.eq_ignore_ascii_case(keyword) => Ok(()),
            Some((at, w)) => Err(error(at, format!("expected `{keyword}`, found `{w}`"))),
            None => Err(error(
                text.len(),
                format!("expected `{keyword}`, found the end of the file"),
            )),
        }
    };
    let number = |words: &mut Words| -> Result<f64, LoadError> {
        match words.next() {
            Some((at, w)) => match w.parse::<f64>() {
                Ok(x) if x.is_finite() => Ok(x),
                _ => Err(error(at, format!("expected a finite number, found `{w}`"))),
            },
            None => Err(error(
                text.len(),
                "expected a number, found the end of the file".into(),
            )),
        }
    };
    // One or more solids, each `solid [name]` facets `endsolid [name]`.
    while let Some((at, word)) = words.next() {
        if !word.eq_ignore_ascii_case("solid") {
            return Err(error(at, format!("expected `solid`, found `{word}`")));
        }
        words.skip_line();
        loop {
            match words.next() {
                Some((_, w)) if w.eq_ignore_ascii_case("endsolid") => {
                    words.skip_line();
                    break;
                }
                Some((_, w)) if w.eq_ignore_ascii_case("facet") => {
                    expect(&mut words, "normal")?;
                    for _ in 0..3 {
                        number(&mut words)?;
                    }
                    expect(&mut words, "outer")?;
                    expect(&mut words, "loop")?;
                    let mut corners = [DVec3::ZERO; 3];
                    for corner in &mut corners {
                        expect(&mut words, "vertex")?;
                        *corner = DVec3::new(
                            number(&mut words)?,
                            number(&mut words)?,
                            number(&mut words)?,
                        );
                    }
                    expect(&mut words, "endloop")?;
                    expect(&mut words, "endfacet")?;
                    mesh.push(corners);
                }
                Some((at, w)) => {
                    return Err(error(
                        at,
                        format!("expected `facet` or `endsolid`, found `{w}`"),
                    ));
                }
                None => {
                    return Err(error(
                        text.len(),
                        "expected `facet` or `endsolid`, found the end of the file".into(),
                    ));
                }
            }
        }
    }
    Ok(())
}

/// A mesh built a triangle at a time, bit-equal vertices merged.
#[derive(Default)]
struct Welded {
    mesh: TriangleMesh,
    index: HashMap<[u64; 3], u32>,
}

impl Welded {
    fn push(&mut self, corners: [DVec3; 3]) {
        let triangle = corners.map(|p| {
            let next = self.mesh.positions.len() as u32;
            *self
                .index
                .entry(p.to_array().map(f64::to_bits))
                .or_insert_with(|| {
                    self.mesh.positions.push(p);
                    next
                })
        });
        self.mesh.indices.push(triangle);
    }
}

/// Writes `meshes` as one binary STL (STL has no objects: their triangles follow each
/// other), coordinates rounded to `f32` as the format stores them, each facet's normal the
/// unit normal of its corners in that order (zero for a degenerate triangle).
pub fn write_stl(w: &mut dyn Write, meshes: &[(&str, &TriangleMesh)]) -> std::io::Result<()> {
    let count: usize = meshes.iter().map(|(_, m)| m.indices.len()).sum();
    let count = u32::try_from(count).map_err(|_| {
        std::io::Error::other(format!(
            "{count} triangles: a binary STL holds at most 2^32 - 1"
        ))
    })?;
    let mut header = [b' '; 80];
    let title = b"binary STL written by patchtrace";
    header[..title.len()].copy_from_slice(title);
    w.write_all(&header)?;
    w.write_all(&count.to_le_bytes())?;
    let mut record = Vec::with_capacity(BINARY_TRIANGLE);
    for (_, m) in meshes {
        for t in &m.indices {
            let [a, b, c] = t.map(|i| m.positions[i as usize]);
            let normal = (b - a).cross(c - a).normalize_or_zero();
            record.clear();
            for p in [normal, a, b, c] {
                for x in p.to_array() {
                    record.extend_from_slice(&(x as f32).to_le_bytes());
                }
            }
            record.extend_from_slice(&0u16.to_le_bytes());
            w.write_all(&record)?;
        }
    }
    Ok(())
}
