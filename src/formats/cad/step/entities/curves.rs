//! Curves: lines, conics, B-splines, trimmed curves and curves on surfaces with their
//! pcurves.

use std::sync::Arc;

use glam::DVec3;

use super::bspline::{CURVE_FORMS, ImpliedKnots, expand_knots, homogeneous};
use super::{Frame, Rec, Resolver};
use crate::formats::cad::step::records::{Instance, Value};
use crate::formats::error::ParseError;
use crate::geom::nurbs::NurbsCurve;

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
    /// A curve on surfaces ([`ON_SURFACE`]: SURFACE_CURVE, SEAM_CURVE, INTERSECTION_CURVE…):
    /// the 3D curve and its pcurves (a seam has two on the same surface).
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

/// The curves on surfaces (ISO 10303-42: surface_curve and its subtypes seam_curve,
/// bounded_surface_curve and intersection_curve, all with the attributes curve_3d,
/// associated_geometry and master_representation).
const ON_SURFACE: [&str; 4] = [
    "SURFACE_CURVE",
    "SEAM_CURVE",
    "BOUNDED_SURFACE_CURVE",
    "INTERSECTION_CURVE",
];

impl<'e, 'a> Resolver<'e, 'a> {
    /// Any supported curve (3D or, in a pcurve, 2D).
    pub fn curve(&self, from: &Rec, i: usize) -> Result<Arc<Curve>, ParseError> {
        let id = from.reference(i, "a curve")?;
        self.curve_by_id(from, id)
    }

    pub fn curve_by_id(&self, from: &Rec, id: u64) -> Result<Arc<Curve>, ParseError> {
        self.cached(&self.curves, from, id, |inst| self.read_curve(inst))
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
        let r = ON_SURFACE
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
            "POLYLINE" => self.polyline(&r).map(Curve::BSpline),
            "SURFACE_CURVE" | "SEAM_CURVE" | "BOUNDED_SURFACE_CURVE" | "INTERSECTION_CURVE" => {
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
            _ => Err(self.unsupported(&r, "a supported curve (LINE, CIRCLE, ELLIPSE, POLYLINE, B_SPLINE_CURVE_WITH_KNOTS, BEZIER_CURVE, UNIFORM_CURVE, QUASI_UNIFORM_CURVE, TRIMMED_CURVE, SURFACE_CURVE, SEAM_CURVE, INTERSECTION_CURVE)")),
        }
    }

    /// POLYLINE(name, points): ISO 10303-42 puts segment i (from 1) between points i and
    /// i + 1 at parameters i - 1 ..= i, which is exactly the degree-1 B-spline on those
    /// points with knots 0, 0, 1, …, n - 2, n - 1, n - 1.
    fn polyline(&self, r: &Rec) -> Result<NurbsCurve, ParseError> {
        let ids = r.references(1, "points")?;
        if ids.len() < 2 {
            return Err(r.error(format!("expected at least 2 points, found {}", ids.len())));
        }
        let points = ids
            .iter()
            .map(|&id| {
                let p = self.expect_type(r, id, &["CARTESIAN_POINT"], 1)?;
                self.coordinates(&p, 1, "coordinates")
            })
            .collect::<Result<Vec<_>, _>>()?;
        let last = (points.len() - 1) as f64;
        let knots = std::iter::once(0.0)
            .chain((0..points.len()).map(|k| k as f64))
            .chain(std::iter::once(last))
            .collect();
        Ok(NurbsCurve {
            degree: 1,
            knots,
            points: homogeneous(&points, &vec![1.0; points.len()]),
        })
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
        // A trim select is a parameter value or a point on the basis curve (ISO 10303-42
        // §4.3.37); the parameter is taken where both are given, a point alone gives the
        // parameter of the basis curve's point nearest it (UG writes the bounds of its
        // CURVE_BOUNDED_SURFACEs so).
        let trim = |i: usize| -> Result<f64, ParseError> {
            let p = r.param(i, "a trim select")?;
            let selects = r.list_of(p, "trim selects")?;
            for item in selects {
                if let Value::Typed("PARAMETER_VALUE", inner) = &item.value {
                    return Ok(r.number(inner, "a parameter value")? * scale);
                }
            }
            for item in selects {
                if let Value::Ref(id) = item.value {
                    let point = self.expect_type(r, id, &["CARTESIAN_POINT"], i)?;
                    return Ok(basis.parameter_of(self.coordinates(&point, 1, "coordinates")?));
                }
            }
            Err(r.error_at(
                p.line,
                p.column,
                "expected a PARAMETER_VALUE or a CARTESIAN_POINT among the trim selects",
            ))
        };
        let (t0, t1) = (trim(2)?, trim(3)?);
        Ok(Curve::Trimmed {
            basis,
            t0,
            t1,
            sense: r.boolean(4, "sense_agreement")?,
        })
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
}
