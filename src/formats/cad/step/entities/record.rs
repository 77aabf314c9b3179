//! One record of an instance, read parameter by parameter: each accessor checks the
//! parameter's kind and locates its error at the parameter's line and column.

use super::Rec;
use crate::formats::cad::step::records::{Param, Value};
use crate::formats::error::ParseError;

impl<'r, 'a> Rec<'r, 'a> {
    pub fn error_at(&self, line: u32, column: u32, message: impl AsRef<str>) -> ParseError {
        ParseError::new(
            self.path,
            line as usize,
            column as usize,
            format!(
                "#{} {}: {}",
                self.inst.id,
                self.inst.type_name(),
                message.as_ref()
            ),
        )
    }

    pub fn error(&self, message: impl AsRef<str>) -> ParseError {
        self.error_at(self.rec.line, self.rec.column, message)
    }

    pub fn param(&self, i: usize, what: &str) -> Result<&'r Param<'a>, ParseError> {
        self.rec.params.get(i).ok_or_else(|| {
            self.error(format!(
                "expected {what} as parameter {}, found only {} parameter(s)",
                i + 1,
                self.rec.params.len()
            ))
        })
    }

    fn wrong(&self, p: &Param, what: &str) -> ParseError {
        let found = match &p.value {
            Value::Integer(_) => "an integer",
            Value::Real(_) => "a real",
            Value::Str(_) => "a string",
            Value::Enumeration(_) => "an enumeration",
            Value::Binary(_) => "a binary",
            Value::Ref(_) => "a reference",
            Value::Unset => "`$`",
            Value::Derived => "`*`",
            Value::List(_) => "a list",
            Value::Typed(..) => "a typed value",
        };
        self.error_at(p.line, p.column, format!("expected {what}, found {found}"))
    }

    /// A finite number (integers are accepted where reals are expected, Part 21 §11.2.5).
    pub fn number(&self, p: &Param, what: &str) -> Result<f64, ParseError> {
        match &p.value {
            Value::Real(r) => Ok(*r),
            Value::Integer(i) => Ok(*i as f64),
            Value::Typed(_, inner) => self.number(inner, what),
            _ => Err(self.wrong(p, what)),
        }
    }

    pub fn real(&self, i: usize, what: &str) -> Result<f64, ParseError> {
        self.number(self.param(i, what)?, what)
    }

    pub fn positive(&self, i: usize, what: &str) -> Result<f64, ParseError> {
        let p = self.param(i, what)?;
        let x = self.number(p, what)?;
        if x > 0.0 {
            Ok(x)
        } else {
            Err(self.error_at(p.line, p.column, format!("expected {what} > 0, found {x}")))
        }
    }

    pub fn integer(&self, p: &Param, what: &str) -> Result<i64, ParseError> {
        match p.value {
            Value::Integer(i) => Ok(i),
            _ => Err(self.wrong(p, what)),
        }
    }

    /// `.T.` or `.F.` (a LOGICAL's `.U.` is refused where a BOOLEAN is needed).
    pub fn boolean(&self, i: usize, what: &str) -> Result<bool, ParseError> {
        let p = self.param(i, what)?;
        match p.value {
            Value::Enumeration("T") => Ok(true),
            Value::Enumeration("F") => Ok(false),
            _ => Err(self.wrong(p, &format!("{what} (.T. or .F.)"))),
        }
    }

    pub fn enumeration(&self, i: usize, what: &str) -> Result<&'a str, ParseError> {
        let p = self.param(i, what)?;
        match p.value {
            Value::Enumeration(e) => Ok(e),
            _ => Err(self.wrong(p, what)),
        }
    }

    pub fn reference_of(&self, p: &Param, what: &str) -> Result<u64, ParseError> {
        match p.value {
            Value::Ref(id) => Ok(id),
            _ => Err(self.wrong(p, &format!("a reference to {what}"))),
        }
    }

    pub fn reference(&self, i: usize, what: &str) -> Result<u64, ParseError> {
        self.reference_of(self.param(i, what)?, what)
    }

    pub fn list_of(&self, p: &'r Param<'a>, what: &str) -> Result<&'r [Param<'a>], ParseError> {
        match &p.value {
            Value::List(items) => Ok(items),
            _ => Err(self.wrong(p, &format!("a list of {what}"))),
        }
    }

    pub fn list(&self, i: usize, what: &str) -> Result<&'r [Param<'a>], ParseError> {
        self.list_of(self.param(i, what)?, what)
    }

    pub fn numbers(&self, p: &'r Param<'a>, what: &str) -> Result<Vec<f64>, ParseError> {
        self.list_of(p, what)?
            .iter()
            .map(|q| self.number(q, what))
            .collect()
    }

    pub fn references(&self, i: usize, what: &str) -> Result<Vec<u64>, ParseError> {
        self.list(i, what)?
            .iter()
            .map(|q| self.reference_of(q, what))
            .collect()
    }
}
