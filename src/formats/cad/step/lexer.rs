//! Tokens of an ISO 10303-21 exchange structure (STEP Part 21, §5–6): keywords, instance
//! names `#123`, integers, reals, strings (with `''` and the `\X\`, `\X2\`, `\X4\`, `\S\`
//! escapes of §6.4.3), enumerations `.T.`, binaries, `$`, `*` and punctuation, each with
//! the 1-based line and column where it starts. Comments `/* … */` are skipped.

use std::borrow::Cow;

/// What a token is; text borrowed from the source where no escape had to be decoded.
#[derive(Clone, Debug, PartialEq)]
pub enum TokenKind<'a> {
    /// A standard or user-defined keyword (`ADVANCED_FACE`, `ISO-10303-21`, `!MY_TYPE`).
    Keyword(&'a str),
    /// `#123`.
    Instance(u64),
    Integer(i64),
    Real(f64),
    Str(Cow<'a, str>),
    /// `.NAME.` without the dots.
    Enumeration(&'a str),
    /// `"..."` hex digits, kept as written.
    Binary(&'a str),
    /// `$`, the unset optional value.
    Unset,
    /// `*`, a value derived from a supertype.
    Derived,
    Open,
    Close,
    Comma,
    Equals,
    Semicolon,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Token<'a> {
    pub kind: TokenKind<'a>,
    pub line: u32,
    pub column: u32,
}

/// A lexical error with its position.
#[derive(Clone, Debug, PartialEq)]
pub struct LexError {
    pub line: u32,
    pub column: u32,
    pub message: String,
}

pub struct Lexer<'a> {
    src: &'a str,
    pos: usize,
    line: u32,
    /// Byte offset where the current line starts; columns count characters from it.
    line_start: usize,
    /// The last column worked out, as (byte offset, column), so that each token costs
    /// only the bytes since the previous one: counting from the line start every time
    /// was quadratic in the length of a line, and writers put whole control nets on one.
    last_column: std::cell::Cell<(usize, u32)>,
    /// Backslashes inside strings that begin no escape of ISO 10303-21 §6.4.3 (Windows paths
    /// written with single backslashes), kept as text: how many, and the first one's
    /// position and text.
    pub literal_backslashes: usize,
    pub first_literal: Option<(u32, u32, String)>,
}

impl<'a> Lexer<'a> {
    pub fn new(src: &'a str) -> Self {
        Lexer {
            src,
            pos: 0,
            line: 1,
            line_start: 0,
            last_column: std::cell::Cell::new((0, 1)),
            literal_backslashes: 0,
            first_literal: None,
        }
    }

    /// The position of the next unread byte.
    pub fn here(&self) -> (u32, u32) {
        (self.line, self.column_of(self.pos))
    }

    fn column_of(&self, pos: usize) -> u32 {
        let (from, column) = match self.last_column.get() {
            (at, column) if at >= self.line_start && at <= pos => (at, column),
            _ => (self.line_start, 1),
        };
        let bytes = &self.src.as_bytes()[from..pos];
        let chars = if bytes.is_ascii() {
            bytes.len()
        } else {
            self.src[from..pos].chars().count()
        };
        let column = column + chars as u32;
        self.last_column.set((pos, column));
        column
    }

    fn error(&self, pos: usize, message: impl Into<String>) -> LexError {
        LexError {
            line: self.line,
            column: self.column_of(pos),
            message: message.into(),
        }
    }

    fn bump_newlines(&mut self, from: usize, to: usize) {
        for (k, &c) in self.src.as_bytes()[from..to].iter().enumerate() {
            if c == b'\n' {
                self.line += 1;
                self.line_start = from + k + 1;
            }
        }
    }

    fn skip_space(&mut self) -> Result<(), LexError> {
        let bytes = self.src.as_bytes();
        loop {
            while self.pos < bytes.len() && bytes[self.pos].is_ascii_whitespace() {
                if bytes[self.pos] == b'\n' {
                    self.line += 1;
                    self.line_start = self.pos + 1;
                }
                self.pos += 1;
            }
            if bytes[self.pos..].starts_with(b"/*") {
                let start = self.pos;
                let Some(len) = self.src[start + 2..].find("*/") else {
                    return Err(self.error(start, "comment `/*` is never closed by `*/`"));
                };
                let end = start + 2 + len + 2;
                self.bump_newlines(start, end);
                self.pos = end;
            } else {
                return Ok(());
            }
        }
    }

    /// Skips the rest of a malformed instance: everything through the next `;` outside
    /// strings, binaries and comments (a `;` inside them ends nothing). A string, binary or
    /// comment left open, or the end of the input before any `;`, is an error.
    pub fn skip_past_semicolon(&mut self) -> Result<(), LexError> {
        let bytes = self.src.as_bytes();
        loop {
            self.skip_space()?;
            let start = self.pos;
            match bytes.get(start) {
                None => {
                    return Err(
                        self.error(start, "expected `;` ending the instance, found end of file")
                    );
                }
                Some(b';') => {
                    self.pos += 1;
                    return Ok(());
                }
                Some(b'\'') => self.pos = self.string(start)?.1,
                Some(b'"') => {
                    self.pos = self.binary_end(start)?;
                    self.bump_newlines(start, self.pos);
                }
                // Byte by byte: a multi-byte character's bytes are all above 127, so the
                // scan never stops inside one.
                Some(_) => self.pos += 1,
            }
        }
    }

    /// The next token, `None` at end of input.
    pub fn next_token(&mut self) -> Result<Option<Token<'a>>, LexError> {
        self.skip_space()?;
        let bytes = self.src.as_bytes();
        let Some(&c) = bytes.get(self.pos) else {
            return Ok(None);
        };
        let start = self.pos;
        let (line, column) = (self.line, self.column_of(start));
        let single = |kind| (kind, start + 1);
        let (kind, end) = match c {
            b'(' => single(TokenKind::Open),
            b')' => single(TokenKind::Close),
            b',' => single(TokenKind::Comma),
            b'=' => single(TokenKind::Equals),
            b';' => single(TokenKind::Semicolon),
            b'$' => single(TokenKind::Unset),
            b'*' => single(TokenKind::Derived),
            b'#' => {
                let end = digits_end(bytes, start + 1);
                let id = self.src[start + 1..end]
                    .parse()
                    .map_err(|_| self.error(start, "expected an instance number after `#`"))?;
                (TokenKind::Instance(id), end)
            }
            b'\'' => self.string(start)?,
            b'"' => {
                let end = self.binary_end(start)?;
                (TokenKind::Binary(&self.src[start + 1..end - 1]), end)
            }
            b'.' if bytes.get(start + 1).is_some_and(u8::is_ascii_alphabetic) => {
                let end = word_end(bytes, start + 1);
                if bytes.get(end) != Some(&b'.') {
                    return Err(self.error(start, "expected `.` closing the enumeration"));
                }
                (TokenKind::Enumeration(&self.src[start + 1..end]), end + 1)
            }
            b'+' | b'-' | b'.' | b'0'..=b'9' => self.number(start)?,
            b'!' | b'A'..=b'Z' | b'a'..=b'z' | b'_' => {
                let end = word_end(bytes, start + 1);
                (TokenKind::Keyword(&self.src[start..end]), end)
            }
            _ => {
                let ch = self.src[start..].chars().next().unwrap_or('?');
                return Err(self.error(start, format!("unexpected character `{ch}`")));
            }
        };
        self.pos = end;
        Ok(Some(Token { kind, line, column }))
    }

    /// The end of the binary opened by the `"` at `start`, past its closing `"`.
    fn binary_end(&self, start: usize) -> Result<usize, LexError> {
        match self.src[start + 1..].find('"') {
            Some(len) => Ok(start + 1 + len + 1),
            None => Err(self.error(start, "binary `\"` is never closed")),
        }
    }

    /// A number per Part 21 §6.3.2/6.3.3: sign, digits, then `.` and an optional exponent
    /// make it real.
    fn number(&self, start: usize) -> Result<(TokenKind<'a>, usize), LexError> {
        let bytes = self.src.as_bytes();
        let mut end = start;
        if matches!(bytes[end], b'+' | b'-') {
            end += 1;
        }
        end = digits_end(bytes, end);
        let mut real = false;
        if bytes.get(end) == Some(&b'.') {
            real = true;
            end = digits_end(bytes, end + 1);
        }
        if matches!(bytes.get(end), Some(b'E' | b'e')) {
            real = true;
            let mut e = end + 1;
            if matches!(bytes.get(e), Some(b'+' | b'-')) {
                e += 1;
            }
            let after = digits_end(bytes, e);
            if after == e {
                return Err(self.error(start, "expected digits in the exponent"));
            }
            end = after;
        }
        let text = &self.src[start..end];
        let bad = || self.error(start, format!("expected a number, found `{text}`"));
        if real {
            // Rust's parser wants a digit after `.` before an exponent ("1.E3").
            let value: f64 = if text.contains(".E") || text.contains(".e") {
                text.replacen('.', ".0", 1).parse().map_err(|_| bad())?
            } else {
                text.parse().map_err(|_| bad())?
            };
            if !value.is_finite() {
                return Err(self.error(start, format!("number `{text}` is out of range")));
            }
            Ok((TokenKind::Real(value), end))
        } else {
            Ok((TokenKind::Integer(text.parse().map_err(|_| bad())?), end))
        }
    }

    /// A string from `start` (its opening quote): `''` is a quote, and backslash escapes
    /// are decoded (Part 21 §6.4.3). Strings may span lines; line breaks are not part of
    /// them.
    fn string(&mut self, start: usize) -> Result<(TokenKind<'a>, usize), LexError> {
        let bytes = self.src.as_bytes();
        let mut i = start + 1;
        let mut plain = true;
        loop {
            match bytes.get(i) {
                None => return Err(self.error(start, "string is never closed by `'`")),
                Some(b'\'') if bytes.get(i + 1) == Some(&b'\'') => {
                    plain = false;
                    i += 2;
                }
                Some(b'\'') => break,
                Some(b'\\' | b'\n' | b'\r') => {
                    plain = false;
                    i += 1;
                }
                Some(_) => i += 1,
            }
        }
        let raw = &self.src[start + 1..i];
        let end = i + 1;
        if plain {
            return Ok((TokenKind::Str(Cow::Borrowed(raw)), end));
        }
        let (decoded, literal) = decode_string(raw);
        if let Some(what) = literal.first() {
            if self.first_literal.is_none() {
                let (line, column) = (self.line, self.column_of(start));
                self.first_literal = Some((line, column, what.clone()));
            }
            self.literal_backslashes += literal.len();
        }
        self.bump_newlines(start, end);
        Ok((TokenKind::Str(Cow::Owned(decoded)), end))
    }
}

fn digits_end(bytes: &[u8], from: usize) -> usize {
    from + bytes[from..]
        .iter()
        .take_while(|c| c.is_ascii_digit())
        .count()
}

fn word_end(bytes: &[u8], from: usize) -> usize {
    from + bytes[from..]
        .iter()
        .take_while(|&&c| c.is_ascii_alphanumeric() || c == b'_' || c == b'-')
        .count()
}

fn hex_chars(hex: &str, width: usize) -> Result<String, String> {
    if !hex.len().is_multiple_of(width) || !hex.bytes().all(|c| c.is_ascii_hexdigit()) {
        return Err(format!(
            "expected groups of {width} hex digits in an escape, found `{hex}`"
        ));
    }
    (0..hex.len() / width)
        .map(|k| {
            let code = u32::from_str_radix(&hex[k * width..(k + 1) * width], 16)
                .map_err(|e| e.to_string())?;
            char::from_u32(code).ok_or_else(|| format!("escape U+{code:X} is not a character"))
        })
        .collect()
}

/// Decodes the body of a string: `''`, `\\`, `\X\hh` (ISO 8859-1), `\X2\…\X0\` (UCS-2),
/// `\X4\…\X0\` (UCS-4), `\S\c` (the upper half of the code page); `\Px\` page switches
/// are dropped (the text is taken as ISO 8859-1); line breaks inside strings are ignored.
/// A backslash that begins no well-formed control directive of ISO 10303-21 §6.4.3 (a
/// Windows path written with single backslashes: `C:\TEMP\part.stp`) is kept as text, as
/// OpenCASCADE reads it; the text of each such escape is returned beside the string.
fn decode_string(raw: &str) -> (String, Vec<String>) {
    let mut out = String::with_capacity(raw.len());
    let mut literal = Vec::new();
    let mut rest = raw;
    while let Some(c) = rest.chars().next() {
        if c == '\'' {
            out.push('\'');
            rest = &rest[2.min(rest.len())..];
        } else if c == '\n' || c == '\r' {
            rest = &rest[1..];
        } else if c == '\\' {
            match control_directive(&rest[1..]) {
                Some((text, t)) => {
                    out.push_str(&text);
                    rest = t;
                }
                None => {
                    let tail = &rest[1..];
                    let shown: String = tail.chars().take(2).collect();
                    literal.push(format!("\\{shown}"));
                    out.push('\\');
                    rest = tail;
                }
            }
        } else {
            out.push(c);
            rest = &rest[c.len_utf8()..];
        }
    }
    (out, literal)
}

/// The text of the control directive that `tail` (what follows a backslash) begins, and
/// what follows it; `None` when it begins none, or a malformed one.
fn control_directive(tail: &str) -> Option<(String, &str)> {
    if let Some(t) = tail.strip_prefix('\\') {
        return Some(("\\".into(), t));
    }
    if let Some(t) = tail.strip_prefix("X\\") {
        let hex = t.get(..2)?;
        return Some((hex_chars(hex, 2).ok()?, &t[2..]));
    }
    if let Some(t) = tail.strip_prefix("X2\\").or(tail.strip_prefix("X4\\")) {
        let width = if tail.starts_with("X2") { 4 } else { 8 };
        let close = t.find("\\X0\\")?;
        return Some((hex_chars(&t[..close], width).ok()?, &t[close + 4..]));
    }
    if let Some(t) = tail.strip_prefix("S\\") {
        let ch = t.chars().next()?;
        let code = char::from_u32(ch as u32 + 128)?;
        return Some((code.to_string(), &t[ch.len_utf8()..]));
    }
    if tail.len() >= 3 && tail.starts_with('P') && tail.as_bytes()[2] == b'\\' {
        return Some((String::new(), &tail[3..]));
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    fn kinds(src: &str) -> Vec<TokenKind<'_>> {
        let mut lx = Lexer::new(src);
        let mut out = Vec::new();
        while let Some(t) = lx.next_token().unwrap() {
            out.push(t.kind);
        }
        out
    }

    #[test]
    fn numbers_enumerations_and_references() {
        assert_eq!(
            kinds("#12=A(1.,-2.5E-1,3,.T.,$,*,1.E3)"),
            vec![
                TokenKind::Instance(12),
                TokenKind::Equals,
                TokenKind::Keyword("A"),
                TokenKind::Open,
                TokenKind::Real(1.0),
                TokenKind::Comma,
                TokenKind::Real(-0.25),
                TokenKind::Comma,
                TokenKind::Integer(3),
                TokenKind::Comma,
                TokenKind::Enumeration("T"),
                TokenKind::Comma,
                TokenKind::Unset,
                TokenKind::Comma,
                TokenKind::Derived,
                TokenKind::Comma,
                TokenKind::Real(1000.0),
                TokenKind::Close,
            ]
        );
    }

    #[test]
    fn string_escapes_decode() {
        let cases = [
            ("'It''s'", "It's"),
            ("'caf\\X\\E9'", "café"),
            ("'\\X2\\03B103B2\\X0\\!'", "αβ!"),
            ("'\\X4\\0001F600\\X0\\'", "😀"),
            ("'a\\\\b'", "a\\b"),
            ("'\\PA\\x\\S\\a'", "xá"),
            // Not control directives (§6.4.3): kept as text.
            ("'C:\\TEMP\\a.stp'", "C:\\TEMP\\a.stp"),
            ("'\\X\\zz'", "\\X\\zz"),
        ];
        for (src, want) in cases {
            assert_eq!(
                kinds(src),
                vec![TokenKind::Str(Cow::Borrowed(want))],
                "{src}"
            );
        }
    }

    #[test]
    fn positions_count_lines_columns_and_skip_comments() {
        let mut lx = Lexer::new("/* a\n b */ #1\n  =\t'x\ny' ;");
        let t = lx.next_token().unwrap().unwrap();
        assert_eq!((t.line, t.column), (2, 7));
        let t = lx.next_token().unwrap().unwrap();
        assert_eq!((t.kind, t.line, t.column), (TokenKind::Equals, 3, 3));
        let t = lx.next_token().unwrap().unwrap();
        assert_eq!(t.kind, TokenKind::Str(Cow::Borrowed("xy")));
        let t = lx.next_token().unwrap().unwrap();
        assert_eq!((t.line, t.column), (4, 4));
    }

    /// Columns count characters, not bytes, across non-ASCII strings on a long line, and
    /// restart on the next line: each token's column is checked against a count made here
    /// by `chars()`.
    #[test]
    fn columns_on_a_long_line_count_characters() {
        let line: String = (0..2000).map(|k| format!("'é{k}',")).collect();
        let src = format!("{line}\n  #7");
        let mut lx = Lexer::new(&src);
        let mut at = 0;
        while let Some(t) = lx.next_token().unwrap() {
            if t.line == 2 {
                assert_eq!((t.kind, t.column), (TokenKind::Instance(7), 3));
                return;
            }
            let want = src[..at].chars().count() as u32 + 1;
            assert_eq!(t.column, want);
            at += match t.kind {
                TokenKind::Comma => 1,
                _ => src[at..].find(',').unwrap(),
            };
        }
        panic!("the second line was not reached");
    }

    #[test]
    fn errors_are_located() {
        let mut lx = Lexer::new("\n  'open");
        let e = lx.next_token().unwrap_err();
        assert_eq!((e.line, e.column), (2, 3));
        assert!(e.message.contains("never closed"));
        let e = Lexer::new("  1e").next_token().unwrap_err();
        assert_eq!(e.column, 3);
        // Malformed escapes are text (§6.4.3 directives only), counted for one warning.
        let mut lx = Lexer::new("'\\X\\G0' '\\X2\\00E9'");
        assert!(lx.next_token().unwrap().is_some() && lx.next_token().unwrap().is_some());
        assert_eq!(lx.literal_backslashes, 4);
        assert_eq!(lx.first_literal, Some((1, 1, "\\X\\".into())));
        assert!(Lexer::new("@").next_token().is_err());
    }
}
