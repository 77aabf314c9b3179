//! The file's syntax (IGES 5.3 §2, OpenCASCADE's `IGESData`): fixed 80-column records
//! with the section letter in column 73 (S, G, D, P, T); the Global section, whose first two
//! fields declare the parameter and record delimiters; free-format parameter lists of
//! numbers (with `D` exponents), Hollerith strings `nH…` and defaulted (empty) fields.
//! Every token keeps its file line and column, so errors can be located.

use std::path::Path;

use crate::formats::error::ParseError;

/// Columns 1–72 hold data, column 73 the section letter (§2.1.1).
const DATA_COLUMNS: usize = 72;
/// In the Parameter Data section, columns 1–64 hold the parameters, 65–72 the back
/// pointer to the directory entry (§2.4).
const PARAMETER_COLUMNS: usize = 64;

/// One line of a section: its data columns and its 1-based line in the file.
#[derive(Clone, Copy, Debug)]
pub struct Record<'a> {
    pub data: &'a str,
    pub line: usize,
}

/// The sections of a file, split by the letter in column 73.
pub struct Sections<'a> {
    pub global: Vec<Record<'a>>,
    pub directory: Vec<Record<'a>>,
    pub parameters: Vec<Record<'a>>,
    /// Per parameter record, the directory entry it belongs to (columns 65–72, §2.2.4.5),
    /// where written.
    pub owners: Vec<Option<usize>>,
}

/// Splits the file into its sections. Lines shorter than 73 columns, an unknown section
/// letter, or sections out of order are located errors; a compressed-format file (`C` in
/// column 73 of the Start section, §2.2.3) is refused by name.
pub fn sections<'a>(path: &Path, src: &'a str) -> Result<Sections<'a>, ParseError> {
    let mut s = Sections {
        global: Vec::new(),
        directory: Vec::new(),
        parameters: Vec::new(),
        owners: Vec::new(),
    };
    let mut order = 0;
    for (i, raw) in src.lines().enumerate() {
        let line = i + 1;
        let text = raw.trim_end_matches('\r');
        if text.trim().is_empty() {
            continue;
        }
        let letter = text.as_bytes().get(DATA_COLUMNS).copied();
        let data = text.get(..DATA_COLUMNS).ok_or_else(|| {
            ParseError::new(
                path,
                line,
                text.len() + 1,
                "expected an 80-column IGES record with its section letter (S, G, D, P or T) in column 73",
            )
        })?;
        let rank = match letter {
            Some(b'S') => 0,
            Some(b'G') => 1,
            Some(b'D') => 2,
            Some(b'P') => 3,
            Some(b'T') => 4,
            Some(b'C') | Some(b'B') => {
                return Err(ParseError::new(
                    path,
                    line,
                    DATA_COLUMNS + 1,
                    "compressed and binary IGES files are not supported: expected the ASCII fixed format",
                ));
            }
            _ => {
                return Err(ParseError::new(
                    path,
                    line,
                    DATA_COLUMNS + 1,
                    "expected a section letter (S, G, D, P or T) in column 73",
                ));
            }
        };
        if rank < order {
            return Err(ParseError::new(
                path,
                line,
                DATA_COLUMNS + 1,
                "expected the sections in the order S, G, D, P, T",
            ));
        }
        order = rank;
        let record = Record { data, line };
        match rank {
            1 => s.global.push(record),
            2 => s.directory.push(record),
            3 => {
                s.parameters.push(Record {
                    data: data.get(..PARAMETER_COLUMNS).unwrap_or(data),
                    line,
                });
                s.owners.push(
                    data.get(PARAMETER_COLUMNS..)
                        .and_then(|d| d.trim().parse().ok()),
                );
            }
            _ => {}
        }
    }
    Ok(s)
}

/// A parameter's value.
#[derive(Clone, Debug, PartialEq)]
pub enum Value {
    /// A defaulted (empty) field.
    Empty,
    /// A number; `integer` when written without a decimal point or exponent.
    Number {
        value: f64,
        integer: bool,
    },
    Text(String),
}

/// A parameter and where it starts.
#[derive(Clone, Debug, PartialEq)]
pub struct Token {
    pub value: Value,
    /// What was written, for error messages.
    pub written: String,
    pub line: usize,
    pub column: usize,
}

/// The delimiters a file declares (Global parameters 1 and 2, §2.2.4.1).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Delimiters {
    pub parameter: u8,
    pub record: u8,
}

/// A run of records joined into one free-format text, with each byte's origin.
struct Joined {
    text: Vec<u8>,
    origin: Vec<(usize, usize)>,
}

impl Joined {
    /// The (line, column) of byte `i`, or of the last byte when `i` is past the end.
    fn at(&self, i: usize) -> (usize, usize) {
        self.origin
            .get(i)
            .or(self.origin.last())
            .copied()
            .unwrap_or((1, 1))
    }
}

fn join(records: &[Record<'_>]) -> Joined {
    let mut text = Vec::new();
    let mut origin = Vec::new();
    for r in records {
        for (c, b) in r.data.bytes().enumerate() {
            text.push(b);
            origin.push((r.line, c + 1));
        }
    }
    Joined { text, origin }
}

/// Reads the Global section: its delimiters and its parameters (parameter 1 first).
pub fn global(
    path: &Path,
    records: &[Record<'_>],
    tolerated: &mut Vec<Tolerated>,
) -> Result<(Delimiters, Vec<Token>), ParseError> {
    let j = join(records);
    let t = &j.text;
    let at = |i: usize| j.at(i);
    // §2.2.4.1: parameter 1 is `1Hc` or empty (then ','); parameter 2 likewise (';').
    let declared = |i: usize| -> Option<u8> {
        (t.get(i) == Some(&b'1') && t.get(i + 1).is_some_and(|h| h.eq_ignore_ascii_case(&b'H')))
            .then(|| t.get(i + 2).copied())
            .flatten()
    };
    let mut pos = 0;
    while t.get(pos) == Some(&b' ') {
        pos += 1;
    }
    let parameter = match declared(pos) {
        Some(c) => {
            pos += 3;
            c
        }
        None => b',',
    };
    let expect_delim = |pos: usize, d: u8| -> Result<(), ParseError> {
        if t.get(pos) == Some(&d) {
            Ok(())
        } else {
            let (line, column) = at(pos);
            Err(ParseError::new(
                path,
                line,
                column,
                format!(
                    "expected the parameter delimiter `{}` after a Global delimiter field (§2.2.4.1)",
                    d as char
                ),
            ))
        }
    };
    expect_delim(pos, parameter)?;
    pos += 1;
    let record = match declared(pos) {
        Some(c) => {
            pos += 3;
            c
        }
        None => b';',
    };
    let delims = Delimiters { parameter, record };
    let mut tokens = vec![
        text_token(parameter, at(0)),
        text_token(record, at(pos.saturating_sub(1))),
    ];
    if t.get(pos) == Some(&record) {
        return Ok((delims, tokens));
    }
    expect_delim(pos, parameter)?;
    let mut rest = tokenize(path, &j, pos + 1, delims, tolerated)?;
    tokens.append(&mut rest);
    Ok((delims, tokens))
}

fn text_token(c: u8, (line, column): (usize, usize)) -> Token {
    Token {
        value: Value::Text((c as char).to_string()),
        written: format!("1H{}", c as char),
        line,
        column,
    }
}

/// Tokenizes one entity's parameter records (from its first record to its last).
pub fn parameters(
    path: &Path,
    records: &[Record<'_>],
    delims: Delimiters,
    tolerated: &mut Vec<Tolerated>,
) -> Result<Vec<Token>, ParseError> {
    tokenize(path, &join(records), 0, delims, tolerated)
}

/// A Hollerith string whose count was wrong, read up to the delimiter that shows where it
/// ends.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tolerated {
    pub line: usize,
    pub column: usize,
    pub announced: usize,
    pub read: usize,
}

/// Whether a field that ends before byte `e` is followed (after spaces) by a delimiter.
fn ends_field(t: &[u8], e: usize, delims: Delimiters) -> bool {
    let mut i = e;
    while t.get(i) == Some(&b' ') {
        i += 1;
    }
    matches!(t.get(i), Some(&c) if c == delims.parameter || c == delims.record)
}

/// Where a Hollerith string whose count `declared` does not end at a delimiter was meant
/// to end, when the records make it clear (writers miscount, e.g. Rhino 7 announces
/// `38H` before a 32-character file name): a count reaching past a delimiter after
/// which its record holds only blanks (the padding of a fixed-format record) ends at
/// that delimiter; a count that stops short of the delimiter later on the same record
/// ends there. Otherwise `None`: the string's end is a guess, and the file is refused.
fn hollerith_intent(
    j: &Joined,
    body: usize,
    declared: Option<usize>,
    delims: Delimiters,
) -> Option<usize> {
    let t = &j.text;
    let is_delim = |c: u8| c == delims.parameter || c == delims.record;
    let line_of = |i: usize| j.origin[i].0;
    let record_end = |i: usize| {
        let line = line_of(i);
        (i..t.len())
            .find(|&k| line_of(k) != line)
            .unwrap_or(t.len())
    };
    let reach = declared.unwrap_or(t.len());
    let overshoot = (body..reach)
        .find(|&d| is_delim(t[d]) && t[d + 1..record_end(d)].iter().all(|&c| c == b' '));
    if overshoot.is_some() {
        return overshoot;
    }
    let e = declared.filter(|&e| e < t.len())?;
    (e..record_end(e)).find(|&d| is_delim(t[d]))
}

/// Free-format fields from `start` to the record delimiter (§2.2.2): numbers, Hollerith
/// strings, or nothing (a defaulted field). Spaces around fields are ignored (outside
/// strings). Text after the record delimiter is a comment. Hollerith strings with a wrong
/// count are read as [`hollerith_intent`] says and noted in `tolerated`.
fn tokenize(
    path: &Path,
    j: &Joined,
    start: usize,
    delims: Delimiters,
    tolerated: &mut Vec<Tolerated>,
) -> Result<Vec<Token>, ParseError> {
    let t = &j.text;
    let at = |i: usize| j.at(i);
    let mut tokens = Vec::new();
    let mut pos = start;
    loop {
        while t.get(pos) == Some(&b' ') {
            pos += 1;
        }
        let (line, column) = at(pos);
        let field_start = pos;
        // A Hollerith string: digits, `H`, then exactly that many characters.
        let digits = t[pos.min(t.len())..]
            .iter()
            .take_while(|b| b.is_ascii_digit())
            .count();
        let value = if digits > 0
            && t.get(pos + digits)
                .is_some_and(|h| h.eq_ignore_ascii_case(&b'H'))
        {
            let n: usize = std::str::from_utf8(&t[pos..pos + digits])
                .ok()
                .and_then(|s| s.parse().ok())
                .unwrap_or(usize::MAX);
            let body = pos + digits + 1;
            let declared = body.checked_add(n).filter(|&e| e <= t.len());
            let end = match declared.filter(|&e| ends_field(t, e, delims)) {
                Some(end) => end,
                None => {
                    let end = hollerith_intent(j, body, declared, delims).ok_or_else(|| {
                        ParseError::new(
                            path,
                            line,
                            column,
                            match declared {
                                Some(_) => format!(
                                    "expected a delimiter after the {n} characters of a Hollerith string, and no delimiter nearby shows where it ends"
                                ),
                                None => format!(
                                    "expected {n} characters of a Hollerith string, found the end of the entity's records"
                                ),
                            },
                        )
                    })?;
                    tolerated.push(Tolerated {
                        line,
                        column,
                        announced: n,
                        read: end - body,
                    });
                    end
                }
            };
            pos = end;
            Value::Text(String::from_utf8_lossy(&t[body..end]).into_owned())
        } else {
            while pos < t.len() && t[pos] != delims.parameter && t[pos] != delims.record {
                pos += 1;
            }
            let raw = String::from_utf8_lossy(&t[field_start..pos]);
            let raw = raw.trim();
            if raw.is_empty() {
                Value::Empty
            } else {
                number(raw).ok_or_else(|| {
                    ParseError::new(
                        path,
                        line,
                        column,
                        format!(
                            "expected a number, a Hollerith string or an empty field, found `{raw}`"
                        ),
                    )
                })?
            }
        };
        while t.get(pos) == Some(&b' ') {
            pos += 1;
        }
        let written = String::from_utf8_lossy(&t[field_start..pos.min(t.len())])
            .trim()
            .to_string();
        tokens.push(Token {
            value,
            written,
            line,
            column,
        });
        match t.get(pos) {
            Some(&c) if c == delims.record => return Ok(tokens),
            Some(&c) if c == delims.parameter => pos += 1,
            _ => {
                let (line, column) = at(pos);
                return Err(ParseError::new(
                    path,
                    line,
                    column,
                    format!(
                        "expected the parameter delimiter `{}` or the record delimiter `{}`",
                        delims.parameter as char, delims.record as char
                    ),
                ));
            }
        }
    }
}

/// An IGES number: an integer, or a real with an optional `E` or `D` exponent (§2.2.2.1–3).
fn number(raw: &str) -> Option<Value> {
    let integer = !raw.contains(['.', 'E', 'e', 'D', 'd']);
    let value: f64 = if raw.contains(['D', 'd']) {
        raw.replace(['D', 'd'], "E").parse().ok()?
    } else {
        raw.parse().ok()?
    };
    value
        .is_finite()
        .then_some(Value::Number { value, integer })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rec(data: &str) -> Record<'_> {
        Record { data, line: 7 }
    }

    #[test]
    fn global_declares_its_delimiters() {
        let (d, t) = global(
            Path::new("g"),
            &[rec("1H//1H#/4HA/B;/1.5D2#")],
            &mut Vec::new(),
        )
        .unwrap();
        assert_eq!((d.parameter, d.record), (b'/', b'#'));
        assert_eq!(t[2].value, Value::Text("A/B;".into()));
        assert_eq!(
            t[3].value,
            Value::Number {
                value: 150.0,
                integer: false
            }
        );
        let (d, t) = global(Path::new("g"), &[rec(",,3Hxyz,2;")], &mut Vec::new()).unwrap();
        assert_eq!((d.parameter, d.record), (b',', b';'));
        assert_eq!(
            t[3].value,
            Value::Number {
                value: 2.0,
                integer: true
            }
        );
    }

    #[test]
    fn parameters_keep_empty_fields_and_positions() {
        let d = Delimiters {
            parameter: b',',
            record: b';',
        };
        let t = parameters(
            Path::new("p"),
            &[rec("110, 1.,,-3.E1;  comment")],
            d,
            &mut Vec::new(),
        )
        .unwrap();
        assert_eq!(t.len(), 4);
        assert_eq!(t[2].value, Value::Empty);
        assert_eq!(
            t[3].value,
            Value::Number {
                value: -30.0,
                integer: false
            }
        );
        assert_eq!((t[1].line, t[1].column), (7, 6));
        let e = parameters(Path::new("p"), &[rec("110,1.x,2;")], d, &mut Vec::new()).unwrap_err();
        assert_eq!(
            e.to_string(),
            "p:7:5: expected a number, a Hollerith string or an empty field, found `1.x`"
        );
        let e = parameters(Path::new("p"), &[rec("110,1,2")], d, &mut Vec::new()).unwrap_err();
        assert!(e.to_string().contains("record delimiter"), "{e}");
    }

    #[test]
    fn miscounted_hollerith_strings_end_at_the_delimiter_that_shows_where() {
        let d = Delimiters {
            parameter: b',',
            record: b';',
        };
        // Too long: the count runs over `,` into the blank padding of its record.
        let (a, b) = ("406,9HABCD,", "  2;");
        let records = [
            Record {
                data: &format!("{a:<20}"),
                line: 3,
            },
            Record { data: b, line: 4 },
        ];
        let mut tolerated = Vec::new();
        let t = parameters(Path::new("p"), &records, d, &mut tolerated).unwrap();
        assert_eq!(t[1].value, Value::Text("ABCD".into()));
        assert_eq!(
            t[2].value,
            Value::Number {
                value: 2.0,
                integer: true
            }
        );
        assert_eq!(
            tolerated,
            [Tolerated {
                line: 3,
                column: 5,
                announced: 9,
                read: 4
            }]
        );
        // Too short: the delimiter follows later on the same record.
        let mut tolerated = Vec::new();
        let t = parameters(Path::new("p"), &[rec("406,2HABCD,3;")], d, &mut tolerated).unwrap();
        assert_eq!(t[1].value, Value::Text("ABCD".into()));
        assert_eq!(tolerated[0].read, 4);
        // No delimiter shows the end: refused, located at the string.
        let e = parameters(Path::new("p"), &[rec("406,2HABCD")], d, &mut Vec::new()).unwrap_err();
        assert_eq!((e.line, e.column), (7, 5), "{e}");
    }
}
