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
        let trimmed = line.trim_start();
        if trimmed.is_empty() || trimmed.starts_with('#') {
            continue;
        }
        let mut tokens = Vec::with_capacity(8);
        let mut column = 1;
        for word in line.split_inclusive(|c: char| c.is_ascii_whitespace()) {
            let text = word.trim_end();
            if !text.is_empty() {
                tokens.push(Token {
                    text,
                    line: index + 1,
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
                index + 1,
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
                    index + 1,
                    tok.column,
                    format!(
                        "expected {} within the f32 range (±{:e}) the kernels work in, found `{}` (ray {})",
                        NAMES[k],
                        f32::MAX,
                        tok.text,
                        rays.len()
                    ),
                ));
            }
        }
        let dir = DVec3::new(v[3], v[4], v[5]);
        if dir.as_vec3() == glam::Vec3::ZERO {
            return Err(ParseError::new(
                path,
                index + 1,
                tokens[3].column,
                format!(
                    "expected a non-zero direction (ray {}: it is zero, or too small to survive rounding to f32)",
                    rays.len()
                ),
            ));
        }
        if v[6] > v[7] {
            return Err(ParseError::new(
                path,
                index + 1,
                tokens[6].column,
                "expected tmin <= tmax",
            ));
        }
        rays.push(RayQuery {
            origin: DVec3::new(v[0], v[1], v[2]),
            dir,
            tmin: v[6],
            tmax: v[7],
        });
    }
    Ok(rays)
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
    fn components_beyond_f32_and_vanishing_directions_are_refused_where_they_stand() {
        // Issue 21: origin 4e38 rounded to inf in f32 and overflowed the BVH stack.
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
