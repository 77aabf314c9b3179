//! Surfaces: the elementary ones (plane, cylinder, cone, sphere, torus), swept ones
//! (revolution, extrusion), B-splines, and the offsets and rectangular trims read as
//! their basis.

use std::sync::Arc;

use glam::DVec3;

use super::bspline::{ImpliedKnots, SURFACE_FORMS, expand_knots, homogeneous};
use super::{Curve, Frame, Rec, Resolver};
use crate::formats::cad::step::records::{Instance, Value};
use crate::formats::error::ParseError;
use crate::geom::nurbs::NurbsSurface;

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

impl<'e, 'a> Resolver<'e, 'a> {
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
}
