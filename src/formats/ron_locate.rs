//! Where things are in a RON scene text, for errors found after deserialising (serde
//! keeps no spans): the keys of struct fields and maps (`name:` or `"name":`) and the
//! enum variants written as calls (`Bezier(`), each with its byte offset, in text order.
//! Comments (`//`, nested `/* */`) and string contents are skipped, so a key inside them is
//! never reported (RON specification, "Comments" and "Strings").

use std::path::Path;

use super::error::ParseError;
use super::text::quoted_end;

/// A key or a call in the text.
#[derive(Clone, Debug, PartialEq)]
struct Mark {
    text: String,
    at: usize,
    call: bool,
}

/// The marks of one RON text, to turn "object 2, surface 1" into a line and column.
pub struct RonLocator<'a> {
    path: &'a Path,
    src: &'a str,
    marks: Vec<Mark>,
}

impl<'a> RonLocator<'a> {
    pub fn new(path: &'a Path, src: &'a str) -> Self {
        RonLocator {
            path,
            src,
            marks: scan(src),
        }
    }

    /// Offset of the `nth` (from 0) key `name`.
    fn key(&self, name: &str, nth: usize) -> Option<usize> {
        self.marks
            .iter()
            .filter(|m| !m.call && m.text == name)
            .nth(nth)
            .map(|m| m.at)
    }

    /// An error at the first key `name` (a top-level field such as `camera`, or a
    /// material's name), or at the start of the text when there is none.
    pub fn at_key(&self, name: &str, message: impl Into<String>) -> ParseError {
        self.error(self.key(name, 0), message)
    }

    /// An error at object `index` (its `geometry:` key: every object has exactly one, and
    /// nothing else has that key).
    pub fn at_object(&self, index: usize, message: impl Into<String>) -> ParseError {
        self.error(self.key("geometry", index), message)
    }

    /// An error at surface `surface` (its `Bezier(` or `Nurbs(`) of object `index`.
    pub fn at_surface(
        &self,
        index: usize,
        surface: usize,
        message: impl Into<String>,
    ) -> ParseError {
        let start = self.key("geometry", index);
        let at = start.and_then(|start| {
            self.marks
                .iter()
                .filter(|m| m.call && m.at > start && (m.text == "Bezier" || m.text == "Nurbs"))
                .nth(surface)
                .map(|m| m.at)
        });
        self.error(at.or(start), message)
    }

    fn error(&self, at: Option<usize>, message: impl Into<String>) -> ParseError {
        ParseError::at_byte(self.path, self.src, at.unwrap_or(0), message)
    }
}

/// Keys and calls of `src`, in order.
fn scan(src: &str) -> Vec<Mark> {
    let b = src.as_bytes();
    let mut marks = Vec::new();
    let mut i = 0;
    // The word just read and where it started, waiting to see whether `:` or `(` follows.
    let mut pending: Option<(String, usize)> = None;
    while i < b.len() {
        let c = b[i];
        if c.is_ascii_whitespace() {
            i += 1;
            continue;
        }
        if b[i..].starts_with(b"//") {
            i = b[i..]
                .iter()
                .position(|&c| c == b'\n')
                .map_or(b.len(), |n| i + n);
            continue;
        }
        if b[i..].starts_with(b"/*") {
            i = skip_block_comment(b, i);
            continue;
        }
        let word = pending.take();
        if c == b'"' {
            let end = quoted_end(b, i);
            pending = Some((
                String::from_utf8_lossy(&b[i + 1..end.saturating_sub(1).max(i + 1)]).into_owned(),
                i,
            ));
            i = end;
            continue;
        }
        if c.is_ascii_alphabetic() || c == b'_' {
            let end = b[i..]
                .iter()
                .position(|&c| !(c.is_ascii_alphanumeric() || c == b'_'))
                .map_or(b.len(), |n| i + n);
            pending = Some((src[i..end].to_string(), i));
            i = end;
            continue;
        }
        if let Some((text, at)) = word
            && (c == b':' || c == b'(')
        {
            marks.push(Mark {
                text,
                at,
                call: c == b'(',
            });
        }
        i += 1;
    }
    marks
}

/// The offset after the (nested) block comment starting at `start`.
fn skip_block_comment(b: &[u8], start: usize) -> usize {
    let mut depth = 0usize;
    let mut i = start;
    while i < b.len() {
        if b[i..].starts_with(b"/*") {
            depth += 1;
            i += 2;
        } else if b[i..].starts_with(b"*/") {
            depth -= 1;
            i += 2;
            if depth == 0 {
                return i;
            }
        } else {
            i += 1;
        }
    }
    b.len()
}

#[cfg(test)]
mod tests {
    use super::*;

    const SRC: &str = r#"Scene(
    // geometry: not this one
    camera: (eye: (0, 0, 1)),
    materials: { "pink": (reflect: 0.5), "a:b": () },
    objects: [
        (geometry: File("x.bpt")),
        (geometry: Surfaces([ Bezier(degree: (1, 1)), /* Nurbs( */ Nurbs(degree: (1, 1)) ])),
    ],
)"#;

    fn place(e: ParseError) -> (usize, usize) {
        (e.line, e.column)
    }

    #[test]
    fn keys_and_variants_are_found_outside_comments_and_strings() {
        let l = RonLocator::new(Path::new("s.ron"), SRC);
        assert_eq!(place(l.at_key("camera", "m")), (3, 5));
        assert_eq!(place(l.at_key("pink", "m")), (4, 18));
        assert_eq!(place(l.at_key("a:b", "m")), (4, 42));
        assert_eq!(place(l.at_object(0, "m")), (6, 10));
        assert_eq!(place(l.at_object(1, "m")), (7, 10));
        assert_eq!(place(l.at_surface(1, 0, "m")), (7, 31));
        assert_eq!(place(l.at_surface(1, 1, "m")), (7, 68));
        // Unknown places fall back to the object, then to the start.
        assert_eq!(place(l.at_surface(1, 5, "m")), (7, 10));
        assert_eq!(place(l.at_key("nowhere", "m")), (1, 1));
    }

    #[test]
    fn unterminated_strings_and_comments_end_the_scan() {
        for src in ["a: \"open", "/* /* */", "x: 1 // y:", "\"\\"] {
            let _ = RonLocator::new(Path::new("s"), src).at_key("y", "m");
        }
        assert_eq!(scan("/* /* */ */ k: 1").len(), 1);
    }
}
