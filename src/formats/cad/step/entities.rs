//! Typed, validated STEP entities (ISO 10303-42 geometry and topology, the AP203/AP214/
//! AP242 subset a B-rep needs), read from the exchange structure by following references
//! (OpenCASCADE's StepGeom/StepShape layer). Every accessor checks the parameter's kind and
//! count and names the instance in its error (`#12 CIRCLE: expected a positive radius`);
//! reference chains are bounded so a cyclic file cannot recurse forever.

use std::cell::{Cell, RefCell};
use std::collections::HashMap;
use std::path::Path;
use std::sync::Arc;

use glam::{DVec3, DVec4};

use super::records::{Exchange, Instance, Param, Record, Value};
use crate::formats::error::ParseError;
pub use crate::geom::nurbs::analytic::Frame;
use crate::geom::nurbs::{NurbsCurve, NurbsSurface};

/// Longest chain of references followed while resolving one entity. Real B-reps are about
/// ten deep (face → loop → edge → curve → placement → direction); a cycle in a damaged
/// file reaches the bound and is reported instead of overflowing the stack.
const MAX_DEPTH: usize = 200;

/// Curves (ISO 10303-42 §4.4.?): parameterisations as the standard defines them, so that
/// pcurve and trimming parameters mean what the file means. 2D curves (in pcurves) have
/// z = 0.
#[derive(Clone, Debug, PartialEq)]
pub enum Curve {
    /// `origin + t · direction` (the direction keeps the vector's magnitude).
    Line { origin: DVec3, direction: DVec3 },
    /// `centre + r (cos t x + sin t y)`, t in radians.
    Circle { frame: Frame, radius: f64 },
    /// `centre + a cos t x + b sin t y`.
    Ellipse { frame: Frame, a: f64, b: f64 },
    /// B_SPLINE_CURVE_WITH_KNOTS, BEZIER_CURVE and their rational forms, as read.
    BSpline(NurbsCurve),
    /// The basis curve between two parameters (already in radians for conics);
    /// `sense` false runs it backwards.
    Trimmed {
        basis: Arc<Curve>,
        t0: f64,
        t1: f64,
        sense: bool,
    },
    /// SURFACE_CURVE / SEAM_CURVE: the 3D curve and its pcurves (a seam has two on the
    /// same surface).
    OnSurface {
        curve: Arc<Curve>,
        pcurves: Vec<PCurve>,
    },
}

/// A curve in the parameter space of a surface (PCURVE through its
/// DEFINITIONAL_REPRESENTATION).
#[derive(Clone, Debug, PartialEq)]
pub struct PCurve {
    pub surface: u64,
    pub curve: Arc<Curve>,
}

/// Surfaces with the parameterisations of ISO 10303-42 §4.4.?; angles in radians.
#[derive(Clone, Debug, PartialEq)]
pub enum SurfaceDef {
    /// `origin + u x + v y`.
    Plane(Frame),
    /// `origin + r (cos u x + sin u y) + v z`.
    Cylinder { frame: Frame, radius: f64 },
    /// `origin + (r + v tan α)(cos u x + sin u y) + v z`.
    Cone {
        frame: Frame,
        radius: f64,
        semi_angle: f64,
    },
    /// `origin + r cos v (cos u x + sin u y) + r sin v z`.
    Sphere { frame: Frame, radius: f64 },
    /// `origin + (R + r cos v)(cos u x + sin u y) + r sin v z`.
    Torus {
        frame: Frame,
        major: f64,
        minor: f64,
    },
    /// The profile rotated by u about the axis through `origin` along unit `axis`;
    /// v is the profile's parameter.
    Revolution {
        profile: Arc<Curve>,
        origin: DVec3,
        axis: DVec3,
    },
    /// `profile(u) + v · direction`.
    Extrusion {
        profile: Arc<Curve>,
        direction: DVec3,
    },
    /// B_SPLINE_SURFACE_WITH_KNOTS, BEZIER_SURFACE and their rational forms, as read.
    BSpline(NurbsSurface),
}

/// A resolved ADVANCED_FACE (or FACE_SURFACE).
#[derive(Clone, Debug)]
pub struct Face {
    pub id: u64,
    pub surface_id: u64,
    pub surface: Arc<SurfaceDef>,
    pub same_sense: bool,
    pub bounds: Vec<Bound>,
}

/// FACE_OUTER_BOUND / FACE_BOUND over an EDGE_LOOP (or a VERTEX_LOOP, a degenerate bound
/// at a cone apex or sphere pole, kept as an empty edge list).
#[derive(Clone, Debug)]
pub struct Bound {
    pub id: u64,
    pub outer: bool,
    pub orientation: bool,
    pub edges: Vec<OrientedEdge>,
    /// The point of a VERTEX_LOOP.
    pub vertex: Option<DVec3>,
}

#[derive(Clone, Debug)]
pub struct OrientedEdge {
    /// False: the loop traverses the edge from its end vertex to its start.
    pub orientation: bool,
    pub edge: Arc<Edge>,
}

/// EDGE_CURVE: from `start` to `end` along `curve` (against it when `same_sense` is false).
#[derive(Clone, Debug)]
pub struct Edge {
    pub id: u64,
    pub start: DVec3,
    pub end: DVec3,
    /// The two vertices are one VERTEX_POINT: a closed edge (a full circle).
    pub closed: bool,
    pub curve: Arc<Curve>,
    pub same_sense: bool,
}

/// Reads typed entities from an exchange structure, caching shared ones.
pub struct Resolver<'e, 'a> {
    pub ex: &'e Exchange<'a>,
    pub path: &'e Path,
    /// Radians per unit of plane angle in the file (1, or π/180 for degrees).
    pub angle_unit: f64,
    depth: Cell<usize>,
    curves: RefCell<HashMap<u64, Arc<Curve>>>,
    surfaces: RefCell<HashMap<u64, Arc<SurfaceDef>>>,
    edges: RefCell<HashMap<u64, Arc<Edge>>>,
    /// The type of the last valid but unsupported entity met (an OFFSET_SURFACE under a
    /// face), which makes its face skipped rather than the file refused.
    unsupported: RefCell<Option<String>>,
}

/// One record of one instance, with accessors that check kinds and locate errors.
#[derive(Clone, Copy)]
pub struct Rec<'r, 'a> {
    pub path: &'r Path,
    pub inst: &'r Instance<'a>,
    pub rec: &'r Record<'a>,
}

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

/// Premultiplied homogeneous points `(w x, w y, w z, w)`.
fn homogeneous(points: &[DVec3], weights: &[f64]) -> Vec<DVec4> {
    points
        .iter()
        .zip(weights)
        .map(|(p, &w)| (*p * w).extend(w))
        .collect()
}

/// Expands B-spline knots given as distinct values and multiplicities.
fn expand_knots(r: &Rec, mult: &Param, knots: &Param) -> Result<Vec<f64>, ParseError> {
    let m = r.list_of(mult, "knot multiplicities")?;
    let k = r.numbers(knots, "knots")?;
    if m.len() != k.len() {
        return Err(r.error_at(
            mult.line,
            mult.column,
            format!(
                "expected as many knot multiplicities as knots, found {} and {}",
                m.len(),
                k.len()
            ),
        ));
    }
    let mut out = Vec::new();
    for (p, &t) in m.iter().zip(&k) {
        let times = r.integer(p, "a knot multiplicity")?;
        if !(1..=64).contains(&times) {
            return Err(r.error_at(
                p.line,
                p.column,
                format!("expected a knot multiplicity in 1..=64, found {times}"),
            ));
        }
        out.extend(std::iter::repeat_n(t, times as usize));
    }
    Ok(out)
}

/// Cosine of the largest angle between a LINE and the chord of its edge's vertices for
/// which a line off its vertices is taken as displaced (cos 4.5e-5 rad): directions
/// written to four or five digits are that far from the true one.
const PARALLEL_COS: f64 = 1.0 - 1e-9;

/// An edge's LINE moved to pass through the edge's vertices when it runs parallel to
/// them but beside them, as OpenCASCADE's reader does (StepToTopoDS_TranslateEdge: some
/// ECAD writers place an edge's line away from its true position with the right
/// direction). Any other curve, or a line through its vertices, is returned unchanged.
fn line_through_vertices(curve: Arc<Curve>, start: DVec3, end: DVec3) -> Arc<Curve> {
    let shifted = |c: &Curve| -> Option<Curve> {
        let Curve::Line { origin, direction } = c else {
            return None;
        };
        let d = direction.try_normalize()?;
        let chord = end - start;
        let off = {
            let r = start - *origin;
            r - r.dot(d) * d
        };
        let parallel = chord.dot(d).abs() >= PARALLEL_COS * chord.length();
        (parallel && off != DVec3::ZERO && chord != DVec3::ZERO).then(|| Curve::Line {
            origin: *origin + off,
            direction: *direction,
        })
    };
    match &*curve {
        Curve::OnSurface { curve: c3, pcurves } => match shifted(c3) {
            Some(line) => Arc::new(Curve::OnSurface {
                curve: Arc::new(line),
                pcurves: pcurves.clone(),
            }),
            None => curve,
        },
        c => shifted(c).map_or(curve, Arc::new),
    }
}

/// OFFSET_SURFACE (ISO 10303-42 §4.4.x: the basis moved by `d` along its unit normal
/// S_u × S_v) of an elementary surface, exactly, as the elementary surface it is: a plane
/// moved along its axis, a cylinder, sphere or torus tube of radius r + d, a cone of
/// radius r + d / cos α about the same frame (its points lie d sin α lower on the axis
/// than the basis parameter's, so its pcurves, if any, are checked and projected
/// again). `None` for other bases, or where the offset passes the axis (a radius ≤ 0).
fn offset_exactly(basis: &SurfaceDef, d: f64) -> Option<SurfaceDef> {
    let positive = |r: f64| (r > 0.0 && r.is_finite()).then_some(r);
    Some(match basis {
        SurfaceDef::Plane(f) => SurfaceDef::Plane(Frame {
            origin: f.origin + d * f.z,
            ..*f
        }),
        SurfaceDef::Cylinder { frame, radius } => SurfaceDef::Cylinder {
            frame: *frame,
            radius: positive(radius + d)?,
        },
        SurfaceDef::Sphere { frame, radius } => SurfaceDef::Sphere {
            frame: *frame,
            radius: positive(radius + d)?,
        },
        SurfaceDef::Torus {
            frame,
            major,
            minor,
        } => SurfaceDef::Torus {
            frame: *frame,
            major: *major,
            minor: positive(minor + d)?,
        },
        SurfaceDef::Cone {
            frame,
            radius,
            semi_angle,
        } => SurfaceDef::Cone {
            frame: *frame,
            // An apex (radius 0) is a cone still.
            radius: Some(radius + d / semi_angle.cos()).filter(|r| *r >= 0.0)?,
            semi_angle: *semi_angle,
        },
        _ => return None,
    })
}

/// The curve entities whose knots are implied, in [`ImpliedKnots`] order.
const CURVE_FORMS: [&str; 3] = ["BEZIER_CURVE", "UNIFORM_CURVE", "QUASI_UNIFORM_CURVE"];
/// The surface entities whose knots are implied, in [`ImpliedKnots`] order.
const SURFACE_FORMS: [&str; 3] = ["BEZIER_SURFACE", "UNIFORM_SURFACE", "QUASI_UNIFORM_SURFACE"];

/// B-spline forms whose knots are implied rather than listed (ISO 10303-42 §4.3.4:
/// bezier_curve, uniform_curve, quasi_uniform_curve and their surface counterparts).
#[derive(Clone, Copy, Debug, PartialEq)]
enum ImpliedKnots {
    Bezier,
    Uniform,
    QuasiUniform,
}

impl ImpliedKnots {
    /// The form an instance declares by one of its records (the simple entity's name or a
    /// partial record of a complex instance), if any; `names` are the entity names of
    /// the three forms, [`CURVE_FORMS`] or [`SURFACE_FORMS`].
    fn of(inst: &Instance, names: [&str; 3]) -> Option<ImpliedKnots> {
        let forms = [
            ImpliedKnots::Bezier,
            ImpliedKnots::Uniform,
            ImpliedKnots::QuasiUniform,
        ];
        names
            .iter()
            .zip(forms)
            .find(|(name, _)| inst.record(name).is_some())
            .map(|(_, k)| k)
    }

    /// The knots for `count` control points of degree `degree`; `None` when the count
    /// does not fit the form (a Bézier needs a multiple of the degree plus one).
    /// - bezier: 0 and the last breakpoint repeated `degree + 1` times, the integers
    ///   between `degree` times (a piecewise Bézier);
    /// - uniform: −degree, −degree + 1, …, count (every knot simple), so the domain is
    ///   [0, count − degree];
    /// - quasi-uniform: 0 and count − degree repeated `degree + 1` times, the integers
    ///   between once (clamped ends, uniform inside).
    fn knots(self, degree: usize, count: usize) -> Option<Vec<f64>> {
        if degree == 0 || count < degree + 1 {
            return None;
        }
        match self {
            ImpliedKnots::Bezier => {
                if !(count - 1).is_multiple_of(degree) {
                    return None;
                }
                let pieces = (count - 1) / degree;
                let mut k = vec![0.0; degree + 1];
                for s in 1..pieces {
                    k.extend(std::iter::repeat_n(s as f64, degree));
                }
                k.extend(std::iter::repeat_n(pieces as f64, degree + 1));
                Some(k)
            }
            ImpliedKnots::Uniform => Some(
                (0..count + degree + 1)
                    .map(|i| i as f64 - degree as f64)
                    .collect(),
            ),
            ImpliedKnots::QuasiUniform => {
                let last = (count - degree) as f64;
                let mut k = vec![0.0; degree + 1];
                k.extend((1..count - degree).map(|i| i as f64));
                k.extend(std::iter::repeat_n(last, degree + 1));
                Some(k)
            }
        }
    }
}

impl<'e, 'a> Resolver<'e, 'a> {
    pub fn new(ex: &'e Exchange<'a>, path: &'e Path) -> Self {
        Resolver {
            ex,
            path,
            angle_unit: 1.0,
            depth: Cell::new(0),
            curves: RefCell::default(),
            surfaces: RefCell::default(),
            edges: RefCell::default(),
            unsupported: RefCell::default(),
        }
    }

    /// Takes the type of the unsupported entity met since the last call, if any.
    pub fn take_unsupported(&self) -> Option<String> {
        self.unsupported.borrow_mut().take()
    }

    pub(super) fn unsupported(&self, r: &Rec, what: &str) -> ParseError {
        *self.unsupported.borrow_mut() = Some(r.inst.type_name().into_owned());
        r.error(format!("expected {what}"))
    }

    /// The instance `id`, referenced from parameter `p` of `from`.
    pub fn instance(&self, from: &Rec, id: u64) -> Result<&'e Instance<'a>, ParseError> {
        self.ex.get(id).ok_or_else(|| {
            from.error(format!(
                "references #{id}, which is not defined in the file"
            ))
        })
    }

    /// The record `name` of `inst` (its only record for a simple instance).
    pub fn rec<'r>(&'r self, inst: &'r Instance<'a>) -> Rec<'r, 'a> {
        Rec {
            path: self.path,
            inst,
            rec: &inst.records[0],
        }
    }

    pub fn named<'r>(&'r self, inst: &'r Instance<'a>, name: &str) -> Option<Rec<'r, 'a>> {
        inst.record(name).map(|rec| Rec {
            path: self.path,
            inst,
            rec,
        })
    }

    /// Runs `f` one reference level deeper, failing past [`MAX_DEPTH`].
    pub(super) fn deeper<T>(
        &self,
        from: &Rec,
        f: impl FnOnce() -> Result<T, ParseError>,
    ) -> Result<T, ParseError> {
        let d = self.depth.get();
        if d >= MAX_DEPTH {
            return Err(from.error(format!(
                "references nest deeper than {MAX_DEPTH} (a reference cycle?)"
            )));
        }
        self.depth.set(d + 1);
        let out = f();
        self.depth.set(d);
        out
    }

    /// Follows parameter `i` of `from` to an instance that must be one of `types`.
    pub(super) fn follow<'r>(
        &'r self,
        from: &Rec,
        i: usize,
        types: &[&str],
    ) -> Result<Rec<'r, 'a>, ParseError> {
        let what = types.join(" or ");
        let id = from.reference(i, &what)?;
        self.expect_type(from, id, types, i)
    }

    pub(super) fn expect_type<'r>(
        &'r self,
        from: &Rec,
        id: u64,
        types: &[&str],
        i: usize,
    ) -> Result<Rec<'r, 'a>, ParseError> {
        let inst = self.instance(from, id)?;
        for t in types {
            if let Some(r) = self.named(inst, t) {
                return Ok(r);
            }
        }
        let p = &from.rec.params[i.min(from.rec.params.len().saturating_sub(1))];
        Err(from.error_at(
            p.line,
            p.column,
            format!(
                "expected a reference to {}, found #{id} {}",
                types.join(" or "),
                inst.type_name()
            ),
        ))
    }

    /// CARTESIAN_POINT (2D points get z = 0).
    pub fn point(&self, from: &Rec, i: usize) -> Result<DVec3, ParseError> {
        let r = self.follow(from, i, &["CARTESIAN_POINT"])?;
        self.coordinates(&r, 1, "coordinates")
    }

    fn coordinates(&self, r: &Rec, i: usize, what: &str) -> Result<DVec3, ParseError> {
        let p = r.param(i, what)?;
        let c = r.numbers(p, what)?;
        match c[..] {
            [x, y] => Ok(DVec3::new(x, y, 0.0)),
            [x, y, z] => Ok(DVec3::new(x, y, z)),
            _ => Err(r.error_at(
                p.line,
                p.column,
                format!("expected 2 or 3 {what}, found {}", c.len()),
            )),
        }
    }

    /// DIRECTION, normalised; a zero direction is an error.
    pub fn direction(&self, from: &Rec, i: usize) -> Result<DVec3, ParseError> {
        let r = self.follow(from, i, &["DIRECTION"])?;
        let d = self.coordinates(&r, 1, "direction ratios")?;
        let n = d.normalize_or_zero();
        if n == DVec3::ZERO || !n.is_finite() {
            return Err(r.error("expected a non-zero direction"));
        }
        Ok(n)
    }

    /// AXIS2_PLACEMENT_3D (location, axis, ref_direction; the last two optional) or
    /// AXIS2_PLACEMENT_2D (location, ref_direction).
    pub fn frame(&self, from: &Rec, i: usize) -> Result<Frame, ParseError> {
        let r = self.follow(from, i, &["AXIS2_PLACEMENT_3D", "AXIS2_PLACEMENT_2D"])?;
        self.deeper(&r, || self.frame_of(&r))
    }

    pub fn frame_of(&self, r: &Rec) -> Result<Frame, ParseError> {
        let origin = self.point(r, 1)?;
        let optional_dir = |i: usize| -> Result<Option<DVec3>, ParseError> {
            match r.rec.params.get(i).map(|p| &p.value) {
                None | Some(Value::Unset) => Ok(None),
                _ => self.direction(r, i).map(Some),
            }
        };
        let (z, x_hint) = if r.rec.name == "AXIS2_PLACEMENT_2D" {
            (Some(DVec3::Z), optional_dir(2)?)
        } else {
            (optional_dir(2)?, optional_dir(3)?)
        };
        // ISO 10303-42 build_axes: a default axis is z, a default or parallel
        // ref_direction falls back to a world axis.
        Frame::new(origin, z.unwrap_or(DVec3::Z), x_hint).map_err(|e| r.error(e.to_string()))
    }

    /// Any supported curve (3D or, in a pcurve, 2D).
    pub fn curve(&self, from: &Rec, i: usize) -> Result<Arc<Curve>, ParseError> {
        let id = from.reference(i, "a curve")?;
        self.curve_by_id(from, id)
    }

    pub fn curve_by_id(&self, from: &Rec, id: u64) -> Result<Arc<Curve>, ParseError> {
        self.cached(&self.curves, from, id, |inst| self.read_curve(inst))
    }

    /// Entity `id` from `cache`, or read by `read` one level deeper and kept.
    fn cached<T>(
        &self,
        cache: &RefCell<HashMap<u64, Arc<T>>>,
        from: &Rec,
        id: u64,
        read: impl FnOnce(&'e Instance<'a>) -> Result<T, ParseError>,
    ) -> Result<Arc<T>, ParseError> {
        if let Some(c) = cache.borrow().get(&id) {
            return Ok(c.clone());
        }
        let inst = self.instance(from, id)?;
        let c = Arc::new(self.deeper(from, || read(inst))?);
        cache.borrow_mut().insert(id, c.clone());
        Ok(c)
    }

    fn read_curve(&self, inst: &'e Instance<'a>) -> Result<Curve, ParseError> {
        if let Some(r) = self.named(inst, "B_SPLINE_CURVE_WITH_KNOTS") {
            return self.bspline_curve(inst, &r).map(Curve::BSpline);
        }
        if ImpliedKnots::of(inst, CURVE_FORMS).is_some() {
            return self
                .bspline_curve(inst, &self.rec(inst))
                .map(Curve::BSpline);
        }
        // A complex instance (BOUNDED_CURVE() CURVE() … SURFACE_CURVE(…), as Alias and
        // AutoCAD write the curves bounding a CURVE_BOUNDED_SURFACE) is read by the record
        // that defines its curve.
        let r = ["SURFACE_CURVE", "SEAM_CURVE", "BOUNDED_SURFACE_CURVE"]
            .iter()
            .find_map(|n| self.named(inst, n))
            .unwrap_or_else(|| self.rec(inst));
        match r.rec.name {
            "LINE" => {
                let origin = self.point(&r, 1)?;
                let v = self.follow(&r, 2, &["VECTOR"])?;
                let dir = self.direction(&v, 1)?;
                let magnitude = v.positive(2, "a magnitude")?;
                Ok(Curve::Line {
                    origin,
                    direction: dir * magnitude,
                })
            }
            "CIRCLE" => Ok(Curve::Circle {
                frame: self.frame(&r, 1)?,
                radius: r.positive(2, "a radius")?,
            }),
            "ELLIPSE" => Ok(Curve::Ellipse {
                frame: self.frame(&r, 1)?,
                a: r.positive(2, "semi_axis_1")?,
                b: r.positive(3, "semi_axis_2")?,
            }),
            "TRIMMED_CURVE" => self.trimmed_curve(&r),
            "SURFACE_CURVE" | "SEAM_CURVE" | "BOUNDED_SURFACE_CURVE" => {
                // (name, curve_3d, associated_geometry, master_representation); in a
                // complex instance the name belongs to REPRESENTATION_ITEM's record.
                let off = usize::from(!inst.complex);
                let curve = self.curve(&r, off)?;
                let mut pcurves = Vec::new();
                for p in r.list(off + 1, "associated geometry (pcurves)")? {
                    let id = r.reference_of(p, "a PCURVE")?;
                    let pc = self.instance(&r, id)?;
                    if pc.record("PCURVE").is_some() {
                        // A pcurve of a kind we do not read is dropped: the edge is then
                        // projected instead.
                        match self.deeper(&r, || self.pcurve(pc)) {
                            Ok(p) => pcurves.push(p),
                            Err(_) if self.take_unsupported().is_some() => {}
                            Err(e) => return Err(e),
                        }
                    }
                }
                Ok(Curve::OnSurface { curve, pcurves })
            }
            _ => Err(self.unsupported(&r, "a supported curve (LINE, CIRCLE, ELLIPSE, B_SPLINE_CURVE_WITH_KNOTS, BEZIER_CURVE, UNIFORM_CURVE, QUASI_UNIFORM_CURVE, TRIMMED_CURVE, SURFACE_CURVE, SEAM_CURVE)")),
        }
    }

    fn pcurve(&self, inst: &'e Instance<'a>) -> Result<PCurve, ParseError> {
        let r = self.rec(inst);
        let surface = r.reference(1, "the basis surface")?;
        let rep = self.follow(&r, 2, &["DEFINITIONAL_REPRESENTATION"])?;
        // As a complex instance (AutoCAD: DEFINITIONAL_REPRESENTATION() REPRESENTATION(…)
        // SHAPE_REPRESENTATION()) the items are REPRESENTATION's.
        let rep = self
            .named(rep.inst, "REPRESENTATION")
            .filter(|x| x.rec.params.len() >= 2)
            .unwrap_or(rep);
        let items = rep.references(1, "representation items")?;
        let first = items
            .first()
            .ok_or_else(|| rep.error("expected one curve in the representation's items"))?;
        let curve = self.deeper(&rep, || self.curve_by_id(&rep, *first))?;
        Ok(PCurve { surface, curve })
    }

    /// TRIMMED_CURVE(name, basis, trim_1, trim_2, sense, preference): trims given as a
    /// PARAMETER_VALUE are used (angles scaled to radians for conics); trims given only
    /// as points are located on the basis by the converter.
    fn trimmed_curve(&self, r: &Rec) -> Result<Curve, ParseError> {
        let basis = self.curve(r, 1)?;
        let conic = matches!(*basis, Curve::Circle { .. } | Curve::Ellipse { .. });
        let scale = if conic { self.angle_unit } else { 1.0 };
        let trim = |i: usize| -> Result<f64, ParseError> {
            let p = r.param(i, "a trim select")?;
            for item in r.list_of(p, "trim selects")? {
                if let Value::Typed("PARAMETER_VALUE", inner) = &item.value {
                    return Ok(r.number(inner, "a parameter value")? * scale);
                }
            }
            *self.unsupported.borrow_mut() = Some("TRIMMED_CURVE trimmed by points".into());
            Err(r.error_at(
                p.line,
                p.column,
                "expected a PARAMETER_VALUE among the trim selects (trims by point alone are not supported)",
            ))
        };
        Ok(Curve::Trimmed {
            basis,
            t0: trim(2)?,
            t1: trim(3)?,
            sense: r.boolean(4, "sense_agreement")?,
        })
    }

    /// Weights of a rational complex instance (`RATIONAL_B_SPLINE_CURVE((w…))` or the
    /// surface form, a list of lists), if present.
    fn weights<'r>(&'r self, inst: &'r Instance<'a>, name: &str) -> Option<Rec<'r, 'a>> {
        self.named(inst, name)
    }

    /// B_SPLINE_CURVE(name, degree, points, form, closed, self_intersect) with the knots
    /// of B_SPLINE_CURVE_WITH_KNOTS (multiplicities, knots, spec) or implied by
    /// BEZIER_CURVE, weights from RATIONAL_B_SPLINE_CURVE. In a complex instance the
    /// B_SPLINE_CURVE record carries the attributes without the name.
    fn bspline_curve(&self, inst: &'e Instance<'a>, r: &Rec) -> Result<NurbsCurve, ParseError> {
        let (base, off) = match self.named(inst, "B_SPLINE_CURVE") {
            Some(b) => (b, 0),
            None => (*r, 1),
        };
        let degree_p = base.param(off, "the degree")?;
        let degree = base.integer(degree_p, "the degree")?;
        if !(1..=crate::geom::MAX_DEGREE as i64).contains(&degree) {
            return Err(base.error_at(
                degree_p.line,
                degree_p.column,
                format!(
                    "expected a degree in 1..={}, found {degree}",
                    crate::geom::MAX_DEGREE
                ),
            ));
        }
        let degree = degree as usize;
        let ids = base.references(off + 1, "control points")?;
        let points = ids
            .iter()
            .map(|&id| {
                let p = self.expect_type(&base, id, &["CARTESIAN_POINT"], off + 1)?;
                self.coordinates(&p, 1, "coordinates")
            })
            .collect::<Result<Vec<_>, _>>()?;
        let knots = if let Some(form) = ImpliedKnots::of(inst, CURVE_FORMS) {
            form.knots(degree, points.len()).ok_or_else(|| {
                base.error(match form {
                    ImpliedKnots::Bezier => format!(
                        "expected a multiple of {degree} plus one control points for a Bézier curve of degree {degree}, found {}",
                        points.len()
                    ),
                    _ => format!(
                        "expected at least {} control points for degree {degree}, found {}",
                        degree + 1,
                        points.len()
                    ),
                })
            })?
        } else {
            let (kr, koff) = match self.named(inst, "B_SPLINE_CURVE_WITH_KNOTS") {
                Some(k) if inst.complex => (k, 0),
                Some(k) => (k, 6),
                None => return Err(base.error("expected knots")),
            };
            expand_knots(
                &kr,
                kr.param(koff, "knot multiplicities")?,
                kr.param(koff + 1, "knots")?,
            )?
        };
        let weights = match self.weights(inst, "RATIONAL_B_SPLINE_CURVE") {
            Some(w) => {
                let p = w.param(0, "weights")?;
                let ws = w.numbers(p, "weights")?;
                if ws.len() != points.len() {
                    return Err(w.error_at(
                        p.line,
                        p.column,
                        format!("expected {} weights, found {}", points.len(), ws.len()),
                    ));
                }
                ws
            }
            None => vec![1.0; points.len()],
        };
        crate::geom::nurbs::knots::validate(degree, &knots, points.len())
            .map_err(|e| base.error(e.to_string()))?;
        if let Some(k) = weights
            .iter()
            .position(|w| w.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater))
        {
            return Err(base.error(format!(
                "weight {k} is {}; weights must be positive",
                weights[k]
            )));
        }
        Ok(NurbsCurve {
            degree,
            knots,
            points: homogeneous(&points, &weights),
        })
    }

    /// Any supported surface, cached by id (faces share their surfaces with pcurves).
    pub fn surface_by_id(&self, from: &Rec, id: u64) -> Result<Arc<SurfaceDef>, ParseError> {
        self.cached(&self.surfaces, from, id, |inst| self.read_surface(inst))
    }

    fn read_surface(&self, inst: &'e Instance<'a>) -> Result<SurfaceDef, ParseError> {
        if inst.record("B_SPLINE_SURFACE_WITH_KNOTS").is_some()
            || ImpliedKnots::of(inst, SURFACE_FORMS).is_some()
        {
            return self.bspline_surface(inst).map(SurfaceDef::BSpline);
        }
        let r = self.rec(inst);
        match r.rec.name {
            "PLANE" => Ok(SurfaceDef::Plane(self.frame(&r, 1)?)),
            "CYLINDRICAL_SURFACE" => Ok(SurfaceDef::Cylinder {
                frame: self.frame(&r, 1)?,
                radius: r.positive(2, "a radius")?,
            }),
            "CONICAL_SURFACE" => {
                let semi_angle = r.real(3, "a semi-angle")? * self.angle_unit;
                if semi_angle.is_nan() || semi_angle.abs() >= std::f64::consts::FRAC_PI_2 {
                    return Err(r.error(format!(
                        "expected a semi-angle below 90°, found {} rad",
                        semi_angle
                    )));
                }
                let radius = r.real(2, "a radius")?;
                if radius < 0.0 {
                    return Err(r.error(format!("expected a radius >= 0, found {radius}")));
                }
                Ok(SurfaceDef::Cone {
                    frame: self.frame(&r, 1)?,
                    radius,
                    semi_angle,
                })
            }
            "SPHERICAL_SURFACE" => Ok(SurfaceDef::Sphere {
                frame: self.frame(&r, 1)?,
                radius: r.positive(2, "a radius")?,
            }),
            "TOROIDAL_SURFACE" | "DEGENERATE_TOROIDAL_SURFACE" => Ok(SurfaceDef::Torus {
                frame: self.frame(&r, 1)?,
                major: r.positive(2, "a major radius")?,
                minor: r.positive(3, "a minor radius")?,
            }),
            "SURFACE_OF_REVOLUTION" => {
                let profile = self.curve(&r, 1)?;
                let axis = self.follow(&r, 2, &["AXIS1_PLACEMENT"])?;
                let origin = self.point(&axis, 1)?;
                let dir = match axis.rec.params.get(2).map(|p| &p.value) {
                    None | Some(Value::Unset) => DVec3::Z,
                    _ => self.direction(&axis, 2)?,
                };
                Ok(SurfaceDef::Revolution {
                    profile,
                    origin,
                    axis: dir,
                })
            }
            "SURFACE_OF_LINEAR_EXTRUSION" => {
                let profile = self.curve(&r, 1)?;
                let v = self.follow(&r, 2, &["VECTOR"])?;
                let dir = self.direction(&v, 1)?;
                let magnitude = v.positive(2, "a magnitude")?;
                Ok(SurfaceDef::Extrusion {
                    profile,
                    direction: dir * magnitude,
                })
            }
            // Inside a face (or under a curve-bounded surface) a rectangular trimmed
            // surface is its basis: ISO 10303-42 §4.4.? gives it the basis's own
            // parameterisation, and the face's bounds lie within the rectangle. Standing
            // alone it is read as its rectangle (`surfaces`).
            "RECTANGULAR_TRIMMED_SURFACE" => Ok((*self
                .surface_by_id(&r, r.reference(1, "a basis surface")?)?)
            .clone()),
            "OFFSET_SURFACE" => {
                let basis = self.surface_by_id(&r, r.reference(1, "a basis surface")?)?;
                let distance = r.real(2, "a distance")?;
                offset_exactly(&basis, distance).ok_or_else(|| {
                    self.unsupported(
                        &r,
                        "an offset of a plane, cylinder, cone, sphere or torus that keeps it one (other offsets are not read)",
                    )
                })
            }
            _ => Err(self.unsupported(&r, "a supported surface (PLANE, CYLINDRICAL_SURFACE, CONICAL_SURFACE, SPHERICAL_SURFACE, TOROIDAL_SURFACE, SURFACE_OF_REVOLUTION, SURFACE_OF_LINEAR_EXTRUSION, B_SPLINE_SURFACE_WITH_KNOTS, BEZIER_SURFACE, UNIFORM_SURFACE, QUASI_UNIFORM_SURFACE, OFFSET_SURFACE, RECTANGULAR_TRIMMED_SURFACE)")),
        }
    }

    /// B_SPLINE_SURFACE(name, u_degree, v_degree, points, form, u_closed, v_closed,
    /// self_intersect) with knots from B_SPLINE_SURFACE_WITH_KNOTS (u_mult, v_mult,
    /// u_knots, v_knots, spec) or implied by BEZIER_SURFACE, weights from
    /// RATIONAL_B_SPLINE_SURFACE.
    fn bspline_surface(&self, inst: &'e Instance<'a>) -> Result<NurbsSurface, ParseError> {
        let (base, off) = match self.named(inst, "B_SPLINE_SURFACE") {
            Some(b) => (b, 0),
            None => (self.rec(inst), 1),
        };
        let degree = |i: usize| -> Result<usize, ParseError> {
            let p = base.param(off + i, "a degree")?;
            let d = base.integer(p, "a degree")?;
            if !(1..=crate::geom::MAX_DEGREE as i64).contains(&d) {
                return Err(base.error_at(
                    p.line,
                    p.column,
                    format!(
                        "expected a degree in 1..={}, found {d}",
                        crate::geom::MAX_DEGREE
                    ),
                ));
            }
            Ok(d as usize)
        };
        let (degree_u, degree_v) = (degree(0)?, degree(1)?);
        let rows_p = base.param(off + 2, "control points")?;
        let mut points = Vec::new();
        for row in base.list_of(rows_p, "lists of control points")? {
            let ids = base.list_of(row, "control points")?;
            let row_points = ids
                .iter()
                .map(|q| {
                    let id = base.reference_of(q, "a CARTESIAN_POINT")?;
                    let p = self.expect_type(&base, id, &["CARTESIAN_POINT"], off + 2)?;
                    self.coordinates(&p, 1, "coordinates")
                })
                .collect::<Result<Vec<_>, _>>()?;
            points.push(row_points);
        }
        let count_v = points.first().map_or(0, Vec::len);
        if points.is_empty() || points.iter().any(|r| r.len() != count_v) {
            return Err(base.error_at(
                rows_p.line,
                rows_p.column,
                "expected a rectangular control net (every row the same length)",
            ));
        }
        let count_u = points.len();
        let (knots_u, knots_v) = if let Some(form) = ImpliedKnots::of(inst, SURFACE_FORMS) {
            match (form.knots(degree_u, count_u), form.knots(degree_v, count_v)) {
                (Some(ku), Some(kv)) => (ku, kv),
                _ if form == ImpliedKnots::Bezier => return Err(base.error("expected a multiple of the degree plus one control points in each direction of a Bézier surface")),
                _ => return Err(base.error("expected more control points than the degree in each direction")),
            }
        } else {
            let (kr, koff) = match self.named(inst, "B_SPLINE_SURFACE_WITH_KNOTS") {
                Some(k) if inst.complex => (k, 0),
                Some(k) => (k, 8),
                None => return Err(base.error("expected knots")),
            };
            (
                expand_knots(
                    &kr,
                    kr.param(koff, "u multiplicities")?,
                    kr.param(koff + 2, "u knots")?,
                )?,
                expand_knots(
                    &kr,
                    kr.param(koff + 1, "v multiplicities")?,
                    kr.param(koff + 3, "v knots")?,
                )?,
            )
        };
        let weights = match self.weights(inst, "RATIONAL_B_SPLINE_SURFACE") {
            Some(w) => {
                let p = w.param(0, "weights")?;
                let rows = w.list_of(p, "lists of weights")?;
                let ws = rows
                    .iter()
                    .map(|row| w.numbers(row, "weights"))
                    .collect::<Result<Vec<_>, _>>()?;
                if ws.len() != count_u || ws.iter().any(|r| r.len() != count_v) {
                    return Err(w.error_at(
                        p.line,
                        p.column,
                        format!("expected {count_u} x {count_v} weights like the control net"),
                    ));
                }
                ws
            }
            None => vec![vec![1.0; count_v]; count_u],
        };
        // STEP's net is a list over u of lists over v; ours runs u fastest.
        let (flat, flat_w): (Vec<DVec3>, Vec<f64>) = (0..count_v)
            .flat_map(|j| (0..count_u).map(move |i| (i, j)))
            .map(|(i, j)| (points[i][j], weights[i][j]))
            .unzip();
        NurbsSurface::new(
            degree_u,
            degree_v,
            knots_u,
            knots_v,
            count_u,
            count_v,
            homogeneous(&flat, &flat_w),
        )
        .map_err(|e| base.error(e.to_string()))
    }

    /// An ADVANCED_FACE or FACE_SURFACE(name, bounds, face_geometry, same_sense).
    pub fn face(&self, inst: &'e Instance<'a>) -> Result<Face, ParseError> {
        let r = self.rec(inst);
        if !matches!(r.rec.name, "ADVANCED_FACE" | "FACE_SURFACE") {
            return Err(r.error("expected an ADVANCED_FACE or FACE_SURFACE"));
        }
        let surface_id = r.reference(2, "the face geometry")?;
        let surface = self.surface_by_id(&r, surface_id)?;
        let same_sense = r.boolean(3, "same_sense")?;
        let mut bounds = Vec::new();
        for id in r.references(1, "face bounds")? {
            let b = self.expect_type(&r, id, &["FACE_OUTER_BOUND", "FACE_BOUND"], 1)?;
            bounds.push(self.deeper(&r, || self.bound(&b))?);
        }
        Ok(Face {
            id: inst.id,
            surface_id,
            surface,
            same_sense,
            bounds,
        })
    }

    fn bound(&self, b: &Rec) -> Result<Bound, ParseError> {
        let orientation = b.boolean(2, "orientation")?;
        let l = self.follow(b, 1, &["EDGE_LOOP", "VERTEX_LOOP"])?;
        let mut edges = Vec::new();
        let mut vertex = None;
        if l.rec.name == "VERTEX_LOOP" {
            vertex = Some(self.vertex(&l, 1)?);
        } else {
            for id in l.references(1, "oriented edges")? {
                let oe = self.expect_type(&l, id, &["ORIENTED_EDGE"], 1)?;
                let orientation = oe.boolean(4, "orientation")?;
                let eid = oe.reference(3, "an EDGE_CURVE")?;
                let edge = self.deeper(&oe, || self.edge(&oe, eid))?;
                edges.push(OrientedEdge { orientation, edge });
            }
        }
        Ok(Bound {
            id: b.inst.id,
            outer: b.rec.name == "FACE_OUTER_BOUND",
            orientation,
            edges,
            vertex,
        })
    }

    fn vertex(&self, from: &Rec, i: usize) -> Result<DVec3, ParseError> {
        let v = self.follow(from, i, &["VERTEX_POINT"])?;
        self.point(&v, 1)
    }

    fn edge(&self, from: &Rec, id: u64) -> Result<Arc<Edge>, ParseError> {
        if let Some(e) = self.edges.borrow().get(&id) {
            return Ok(e.clone());
        }
        let e = self.expect_type(from, id, &["EDGE_CURVE"], 3)?;
        let (start, end) = (self.vertex(&e, 1)?, self.vertex(&e, 2)?);
        let edge = Arc::new(Edge {
            id,
            start,
            end,
            closed: e.reference(1, "a vertex")? == e.reference(2, "a vertex")?,
            curve: line_through_vertices(self.curve(&e, 3)?, start, end),
            same_sense: e.boolean(4, "same_sense")?,
        });
        self.edges.borrow_mut().insert(id, edge.clone());
        Ok(edge)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn implied_knots_follow_iso_42() {
        let bezier = |d, n| ImpliedKnots::Bezier.knots(d, n);
        assert_eq!(bezier(3, 4).unwrap(), [0., 0., 0., 0., 1., 1., 1., 1.]);
        assert_eq!(bezier(2, 5).unwrap(), [0., 0., 0., 1., 1., 2., 2., 2.]);
        assert!(bezier(2, 4).is_none());
        // ISO 10303-42 §4.3.4: uniform knots run from −degree by 1, quasi-uniform ones are
        // clamped (degree + 1 at each end) with unit steps between.
        assert_eq!(
            ImpliedKnots::Uniform.knots(2, 4).unwrap(),
            [-2., -1., 0., 1., 2., 3., 4.]
        );
        assert_eq!(
            ImpliedKnots::QuasiUniform.knots(2, 5).unwrap(),
            [0., 0., 0., 1., 2., 3., 3., 3.]
        );
        assert_eq!(
            ImpliedKnots::QuasiUniform.knots(3, 4).unwrap(),
            [0., 0., 0., 0., 1., 1., 1., 1.]
        );
        assert!(ImpliedKnots::Uniform.knots(3, 3).is_none());
    }
}
