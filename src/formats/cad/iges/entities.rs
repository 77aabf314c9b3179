//! Typed, validated entities (IGES 5.3 chapter 4; OpenCASCADE's `IGESGeom`): each supported
//! entity type's parameters read into a struct, pointers kept as directory sequence
//! numbers. Parameters are numbered as the standard numbers them: 1 is the first after the
//! entity type.

use std::path::Path;

use glam::{DAffine3, DMat3, DVec2, DVec3};

use super::directory::DirEntry;
use super::records::{Token, Value};
use crate::formats::error::ParseError;

/// One entity's parameters, with what is needed to locate an error in them.
pub struct Params<'a> {
    pub path: &'a Path,
    pub entry: &'a DirEntry,
    pub tokens: Vec<Token>,
}

impl Params<'_> {
    fn error(&self, i: usize, expected: &str) -> ParseError {
        let e = self.entry;
        let (line, column, found) = match self.tokens.get(i) {
            Some(t) if t.written.is_empty() => (t.line, t.column, "an empty field".to_string()),
            Some(t) => (t.line, t.column, format!("`{}`", t.written)),
            None => {
                let last = self.tokens.last();
                (
                    last.map_or(e.line, |t| t.line),
                    last.map_or(1, |t| t.column),
                    "the end of its parameters".to_string(),
                )
            }
        };
        ParseError::new(
            self.path,
            line,
            column,
            format!(
                "parameter {i} of entity {} (D {}): expected {expected}, found {found}",
                e.entity_type, e.sequence
            ),
        )
    }

    fn number(&self, i: usize) -> Option<(f64, bool)> {
        match self.tokens.get(i)?.value {
            Value::Number { value, integer } => Some((value, integer)),
            _ => None,
        }
    }

    /// Parameter `i` as a real (integers are reals too).
    pub fn real(&self, i: usize) -> Result<f64, ParseError> {
        self.number(i)
            .map(|n| n.0)
            .ok_or_else(|| self.error(i, "a real"))
    }

    /// Parameter `i` as a real, `default` where the field is empty or absent.
    pub fn real_or(&self, i: usize, default: f64) -> Result<f64, ParseError> {
        match self.tokens.get(i).map(|t| &t.value) {
            None | Some(Value::Empty) => Ok(default),
            _ => self.real(i),
        }
    }

    /// Parameter `i` as an integer.
    pub fn int(&self, i: usize) -> Result<i64, ParseError> {
        match self.tokens.get(i).map(|t| &t.value) {
            Some(Value::Empty) => Ok(0),
            _ => match self.number(i) {
                Some((v, true)) if v.abs() < 1e15 => Ok(v as i64),
                _ => Err(self.error(i, "an integer")),
            },
        }
    }

    /// Parameter `i` as a count in `0..=limit`.
    pub fn count(&self, i: usize, limit: usize) -> Result<usize, ParseError> {
        let v = self.int(i)?;
        usize::try_from(v)
            .ok()
            .filter(|&n| n <= limit)
            .ok_or_else(|| self.error(i, &format!("a count from 0 to {limit}")))
    }

    /// Parameter `i` as a directory pointer (0 for none). Negative pointers (§2.2.4.4.2,
    /// used by some writers for back pointers) are taken by their magnitude.
    pub fn pointer(&self, i: usize) -> Result<usize, ParseError> {
        Ok(self.int(i)?.unsigned_abs() as usize)
    }

    pub fn point(&self, i: usize) -> Result<DVec3, ParseError> {
        Ok(DVec3::new(
            self.real(i)?,
            self.real(i + 1)?,
            self.real(i + 2)?,
        ))
    }

    fn reals(&self, i: usize, n: usize) -> Result<Vec<f64>, ParseError> {
        (i..i + n).map(|k| self.real(k)).collect()
    }

    /// More than the parameters present cannot be asked for: counts that point past the
    /// end are errors here rather than huge allocations.
    fn need(&self, last: usize) -> Result<(), ParseError> {
        if last >= self.tokens.len() {
            return Err(self.error(self.tokens.len(), "more parameters"));
        }
        Ok(())
    }
}

/// The B-spline curve of entity 126 (§4.23).
#[derive(Clone, Debug, PartialEq)]
pub struct BSplineCurve {
    pub degree: usize,
    pub knots: Vec<f64>,
    pub weights: Vec<f64>,
    pub points: Vec<DVec3>,
    /// The parameter range [V(0), V(1)].
    pub range: [f64; 2],
}

/// The B-spline surface of entity 128 (§4.24): points and weights u index fastest.
#[derive(Clone, Debug, PartialEq)]
pub struct BSplineSurface {
    pub degree: [usize; 2],
    pub counts: [usize; 2],
    pub knots: [Vec<f64>; 2],
    pub weights: Vec<f64>,
    pub points: Vec<DVec3>,
    /// [U(0), U(1), V(0), V(1)].
    pub range: [f64; 4],
}

/// The parametric spline surface of entity 114 (§4.15): bicubic polynomial patches on a
/// grid of breakpoints; patch `i * n_v + j` spans `[u[i], u[i+1]] × [v[j], v[j+1]]`.
#[derive(Clone, Debug, PartialEq)]
pub struct SplineSurface {
    pub u: Vec<f64>,
    pub v: Vec<f64>,
    /// Per patch, per coordinate x, y, z, the 16 coefficients of s^a t^b at `a + 4 b`
    /// (AX, BX, CX, DX, EX, … SX), s and t measured from the patch's lower breakpoints.
    pub patches: Vec<[[f64; 16]; 3]>,
}

/// The shape of an IGES 5.3 analytic surface (190–198, §4.38–4.42).
#[derive(Clone, Debug, PartialEq)]
pub enum Elementary {
    Plane,
    Cylinder {
        radius: f64,
    },
    /// `radius` at the location; the semi-angle as written, in degrees.
    Cone {
        radius: f64,
        semi_angle: f64,
    },
    Sphere {
        radius: f64,
    },
    Torus {
        major: f64,
        minor: f64,
    },
}

/// One model-space curve of a 141 boundary and its parameter-space curves.
#[derive(Clone, Debug, PartialEq)]
pub struct BoundaryCurve {
    pub model: usize,
    /// SENSE 2: the curve runs against the boundary's direction.
    pub reversed: bool,
    pub parameter: Vec<usize>,
}

/// One entry of a 508 loop: an edge of a 504 edge list, or a vertex (then empty).
#[derive(Clone, Debug, PartialEq)]
pub struct LoopEdge {
    /// The 504 and the 1-based index of the edge in it (0, 0 for a vertex entry).
    pub list: usize,
    pub index: usize,
    /// OF 0: the edge runs against its curve's direction in the loop.
    pub reversed: bool,
    /// Its parameter-space curves on the face's surface.
    pub parameter: Vec<usize>,
}

/// The supported entities. Pointers are directory sequence numbers (0 for none).
#[derive(Clone, Debug, PartialEq)]
pub enum Entity {
    /// 100: circular arc in the plane z = `z`, counter-clockwise from `start` to `end`.
    Arc {
        z: f64,
        centre: DVec2,
        start: DVec2,
        end: DVec2,
    },
    /// 102: composite curve.
    Composite(Vec<usize>),
    /// 104: conic arc `A x² + B xy + C y² + D x + E y + F = 0` in the plane z = `z`.
    Conic {
        coefficients: [f64; 6],
        z: f64,
        start: DVec2,
        end: DVec2,
    },
    /// 106 forms 1, 2, 11, 12, 63: points joined in order.
    Copious(Vec<DVec3>),
    /// 110: line segment, t in [0, 1].
    Line { start: DVec3, end: DVec3 },
    /// 112: parametric cubic spline; per segment the coefficients (a, b, c, d) of x, y, z
    /// in s = t − breaks[i].
    Spline {
        breaks: Vec<f64>,
        coefficients: Vec<[[f64; 4]; 3]>,
    },
    /// 124: transformation matrix.
    Transform(DAffine3),
    /// 126.
    BSplineCurve(BSplineCurve),
    /// 128.
    BSplineSurface(BSplineSurface),
    /// 108: the plane A x + B y + C z = D, bounded by a curve (form 1) or not.
    Plane {
        coefficients: [f64; 4],
        boundary: usize,
    },
    /// 118: ruled surface between two curves; `reversed` joins the first curve's start
    /// to the second's end; `form` 0 (equal arc length) or 1 (equal parameter).
    Ruled {
        curves: [usize; 2],
        reversed: bool,
        form: i32,
    },
    /// 120: surface of revolution of `generatrix` about the 110 `axis`.
    Revolution {
        axis: usize,
        generatrix: usize,
        angles: [f64; 2],
    },
    /// 140: the surface `base` moved by `distance` along its unit normal.
    Offset { base: usize, distance: f64 },
    /// 122: tabulated cylinder of `directrix` to the generatrix end point.
    Tabulated { directrix: usize, end: DVec3 },
    /// 114: parametric spline surface.
    SplineSurface(SplineSurface),
    /// 116: point.
    Point(DVec3),
    /// 123: direction.
    Direction(DVec3),
    /// 190–198: the analytic surface `shape` placed by the 116 `location` (centre), the
    /// 123 `axis` (normal; 0 where form 0 of a sphere gives none) and, for form 1
    /// (parameterised), the 123 `reference` direction (else 0).
    Elementary {
        shape: Elementary,
        location: usize,
        axis: usize,
        reference: usize,
    },
    /// 141: boundary on `surface`; `model_preferred` is PREF 1 (model-space curves
    /// preferred); TYPE 0 boundaries carry no parameter-space curves.
    Boundary {
        surface: usize,
        model_preferred: bool,
        curves: Vec<BoundaryCurve>,
    },
    /// 143: bounded surface: `surface` cut by the 141 `boundaries`.
    Bounded {
        surface: usize,
        boundaries: Vec<usize>,
    },
    /// 186: manifold solid B-rep object: its outer shell and void shells (514s).
    Brep { shells: Vec<usize> },
    /// 308: subfigure definition: its member entities.
    Subfigure(Vec<usize>),
    /// 408: singular subfigure instance of the 308 `definition`, translated and scaled.
    Instance {
        definition: usize,
        translation: DVec3,
        scale: f64,
    },
    /// 504: edge list: the model-space curve of each edge (its vertices are not needed:
    /// the curves run between them).
    Edges(Vec<usize>),
    /// 508: loop of edges.
    Loop(Vec<LoopEdge>),
    /// 510: face of `surface` bounded by its 508 `loops`; `outer_first`: OF 1, the first
    /// loop is the outer one.
    Face {
        surface: usize,
        outer_first: bool,
        loops: Vec<usize>,
    },
    /// 514: shell: its 510 faces.
    Shell(Vec<usize>),
    /// 142: curve on a parametric surface.
    CurveOnSurface {
        surface: usize,
        parameter_curve: usize,
        model_curve: usize,
        preferred: i64,
    },
    /// 144: trimmed surface; `outer` none when the domain boundary is the outer boundary.
    Trimmed {
        surface: usize,
        outer: Option<usize>,
        holes: Vec<usize>,
    },
    /// 314: colour, RGB in percent.
    Colour(DVec3),
    /// Any other type: counted, not read.
    Unsupported,
}

/// Whether an entity type is read at all.
pub fn is_supported(entity_type: i32) -> bool {
    matches!(
        entity_type,
        100 | 102
            | 104
            | 106
            | 108
            | 110
            | 112
            | 114
            | 116
            | 118
            | 120
            | 122
            | 123
            | 124
            | 126
            | 128
            | 140
            | 141
            | 142
            | 143
            | 144
            | 186
            | 190
            | 192
            | 194
            | 196
            | 198
            | 308
            | 314
            | 408
            | 504
            | 508
            | 510
            | 514
    )
}

/// A sane upper bound on counts read from a file (control points per direction, segments,
/// pieces), so a corrupt count is an error, not an allocation failure.
const MAX_COUNT: usize = 1 << 24;

/// Reads the parameters of a supported entity type.
pub fn read(p: &Params<'_>) -> Result<Entity, ParseError> {
    let form = p.entry.form;
    Ok(match p.entry.entity_type {
        100 => Entity::Arc {
            z: p.real(1)?,
            centre: DVec2::new(p.real(2)?, p.real(3)?),
            start: DVec2::new(p.real(4)?, p.real(5)?),
            end: DVec2::new(p.real(6)?, p.real(7)?),
        },
        102 => {
            let n = p.count(1, MAX_COUNT)?;
            p.need(1 + n)?;
            Entity::Composite((2..2 + n).map(|i| p.pointer(i)).collect::<Result<_, _>>()?)
        }
        104 => Entity::Conic {
            coefficients: p.reals(1, 6)?.try_into().expect("six reals"),
            z: p.real(7)?,
            start: DVec2::new(p.real(8)?, p.real(9)?),
            end: DVec2::new(p.real(10)?, p.real(11)?),
        },
        106 => {
            let ip = p.int(1)?;
            let n = p.count(2, MAX_COUNT)?;
            let points = match ip {
                1 => {
                    let z = p.real(3)?;
                    p.need(3 + 2 * n)?;
                    (0..n)
                        .map(|k| Ok(DVec3::new(p.real(4 + 2 * k)?, p.real(5 + 2 * k)?, z)))
                        .collect::<Result<_, ParseError>>()?
                }
                2 | 3 => {
                    let stride = if ip == 2 { 3 } else { 6 };
                    p.need(2 + stride * n)?;
                    (0..n)
                        .map(|k| p.point(3 + stride * k))
                        .collect::<Result<_, _>>()?
                }
                _ => return Err(p.error(1, "the interpretation flag 1, 2 or 3")),
            };
            Entity::Copious(points)
        }
        108 => Entity::Plane {
            coefficients: p.reals(1, 4)?.try_into().expect("four reals"),
            boundary: if form == 0 { 0 } else { p.pointer(5)? },
        },
        110 => Entity::Line {
            start: p.point(1)?,
            end: p.point(4)?,
        },
        112 => {
            let n = p.count(4, MAX_COUNT)?;
            p.need(4 + (n + 1) + 12 * n)?;
            let breaks = p.reals(5, n + 1)?;
            let base = 6 + n;
            let coefficients = (0..n)
                .map(|k| {
                    let c = p.reals(base + 12 * k, 12)?;
                    Ok([0, 1, 2].map(|d| [c[4 * d], c[4 * d + 1], c[4 * d + 2], c[4 * d + 3]]))
                })
                .collect::<Result<_, ParseError>>()?;
            Entity::Spline {
                breaks,
                coefficients,
            }
        }
        114 => {
            let (m, n) = (p.count(3, MAX_COUNT)?, p.count(4, MAX_COUNT)?);
            m.checked_mul(n)
                .filter(|&c| (1..=MAX_COUNT).contains(&c))
                .ok_or_else(|| p.error(3, "from 1 to 2^24 patches"))?;
            let (u_at, v_at) = (5, 6 + m);
            // After each row of n patches, and after the last row, the standard stores
            // 48 arbitrary values per patch position (one more patch per row, one more
            // row); they carry nothing and are skipped, and may be missing at the end.
            let patch_at = |i: usize, j: usize| 7 + m + n + 48 * (i * (n + 1) + j);
            p.need(patch_at(m - 1, n - 1) + 47)?;
            let patches = (0..m)
                .flat_map(|i| (0..n).map(move |j| (i, j)))
                .map(|(i, j)| {
                    let c = p.reals(patch_at(i, j), 48)?;
                    Ok([0, 1, 2].map(|d| {
                        let mut k = [0.0; 16];
                        k.copy_from_slice(&c[16 * d..16 * d + 16]);
                        k
                    }))
                })
                .collect::<Result<_, ParseError>>()?;
            Entity::SplineSurface(SplineSurface {
                u: p.reals(u_at, m + 1)?,
                v: p.reals(v_at, n + 1)?,
                patches,
            })
        }
        116 => Entity::Point(p.point(1)?),
        123 => Entity::Direction(p.point(1)?),
        118 => Entity::Ruled {
            curves: [p.pointer(1)?, p.pointer(2)?],
            reversed: p.int(3)? == 1,
            form,
        },
        120 => Entity::Revolution {
            axis: p.pointer(1)?,
            generatrix: p.pointer(2)?,
            angles: [p.real(3)?, p.real(4)?],
        },
        // Parameters 1-3 are the offset indicator, a normal at one point that the
        // distance's sign already fixes; OpenCASCADE reads only D and the surface too.
        140 => Entity::Offset {
            distance: p.real(4)?,
            base: p.pointer(5)?,
        },
        122 => Entity::Tabulated {
            directrix: p.pointer(1)?,
            end: p.point(2)?,
        },
        124 => {
            let r = p.reals(1, 12)?;
            let m = DMat3::from_cols(
                DVec3::new(r[0], r[4], r[8]),
                DVec3::new(r[1], r[5], r[9]),
                DVec3::new(r[2], r[6], r[10]),
            );
            Entity::Transform(DAffine3::from_mat3_translation(
                m,
                DVec3::new(r[3], r[7], r[11]),
            ))
        }
        126 => {
            let k = p.count(1, MAX_COUNT)?;
            let m = p.count(2, crate::geom::MAX_DEGREE)?;
            let n = k + 1;
            let knots_at = 7;
            let weights_at = knots_at + n + m + 1;
            let points_at = weights_at + n;
            p.need(points_at + 3 * n + 1)?;
            Entity::BSplineCurve(BSplineCurve {
                degree: m,
                knots: p.reals(knots_at, n + m + 1)?,
                weights: p.reals(weights_at, n)?,
                points: (0..n)
                    .map(|i| p.point(points_at + 3 * i))
                    .collect::<Result<_, _>>()?,
                range: [p.real(points_at + 3 * n)?, p.real(points_at + 3 * n + 1)?],
            })
        }
        128 => {
            let (k1, k2) = (p.count(1, MAX_COUNT)?, p.count(2, MAX_COUNT)?);
            let (m1, m2) = (
                p.count(3, crate::geom::MAX_DEGREE)?,
                p.count(4, crate::geom::MAX_DEGREE)?,
            );
            let (n1, n2) = (k1 + 1, k2 + 1);
            let total = n1
                .checked_mul(n2)
                .filter(|&t| t <= MAX_COUNT)
                .ok_or_else(|| p.error(1, "a control net of at most 2^24 points"))?;
            let knots_u_at = 10;
            let knots_v_at = knots_u_at + n1 + m1 + 1;
            let weights_at = knots_v_at + n2 + m2 + 1;
            let points_at = weights_at + total;
            let range_at = points_at + 3 * total;
            p.need(range_at + 3)?;
            Entity::BSplineSurface(BSplineSurface {
                degree: [m1, m2],
                counts: [n1, n2],
                knots: [
                    p.reals(knots_u_at, n1 + m1 + 1)?,
                    p.reals(knots_v_at, n2 + m2 + 1)?,
                ],
                weights: p.reals(weights_at, total)?,
                points: (0..total)
                    .map(|i| p.point(points_at + 3 * i))
                    .collect::<Result<_, _>>()?,
                range: [
                    p.real(range_at)?,
                    p.real(range_at + 1)?,
                    p.real(range_at + 2)?,
                    p.real(range_at + 3)?,
                ],
            })
        }
        141 => {
            let n = p.count(4, MAX_COUNT)?;
            let mut curves = Vec::with_capacity(n.min(1024));
            let mut at = 5;
            for _ in 0..n {
                let k = p.count(at + 2, MAX_COUNT)?;
                p.need(at + 2 + k)?;
                curves.push(BoundaryCurve {
                    model: p.pointer(at)?,
                    reversed: p.int(at + 1)? == 2,
                    parameter: (at + 3..at + 3 + k)
                        .map(|i| p.pointer(i))
                        .collect::<Result<_, _>>()?,
                });
                at += 3 + k;
            }
            Entity::Boundary {
                surface: p.pointer(3)?,
                model_preferred: p.int(2)? == 1,
                curves,
            }
        }
        143 => {
            let n = p.count(3, MAX_COUNT)?;
            p.need(3 + n)?;
            Entity::Bounded {
                surface: p.pointer(2)?,
                boundaries: (4..4 + n).map(|i| p.pointer(i)).collect::<Result<_, _>>()?,
            }
        }
        142 => Entity::CurveOnSurface {
            surface: p.pointer(2)?,
            parameter_curve: p.pointer(3)?,
            model_curve: p.pointer(4)?,
            preferred: p.int(5)?,
        },
        144 => {
            let n1 = p.int(2)?;
            let n2 = p.count(3, MAX_COUNT)?;
            p.need(4 + n2)?;
            let outer = p.pointer(4)?;
            Entity::Trimmed {
                surface: p.pointer(1)?,
                outer: (n1 != 0 && outer != 0).then_some(outer),
                holes: (5..5 + n2)
                    .map(|i| p.pointer(i))
                    .collect::<Result<_, _>>()?,
            }
        }
        190 => Entity::Elementary {
            shape: Elementary::Plane,
            location: p.pointer(1)?,
            axis: p.pointer(2)?,
            reference: if form == 1 { p.pointer(3)? } else { 0 },
        },
        192 => Entity::Elementary {
            shape: Elementary::Cylinder { radius: p.real(3)? },
            location: p.pointer(1)?,
            axis: p.pointer(2)?,
            reference: if form == 1 { p.pointer(4)? } else { 0 },
        },
        194 => Entity::Elementary {
            shape: Elementary::Cone {
                radius: p.real(3)?,
                semi_angle: p.real(4)?,
            },
            location: p.pointer(1)?,
            axis: p.pointer(2)?,
            reference: if form == 1 { p.pointer(5)? } else { 0 },
        },
        196 => Entity::Elementary {
            shape: Elementary::Sphere { radius: p.real(2)? },
            location: p.pointer(1)?,
            axis: if form == 1 { p.pointer(3)? } else { 0 },
            reference: if form == 1 { p.pointer(4)? } else { 0 },
        },
        198 => Entity::Elementary {
            shape: Elementary::Torus {
                major: p.real(3)?,
                minor: p.real(4)?,
            },
            location: p.pointer(1)?,
            axis: p.pointer(2)?,
            reference: if form == 1 { p.pointer(5)? } else { 0 },
        },
        186 => {
            // SHELL, SOF, N, then N × (VOID, VOF); orientation flags do not matter to
            // the even–odd trims of each face.
            let n = p.count(3, MAX_COUNT)?;
            p.need(3 + 2 * n)?;
            let mut shells = vec![p.pointer(1)?];
            for k in 0..n {
                shells.push(p.pointer(4 + 2 * k)?);
            }
            Entity::Brep { shells }
        }
        308 => {
            // DEPTH, NAME, N, then N pointers.
            let n = p.count(3, MAX_COUNT)?;
            p.need(3 + n)?;
            Entity::Subfigure((4..4 + n).map(|i| p.pointer(i)).collect::<Result<_, _>>()?)
        }
        408 => Entity::Instance {
            definition: p.pointer(1)?,
            translation: DVec3::new(p.real_or(2, 0.0)?, p.real_or(3, 0.0)?, p.real_or(4, 0.0)?),
            scale: p.real_or(5, 1.0)?,
        },
        504 => {
            // N, then N × (CURV, SVP, SV, TVP, TV).
            let n = p.count(1, MAX_COUNT)?;
            p.need(1 + 5 * n)?;
            Entity::Edges(
                (0..n)
                    .map(|k| p.pointer(2 + 5 * k))
                    .collect::<Result<_, _>>()?,
            )
        }
        508 => {
            // N, then per entry TYPE, EDGE, NDX, OF, K and K × (ISOP, CURV).
            let n = p.count(1, MAX_COUNT)?;
            let mut edges = Vec::with_capacity(n.min(1024));
            let mut at = 2;
            for _ in 0..n {
                let k = p.count(at + 4, MAX_COUNT)?;
                p.need(at + 4 + 2 * k)?;
                let vertex = p.int(at)? == 1;
                edges.push(LoopEdge {
                    list: if vertex { 0 } else { p.pointer(at + 1)? },
                    index: if vertex {
                        0
                    } else {
                        p.count(at + 2, MAX_COUNT)?
                    },
                    reversed: p.int(at + 3)? == 0,
                    parameter: (0..k)
                        .map(|j| p.pointer(at + 6 + 2 * j))
                        .collect::<Result<_, _>>()?,
                });
                at += 5 + 2 * k;
            }
            Entity::Loop(edges)
        }
        510 => {
            let n = p.count(2, MAX_COUNT)?;
            p.need(3 + n)?;
            Entity::Face {
                surface: p.pointer(1)?,
                outer_first: p.int(3)? == 1,
                loops: (4..4 + n).map(|i| p.pointer(i)).collect::<Result<_, _>>()?,
            }
        }
        514 => {
            let n = p.count(1, MAX_COUNT)?;
            p.need(1 + 2 * n)?;
            Entity::Shell(
                (0..n)
                    .map(|k| p.pointer(2 + 2 * k))
                    .collect::<Result<_, _>>()?,
            )
        }
        314 => Entity::Colour(DVec3::new(p.real(1)?, p.real(2)?, p.real(3)?)),
        _ => Entity::Unsupported,
    })
}
