//! pbrt-v3 scene files: the `Shape "nurbs"` surfaces they hold.
//!
//! The tokenizer follows pbrt-v3's: `#` comments, quoted strings, `[ ]` lists, and bare
//! numbers; a parameter value may be a list or a single value without brackets. The
//! transform directives `Identity`, `Translate`, `Scale`, `Rotate`, `Transform` and
//! `ConcatTransform` are applied to the shapes that follow them, scoped by
//! `AttributeBegin`/`AttributeEnd` and `TransformBegin`/`TransformEnd`, and `WorldBegin`
//! resets the transform as in pbrt. Not applied: `LookAt`, `CoordinateSystem` and
//! `CoordSysTransform` (camera placement), and everything about cameras, lights,
//! materials and rendering. Other shapes are ignored. `Include` and `Import` are refused.
//!
//! `Shape "nurbs"` parameters (pbrt-v3 `src/shapes/nurbs.cpp`): `nu`, `nv` control point
//! counts, `uorder`, `vorder` (degree + 1), `uknots`, `vknots` (`nu + uorder` and
//! `nv + vorder` values), the points as `"point P"` (x y z) or `"float Pw"` (homogeneous
//! x y z w, used by pbrt as given, so already premultiplied by w), indexed `v · nu + u`.
//! The parameter range `u0 u1 v0 v1` is read and checked but not applied: the whole
//! surface is kept.

use std::path::Path;

use glam::{DAffine3, DMat4, DVec3, DVec4};

use super::error::ParseError;
use crate::geom::MAX_DEGREE;
use crate::geom::nurbs::NurbsSurface;
use crate::scene::model::{Surface, SurfaceGeometry};

/// Parses the NURBS shapes of a pbrt-v3 file; `path` is used in error messages only.
pub fn parse_pbrt(path: &Path, src: &str) -> Result<Vec<Surface>, ParseError> {
    let mut p = Parser {
        lexer: Lexer {
            path,
            src,
            pos: 0,
            line: 1,
            column: 1,
        },
        peeked: None,
    };
    let mut ctm = DMat4::IDENTITY;
    let mut stack: Vec<DMat4> = Vec::new();
    let mut surfaces = Vec::new();
    while let Some(tok) = p.next_opt()? {
        let Kind::Word = tok.kind else {
            return Err(p.error(
                &tok,
                format!("expected a directive, found {}", tok.describe()),
            ));
        };
        match tok.text {
            "WorldBegin" => {
                ctm = DMat4::IDENTITY;
                stack.clear();
            }
            "AttributeBegin" | "TransformBegin" => stack.push(ctm),
            "AttributeEnd" | "TransformEnd" => {
                ctm = stack.pop().ok_or_else(|| {
                    p.error(
                        &tok,
                        format!(
                            "expected a matching `{}` before `{}`",
                            tok.text.replace("End", "Begin"),
                            tok.text
                        ),
                    )
                })?;
            }
            "Identity" => ctm = DMat4::IDENTITY,
            "Translate" => ctm *= DMat4::from_translation(p.vec3("Translate")?),
            "Scale" => ctm *= DMat4::from_scale(p.vec3("Scale")?),
            "Rotate" => {
                let angle = p.number("the Rotate angle in degrees")?;
                let axis_tok = p.peek()?;
                let axis = p.vec3("Rotate")?;
                if axis == DVec3::ZERO {
                    let at = axis_tok.unwrap_or(tok);
                    return Err(p.error(&at, "expected a non-zero rotation axis"));
                }
                ctm *= DMat4::from_axis_angle(axis.normalize(), angle.to_radians());
            }
            "Transform" | "ConcatTransform" => {
                let m = p.matrix(tok.text)?;
                ctm = if tok.text == "Transform" { m } else { ctm * m };
            }
            "Include" | "Import" => {
                return Err(p.error(
                    &tok,
                    format!(
                        "`{}` is not supported: expected a self-contained file",
                        tok.text
                    ),
                ));
            }
            "Shape" => {
                let name = p.next("a shape name")?;
                let Kind::Str = name.kind else {
                    return Err(p.error(
                        &name,
                        format!("expected a quoted shape name, found {}", name.describe()),
                    ));
                };
                let params = p.params()?;
                if name.text == "nurbs" {
                    let mut surface = nurbs(&p, &tok, &params)?;
                    if ctm.row(3) != DVec4::W {
                        return Err(p.error(
                            &tok,
                            "expected an affine transform for this shape, found a projective one",
                        ));
                    }
                    surface.transform(&DAffine3::from_mat4(ctm));
                    surfaces.push(surface);
                }
            }
            _ => {
                p.params()?;
            }
        }
    }
    Ok(surfaces)
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Kind {
    Word,
    Str,
    Open,
    Close,
}

#[derive(Clone, Copy, Debug)]
struct Tok<'a> {
    kind: Kind,
    /// The word, or a string's contents without quotes.
    text: &'a str,
    line: usize,
    column: usize,
}

impl Tok<'_> {
    fn describe(&self) -> String {
        match self.kind {
            Kind::Str => format!("\"{}\"", self.text),
            _ => format!("`{}`", self.text),
        }
    }

    fn number(&self) -> Option<f64> {
        match self.kind {
            Kind::Word => self.text.parse().ok(),
            _ => None,
        }
    }
}

struct Lexer<'a> {
    path: &'a Path,
    src: &'a str,
    pos: usize,
    line: usize,
    column: usize,
}

impl<'a> Lexer<'a> {
    fn advance(&mut self, c: char) {
        self.pos += c.len_utf8();
        if c == '\n' {
            self.line += 1;
            self.column = 1;
        } else {
            self.column += 1;
        }
    }

    fn next(&mut self) -> Result<Option<Tok<'a>>, ParseError> {
        let mut in_comment = false;
        while let Some(c) = self.src[self.pos..].chars().next() {
            if c == '\n' {
                in_comment = false;
            } else if c == '#' {
                in_comment = true;
            } else if !in_comment && !c.is_whitespace() {
                break;
            }
            self.advance(c);
        }
        let (line, column, start) = (self.line, self.column, self.pos);
        let Some(c) = self.src[start..].chars().next() else {
            return Ok(None);
        };
        let tok = |kind, text| Tok {
            kind,
            text,
            line,
            column,
        };
        match c {
            '[' | ']' => {
                self.advance(c);
                let kind = if c == '[' { Kind::Open } else { Kind::Close };
                Ok(Some(tok(kind, &self.src[start..self.pos])))
            }
            '"' => {
                self.advance(c);
                let body = start + 1;
                match self.src[body..].find(['"', '\n']) {
                    Some(len) if self.src[body + len..].starts_with('"') => {
                        for ch in self.src[body..=body + len].chars() {
                            self.advance(ch);
                        }
                        Ok(Some(tok(Kind::Str, &self.src[body..body + len])))
                    }
                    _ => Err(ParseError::new(
                        self.path,
                        line,
                        column,
                        "expected a closing `\"` on the same line",
                    )),
                }
            }
            _ => {
                while let Some(ch) = self.src[self.pos..].chars().next() {
                    if ch.is_whitespace() || matches!(ch, '[' | ']' | '"' | '#') {
                        break;
                    }
                    self.advance(ch);
                }
                Ok(Some(tok(Kind::Word, &self.src[start..self.pos])))
            }
        }
    }
}

/// One parameter: `"type name"` and its values.
struct Param<'a> {
    decl: Tok<'a>,
    ty: &'a str,
    name: &'a str,
    values: Vec<Tok<'a>>,
}

struct Parser<'a> {
    lexer: Lexer<'a>,
    peeked: Option<Option<Tok<'a>>>,
}

impl<'a> Parser<'a> {
    fn error(&self, tok: &Tok, message: impl Into<String>) -> ParseError {
        ParseError::new(self.lexer.path, tok.line, tok.column, message)
    }

    fn peek(&mut self) -> Result<Option<Tok<'a>>, ParseError> {
        if self.peeked.is_none() {
            self.peeked = Some(self.lexer.next()?);
        }
        Ok(self.peeked.flatten())
    }

    fn next_opt(&mut self) -> Result<Option<Tok<'a>>, ParseError> {
        match self.peeked.take() {
            Some(t) => Ok(t),
            None => self.lexer.next(),
        }
    }

    fn next(&mut self, what: &str) -> Result<Tok<'a>, ParseError> {
        self.next_opt()?.ok_or_else(|| {
            ParseError::new(
                self.lexer.path,
                self.lexer.line,
                self.lexer.column,
                format!("expected {what}, found end of file"),
            )
        })
    }

    fn number(&mut self, what: &str) -> Result<f64, ParseError> {
        let tok = self.next(what)?;
        finite(self, &tok, what)
    }

    fn vec3(&mut self, directive: &str) -> Result<DVec3, ParseError> {
        let what = format!("three numbers after `{directive}`");
        Ok(DVec3::new(
            self.number(&what)?,
            self.number(&what)?,
            self.number(&what)?,
        ))
    }

    /// 16 numbers, column-major as pbrt-v3 reads them, with or without brackets.
    fn matrix(&mut self, directive: &str) -> Result<DMat4, ParseError> {
        let bracketed = matches!(self.peek()?, Some(t) if t.kind == Kind::Open);
        if bracketed {
            self.next_opt()?;
        }
        let what = format!("16 numbers after `{directive}`");
        let mut m = [0.0; 16];
        for x in &mut m {
            *x = self.number(&what)?;
        }
        if bracketed {
            let close = self.next("`]`")?;
            if close.kind != Kind::Close {
                return Err(self.error(&close, format!("expected `]`, found {}", close.describe())));
            }
        }
        Ok(DMat4::from_cols_array(&m))
    }

    /// The arguments of a directive: strings, numbers and bracketed lists up to the next
    /// directive, grouped into `"type name" value` parameters.
    fn params(&mut self) -> Result<Vec<Param<'a>>, ParseError> {
        let mut params = Vec::new();
        while let Some(tok) = self.peek()? {
            match tok.kind {
                Kind::Word if tok.number().is_none() => break,
                // A one-word string is a positional argument: the type of a camera,
                // material or light (`Camera "perspective"`), or a texture's name.
                Kind::Str if !tok.text.trim().contains(char::is_whitespace) => {
                    self.next_opt()?;
                }
                Kind::Str => {
                    self.next_opt()?;
                    let mut words = tok.text.split_whitespace();
                    let (ty, name) = match (words.next(), words.next(), words.next()) {
                        (Some(ty), Some(name), None) => (ty, name),
                        _ => {
                            return Err(self.error(
                                &tok,
                                format!(
                                    "expected a parameter declaration \"type name\", found {}",
                                    tok.describe()
                                ),
                            ));
                        }
                    };
                    let values = self.values(&tok)?;
                    params.push(Param {
                        decl: tok,
                        ty,
                        name,
                        values,
                    });
                }
                // Positional arguments of directives we do not apply (`LookAt 0 0 5 ...`).
                Kind::Word | Kind::Open => {
                    self.values(&tok)?;
                }
                Kind::Close => {
                    return Err(self.error(&tok, "expected a value or a directive, found `]`"));
                }
            }
        }
        Ok(params)
    }

    /// A parameter's value (after its declaration `decl`): a bracketed list or one bare
    /// value.
    fn values(&mut self, decl: &Tok) -> Result<Vec<Tok<'a>>, ParseError> {
        let what = format!("a value after {}", decl.describe());
        let first = self.next(&what)?;
        match first.kind {
            Kind::Open => {
                let mut values = Vec::new();
                loop {
                    let t = self.next("`]`")?;
                    match t.kind {
                        Kind::Close => return Ok(values),
                        Kind::Open => {
                            return Err(self.error(&t, "expected a value or `]`, found `[`"));
                        }
                        _ => values.push(t),
                    }
                }
            }
            Kind::Close => Err(self.error(&first, format!("expected {what}, found `]`"))),
            _ => Ok(vec![first]),
        }
    }
}

fn finite(p: &Parser, tok: &Tok, what: &str) -> Result<f64, ParseError> {
    match tok.number() {
        Some(x) if x.is_finite() => Ok(x),
        Some(_) => Err(p.error(
            tok,
            format!(
                "expected {what} as a finite number, found {}",
                tok.describe()
            ),
        )),
        None => Err(p.error(tok, format!("expected {what}, found {}", tok.describe()))),
    }
}

/// Finds a parameter by name, checking its type is one of `types`.
fn find<'p, 'a>(
    p: &Parser,
    params: &'p [Param<'a>],
    types: &[&str],
    name: &str,
) -> Result<Option<&'p Param<'a>>, ParseError> {
    match params.iter().find(|q| q.name == name) {
        Some(q) if !types.contains(&q.ty) => Err(p.error(
            &q.decl,
            format!(
                "expected \"{} {name}\", found \"{}\"",
                types[0], q.decl.text
            ),
        )),
        found => Ok(found),
    }
}

/// A parameter's values as finite numbers.
fn numbers(p: &Parser, q: &Param) -> Result<Vec<f64>, ParseError> {
    let what = format!("a number in \"{}\"", q.decl.text);
    q.values.iter().map(|t| finite(p, t, &what)).collect()
}

/// A required single integer parameter, with its token.
fn integer<'a>(
    p: &Parser,
    shape: &Tok,
    params: &[Param<'a>],
    name: &str,
) -> Result<(usize, Tok<'a>), ParseError> {
    let q = find(p, params, &["integer"], name)?.ok_or_else(|| {
        p.error(
            shape,
            format!("expected parameter \"integer {name}\" for Shape \"nurbs\""),
        )
    })?;
    match q.values.as_slice() {
        [t] => match t.text.parse::<usize>() {
            Ok(n) if t.kind == Kind::Word => Ok((n, *t)),
            _ => Err(p.error(
                t,
                format!(
                    "expected a non-negative integer for \"{}\", found {}",
                    q.decl.text,
                    t.describe()
                ),
            )),
        },
        _ => Err(p.error(
            &q.decl,
            format!(
                "expected one value for \"{}\", found {}",
                q.decl.text,
                q.values.len()
            ),
        )),
    }
}

/// The degree from an order parameter (order = degree + 1).
fn degree(p: &Parser, shape: &Tok, params: &[Param], name: &str) -> Result<usize, ParseError> {
    let (order, tok) = integer(p, shape, params, name)?;
    match order.checked_sub(1) {
        Some(d) if (1..=MAX_DEGREE).contains(&d) => Ok(d),
        _ => Err(p.error(
            &tok,
            format!(
                "expected an order from 2 to {} (degree + 1), found `{}`",
                MAX_DEGREE + 1,
                tok.text
            ),
        )),
    }
}

/// A knot vector of `count` non-decreasing values.
fn knots(
    p: &Parser,
    shape: &Tok,
    params: &[Param],
    name: &str,
    count: usize,
) -> Result<Vec<f64>, ParseError> {
    let q = find(p, params, &["float"], name)?.ok_or_else(|| {
        p.error(
            shape,
            format!("expected parameter \"float {name}\" for Shape \"nurbs\""),
        )
    })?;
    let knots = numbers(p, q)?;
    if knots.len() != count {
        return Err(p.error(
            &q.decl,
            format!(
                "expected {count} values in \"{}\" (control points + order), found {}",
                q.decl.text,
                knots.len()
            ),
        ));
    }
    for (k, pair) in knots.windows(2).enumerate() {
        if pair[1] < pair[0] {
            let t = &q.values[k + 1];
            return Err(p.error(
                t,
                format!(
                    "expected knots in non-decreasing order, found `{}` after `{}`",
                    t.text, q.values[k].text
                ),
            ));
        }
    }
    Ok(knots)
}

/// Builds the surface of one `Shape "nurbs"` (in object space).
fn nurbs(p: &Parser, shape: &Tok, params: &[Param]) -> Result<Surface, ParseError> {
    let (nu, _) = integer(p, shape, params, "nu")?;
    let (nv, _) = integer(p, shape, params, "nv")?;
    let du = degree(p, shape, params, "uorder")?;
    let dv = degree(p, shape, params, "vorder")?;
    let knots_u = knots(p, shape, params, "uknots", nu + du + 1)?;
    let knots_v = knots(p, shape, params, "vknots", nv + dv + 1)?;
    for name in ["u0", "u1", "v0", "v1"] {
        if let Some(q) = find(p, params, &["float"], name)? {
            numbers(p, q)?;
        }
    }
    let (q, dims) = match (
        find(p, params, &["point", "point3"], "P")?,
        find(p, params, &["float"], "Pw")?,
    ) {
        (Some(q), _) => (q, 3),
        (None, Some(q)) => (q, 4),
        (None, None) => {
            return Err(p.error(
                shape,
                "expected control points as \"point P\" or \"float Pw\" for Shape \"nurbs\"",
            ));
        }
    };
    let values = numbers(p, q)?;
    if values.len() != dims * nu * nv {
        return Err(p.error(
            &q.decl,
            format!(
                "expected {dims} × nu × nv = {} values in \"{}\", found {}",
                dims * nu * nv,
                q.decl.text,
                values.len()
            ),
        ));
    }
    let mut points = Vec::with_capacity(nu * nv);
    for (k, c) in values.chunks_exact(dims).enumerate() {
        let w = if dims == 4 { c[3] } else { 1.0 };
        if w <= 0.0 {
            let t = &q.values[k * dims + 3];
            return Err(p.error(t, format!("expected a positive weight, found `{}`", t.text)));
        }
        points.push(DVec4::new(c[0], c[1], c[2], w));
    }
    let surface = NurbsSurface::new(du, dv, knots_u, knots_v, nu, nv, points)
        .map_err(|e| p.error(shape, e.to_string()))?;
    Ok(Surface {
        geometry: SurfaceGeometry::Nurbs(surface),
        trims: Vec::new(),
        trim_space: Default::default(),
    })
}
