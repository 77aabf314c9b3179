//! The exchange structure of ISO 10303-21 (§7–§11): the `HEADER` section's records and the
//! `DATA` section's entity instances `#id = NAME(params);`, simple or complex
//! (`#id = (A(...) B(...));`, §11.2.5.3: how rational B-splines are written), in any order
//! and with forward references. This layer knows nothing of what the entities mean
//! (OpenCASCADE's StepData); every parameter keeps its line and column for error messages.

use std::borrow::Cow;
use std::collections::HashMap;

use super::lexer::{LexError, Lexer, Token, TokenKind};

/// One parameter value (§11.2.5).
#[derive(Clone, Debug, PartialEq)]
pub enum Value<'a> {
    Integer(i64),
    Real(f64),
    Str(Cow<'a, str>),
    Enumeration(&'a str),
    Binary(&'a str),
    Ref(u64),
    Unset,
    Derived,
    List(Vec<Param<'a>>),
    /// A typed parameter such as `LENGTH_MEASURE(2.5)` (a SELECT value).
    Typed(&'a str, Box<Param<'a>>),
}

#[derive(Clone, Debug, PartialEq)]
pub struct Param<'a> {
    pub value: Value<'a>,
    pub line: u32,
    pub column: u32,
}

/// `NAME(params)`, one partial record of an instance.
#[derive(Clone, Debug, PartialEq)]
pub struct Record<'a> {
    pub name: &'a str,
    pub params: Vec<Param<'a>>,
    pub line: u32,
    pub column: u32,
}

/// An entity instance: one record, or for a complex instance the records of each
/// supertype and subtype, in the order written (Part 21 requires alphabetical).
#[derive(Clone, Debug, PartialEq)]
pub struct Instance<'a> {
    pub id: u64,
    pub records: Vec<Record<'a>>,
    pub complex: bool,
    pub line: u32,
    pub column: u32,
}

impl<'a> Instance<'a> {
    /// The record named `name` (for a simple instance, the record if it has that name).
    pub fn record(&self, name: &str) -> Option<&Record<'a>> {
        self.records.iter().find(|r| r.name == name)
    }

    /// The instance's shape representation record (`SHAPE_REPRESENTATION` or a subtype
    /// such as `ADVANCED_BREP_SHAPE_REPRESENTATION`, whose attributes are name, items and
    /// context of items), when it is one.
    pub fn shape_representation(&self) -> Option<&Record<'a>> {
        self.records
            .iter()
            .find(|r| r.name.ends_with("SHAPE_REPRESENTATION") && r.params.len() >= 3)
    }

    /// The type name: the record's for a simple instance, the records' names joined by
    /// `+` for a complex one.
    pub fn type_name(&self) -> Cow<'a, str> {
        if self.records.len() == 1 {
            Cow::Borrowed(self.records[0].name)
        } else {
            Cow::Owned(
                self.records
                    .iter()
                    .map(|r| r.name)
                    .collect::<Vec<_>>()
                    .join("+"),
            )
        }
    }
}

/// A whole exchange file.
#[derive(Debug, Default)]
pub struct Exchange<'a> {
    pub header: Vec<Record<'a>>,
    pub instances: Vec<Instance<'a>>,
    index: HashMap<u64, usize>,
    /// What the syntax tolerated, one line each (backslashes kept as text).
    pub warnings: Vec<String>,
}

impl<'a> Exchange<'a> {
    pub fn get(&self, id: u64) -> Option<&Instance<'a>> {
        self.index.get(&id).map(|&k| &self.instances[k])
    }

    /// The schema names of `FILE_SCHEMA` (AP203 `CONFIG_CONTROL_DESIGN`, AP214
    /// `AUTOMOTIVE_DESIGN`, AP242 `AP242_MANAGED_MODEL_BASED_3D_ENGINEERING…`).
    pub fn schemas(&self) -> Vec<String> {
        let Some(r) = self.header.iter().find(|r| r.name == "FILE_SCHEMA") else {
            return Vec::new();
        };
        let mut out = Vec::new();
        if let Some(Param {
            value: Value::List(items),
            ..
        }) = r.params.first()
        {
            for p in items {
                if let Value::Str(s) = &p.value {
                    out.push(s.to_string());
                }
            }
        }
        out
    }
}

fn describe(kind: &TokenKind) -> String {
    match kind {
        TokenKind::Keyword(k) => format!("`{k}`"),
        TokenKind::Instance(id) => format!("`#{id}`"),
        TokenKind::Integer(i) => format!("`{i}`"),
        TokenKind::Real(r) => format!("`{r}`"),
        TokenKind::Str(_) => "a string".into(),
        TokenKind::Enumeration(e) => format!("`.{e}.`"),
        TokenKind::Binary(_) => "a binary".into(),
        TokenKind::Unset => "`$`".into(),
        TokenKind::Derived => "`*`".into(),
        TokenKind::Open => "`(`".into(),
        TokenKind::Close => "`)`".into(),
        TokenKind::Comma => "`,`".into(),
        TokenKind::Equals => "`=`".into(),
        TokenKind::Semicolon => "`;`".into(),
    }
}

/// Deepest nesting of parameter lists accepted; real files nest three or four deep
/// (a B-spline surface's control net is a list of lists), and a bound keeps a hostile
/// file from exhausting the stack.
const MAX_NESTING: usize = 64;

struct Parser<'a> {
    lexer: Lexer<'a>,
    peeked: Option<Token<'a>>,
    /// Whether the last token read was a `;` (so a malformed instance that it ended needs
    /// no skipping).
    ended: bool,
}

/// Instances of the DATA section left out, for the one warning that reports them.
#[derive(Default)]
struct Dropped {
    count: usize,
    /// The first one's instance name (when it got that far) and error.
    first: Option<(Option<u64>, LexError)>,
}

impl Dropped {
    fn push(&mut self, id: Option<u64>, e: LexError) {
        self.count += 1;
        self.first.get_or_insert((id, e));
    }
}

impl<'a> Parser<'a> {
    fn peek(&mut self) -> Result<Option<&Token<'a>>, LexError> {
        if self.peeked.is_none() {
            self.peeked = self
                .lexer
                .next_token()
                .inspect_err(|_| self.ended = false)?;
        }
        Ok(self.peeked.as_ref())
    }

    fn next(&mut self, what: &str) -> Result<Token<'a>, LexError> {
        self.peek()?;
        match self.peeked.take() {
            Some(t) => {
                self.ended = t.kind == TokenKind::Semicolon;
                Ok(t)
            }
            None => {
                let (line, column) = self.lexer.here();
                Err(LexError {
                    line,
                    column,
                    message: format!("expected {what}, found end of file"),
                })
            }
        }
    }

    fn unexpected(t: &Token, what: &str) -> LexError {
        LexError {
            line: t.line,
            column: t.column,
            message: format!("expected {what}, found {}", describe(&t.kind)),
        }
    }

    fn expect(&mut self, kind: TokenKind<'static>, what: &str) -> Result<Token<'a>, LexError> {
        let t = self.next(what)?;
        if t.kind == kind {
            Ok(t)
        } else {
            Err(Self::unexpected(&t, what))
        }
    }

    fn keyword(&mut self, word: &str) -> Result<(), LexError> {
        let t = self.next(&format!("`{word}`"))?;
        match t.kind {
            TokenKind::Keyword(k) if k == word => Ok(()),
            _ => Err(Self::unexpected(&t, &format!("`{word}`"))),
        }
    }

    /// `NAME(params)` with the name already read.
    fn record(&mut self, name: &'a str, line: u32, column: u32) -> Result<Record<'a>, LexError> {
        self.expect(TokenKind::Open, &format!("`(` after `{name}`"))?;
        let params = self.list_tail(0)?;
        Ok(Record {
            name,
            params,
            line,
            column,
        })
    }

    /// Parameters after an opening `(`, through the closing `)`.
    fn list_tail(&mut self, depth: usize) -> Result<Vec<Param<'a>>, LexError> {
        let mut params = Vec::new();
        if matches!(self.peek()?, Some(t) if t.kind == TokenKind::Close) {
            self.peeked = None;
            return Ok(params);
        }
        loop {
            params.push(self.param(depth)?);
            let t = self.next("`,` or `)`")?;
            match t.kind {
                TokenKind::Comma => {}
                TokenKind::Close => return Ok(params),
                _ => return Err(Self::unexpected(&t, "`,` or `)`")),
            }
        }
    }

    fn param(&mut self, depth: usize) -> Result<Param<'a>, LexError> {
        let t = self.next("a parameter")?;
        if depth > MAX_NESTING {
            return Err(LexError {
                line: t.line,
                column: t.column,
                message: format!("parameter lists nest deeper than {MAX_NESTING}"),
            });
        }
        let value = match t.kind {
            TokenKind::Integer(i) => Value::Integer(i),
            TokenKind::Real(r) => Value::Real(r),
            TokenKind::Str(s) => Value::Str(s),
            TokenKind::Enumeration(e) => Value::Enumeration(e),
            TokenKind::Binary(b) => Value::Binary(b),
            TokenKind::Instance(id) => Value::Ref(id),
            TokenKind::Unset => Value::Unset,
            TokenKind::Derived => Value::Derived,
            TokenKind::Open => Value::List(self.list_tail(depth + 1)?),
            TokenKind::Keyword(name) => {
                self.expect(TokenKind::Open, &format!("`(` after `{name}`"))?;
                let inner = self.param(depth + 1)?;
                self.expect(TokenKind::Close, &format!("`)` closing `{name}(`"))?;
                Value::Typed(name, Box::new(inner))
            }
            _ => return Err(Self::unexpected(&t, "a parameter")),
        };
        Ok(Param {
            value,
            line: t.line,
            column: t.column,
        })
    }

    /// Records up to `ENDSEC;` (header section).
    fn header(&mut self) -> Result<Vec<Record<'a>>, LexError> {
        let mut out = Vec::new();
        loop {
            let t = self.next("a header record or `ENDSEC`")?;
            match t.kind {
                TokenKind::Keyword("ENDSEC") => {
                    self.expect(TokenKind::Semicolon, "`;` after `ENDSEC`")?;
                    return Ok(out);
                }
                TokenKind::Keyword(name) => {
                    out.push(self.record(name, t.line, t.column)?);
                    self.expect(TokenKind::Semicolon, "`;` ending the record")?;
                }
                _ => return Err(Self::unexpected(&t, "a header record or `ENDSEC`")),
            }
        }
    }

    /// `#id = …;` instances up to `ENDSEC;`, appended to `ex`. An instance that does not
    /// parse is skipped through the `;` that ends it, and a second definition of an
    /// instance name is ignored, as OpenCASCADE's reader does: the error is then the
    /// entities' that reference them, not the whole file's. A section that never ends
    /// (a string left open, no `ENDSEC;`) is an error.
    fn data(
        &mut self,
        ex: &mut Exchange<'a>,
        malformed: &mut Dropped,
        duplicates: &mut Dropped,
    ) -> Result<(), LexError> {
        loop {
            if matches!(self.peek(), Ok(Some(t)) if t.kind == TokenKind::Keyword("ENDSEC")) {
                self.peeked = None;
                self.expect(TokenKind::Semicolon, "`;` after `ENDSEC`")?;
                return Ok(());
            }
            let mut id = None;
            match self.instance(&mut id) {
                Ok(inst) if ex.index.contains_key(&inst.id) => duplicates.push(
                    Some(inst.id),
                    LexError {
                        line: inst.line,
                        column: inst.column,
                        message: format!("#{} is defined again", inst.id),
                    },
                ),
                Ok(inst) => {
                    ex.index.insert(inst.id, ex.instances.len());
                    ex.instances.push(inst);
                }
                Err(e) => {
                    if self
                        .peeked
                        .take()
                        .is_some_and(|t| t.kind == TokenKind::Semicolon)
                        || self.ended
                    {
                        self.ended = false;
                    } else if self.lexer.skip_past_semicolon().is_err() {
                        // Nothing ends it: the file is cut or a string runs to its end.
                        return Err(e);
                    }
                    malformed.push(id, e);
                }
            }
        }
    }

    /// One instance `#id = NAME(…);` or `#id = (A(…) B(…));`; `id` is set once read.
    fn instance(&mut self, id: &mut Option<u64>) -> Result<Instance<'a>, LexError> {
        let t = self.next("an instance `#id = …;` or `ENDSEC`")?;
        let TokenKind::Instance(n) = t.kind else {
            return Err(Self::unexpected(&t, "an instance `#id = …;` or `ENDSEC`"));
        };
        *id = Some(n);
        self.expect(TokenKind::Equals, &format!("`=` after `#{n}`"))?;
        let first = self.next("an entity name or `(`")?;
        let (records, complex) = match first.kind {
            TokenKind::Keyword(name) => (vec![self.record(name, first.line, first.column)?], false),
            TokenKind::Open => {
                let mut records = Vec::new();
                loop {
                    let r = self.next("a partial entity name or `)`")?;
                    match r.kind {
                        TokenKind::Keyword(name) => {
                            records.push(self.record(name, r.line, r.column)?)
                        }
                        TokenKind::Close if !records.is_empty() => break,
                        _ => return Err(Self::unexpected(&r, "a partial entity name or `)`")),
                    }
                }
                (records, true)
            }
            _ => return Err(Self::unexpected(&first, "an entity name or `(`")),
        };
        self.expect(TokenKind::Semicolon, "`;` ending the instance")?;
        Ok(Instance {
            id: n,
            records,
            complex,
            line: t.line,
            column: t.column,
        })
    }
}

/// Parses a whole exchange structure (`ISO-10303-21; HEADER; …; ENDSEC; DATA; …; ENDSEC;
/// END-ISO-10303-21;`, several DATA sections allowed as in §9).
pub fn parse(src: &str) -> Result<Exchange<'_>, LexError> {
    let mut p = Parser {
        lexer: Lexer::new(src),
        peeked: None,
        ended: false,
    };
    let (mut malformed, mut duplicates) = (Dropped::default(), Dropped::default());
    p.keyword("ISO-10303-21")?;
    p.expect(TokenKind::Semicolon, "`;` after `ISO-10303-21`")?;
    p.keyword("HEADER")?;
    p.expect(TokenKind::Semicolon, "`;` after `HEADER`")?;
    let mut ex = Exchange {
        header: p.header()?,
        ..Default::default()
    };
    loop {
        let t = p.next("`DATA` or `END-ISO-10303-21`")?;
        match t.kind {
            TokenKind::Keyword("DATA") => {
                // A DATA section may name itself: DATA('name', ('schema'));
                if matches!(p.peek()?, Some(t) if t.kind == TokenKind::Open) {
                    p.peeked = None;
                    p.list_tail(0)?;
                }
                p.expect(TokenKind::Semicolon, "`;` after `DATA`")?;
                p.data(&mut ex, &mut malformed, &mut duplicates)?;
            }
            TokenKind::Keyword("END-ISO-10303-21") => {
                p.expect(TokenKind::Semicolon, "`;` after `END-ISO-10303-21`")?;
                if let Some((id, e)) = &malformed.first {
                    let name = id.map(|id| format!("#{id}: ")).unwrap_or_default();
                    ex.warnings.push(format!(
                        "{}:{}: {} instance(s) of the DATA section do not parse and were skipped through their `;` (first {name}{})",
                        e.line, e.column, malformed.count, e.message
                    ));
                }
                if let Some((_, e)) = &duplicates.first {
                    ex.warnings.push(format!(
                        "{}:{}: {} instance name(s) defined more than once; the first definition of each is kept (first: {})",
                        e.line, e.column, duplicates.count, e.message
                    ));
                }
                if let Some((line, column, text)) = &p.lexer.first_literal {
                    ex.warnings.push(format!(
                        "{line}:{column}: {} backslash(es) in strings begin no escape of ISO 10303-21 §6.4.3 (first `{text}`, as in a Windows path) and were kept as text",
                        p.lexer.literal_backslashes
                    ));
                }
                return Ok(ex);
            }
            _ => return Err(Parser::unexpected(&t, "`DATA` or `END-ISO-10303-21`")),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const FILE: &str = "ISO-10303-21;\nHEADER;\nFILE_DESCRIPTION((''),'2;1');\n\
        FILE_SCHEMA(('AUTOMOTIVE_DESIGN'));\nENDSEC;\nDATA;\n\
        #2=CARTESIAN_POINT('',(0.,1.,2.));\n\
        #1=(BOUNDED_CURVE() B_SPLINE_CURVE(1,(#2,#2),.UNSPECIFIED.,.F.,.F.)\n\
           RATIONAL_B_SPLINE_CURVE((1.,2.)));\n\
        #3=MEASURE_REPRESENTATION_ITEM('',LENGTH_MEASURE(2.5),#1);\nENDSEC;\nEND-ISO-10303-21;\n";

    #[test]
    fn parses_simple_complex_and_typed_instances() {
        let ex = parse(FILE).unwrap();
        assert_eq!(ex.schemas(), vec!["AUTOMOTIVE_DESIGN"]);
        assert_eq!(ex.instances.len(), 3);
        let c = ex.get(1).unwrap();
        assert!(c.complex);
        assert_eq!(
            c.type_name(),
            "BOUNDED_CURVE+B_SPLINE_CURVE+RATIONAL_B_SPLINE_CURVE"
        );
        let r = c.record("RATIONAL_B_SPLINE_CURVE").unwrap();
        assert_eq!((r.line, r.column), (9, 1));
        let p = &ex.get(2).unwrap().records[0].params[1];
        assert!(matches!(&p.value, Value::List(v) if v.len() == 3));
        let m = &ex.get(3).unwrap().records[0].params[1];
        assert!(
            matches!(&m.value, Value::Typed("LENGTH_MEASURE", b) if b.value == Value::Real(2.5))
        );
        assert_eq!((m.line, m.column), (10, 35));
    }

    /// As OpenCASCADE reads them: an instance that does not parse is skipped through its
    /// `;` (one inside a string or a comment ends nothing), a name defined twice keeps its
    /// first definition, each with one located warning; the rest of the file is read.
    #[test]
    fn malformed_instances_are_skipped_and_duplicates_keep_the_first() {
        let bad = FILE.replace("(0.,1.,2.)", "(0.,1. 2.)");
        let ex = parse(&bad).unwrap();
        assert!(ex.get(2).is_none());
        assert_eq!(ex.instances.len(), 2);
        assert_eq!(
            ex.warnings,
            vec![
                "7:30: 1 instance(s) of the DATA section do not parse and were skipped through their `;` (first #2: expected `,` or `)`, found `2`)"
            ]
        );
        // The skip looks past `;` in strings and comments, and a `;` that is itself the
        // unexpected token ends the instance.
        let bad = FILE.replace(
            "#2=CARTESIAN_POINT('',(0.,1.,2.));",
            "#2=CARTESIAN_POINT('a;b' /* ; */ 5 'c;');\n#4=CARTESIAN_POINT('',(0.,1.;\n#5=A();",
        );
        let ex = parse(&bad).unwrap();
        assert_eq!(
            ex.instances.iter().map(|i| i.id).collect::<Vec<_>>(),
            vec![5, 1, 3]
        );
        assert!(
            ex.warnings[0].contains(" 2 instance(s) "),
            "{:?}",
            ex.warnings
        );
        let twice = FILE.replace("#3=", "#2=");
        let ex = parse(&twice).unwrap();
        assert_eq!(ex.instances.len(), 2);
        assert_eq!(ex.get(2).unwrap().records[0].name, "CARTESIAN_POINT");
        assert_eq!(
            ex.warnings,
            vec![
                "10:1: 1 instance name(s) defined more than once; the first definition of each is kept (first: #2 is defined again)"
            ]
        );
        let deep = format!("{}{}", "(".repeat(100), ")".repeat(100));
        let bad = FILE.replace("(0.,1.,2.)", &deep);
        let ex = parse(&bad).unwrap();
        assert!(ex.warnings[0].contains("nest deeper"), "{:?}", ex.warnings);
    }

    /// What breaks the file's structure stays a located error: a cut file, a string left
    /// open to the end, a header that does not parse.
    #[test]
    fn broken_structure_is_a_located_error() {
        let e = parse(&FILE[..FILE.len() - 26]).unwrap_err();
        assert!(e.message.contains("end of file"), "{}", e.message);
        let e = parse(&FILE.replace("(0.,1.,2.));", "(0.,'1.,2.));")).unwrap_err();
        assert_eq!((e.line, e.column), (7, 27));
        assert!(e.message.contains("never closed"), "{}", e.message);
        let e = parse(&FILE.replace("'2;1');", "'2;1';")).unwrap_err();
        assert_eq!((e.line, e.column), (3, 28));
        let e = parse(&FILE.replace("DATA;", "")).unwrap_err();
        assert!(e.message.contains("`DATA`"), "{}", e.message);
    }
}
