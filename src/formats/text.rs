//! A whitespace tokenizer that remembers where each token starts, shared by the text
//! formats so that every parse error can name its line and column.

use std::path::Path;
use std::str::FromStr;

use super::error::ParseError;

/// One whitespace-separated word and its 1-based position.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Token<'a> {
    pub text: &'a str,
    pub line: usize,
    pub column: usize,
}

/// Tokens of a text, skipping whitespace and (optionally) `#` comments to end of line.
pub struct Tokens<'a> {
    path: &'a Path,
    src: &'a str,
    pos: usize,
    line: usize,
    column: usize,
    comments: bool,
}

impl<'a> Tokens<'a> {
    pub fn new(path: &'a Path, src: &'a str, comments: bool) -> Self {
        Tokens {
            path,
            src,
            pos: 0,
            line: 1,
            column: 1,
            comments,
        }
    }

    fn skip_space(&mut self) {
        let bytes = self.src.as_bytes();
        while self.pos < bytes.len() {
            let c = bytes[self.pos];
            if c == b'\n' {
                self.line += 1;
                self.column = 1;
                self.pos += 1;
            } else if c.is_ascii_whitespace() {
                self.column += 1;
                self.pos += 1;
            } else if self.comments && c == b'#' {
                while self.pos < bytes.len() && bytes[self.pos] != b'\n' {
                    self.pos += 1;
                }
            } else {
                break;
            }
        }
    }

    /// The next token, or `None` at end of input.
    pub fn next_opt(&mut self) -> Option<Token<'a>> {
        self.skip_space();
        if self.pos >= self.src.len() {
            return None;
        }
        let start = self.pos;
        let (line, column) = (self.line, self.column);
        let rest = &self.src[start..];
        let len = rest
            .find(|c: char| c.is_ascii_whitespace() || (self.comments && c == '#'))
            .unwrap_or(rest.len());
        self.pos += len;
        self.column += rest[..len].chars().count();
        Some(Token {
            text: &rest[..len],
            line,
            column,
        })
    }

    /// The next token, or an error saying `what` was expected at end of file.
    pub fn next(&mut self, what: &str) -> Result<Token<'a>, ParseError> {
        self.next_opt()
            .ok_or_else(|| self.error_here(format!("expected {what}, found end of file")))
    }

    /// The next token parsed as `T`.
    pub fn parse<T: FromStr>(&mut self, what: &str) -> Result<T, ParseError> {
        let tok = self.next(what)?;
        tok.text
            .parse()
            .map_err(|_| self.error_at(&tok, format!("expected {what}, found `{}`", tok.text)))
    }

    /// The next token as a finite `f64`.
    pub fn finite(&mut self, what: &str) -> Result<f64, ParseError> {
        let tok = self.next(what)?;
        parse_finite(self.path, &tok, what)
    }

    /// Fails unless the input is exhausted.
    pub fn expect_end(&mut self) -> Result<(), ParseError> {
        match self.next_opt() {
            None => Ok(()),
            Some(t) => Err(self.error_at(&t, format!("expected end of file, found `{}`", t.text))),
        }
    }

    pub fn error_at(&self, tok: &Token, message: impl Into<String>) -> ParseError {
        ParseError::new(self.path, tok.line, tok.column, message)
    }

    pub fn error_here(&self, message: impl Into<String>) -> ParseError {
        ParseError::new(self.path, self.line, self.column, message)
    }
}

/// Parses a token as a finite number, with a message naming what was expected.
pub fn parse_finite(path: &Path, tok: &Token, what: &str) -> Result<f64, ParseError> {
    match tok.text.parse::<f64>() {
        Ok(x) if x.is_finite() => Ok(x),
        Ok(_) => Err(ParseError::new(
            path,
            tok.line,
            tok.column,
            format!("expected {what} as a finite number, found `{}`", tok.text),
        )),
        Err(_) => Err(ParseError::new(
            path,
            tok.line,
            tok.column,
            format!("expected {what}, found `{}`", tok.text),
        )),
    }
}

/// The offset after the double-quoted string starting at byte `start` of `b` (a `"`),
/// backslash escapes skipped (JSON, RFC 8259 §7, and RON strings alike), or the end of
/// `b` for an unterminated string. For scanners that locate things in a text.
pub fn quoted_end(b: &[u8], start: usize) -> usize {
    let mut i = start + 1;
    while i < b.len() {
        match b[i] {
            b'\\' => i += 2,
            b'"' => return i + 1,
            _ => i += 1,
        }
    }
    b.len()
}

/// One logical line of a line-oriented format (OBJ): its words with their original
/// positions, and the position just past its last character (where "found end of line"
/// errors point).
#[derive(Clone, Debug, PartialEq)]
pub struct LogicalLine<'a> {
    pub tokens: Vec<Token<'a>>,
    pub end: (usize, usize),
}

/// Splits a text into logical lines: `#` starts a comment to the end of the physical
/// line, and a backslash ending a physical line joins the next one to it (the OBJ
/// continuation rule). Each token keeps the line and column where it was written, so
/// errors inside a continued statement point at the right physical line. Blank lines are
/// dropped. Also returns where "found end of file" errors point: the end of the last
/// logical line (or 1:1 for an empty text).
pub fn logical_lines(src: &str) -> (Vec<LogicalLine<'_>>, (usize, usize)) {
    let mut lines = Vec::new();
    let mut current = Vec::new();
    let mut end = (1, 1);
    for (index, physical) in src.split('\n').enumerate() {
        let number = index + 1;
        let physical = physical.strip_suffix('\r').unwrap_or(physical);
        let content = physical.split('#').next().unwrap_or("").trim_end();
        let (content, continued) = match content.strip_suffix('\\') {
            Some(c) => (c, true),
            None => (content, false),
        };
        let mut column = 1;
        let mut rest = content;
        while let Some(start) = rest.find(|c: char| !c.is_whitespace()) {
            column += rest[..start].chars().count();
            rest = &rest[start..];
            let len = rest.find(char::is_whitespace).unwrap_or(rest.len());
            current.push(Token {
                text: &rest[..len],
                line: number,
                column,
            });
            column += rest[..len].chars().count();
            rest = &rest[len..];
        }
        end = (number, content.chars().count() + 1);
        if !continued && !current.is_empty() {
            lines.push(LogicalLine {
                tokens: std::mem::take(&mut current),
                end,
            });
        }
    }
    if !current.is_empty() {
        lines.push(LogicalLine {
            tokens: current,
            end,
        });
    }
    let eof = lines.last().map_or((1, 1), |l| l.end);
    (lines, eof)
}

/// A cursor over the words of one logical line, with errors that name what was expected.
pub struct Words<'l, 'a> {
    path: &'l Path,
    line: &'l LogicalLine<'a>,
    next: usize,
}

impl<'l, 'a> Words<'l, 'a> {
    pub fn new(path: &'l Path, line: &'l LogicalLine<'a>) -> Self {
        Words {
            path,
            line,
            next: 0,
        }
    }

    /// The next word, if any.
    pub fn next_opt(&mut self) -> Option<Token<'a>> {
        let t = self.line.tokens.get(self.next).copied();
        self.next += t.is_some() as usize;
        t
    }

    /// The next word, or an error at the end of the line saying `what` was expected.
    pub fn next(&mut self, what: &str) -> Result<Token<'a>, ParseError> {
        self.next_opt()
            .ok_or_else(|| self.error_at_end(format!("expected {what}, found end of line")))
    }

    /// The next word as a finite `f64`.
    pub fn finite(&mut self, what: &str) -> Result<f64, ParseError> {
        let tok = self.next(what)?;
        parse_finite(self.path, &tok, what)
    }

    /// The next word, if any, as a finite `f64`.
    pub fn finite_opt(&mut self, what: &str) -> Result<Option<(f64, Token<'a>)>, ParseError> {
        self.next_opt()
            .map(|tok| parse_finite(self.path, &tok, what).map(|x| (x, tok)))
            .transpose()
    }

    /// The words not consumed yet.
    pub fn rest(&mut self) -> &'l [Token<'a>] {
        let rest = &self.line.tokens[self.next.min(self.line.tokens.len())..];
        self.next = self.line.tokens.len();
        rest
    }

    /// Fails unless every word was consumed.
    pub fn expect_end(&mut self) -> Result<(), ParseError> {
        match self.next_opt() {
            None => Ok(()),
            Some(t) => Err(self.error_at(&t, format!("expected end of line, found `{}`", t.text))),
        }
    }

    pub fn error_at(&self, tok: &Token, message: impl Into<String>) -> ParseError {
        ParseError::new(self.path, tok.line, tok.column, message)
    }

    pub fn error_at_end(&self, message: impl Into<String>) -> ParseError {
        ParseError::new(self.path, self.line.end.0, self.line.end.1, message)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn positions_are_one_based_lines_and_columns() {
        let p = Path::new("x");
        let mut t = Tokens::new(p, "a  bb\n  c # d\ne", true);
        let got: Vec<_> = std::iter::from_fn(|| t.next_opt())
            .map(|t| (t.text, t.line, t.column))
            .collect();
        assert_eq!(
            got,
            vec![("a", 1, 1), ("bb", 1, 4), ("c", 2, 3), ("e", 3, 1)]
        );
    }

    #[test]
    fn non_finite_numbers_are_refused_with_their_place() {
        let p = Path::new("f.bpt");
        let mut t = Tokens::new(p, "1\n nan", false);
        assert_eq!(t.finite("x").unwrap(), 1.0);
        let e = t.finite("x coordinate").unwrap_err();
        assert_eq!((e.line, e.column), (2, 2));
        assert!(e.to_string().contains("finite"), "{e}");
    }
    #[test]
    fn continued_lines_keep_their_physical_positions() {
        let (lines, eof) = logical_lines("v 1 \\\n  2 3 # c\n\nsurf\\\n\tx\n");
        let words: Vec<Vec<_>> = lines
            .iter()
            .map(|l| {
                l.tokens
                    .iter()
                    .map(|t| (t.text, t.line, t.column))
                    .collect()
            })
            .collect();
        assert_eq!(
            words,
            vec![
                vec![("v", 1, 1), ("1", 1, 3), ("2", 2, 3), ("3", 2, 5)],
                vec![("surf", 4, 1), ("x", 5, 2)],
            ]
        );
        assert_eq!(lines[0].end, (2, 6));
        assert_eq!(eof, (5, 3));
    }

    #[test]
    fn words_report_missing_and_extra_words() {
        let (lines, _) = logical_lines("deg 3\ndeg 1 2 3");
        let p = Path::new("a.obj");
        let mut w = Words::new(p, &lines[0]);
        w.next("keyword").unwrap();
        w.next("du").unwrap();
        let e = w.next("dv").unwrap_err();
        assert_eq!((e.line, e.column), (1, 6));
        assert!(
            e.message.starts_with("expected dv, found end of line"),
            "{e}"
        );
        let mut w = Words::new(p, &lines[1]);
        w.rest();
        assert!(w.expect_end().is_ok());
        let mut w = Words::new(p, &lines[1]);
        for _ in 0..3 {
            w.next("x").unwrap();
        }
        let e = w.expect_end().unwrap_err();
        assert_eq!(
            (e.line, e.column, e.message.as_str()),
            (2, 9, "expected end of line, found `3`")
        );
    }
}
