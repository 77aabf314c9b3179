//! STEP curves and surfaces as their ISO 10303-42 definitions (§4.4.?): points in `f64`,
//! parameters of points (closed forms for lines, conics and the elementary surfaces), and
//! the conversion of each surface to an exact rational NURBS over a parameter rectangle
//! through the shared `geom::nurbs::analytic` (OpenCASCADE's StepToGeom).

use std::f64::consts::TAU;

use glam::{DQuat, DVec2, DVec3};

use super::entities::{Curve, SurfaceDef};
use crate::geom::nurbs::NurbsCurve;
use crate::geom::nurbs::analytic::{self, MappedSurface, ShapeError, Span};
use crate::geom::trim::AxisMap;

/// Samples taken along a parameter interval before refining the closest one; enough to
/// separate the local minima of the distance to a cubic B-spline span or a conic.
const CLOSEST_SAMPLES: usize = 64;

/// Golden-section steps refining a closest parameter: 0.618^80 ≈ 2e-17 of the bracket,
/// below f64 resolution of any parameter.
const GOLDEN_STEPS: usize = 80;

/// The parameter in `[t0, t1]` where `f` comes closest to `p`: the best of
/// [`CLOSEST_SAMPLES`] samples, refined by golden-section search on the distance in the
/// bracket of its neighbours.
pub fn closest_param(f: impl Fn(f64) -> DVec3, t0: f64, t1: f64, p: DVec3) -> f64 {
    let n = CLOSEST_SAMPLES;
    let at = |k: usize| t0 + (t1 - t0) * k as f64 / n as f64;
    let dist = |t: f64| f(t).distance_squared(p);
    let best = (0..=n)
        .min_by(|&a, &b| dist(at(a)).total_cmp(&dist(at(b))))
        .unwrap_or(0);
    let t = crate::geom::golden::minimize(
        dist,
        at(best.saturating_sub(1)),
        at((best + 1).min(n)),
        GOLDEN_STEPS,
    );
    // The sampled ends are candidates too: the search only narrows an interior bracket.
    [t, t0, t1]
        .into_iter()
        .min_by(|&x, &y| dist(x).total_cmp(&dist(y)))
        .unwrap_or(t)
}

impl Curve {
    /// The point at parameter `t`.
    pub fn point(&self, t: f64) -> DVec3 {
        match self {
            Curve::Line { origin, direction } => *origin + t * *direction,
            Curve::Circle { frame, radius } => frame.point(radius * t.cos(), radius * t.sin(), 0.0),
            Curve::Ellipse { frame, a, b } => frame.point(a * t.cos(), b * t.sin(), 0.0),
            Curve::BSpline(c) => c.eval(t),
            Curve::Trimmed { basis, .. } => basis.point(t),
            Curve::OnSurface { curve, .. } => curve.point(t),
        }
    }

    /// The period of a closed curve's parameter (2π for conics).
    pub fn period(&self) -> Option<f64> {
        match self {
            Curve::Circle { .. } | Curve::Ellipse { .. } => Some(TAU),
            Curve::OnSurface { curve, .. } => curve.period(),
            _ => None,
        }
    }

    /// The parameter range a point may be looked for in: the knot domain of a B-spline,
    /// one period of a conic, the trimmed interval.
    pub fn domain(&self) -> (f64, f64) {
        match self {
            Curve::Line { .. } => (f64::NEG_INFINITY, f64::INFINITY),
            Curve::Circle { .. } | Curve::Ellipse { .. } => (0.0, TAU),
            Curve::BSpline(c) => crate::geom::nurbs::knots::domain(c.degree, &c.knots),
            Curve::Trimmed {
                basis,
                t0,
                t1,
                sense,
                ..
            } => {
                let (mut a, mut b) = if *sense { (*t0, *t1) } else { (*t1, *t0) };
                if let Some(p) = basis.period() {
                    // Not a loop adding p: beyond 2^53 · p an addition leaves b unchanged.
                    b = a + (b - a).rem_euclid(p);
                    if b <= a {
                        b = a + p;
                    }
                } else if b < a {
                    std::mem::swap(&mut a, &mut b);
                }
                (a, b)
            }
            Curve::OnSurface { curve, .. } => curve.domain(),
        }
    }

    /// The parameter of the curve's point closest to `p` (exact for lines and conics; for a
    /// periodic curve in `[0, 2π)`).
    pub fn parameter_of(&self, p: DVec3) -> f64 {
        match self {
            Curve::Line { origin, direction } => {
                (p - *origin).dot(*direction) / direction.length_squared()
            }
            Curve::Circle { frame, .. } => {
                let l = frame.local(p);
                l.y.atan2(l.x).rem_euclid(TAU)
            }
            Curve::Ellipse { frame, a, b } => {
                let l = frame.local(p);
                (l.y / b).atan2(l.x / a).rem_euclid(TAU)
            }
            Curve::BSpline(_) => {
                let (a, b) = self.domain();
                closest_param(|t| self.point(t), a, b, p)
            }
            Curve::Trimmed { basis, .. } => {
                let (a, b) = self.domain();
                match basis.period() {
                    Some(period) => {
                        let t = basis.parameter_of(p);
                        a + (t - a).rem_euclid(period)
                    }
                    None => match **basis {
                        Curve::Line { .. } => basis.parameter_of(p),
                        _ => closest_param(|t| basis.point(t), a, b, p),
                    },
                }
            }
            Curve::OnSurface { curve, .. } => curve.parameter_of(p),
        }
    }

    /// The period of a closed B-spline (its two ends the same point, within rounding):
    /// the length of its domain, over which its points then repeat.
    pub fn closed_period(&self) -> Option<f64> {
        let Curve::BSpline(c) = self.space_curve() else {
            return None;
        };
        let (a, b) = crate::geom::nurbs::knots::domain(c.degree, &c.knots);
        let (p, q) = (c.eval(a), c.eval(b));
        (p.distance(q) <= 1e-9 * (1.0 + p.abs().max_element())).then_some(b - a)
    }

    /// The 3D curve of a SURFACE_CURVE / SEAM_CURVE, the curve itself otherwise.
    pub fn space_curve(&self) -> &Curve {
        match self {
            Curve::OnSurface { curve, .. } => curve.space_curve(),
            c => c,
        }
    }
}

impl SurfaceDef {
    /// The point at parameters (u, v) by the definition.
    pub fn point(&self, u: f64, v: f64) -> DVec3 {
        match self {
            SurfaceDef::Plane(f) => f.point(u, v, 0.0),
            SurfaceDef::Cylinder { frame, radius } => {
                frame.point(radius * u.cos(), radius * u.sin(), v)
            }
            SurfaceDef::Cone {
                frame,
                radius,
                semi_angle,
            } => {
                let r = radius + v * semi_angle.tan();
                frame.point(r * u.cos(), r * u.sin(), v)
            }
            SurfaceDef::Sphere { frame, radius } => {
                let r = radius * v.cos();
                frame.point(r * u.cos(), r * u.sin(), radius * v.sin())
            }
            SurfaceDef::Torus {
                frame,
                major,
                minor,
            } => {
                let r = major + minor * v.cos();
                frame.point(r * u.cos(), r * u.sin(), minor * v.sin())
            }
            SurfaceDef::Revolution {
                profile,
                origin,
                axis,
            } => *origin + DQuat::from_axis_angle(*axis, u) * (profile.point(v) - *origin),
            SurfaceDef::Extrusion { profile, direction } => profile.point(u) + v * *direction,
            SurfaceDef::BSpline(s) => s.eval(u, v),
        }
    }

    /// Periods of (u, v): 2π for the angles of the elementary surfaces of revolution, the
    /// domain's length along a closed profile of an extrusion or revolution.
    pub fn periods(&self) -> [Option<f64>; 2] {
        match self {
            SurfaceDef::Cylinder { .. } | SurfaceDef::Cone { .. } | SurfaceDef::Sphere { .. } => {
                [Some(TAU), None]
            }
            SurfaceDef::Revolution { profile, .. } => [Some(TAU), profile.closed_period()],
            SurfaceDef::Extrusion { profile, .. } => [profile.closed_period(), None],
            SurfaceDef::Torus { .. } => [Some(TAU), Some(TAU)],
            _ => [None, None],
        }
    }

    /// The interval a parameter is defined over when the surface ends there rather than
    /// going on (a B-spline's domain, a B-spline profile's); `None` for angles and lines.
    pub fn fixed_span(&self, axis: usize) -> Option<(f64, f64)> {
        let profile_span = |c: &Curve| match c.space_curve() {
            Curve::BSpline(_) => Some(c.domain()),
            _ => None,
        };
        match (self, axis) {
            (SurfaceDef::BSpline(n), _) => {
                let d = n.domain();
                Some(if axis == 0 {
                    (d.u0, d.u1)
                } else {
                    (d.v0, d.v1)
                })
            }
            (SurfaceDef::Extrusion { profile, .. }, 0) => profile_span(profile),
            (SurfaceDef::Revolution { profile, .. }, 1) => profile_span(profile),
            _ => None,
        }
    }

    /// The parameters of `p`, a point on (or near) the surface, in closed form where the
    /// definition allows (angles in (-π, π]); `None` for B-spline surfaces, which need
    /// point inversion on the NURBS.
    pub fn parameters_of(&self, p: DVec3) -> Option<DVec2> {
        let angle = |l: DVec3| l.y.atan2(l.x);
        Some(match self {
            SurfaceDef::Plane(f) => f.local(p).truncate(),
            SurfaceDef::Cylinder { frame, .. } | SurfaceDef::Cone { frame, .. } => {
                let l = frame.local(p);
                DVec2::new(angle(l), l.z)
            }
            SurfaceDef::Sphere { frame, .. } => {
                let l = frame.local(p);
                DVec2::new(angle(l), l.z.atan2(l.x.hypot(l.y)))
            }
            SurfaceDef::Torus { frame, major, .. } => {
                let l = frame.local(p);
                DVec2::new(angle(l), l.z.atan2(l.x.hypot(l.y) - major))
            }
            SurfaceDef::Revolution {
                profile,
                origin,
                axis,
            } => {
                // The angle about the axis from the profile's own half-plane (taken at
                // the middle of its domain) to the point's.
                let (a, b) = profile.domain();
                let mid = if a.is_finite() && b.is_finite() {
                    0.5 * (a + b)
                } else {
                    0.0
                };
                let radial = |q: DVec3| {
                    let d = q - *origin;
                    d - d.dot(*axis) * *axis
                };
                let r0 = radial(profile.point(mid));
                let r1 = radial(p);
                let u = axis.dot(r0.cross(r1)).atan2(r0.dot(r1));
                let back = *origin + DQuat::from_axis_angle(*axis, -u) * (p - *origin);
                DVec2::new(u, profile.parameter_of(back))
            }
            SurfaceDef::Extrusion { profile, direction } => {
                let d = direction.normalize();
                let flat = |q: DVec3| q - q.dot(d) * d;
                let u = match profile.space_curve() {
                    Curve::Line {
                        origin,
                        direction: l,
                    } => {
                        let fl = flat(*l);
                        fl.dot(flat(p - *origin)) / fl.length_squared()
                    }
                    c => {
                        let (a, b) = c.domain();
                        closest_param(|t| flat(c.point(t)), a, b, flat(p))
                    }
                };
                let v = (p - profile.point(u)).dot(*direction) / direction.length_squared();
                DVec2::new(u, v)
            }
            SurfaceDef::BSpline(_) => return None,
        })
    }
}

/// A curve as an exact NURBS over its parameters `[t0, t1]` and the map from the NURBS
/// parameter to the curve's own (angles for conics); B-splines keep their own domain.
pub fn curve_to_nurbs(c: &Curve, [t0, t1]: Span) -> Result<(NurbsCurve, AxisMap), ShapeError> {
    match c {
        Curve::Line { origin, direction } => Ok((
            analytic::line_segment(*origin + t0 * *direction, *origin + t1 * *direction, t0, t1)?,
            AxisMap::Identity,
        )),
        Curve::Circle { frame, radius } => analytic::circle_arc(frame, *radius, t0, t1),
        Curve::Ellipse { frame, a, b } => analytic::ellipse_arc(frame, *a, *b, [t0, t1]),
        Curve::BSpline(n) => Ok((n.clone(), AxisMap::Identity)),
        Curve::Trimmed { basis, .. } => curve_to_nurbs(basis, [t0, t1]),
        Curve::OnSurface { curve, .. } => curve_to_nurbs(curve, [t0, t1]),
    }
}

/// The surface as an exact rational NURBS over the parameter rectangle `u × v` (B-spline
/// surfaces keep their own domain), with the maps from its NURBS parameters to the
/// definition's, so trim loops written in the definition's parameters apply unchanged.
pub fn surface_to_nurbs(s: &SurfaceDef, u: Span, v: Span) -> Result<MappedSurface, ShapeError> {
    match s {
        SurfaceDef::Plane(f) => analytic::plane(f, u[0], u[1], v[0], v[1]),
        SurfaceDef::Cylinder { frame, radius } => analytic::cylinder(frame, *radius, u, v),
        SurfaceDef::Cone {
            frame,
            radius,
            semi_angle,
        } => analytic::cone(frame, *radius, *semi_angle, u, v),
        SurfaceDef::Sphere { frame, radius } => analytic::sphere(frame, *radius, u, v),
        SurfaceDef::Torus {
            frame,
            major,
            minor,
        } => analytic::torus(frame, *major, *minor, u, v),
        SurfaceDef::Revolution {
            profile,
            origin,
            axis,
        } => {
            // The definition's u is the angle from the profile's own half-plane, which is
            // where analytic::revolution starts too.
            let (curve, v_map) = curve_to_nurbs(profile, v)?;
            let (surface, [u_map, _]) = analytic::revolution(&curve, *origin, *axis, u[0], u[1])?;
            Ok((surface, [u_map, v_map]))
        }
        SurfaceDef::Extrusion { profile, direction } => {
            let (curve, u_map) = curve_to_nurbs(profile, u)?;
            let (surface, [_, v_map]) = analytic::extrusion(&curve, *direction, v[0], v[1])?;
            Ok((surface, [u_map, v_map]))
        }
        SurfaceDef::BSpline(n) => Ok((n.clone(), Default::default())),
    }
}
