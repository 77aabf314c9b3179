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
}
