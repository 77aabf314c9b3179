//! Ray files for `trace` (DESIGN.md contract): one ray per line,
//! `ox oy oz dx dy dz [tmin [tmax]]`; blank lines and lines starting with `#` are skipped.

use std::path::Path;

use glam::DVec3;

use super::error::ParseError;
use super::text::{Token, parse_finite};

/// One query ray as read, in `f64`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RayQuery {
    pub origin: DVec3,
    pub dir: DVec3,
    pub tmin: f64,
    pub tmax: f64,
}

/// Parses a ray file.
pub fn parse_rays(path: &Path, src: &str) -> Result<Vec<RayQuery>, ParseError> {
    let mut rays = Vec::new();
    for (index, line) in src.lines().enumerate() {
        if let Some(q) = parse_ray_line(path, index + 1, line, rays.len())? {
            rays.push(q);
        }
    }
    Ok(rays)
}

/// Parses line `line_number` (from 1) of a ray file, which holds ray number `ray` (from
/// 0) if it is not blank or a comment.
pub fn parse_ray_line(
    path: &Path,
    line_number: usize,
    line: &str,
    ray: usize,
) -> Result<Option<RayQuery>, ParseError> {
    let trimmed = line.trim_start();
    if trimmed.is_empty() || trimmed.starts_with('#') {
        return Ok(None);
    }
    let mut tokens = Vec::with_capacity(8);
    let mut column = 1;
    for word in line.split_inclusive(|c: char| c.is_ascii_whitespace()) {
        let text = word.trim_end();
        if !text.is_empty() {
            tokens.push(Token {
                text,
                line: line_number,
                column,
            });
        }
        column += word.chars().count();
    }
    const NAMES: [&str; 8] = ["ox", "oy", "oz", "dx", "dy", "dz", "tmin", "tmax"];
    if tokens.len() < 6 || tokens.len() > 8 {
        let at = tokens
            .get(8)
            .map_or(tokens.last().map_or(1, |t| t.column), |t| t.column);
        return Err(ParseError::new(
            path,
            line_number,
            at,
            format!(
                "expected `ox oy oz dx dy dz [tmin [tmax]]` (6 to 8 numbers), found {}",
                tokens.len()
            ),
        ));
    }
    let mut v = [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, f64::INFINITY];
    for (k, tok) in tokens.iter().enumerate() {
        v[k] = if k == 7 && tok.text.eq_ignore_ascii_case("inf") {
            f64::INFINITY
        } else {
            parse_finite(path, tok, NAMES[k])?
        };
    }
    // The kernels take the ray in f32: a component beyond its range would become
    // infinite there (and an infinite origin reaches every box plane at t = inf), so
    // it is refused here, where the ray and the number can be named. tmax may be
    // infinite: a bound beyond f32 rounds to the same unbounded ray.
    for (k, tok) in tokens.iter().enumerate().take(7) {
        if !(v[k] as f32).is_finite() {
            return Err(ParseError::new(
                path,
                line_number,
                tok.column,
                format!(
                    "expected {} within the f32 range (±{:e}) the kernels work in, found `{}` (ray {})",
                    NAMES[k],
                    f32::MAX,
                    tok.text,
                    ray
                ),
            ));
        }
    }
    let dir = DVec3::new(v[3], v[4], v[5]);
    if dir.as_vec3() == glam::Vec3::ZERO {
        return Err(ParseError::new(
            path,
            line_number,
            tokens[3].column,
            format!(
                "expected a non-zero direction (ray {}: it is zero, or too small to survive rounding to f32)",
                ray
            ),
        ));
    }
    if v[6] > v[7] {
        return Err(ParseError::new(
            path,
            line_number,
            tokens[6].column,
            "expected tmin <= tmax",
        ));
    }
    Ok(Some(RayQuery {
        origin: DVec3::new(v[0], v[1], v[2]),
        dir,
        tmin: v[6],
        tmax: v[7],
    }))
}

/// Rays read from a file a chunk at a time, so that `trace` holds one chunk in memory
/// however long the file is (10 M rays took 2.26 GB and aborted). Lines are read
/// as bytes, so invalid UTF-8 is reported at its line and column.
pub struct RayChunks<R> {
    path: std::path::PathBuf,
    reader: R,
    line_number: usize,
    rays: usize,
    buf: Vec<u8>,
}

impl<R: std::io::BufRead> RayChunks<R> {
    pub fn new(path: &Path, reader: R) -> Self {
        RayChunks {
            path: path.to_path_buf(),
            reader,
            line_number: 0,
            rays: 0,
            buf: Vec::new(),
        }
    }

    /// The next up to `max` rays, empty at the end of the file.
    pub fn next_chunk(&mut self, max: usize) -> Result<Vec<RayQuery>, super::LoadError> {
        let mut out = Vec::with_capacity(max.min(1 << 16));
        while out.len() < max {
            self.buf.clear();
            let n = self
                .reader
                .read_until(b'\n', &mut self.buf)
                .map_err(|e| super::LoadError::io(&self.path, e))?;
            if n == 0 {
                break;
            }
            self.line_number += 1;
            let bytes = self.buf.strip_suffix(b"\n").unwrap_or(&self.buf);
            let bytes = bytes.strip_suffix(b"\r").unwrap_or(bytes);
            let line = std::str::from_utf8(bytes).map_err(|e| {
                let valid = std::str::from_utf8(&bytes[..e.valid_up_to()]).unwrap_or_default();
                ParseError::new(
                    &self.path,
                    self.line_number,
                    valid.chars().count() + 1,
                    format!(
                        "expected UTF-8 text, found byte 0x{:02x}",
                        bytes[e.valid_up_to()]
                    ),
                )
            })?;
            if let Some(q) = parse_ray_line(&self.path, self.line_number, line, self.rays)? {
                out.push(q);
                self.rays += 1;
            }
        }
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_comments_and_optional_bounds() {
        let src = "# header\n\n0 0 -5 0 0 1\n1 2 3 4 5 6 0.5\n1 2 3 4 5 6 0.5 9\n";
        let r = parse_rays(Path::new("r"), src).unwrap();
        assert_eq!(r.len(), 3);
        assert_eq!((r[0].tmin, r[0].tmax), (0.0, f64::INFINITY));
        assert_eq!((r[1].tmin, r[1].tmax), (0.5, f64::INFINITY));
        assert_eq!((r[2].tmin, r[2].tmax), (0.5, 9.0));
    }

    #[test]
    fn errors_name_line_and_column() {
        let e = parse_rays(Path::new("r.txt"), "0 0 0 0 0 1\n0 0 0 x 0 1\n").unwrap_err();
        assert_eq!((e.line, e.column), (2, 7));
        assert!(e.to_string().starts_with("r.txt:2:7: expected dx"), "{e}");
        let e = parse_rays(Path::new("r.txt"), "0 0 0 0 0\n").unwrap_err();
        assert!(e.message.contains("6 to 8 numbers"), "{e}");
        let e = parse_rays(Path::new("r.txt"), "0 0 0 0 0 0\n").unwrap_err();
        assert!(e.message.contains("non-zero direction"), "{e}");
    }

    #[test]
    fn chunks_give_the_same_rays_as_the_whole_file_and_locate_bad_bytes() {
        let src = "# c\n0 0 -5 0 0 1\n\n1 2 3 4 5 6 0.5\r\n1 2 3 4 5 6 0.5 9\n0 0 0 1 0 0";
        let whole = parse_rays(Path::new("r"), src).unwrap();
        let mut chunks = RayChunks::new(Path::new("r"), src.as_bytes());
        let mut read = Vec::new();
        loop {
            let c = chunks.next_chunk(2).unwrap();
            if c.is_empty() {
                break;
            }
            assert!(c.len() <= 2);
            read.extend(c);
        }
        assert_eq!(read, whole);
        assert_eq!(read.len(), 4);
        let bad = b"0 0 0 0 0 1\n0 0 \xff 0 0 1\n";
        let e = RayChunks::new(Path::new("r"), &bad[..])
            .next_chunk(10)
            .unwrap_err();
        assert_eq!(e.to_string(), "r:2:5: expected UTF-8 text, found byte 0xff");
    }

    #[test]
    fn components_beyond_f32_and_vanishing_directions_are_refused_where_they_stand() {
        // origin 4e38 rounded to inf in f32 and overflowed the BVH stack.
        let e = parse_rays(Path::new("r"), "0 0 0 0 0 1\n4e38 -8e38 4e38 -1 2 -1\n").unwrap_err();
        assert_eq!((e.line, e.column), (2, 1), "{e}");
        assert!(
            e.message.starts_with("expected ox within the f32 range"),
            "{e}"
        );
        assert!(e.message.contains("ray 1"), "{e}");
        let e = parse_rays(Path::new("r"), "0 0 0 0 0 1 3.5e38\n").unwrap_err();
        assert_eq!(e.column, 13, "{e}");
        // 1e-50 is not zero in f64 but is in f32.
        let e = parse_rays(Path::new("r"), "0 0 0 1e-50 0 0\n").unwrap_err();
        assert!(e.message.contains("non-zero direction"), "{e}");
        // The largest finite f32 values and an infinite tmax stay accepted.
        let r = parse_rays(Path::new("r"), "3.4e38 0 0 -1 0 0 0 1e39\n").unwrap();
        assert_eq!(r[0].origin.x, 3.4e38);
    }
}
