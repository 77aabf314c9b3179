//! The OBJ free-form reader.
//!
//! Read: `v x y z [w]`, `vp u [v [w]]`, `cstype [rat] bezier|bspline`, `deg du [dv]`,
//! `surf s0 s1 t0 t1 v...`, `curv2 vp...`, `parm u|v ...`, `trim`/`hole t0 t1 curv2d ...`
//! and `end`. Indices are 1-based, or negative to count back from the last vertex (or
//! `curv2`) defined so far; `v/vt/vn` index forms use their `v` part. A backslash at the
//! end of a line continues the statement on the next line.
//!
//! The `s0 s1 t0 t1` range of `surf` restricts the surface exactly (knot insertion): a
//! range reaching past the parameter domain, as rounding in exporters writes it, is taken
//! within the domain. Read and ignored: 3D curves (`curv`), special curves and points
//! (`scrv`, `sp`), and every polygon, grouping, display and render statement.
//!
//! A piecewise Bézier `surf` (more control points than one patch needs, with `parm`
//! breakpoints) is split into its patches in span order, u spans fastest; each patch's
//! domain maps its [0,1]² onto its span of the global parameters, and each carries the
//! surface's trim loops (which are in global parameters).

use std::path::Path;

use glam::{DVec3, DVec4};

use crate::formats::error::ParseError;
use crate::formats::text::{Token, Words, logical_lines};
use crate::geom::MAX_DEGREE;
use crate::geom::bezier::{BezierPatch, ParamRect};
use crate::geom::nurbs::NurbsSurface;
use crate::geom::trim::{ParamCurve, TrimLoop, TrimSegment};
use crate::scene::model::{Surface, SurfaceGeometry};

/// Parses the free-form surfaces of an OBJ text; `path` is used in error messages only.
pub fn parse_obj_freeform(path: &Path, src: &str) -> Result<Vec<Surface>, ParseError> {
    let (lines, eof) = logical_lines(src);
    let mut reader = Reader {
        path,
        vertices: Vec::new(),
        params: Vec::new(),
        curves: Vec::new(),
        cstype: None,
        degree: None,
        block: None,
        surfaces: Vec::new(),
    };
    for line in &lines {
        reader.statement(&mut Words::new(path, line))?;
    }
    if let Some(block) = &reader.block {
        return Err(ParseError::new(
            path,
            eof.0,
            eof.1,
            format!(
                "expected `end` to close the `{}` from line {}, found end of file",
                block.keyword.text, block.keyword.line
            ),
        ));
    }
    Ok(reader.surfaces)
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Basis {
    Bezier,
    BSpline,
}

#[derive(Clone, Copy, Debug)]
struct CsType {
    basis: Basis,
    rational: bool,
}

/// A geometric (`v`) or parameter (`vp`) vertex as written: its coordinates, how many
/// were given, and its weight with the weight's token (for errors about bad weights,
/// which only matter once a rational element uses the vertex).
#[derive(Clone, Copy)]
struct Vertex<'a> {
    coords: DVec3,
    dims: usize,
    weight: f64,
    weight_tok: Option<Token<'a>>,
}

#[derive(Clone, Copy, PartialEq)]
enum ElementKind {
    Surface,
    Curve2,
    /// A 3D curve (`curv`): its block is read for syntax and dropped.
    Ignored,
}

/// `parm u|v` values with their tokens.
struct Parm<'a> {
    keyword: Token<'a>,
    values: Vec<(f64, Token<'a>)>,
}

/// An element from its statement to its `end`, with the state it was opened under.
struct Block<'a> {
    keyword: Token<'a>,
    kind: ElementKind,
    cstype: CsType,
    degree: (usize, usize),
    /// 0-based vertex indices (into `v` for surfaces, `vp` for curves) with their tokens.
    indices: Vec<(usize, Token<'a>)>,
    parm_u: Option<Parm<'a>>,
    parm_v: Option<Parm<'a>>,
    trims: Vec<TrimLoop>,
    /// The `surf s0 s1 t0 t1` range.
    range: ParamRect,
}

struct Reader<'a, 'p> {
    path: &'p Path,
    vertices: Vec<Vertex<'a>>,
    params: Vec<Vertex<'a>>,
    curves: Vec<ParamCurve>,
    cstype: Option<(CsType, Token<'a>)>,
    degree: Option<(usize, Option<usize>)>,
    block: Option<Block<'a>>,
    surfaces: Vec<Surface>,
}

impl<'a> Reader<'a, '_> {
    fn error(&self, tok: &Token, message: impl Into<String>) -> ParseError {
        ParseError::new(self.path, tok.line, tok.column, message)
    }

    fn statement(&mut self, w: &mut Words<'_, 'a>) -> Result<(), ParseError> {
        let keyword = w.next("a statement")?;
        match keyword.text {
            "v" => {
                let v = vertex(w, &["x coordinate", "y coordinate", "z coordinate"], 3)?;
                self.vertices.push(v);
            }
            "vp" => {
                let v = vertex(w, &["u parameter", "v parameter"], 1)?;
                self.params.push(v);
            }
            "cstype" => self.cstype = Some((cstype(w)?, keyword)),
            "deg" => {
                let du = degree(w, "the u degree")?;
                let dv = match w.next_opt() {
                    Some(tok) => Some(degree_value(w, &tok)?),
                    None => None,
                };
                w.expect_end()?;
                self.degree = Some((du, dv));
            }
            "surf" | "curv2" | "curv" => self.open_block(keyword, w)?,
            "parm" => self.parm(keyword, w)?,
            "trim" | "hole" => self.trim(keyword, w)?,
            "end" => {
                w.expect_end()?;
                let block = self.block.take().ok_or_else(|| {
                    self.error(
                        &keyword,
                        "expected a `surf`, `curv2` or `curv` statement before `end`",
                    )
                })?;
                self.close_block(block, &keyword)?;
            }
            // Special curves and points, and every non-free-form statement: skipped.
            _ => {}
        }
        Ok(())
    }

    fn open_block(&mut self, keyword: Token<'a>, w: &mut Words<'_, 'a>) -> Result<(), ParseError> {
        if let Some(open) = &self.block {
            return Err(self.error(
                &keyword,
                format!(
                    "expected `end` to close the `{}` from line {}, found `{}`",
                    open.keyword.text, open.keyword.line, keyword.text
                ),
            ));
        }
        let kind = match keyword.text {
            "surf" => ElementKind::Surface,
            "curv2" => ElementKind::Curve2,
            _ => ElementKind::Ignored,
        };
        if kind == ElementKind::Ignored {
            w.rest();
            self.block = Some(Block {
                keyword,
                kind,
                cstype: CsType {
                    basis: Basis::Bezier,
                    rational: false,
                },
                degree: (1, 1),
                indices: Vec::new(),
                parm_u: None,
                parm_v: None,
                trims: Vec::new(),
                range: ParamRect::UNIT,
            });
            return Ok(());
        }
        let (cstype, _) = self.cstype.ok_or_else(|| {
            self.error(
                &keyword,
                format!("expected `cstype` before `{}`", keyword.text),
            )
        })?;
        let (du, dv) = self.degree.ok_or_else(|| {
            self.error(
                &keyword,
                format!("expected `deg` before `{}`", keyword.text),
            )
        })?;
        let degree = match (kind, dv) {
            (ElementKind::Surface, Some(dv)) => (du, dv),
            (ElementKind::Surface, None) => {
                return Err(self.error(
                    &keyword,
                    "expected two degrees (`deg du dv`) before `surf`, found one",
                ));
            }
            _ => (du, 0),
        };
        let mut range = ParamRect::UNIT;
        let (what, count) = if kind == ElementKind::Surface {
            let mut r = [0.0; 4];
            for (x, what) in r.iter_mut().zip(["s0", "s1", "t0", "t1"]) {
                *x = w.finite(&format!("the parameter range value {what}"))?;
            }
            range = ParamRect {
                u0: r[0],
                u1: r[1],
                v0: r[2],
                v1: r[3],
            };
            ("vertex", self.vertices.len())
        } else {
            ("parameter vertex", self.params.len())
        };
        let mut indices = Vec::new();
        for tok in w.rest() {
            indices.push((resolve_index(self.path, tok, count, what)?, *tok));
        }
        if indices.is_empty() {
            return Err(w.error_at_end(format!(
                "expected {what} indices of the control points, found end of line"
            )));
        }
        self.block = Some(Block {
            keyword,
            kind,
            cstype,
            degree,
            indices,
            parm_u: None,
            parm_v: None,
            trims: Vec::new(),
            range,
        });
        Ok(())
    }

    fn parm(&mut self, keyword: Token<'a>, w: &mut Words<'_, 'a>) -> Result<(), ParseError> {
        let Some(block) = &mut self.block else {
            return Err(self.error(
                &keyword,
                "expected a `surf`, `curv2` or `curv` statement before `parm`",
            ));
        };
        let dir = w.next("`u` or `v`")?;
        let slot = match (dir.text, block.kind) {
            ("u", _) => &mut block.parm_u,
            ("v", ElementKind::Surface | ElementKind::Ignored) => &mut block.parm_v,
            _ => {
                let expected = if block.kind == ElementKind::Curve2 {
                    "`u` (a curve has one parameter)"
                } else {
                    "`u` or `v`"
                };
                return Err(w.error_at(&dir, format!("expected {expected}, found `{}`", dir.text)));
            }
        };
        let mut values: Vec<(f64, Token<'a>)> = Vec::new();
        while let Some((x, tok)) = w.finite_opt("a parameter value")? {
            if let Some((_, prev_tok)) = values.last().filter(|(prev, _)| x < *prev) {
                return Err(w.error_at(
                    &tok,
                    format!(
                        "expected parameter values in non-decreasing order, found `{}` after `{}`",
                        tok.text, prev_tok.text
                    ),
                ));
            }
            values.push((x, tok));
        }
        if values.is_empty() {
            return Err(w.error_at_end("expected parameter values, found end of line"));
        }
        *slot = Some(Parm { keyword, values });
        Ok(())
    }

    fn trim(&mut self, keyword: Token<'a>, w: &mut Words<'_, 'a>) -> Result<(), ParseError> {
        if !matches!(&self.block, Some(b) if b.kind == ElementKind::Surface) {
            return Err(self.error(
                &keyword,
                format!("expected a `surf` statement before `{}`", keyword.text),
            ));
        }
        let mut segments = Vec::new();
        loop {
            let t0 = match w.finite_opt("the start parameter t0 of a trimming curve")? {
                Some((t0, _)) => t0,
                None if segments.is_empty() => {
                    return Err(w.error_at_end("expected `t0 t1 curv2d`, found end of line"));
                }
                None => break,
            };
            let t1 = w.finite("the end parameter t1 of a trimming curve")?;
            let tok = w.next("a `curv2` index")?;
            let index = resolve_index(self.path, &tok, self.curves.len(), "curv2")?;
            segments.push(TrimSegment {
                t0,
                t1,
                curve: self.curves[index].clone(),
            });
        }
        if let Some(block) = &mut self.block {
            block.trims.push(TrimLoop {
                hole: keyword.text == "hole",
                segments,
            });
        }
        Ok(())
    }

    fn close_block(&mut self, block: Block<'a>, end: &Token) -> Result<(), ParseError> {
        match block.kind {
            ElementKind::Ignored => {}
            ElementKind::Curve2 => {
                let curve = self.curve2(&block, end)?;
                self.curves.push(curve);
            }
            ElementKind::Surface => {
                let surfaces = self.surface(block, end)?;
                self.surfaces.extend(surfaces);
            }
        }
        Ok(())
    }

    /// The `parm` of a block, or an error at `end` saying it is missing.
    fn require_parm<'b>(
        &self,
        parm: &'b Option<Parm<'a>>,
        dir: &str,
        block: &Block,
        end: &Token,
    ) -> Result<&'b Parm<'a>, ParseError> {
        parm.as_ref().ok_or_else(|| {
            self.error(
                end,
                format!(
                    "expected `parm {dir}` for the `{}` from line {} before `end`",
                    block.keyword.text, block.keyword.line
                ),
            )
        })
    }

    /// Homogeneous premultiplied control point `(w x, w y, w z, w)` of a vertex used by
    /// an element; non-rational elements ignore the weight.
    fn homogeneous(&self, v: &Vertex, rational: bool) -> Result<DVec4, ParseError> {
        if !rational {
            return Ok(v.coords.extend(1.0));
        }
        if let Some(tok) = v.weight_tok.filter(|_| v.weight <= 0.0) {
            return Err(self.error(
                &tok,
                format!("expected a positive weight, found `{}`", tok.text),
            ));
        }
        Ok((v.coords * v.weight).extend(v.weight))
    }

    fn curve2(&self, block: &Block, end: &Token) -> Result<ParamCurve, ParseError> {
        let degree = block.degree.0;
        let parm = self.require_parm(&block.parm_u, "u", block, end)?;
        let mut points = Vec::with_capacity(block.indices.len());
        for (i, tok) in &block.indices {
            let v = &self.params[*i];
            if v.dims < 2 {
                return Err(self.error(
                    tok,
                    format!(
                        "expected a parameter vertex with u and v, `vp` {} has only u",
                        i + 1
                    ),
                ));
            }
            let h = self.homogeneous(v, block.cstype.rational)?;
            points.push(DVec3::new(h.x, h.y, h.w));
        }
        let knots = match block.cstype.basis {
            Basis::BSpline => {
                let knots: Vec<f64> = parm.values.iter().map(|v| v.0).collect();
                let expected = points.len() + degree + 1;
                if knots.len() != expected {
                    return Err(self.error(
                        &parm.keyword,
                        format!(
                            "expected {expected} values in `parm u` ({} control points + degree {degree} + 1), found {}",
                            points.len(),
                            knots.len()
                        ),
                    ));
                }
                knots
            }
            Basis::Bezier => {
                let breaks = self.breakpoints(parm)?;
                let expected = (breaks.len() - 1) * degree + 1;
                if points.len() != expected {
                    return Err(self.error(
                        &block.keyword,
                        format!(
                            "expected {expected} control points for {} Bézier piece(s) of degree {degree}, found {}",
                            breaks.len() - 1,
                            points.len()
                        ),
                    ));
                }
                crate::geom::nurbs::knots::bezier_knots(&breaks, degree)
            }
        };
        Ok(ParamCurve {
            degree,
            knots,
            points,
        })
    }

    /// Bézier breakpoints: at least two, strictly increasing.
    fn breakpoints(&self, parm: &Parm) -> Result<Vec<f64>, ParseError> {
        if parm.values.len() < 2 {
            return Err(self.error(
                &parm.keyword,
                format!(
                    "expected at least 2 breakpoints in `parm`, found {}",
                    parm.values.len()
                ),
            ));
        }
        for pair in parm.values.windows(2) {
            if pair[1].0 <= pair[0].0 {
                return Err(self.error(
                    &pair[1].1,
                    format!(
                        "expected Bézier breakpoints in increasing order, found `{}` after `{}`",
                        pair[1].1.text, pair[0].1.text
                    ),
                ));
            }
        }
        Ok(parm.values.iter().map(|v| v.0).collect())
    }

    /// A B-spline knot vector: enough knots for the degree and a non-empty domain.
    fn knots(&self, parm: &Parm, dir: &str, degree: usize) -> Result<Vec<f64>, ParseError> {
        let knots: Vec<f64> = parm.values.iter().map(|v| v.0).collect();
        let min = 2 * (degree + 1);
        if knots.len() < min {
            return Err(self.error(
                &parm.keyword,
                format!(
                    "expected at least {min} values in `parm {dir}` for degree {degree}, found {}",
                    knots.len()
                ),
            ));
        }
        let count = knots.len() - degree - 1;
        if knots[degree] >= knots[count] {
            return Err(self.error(
                &parm.keyword,
                format!("expected `parm {dir}` to span a non-empty parameter range"),
            ));
        }
        Ok(knots)
    }

    /// The block's `surf` range within `domain`: exporters write ranges a rounding past the
    /// domain's ends, so the range is clipped to the domain; a range that misses it is an
    /// error.
    fn range_within(&self, block: &Block, domain: ParamRect) -> Result<ParamRect, ParseError> {
        let r = block.range;
        let clipped = ParamRect {
            u0: r.u0.max(domain.u0),
            u1: r.u1.min(domain.u1),
            v0: r.v0.max(domain.v0),
            v1: r.v1.min(domain.v1),
        };
        if clipped.u0 < clipped.u1 && clipped.v0 < clipped.v1 {
            Ok(clipped)
        } else {
            Err(self.error(
                &block.keyword,
                format!(
                    "expected the range `s0 s1 t0 t1` to overlap the parameter domain [{}, {}] × [{}, {}], found {} {} {} {}",
                    domain.u0, domain.u1, domain.v0, domain.v1, r.u0, r.u1, r.v0, r.v1
                ),
            ))
        }
    }

    fn surface(&self, block: Block, end: &Token) -> Result<Vec<Surface>, ParseError> {
        let (du, dv) = block.degree;
        let parm_u = self.require_parm(&block.parm_u, "u", &block, end)?;
        let parm_v = self.require_parm(&block.parm_v, "v", &block, end)?;
        let count_error = |cu: usize, cv: usize, source: &str| {
            self.error(
                &block.keyword,
                format!(
                    "expected {cu} × {cv} = {} control points (from `deg` and {source}), found {}",
                    cu * cv,
                    block.indices.len()
                ),
            )
        };
        let mut points = Vec::with_capacity(block.indices.len());
        for (i, _) in &block.indices {
            points.push(self.homogeneous(&self.vertices[*i], block.cstype.rational)?);
        }
        let geometry_error = |e: crate::geom::GeomError| self.error(&block.keyword, e.to_string());
        match block.cstype.basis {
            Basis::BSpline => {
                let knots_u = self.knots(parm_u, "u", du)?;
                let knots_v = self.knots(parm_v, "v", dv)?;
                let (cu, cv) = (knots_u.len() - du - 1, knots_v.len() - dv - 1);
                if points.len() != cu * cv {
                    return Err(count_error(
                        cu,
                        cv,
                        "the knot counts of `parm u` and `parm v`",
                    ));
                }
                let nurbs = NurbsSurface::new(du, dv, knots_u, knots_v, cu, cv, points)
                    .map_err(geometry_error)?;
                let domain = nurbs.domain();
                let range = self.range_within(&block, domain)?;
                let nurbs = if range == domain {
                    nurbs
                } else {
                    nurbs.restricted(range)
                };
                Ok(vec![Surface {
                    geometry: SurfaceGeometry::Nurbs(nurbs),
                    trims: block.trims,
                    trim_space: Default::default(),
                }])
            }
            Basis::Bezier => {
                let breaks_u = self.breakpoints(parm_u)?;
                let breaks_v = self.breakpoints(parm_v)?;
                let (su, sv) = (breaks_u.len() - 1, breaks_v.len() - 1);
                let (cu, cv) = (su * du + 1, sv * dv + 1);
                if points.len() != cu * cv {
                    return Err(count_error(
                        cu,
                        cv,
                        "the breakpoints of `parm u` and `parm v`",
                    ));
                }
                let range = self.range_within(
                    &block,
                    ParamRect {
                        u0: breaks_u[0],
                        u1: breaks_u[su],
                        v0: breaks_v[0],
                        v1: breaks_v[sv],
                    },
                )?;
                let mut surfaces = Vec::with_capacity(su * sv);
                for j in 0..sv {
                    for i in 0..su {
                        let patch_points = (0..=dv)
                            .flat_map(|b| (0..=du).map(move |a| (j * dv + b) * cu + i * du + a))
                            .map(|k| points[k])
                            .collect();
                        let patch = BezierPatch::new(du, dv, patch_points)
                            .map_err(geometry_error)?
                            .with_domain(ParamRect {
                                u0: breaks_u[i],
                                u1: breaks_u[i + 1],
                                v0: breaks_v[j],
                                v1: breaks_v[j + 1],
                            });
                        let Some(patch) = restricted_patch(patch, range) else {
                            continue;
                        };
                        surfaces.push(Surface {
                            geometry: SurfaceGeometry::Bezier(patch),
                            trims: block.trims.clone(),
                            trim_space: Default::default(),
                        });
                    }
                }
                Ok(surfaces)
            }
        }
    }
}

/// `patch` (with its domain) restricted to `range`: `None` where they do not overlap in an
/// area, the patch itself where `range` covers it, else the sub-patch over the overlap
/// (as a NURBS surface on the patch's domain restricted exactly, A5.1).
fn restricted_patch(patch: BezierPatch, range: ParamRect) -> Option<BezierPatch> {
    let d = patch.domain();
    let overlap = ParamRect {
        u0: d.u0.max(range.u0),
        u1: d.u1.min(range.u1),
        v0: d.v0.max(range.v0),
        v1: d.v1.min(range.v1),
    };
    if overlap.u0 >= overlap.u1 || overlap.v0 >= overlap.v1 {
        return None;
    }
    if overlap == d {
        return Some(patch);
    }
    let (du, dv) = (patch.degree_u(), patch.degree_v());
    let knots = |a: f64, b: f64, p: usize| {
        let mut k = vec![a; p + 1];
        k.extend(std::iter::repeat_n(b, p + 1));
        k
    };
    let nurbs = NurbsSurface::new(
        du,
        dv,
        knots(d.u0, d.u1, du),
        knots(d.v0, d.v1, dv),
        du + 1,
        dv + 1,
        patch.homogeneous_points().to_vec(),
    )
    .ok()?;
    nurbs
        .restricted(overlap)
        .to_bezier_patches()
        .into_iter()
        .next()
}

/// `v x y z [w]` or `vp u [v [w]]`: the coordinates named in `names`, the first
/// `required` of which must be given; a weight may follow a full set of coordinates.
fn vertex<'a>(
    w: &mut Words<'_, 'a>,
    names: &[&str],
    required: usize,
) -> Result<Vertex<'a>, ParseError> {
    let mut coords = [0.0; 3];
    let mut given = 0;
    for (k, name) in names.iter().enumerate() {
        if k < required {
            coords[k] = w.finite(name)?;
        } else {
            match w.finite_opt(name)? {
                Some((x, _)) => coords[k] = x,
                None => break,
            }
        }
        given = k + 1;
    }
    let (weight, weight_tok) = match given == names.len() {
        true => match w.finite_opt("weight")? {
            Some((x, tok)) => (x, Some(tok)),
            None => (1.0, None),
        },
        false => (1.0, None),
    };
    w.expect_end()?;
    Ok(Vertex {
        coords: DVec3::from_array(coords),
        dims: given,
        weight,
        weight_tok,
    })
}

fn cstype(w: &mut Words) -> Result<CsType, ParseError> {
    let mut tok = w.next("a curve/surface type")?;
    let rational = tok.text == "rat";
    if rational {
        tok = w.next("a curve/surface type after `rat`")?;
    }
    let basis = match tok.text {
        "bezier" => Basis::Bezier,
        "bspline" => Basis::BSpline,
        "bmatrix" | "cardinal" | "taylor" => {
            return Err(w.error_at(
                &tok,
                format!(
                    "unsupported curve/surface type `{}`: expected `bezier` or `bspline`",
                    tok.text
                ),
            ));
        }
        _ => {
            return Err(w.error_at(
                &tok,
                format!("expected `bezier` or `bspline`, found `{}`", tok.text),
            ));
        }
    };
    w.expect_end()?;
    Ok(CsType { basis, rational })
}

fn degree(w: &mut Words, what: &str) -> Result<usize, ParseError> {
    let tok = w.next(what)?;
    degree_value(w, &tok)
}

fn degree_value(w: &Words, tok: &Token) -> Result<usize, ParseError> {
    match tok.text.parse::<usize>() {
        Ok(d) if (1..=MAX_DEGREE).contains(&d) => Ok(d),
        _ => Err(w.error_at(
            tok,
            format!(
                "expected a degree from 1 to {MAX_DEGREE}, found `{}`",
                tok.text
            ),
        )),
    }
}

/// A 1-based or negative (relative) index into `count` items, as a 0-based index. In
/// `v/vt/vn` forms only the first part is used.
fn resolve_index(path: &Path, tok: &Token, count: usize, what: &str) -> Result<usize, ParseError> {
    let error = |message: String| ParseError::new(path, tok.line, tok.column, message);
    let text = tok.text.split('/').next().unwrap_or("");
    let n: i64 = text
        .parse()
        .map_err(|_| error(format!("expected a {what} index, found `{}`", tok.text)))?;
    let resolved = if n > 0 {
        usize::try_from(n - 1).ok().filter(|&i| i < count)
    } else if n < 0 {
        usize::try_from(n.unsigned_abs())
            .ok()
            .and_then(|back| count.checked_sub(back))
    } else {
        return Err(error(format!(
            "expected a {what} index (1-based, or negative to count back), found `0`"
        )));
    };
    resolved.ok_or_else(|| {
        error(match count {
            0 => format!(
                "dangling {what} index `{}`: no {what} is defined before this line",
                tok.text
            ),
            _ => format!(
                "dangling {what} index `{}`: expected 1 to {count} or -{count} to -1 ({count} defined so far)",
                tok.text
            ),
        })
    })
}
