//! Analytic geometry as exact rational NURBS: the one place every CAD reader (IGES, STEP)
//! turns circles, conics, lines, planes, cylinders, cones, spheres, tori, surfaces of
//! revolution, extrusions and ruled surfaces into [`NurbsCurve`]s and [`NurbsSurface`]s,
//! as OpenCASCADE's `GeomConvert` does for its readers.
//!
//! Circles follow Piegl & Tiller, *The NURBS Book*, §7.3 (A7.1 MakeNurbsCircle): an arc is
//! split into pieces of at most 90°, each a rational quadratic with end weights 1 and
//! middle weight cos(Δ/2). The knots at the piece ends are the angles themselves, so the
//! NURBS parameter equals the angle there, and [`AxisMap::Arcs`] maps it to the angle
//! exactly in between. Surfaces of revolution are A8.1 (MakeRevolvedSurf): every control
//! point of the profile sweeps its own circle about the axis, weights multiplied.
//!
//! Every surface function returns the surface and the `[AxisMap; 2]` from its NURBS
//! parameters to the analytic ones (angles in radians; lengths are identity), so trim
//! curves written in the analytic parameters land where the CAD system meant them.
//! Angular parameters come first (u), as in ISO 10303-42 §4.4.

use std::f64::consts::{FRAC_PI_2, TAU};

use glam::{DVec3, DVec4};
use thiserror::Error;

use super::curve::NurbsCurve;
use super::surface::NurbsSurface;
use crate::geom::bezier::{GeomError, dehomogenize};
use crate::geom::trim::AxisMap;

/// Why an analytic shape has no NURBS form.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum ShapeError {
    #[error("the {0} direction has zero length or is not finite")]
    Direction(&'static str),
    #[error("{name} must be positive and finite, found {value}")]
    Length { name: &'static str, value: f64 },
    #[error("the parameter range [{start}, {end}] is empty or not finite")]
    Range { start: f64, end: f64 },
    #[error("the angle range [{start}, {end}] spans more than a full turn")]
    TooLong { start: f64, end: f64 },
    #[error(transparent)]
    Geom(#[from] GeomError),
}

/// A surface and the maps from its NURBS parameters to the analytic parameters its trim
/// curves are written in.
pub type MappedSurface = (NurbsSurface, [AxisMap; 2]);

/// A parameter range `[start, end]`, `start < end`.
pub type Span = [f64; 2];

/// How far beyond 2π an angle range may reach and still be one turn: a few ulps of 2π,
/// what `end − start` of two angles written in decimal may round to.
const TURN_SLACK: f64 = 8.0 * f64::EPSILON * TAU;

/// A right-handed orthonormal frame: the placement of every analytic shape (STEP
/// `axis2_placement_3d`, IGES 190–198 axis and reference direction).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frame {
    pub origin: DVec3,
    pub x: DVec3,
    pub y: DVec3,
    pub z: DVec3,
}

impl Frame {
    /// The frame with z along `axis` and x along the part of `reference` orthogonal to it;
    /// without a usable reference (none, or parallel to the axis) x is the world axis least
    /// aligned with z, projected (the convention of ISO 10303-42 `build_axes`).
    pub fn new(origin: DVec3, axis: DVec3, reference: Option<DVec3>) -> Result<Frame, ShapeError> {
        let z = unit(axis, "axis")?;
        let x = reference
            .map(|r| r - z * r.dot(z))
            .and_then(|r| unit(r, "reference").ok())
            .unwrap_or_else(|| {
                let a = z.abs();
                let w = if a.x <= a.y && a.x <= a.z {
                    DVec3::X
                } else if a.y <= a.z {
                    DVec3::Y
                } else {
                    DVec3::Z
                };
                (w - z * w.dot(z)).normalize()
            });
        Ok(Frame {
            origin,
            x,
            y: z.cross(x),
            z,
        })
    }

    /// The world point at frame coordinates `(a, b, c)`.
    pub fn point(&self, a: f64, b: f64, c: f64) -> DVec3 {
        self.origin + self.x * a + self.y * b + self.z * c
    }

    /// The frame coordinates of the world point `p` (the inverse of [`Frame::point`]).
    pub fn local(&self, p: DVec3) -> DVec3 {
        let d = p - self.origin;
        DVec3::new(d.dot(self.x), d.dot(self.y), d.dot(self.z))
    }

    /// The affine map from frame coordinates to world coordinates.
    pub fn to_affine(&self) -> glam::DAffine3 {
        glam::DAffine3::from_mat3_translation(
            glam::DMat3::from_cols(self.x, self.y, self.z),
            self.origin,
        )
    }
}

fn unit(v: DVec3, name: &'static str) -> Result<DVec3, ShapeError> {
    let n = v.normalize_or_zero();
    if n == DVec3::ZERO || !n.is_finite() {
        return Err(ShapeError::Direction(name));
    }
    Ok(n)
}

fn positive(value: f64, name: &'static str) -> Result<f64, ShapeError> {
    if value > 0.0 && value.is_finite() {
        Ok(value)
    } else {
        Err(ShapeError::Length { name, value })
    }
}

fn range(start: f64, end: f64) -> Result<(), ShapeError> {
    if start < end && start.is_finite() && end.is_finite() {
        Ok(())
    } else {
        Err(ShapeError::Range { start, end })
    }
}

/// An arc of the unit circle from `a0` to `a1` as rational quadratic pieces of at most 90°
/// (A7.1): knots (the angles at the piece ends, repeated twice inside, three times at the
/// ends), Euclidean points `(cos, sin)` with their weights, and the angle map.
struct UnitArc {
    knots: Vec<f64>,
    points: Vec<(f64, f64, f64)>,
    map: AxisMap,
}

fn unit_arc(a0: f64, a1: f64) -> Result<UnitArc, ShapeError> {
    range(a0, a1)?;
    let delta = a1 - a0;
    if delta > TAU + TURN_SLACK {
        return Err(ShapeError::TooLong { start: a0, end: a1 });
    }
    let pieces = (delta / FRAC_PI_2).ceil().max(1.0) as usize;
    let step = delta / pieces as f64;
    let angles: Vec<f64> = (0..=pieces)
        .map(|i| {
            if i == pieces {
                a1
            } else {
                a0 + step * i as f64
            }
        })
        .collect();
    let w = (0.5 * step).cos();
    let mut points = vec![(a0.cos(), a0.sin(), 1.0)];
    let mut knots = vec![a0; 3];
    for pair in angles.windows(2) {
        let mid = 0.5 * (pair[0] + pair[1]);
        points.push((mid.cos() / w, mid.sin() / w, w));
        points.push((pair[1].cos(), pair[1].sin(), 1.0));
        knots.extend([pair[1], pair[1]]);
    }
    knots.push(a1);
    Ok(UnitArc {
        knots,
        points,
        map: AxisMap::Arcs {
            breaks: angles.clone(),
            angles,
        },
    })
}

fn homogeneous(p: DVec3, w: f64) -> DVec4 {
    (p * w).extend(w)
}

// ---------------------------------------------------------------------------------------
// Curves

/// The arc `origin + a cos t · x + b sin t · y` for t in `[t0, t1]` (an ellipse with semi-
/// axes `a`, `b`; a circle when they are equal), and the map from its parameter to t.
/// The ellipse is the affine image of the unit circle, and affine maps act on control
/// points exactly.
pub fn ellipse_arc(
    frame: &Frame,
    a: f64,
    b: f64,
    [t0, t1]: Span,
) -> Result<(NurbsCurve, AxisMap), ShapeError> {
    positive(a, "semi-axis a")?;
    positive(b, "semi-axis b")?;
    let arc = unit_arc(t0, t1)?;
    let points = arc
        .points
        .iter()
        .map(|&(c, s, w)| homogeneous(frame.point(a * c, b * s, 0.0), w))
        .collect();
    Ok((
        NurbsCurve {
            degree: 2,
            knots: arc.knots,
            points,
        },
        arc.map,
    ))
}

/// The circular arc of `radius` about `frame.origin` in the frame's xy plane, from angle
/// `a0` to `a1` (radians, counter-clockwise about z, 0 on x).
pub fn circle_arc(
    frame: &Frame,
    radius: f64,
    a0: f64,
    a1: f64,
) -> Result<(NurbsCurve, AxisMap), ShapeError> {
    ellipse_arc(frame, radius, radius, [a0, a1])
}

/// The hyperbola branch `origin + a cosh t · x + b sinh t · y`, t in `[t0, t1]`, as one
/// rational quadratic: with h the half width and m the middle of the range, the tangents
/// at the ends meet at `(cosh m, sinh m) / cosh h` and the middle weight is `cosh h` (the
/// hyperbolic analogue of the circular arc: the hyperbolic rotation by m maps the arc
/// symmetric about t = 0 onto it). The NURBS parameter is not t.
pub fn hyperbola_arc(
    frame: &Frame,
    a: f64,
    b: f64,
    [t0, t1]: Span,
) -> Result<NurbsCurve, ShapeError> {
    positive(a, "semi-axis a")?;
    positive(b, "semi-axis b")?;
    range(t0, t1)?;
    let (h, m) = (0.5 * (t1 - t0), 0.5 * (t0 + t1));
    let w = h.cosh();
    let points = vec![
        homogeneous(frame.point(a * t0.cosh(), b * t0.sinh(), 0.0), 1.0),
        homogeneous(frame.point(a * m.cosh() / w, b * m.sinh() / w, 0.0), w),
        homogeneous(frame.point(a * t1.cosh(), b * t1.sinh(), 0.0), 1.0),
    ];
    Ok(NurbsCurve {
        degree: 2,
        knots: vec![t0, t0, t0, t1, t1, t1],
        points,
    })
}

/// The parabola `origin + k t² · x + t · y`, t in `[t0, t1]`, as the polynomial quadratic
/// with middle point `(k t0 t1, (t0 + t1)/2)`; its parameter is t.
pub fn parabola_arc(frame: &Frame, k: f64, t0: f64, t1: f64) -> Result<NurbsCurve, ShapeError> {
    range(t0, t1)?;
    if !k.is_finite() {
        return Err(ShapeError::Length {
            name: "parabola coefficient",
            value: k,
        });
    }
    let points = vec![
        homogeneous(frame.point(k * t0 * t0, t0, 0.0), 1.0),
        homogeneous(frame.point(k * t0 * t1, 0.5 * (t0 + t1), 0.0), 1.0),
        homogeneous(frame.point(k * t1 * t1, t1, 0.0), 1.0),
    ];
    Ok(NurbsCurve {
        degree: 2,
        knots: vec![t0, t0, t0, t1, t1, t1],
        points,
    })
}

/// The segment from `p0` (parameter `t0`) to `p1` (`t1`), degree 1.
pub fn line_segment(p0: DVec3, p1: DVec3, t0: f64, t1: f64) -> Result<NurbsCurve, ShapeError> {
    range(t0, t1)?;
    Ok(NurbsCurve {
        degree: 1,
        knots: vec![t0, t0, t1, t1],
        points: vec![p0.extend(1.0), p1.extend(1.0)],
    })
}

// ---------------------------------------------------------------------------------------
// Surfaces

/// The plane patch `origin + u x + v y`, (u, v) in `[u0, u1] × [v0, v1]`, bilinear.
pub fn plane(
    frame: &Frame,
    u0: f64,
    u1: f64,
    v0: f64,
    v1: f64,
) -> Result<MappedSurface, ShapeError> {
    range(u0, u1)?;
    range(v0, v1)?;
    let points = [(u0, v0), (u1, v0), (u0, v1), (u1, v1)]
        .map(|(u, v)| frame.point(u, v, 0.0).extend(1.0))
        .to_vec();
    let s = NurbsSurface::new(
        1,
        1,
        vec![u0, u0, u1, u1],
        vec![v0, v0, v1, v1],
        2,
        2,
        points,
    )?;
    Ok((s, Default::default()))
}

/// The surface of revolution of `profile` about the line through `axis_point` along
/// `axis`: the point at angle θ in `[a0, a1]` (radians) is the profile rotated by θ,
/// right-handed about the axis (IGES 120, ISO 10303-42 surface_of_revolution): A8.1. u is the angle (mapped by the returned `AxisMap`), v the profile's
/// own parameter (identity). Profile points on the axis give collapsed edges (poles).
pub fn revolution(
    profile: &NurbsCurve,
    axis_point: DVec3,
    axis: DVec3,
    a0: f64,
    a1: f64,
) -> Result<MappedSurface, ShapeError> {
    let d = unit(axis, "axis")?;
    let arc = unit_arc(a0, a1)?;
    let mut points = Vec::with_capacity(arc.points.len() * profile.points.len());
    for q in &profile.points {
        let p = dehomogenize(*q);
        let foot = axis_point + d * (p - axis_point).dot(d);
        let radial = p - foot;
        let side = d.cross(radial);
        for &(c, s, w) in &arc.points {
            points.push(homogeneous(foot + radial * c + side * s, w * q.w));
        }
    }
    let surface = NurbsSurface::new(
        2,
        profile.degree,
        arc.knots.clone(),
        profile.knots.clone(),
        arc.points.len(),
        profile.points.len(),
        points,
    )?;
    Ok((surface, [arc.map, AxisMap::Identity]))
}

/// Revolves a profile given in frame coordinates, in the (ρ, z) half plane (ρ along x),
/// about the frame's z axis: angle 0 is the frame's x.
fn revolve_in_frame(
    frame: &Frame,
    profile: &NurbsCurve,
    [a0, a1]: Span,
) -> Result<MappedSurface, ShapeError> {
    revolution(&in_frame(frame, profile), frame.origin, frame.z, a0, a1)
}

/// The cylinder `origin + r (cos u x + sin u y) + v z`, u and v in their spans
/// (ISO 10303-42 cylindrical_surface).
pub fn cylinder(frame: &Frame, radius: f64, u: Span, v: Span) -> Result<MappedSurface, ShapeError> {
    positive(radius, "radius")?;
    cone(frame, radius, 0.0, u, v)
}

/// The cone `origin + (r + v tan α)(cos u x + sin u y) + v z`, u and v in their spans (ISO 10303-42 conical_surface; `radius` is the radius at v = 0, `semi_angle`
/// the half angle α in radians, and r + v tan α may reach 0, the apex).
pub fn cone(
    frame: &Frame,
    radius: f64,
    semi_angle: f64,
    u: Span,
    [v0, v1]: Span,
) -> Result<MappedSurface, ShapeError> {
    let t = semi_angle.tan();
    if !(radius >= 0.0 && t.is_finite()) {
        return Err(ShapeError::Length {
            name: "cone radius",
            value: radius,
        });
    }
    let line = line_segment(
        DVec3::new(radius + v0 * t, 0.0, v0),
        DVec3::new(radius + v1 * t, 0.0, v1),
        v0,
        v1,
    )?;
    revolve_in_frame(frame, &line, u)
}

/// The sphere `origin + r cos v (cos u x + sin u y) + r sin v z`, u (longitude) and v
/// (latitude, within [−π/2, π/2]) in their spans (ISO 10303-42 spherical_surface).
pub fn sphere(frame: &Frame, radius: f64, u: Span, v: Span) -> Result<MappedSurface, ShapeError> {
    positive(radius, "radius")?;
    tube_revolution(frame, 0.0, radius, u, v)
}

/// The torus `origin + (R + r cos v)(cos u x + sin u y) + r sin v z`, u and v in their spans
/// (ISO 10303-42 toroidal_surface; `major` R, `minor` r).
pub fn torus(
    frame: &Frame,
    major: f64,
    minor: f64,
    u: Span,
    v: Span,
) -> Result<MappedSurface, ShapeError> {
    positive(major, "major radius")?;
    positive(minor, "minor radius")?;
    tube_revolution(frame, major, minor, u, v)
}

/// A circle of `radius` about (ρ, z) = (`centre`, 0) in the meridian half plane, from
/// angle v0 to v1 (measured from the ρ axis towards z), revolved through the angles u: the torus,
/// and for `centre` = 0 the sphere.
fn tube_revolution(
    frame: &Frame,
    centre: f64,
    radius: f64,
    u: Span,
    [v0, v1]: Span,
) -> Result<MappedSurface, ShapeError> {
    let meridian = Frame {
        origin: DVec3::new(centre, 0.0, 0.0),
        x: DVec3::X,
        y: DVec3::Z,
        z: -DVec3::Y,
    };
    let (arc, v_map) = circle_arc(&meridian, radius, v0, v1)?;
    let (s, [u_map, _]) = revolve_in_frame(frame, &arc, u)?;
    Ok((s, [u_map, v_map]))
}

/// A curve given in frame coordinates, placed in the world.
fn in_frame(frame: &Frame, curve: &NurbsCurve) -> NurbsCurve {
    let points = curve
        .points
        .iter()
        .map(|q| {
            let p = dehomogenize(*q);
            homogeneous(frame.point(p.x, p.y, p.z), q.w)
        })
        .collect();
    NurbsCurve {
        degree: curve.degree,
        knots: curve.knots.clone(),
        points,
    }
}

/// The linear extrusion (IGES 122 tabulated cylinder, STEP surface_of_linear_extrusion)
/// `curve(u) + v · direction`, v in `[v0, v1]`: the tensor product with a degree-1 line.
pub fn extrusion(
    curve: &NurbsCurve,
    direction: DVec3,
    v0: f64,
    v1: f64,
) -> Result<MappedSurface, ShapeError> {
    range(v0, v1)?;
    if !direction.is_finite() || direction == DVec3::ZERO {
        return Err(ShapeError::Direction("extrusion"));
    }
    let points = [v0, v1]
        .iter()
        .flat_map(|&v| {
            curve
                .points
                .iter()
                .map(move |q| homogeneous(dehomogenize(*q) + direction * v, q.w))
        })
        .collect();
    let s = NurbsSurface::new(
        curve.degree,
        1,
        curve.knots.clone(),
        vec![v0, v0, v1, v1],
        curve.points.len(),
        2,
        points,
    )?;
    Ok((s, Default::default()))
}

/// The ruled surface `(1 − v) c0(s) + v c1(s)` between two curves whose parameters are
/// each mapped linearly onto u in [0, 1] (IGES 118 form 1, STEP ruled surfaces by
/// parameter): both become piecewise Bézier of the higher degree on the union of their
/// breakpoints (degree elevation, Piegl & Tiller eq. 5.36; Boehm insertion), then rows
/// of one net, linear in v. For rational curves the blend is linear in homogeneous space:
/// the point at (u, v) still lies on the segment from c0(u) to c1(u), so the surface is the
/// same ruled surface exactly, but where the two weights differ v runs along each ruling
/// as a rational (not linear) parameter.
pub fn ruled(c0: &NurbsCurve, c1: &NurbsCurve) -> Result<MappedSurface, ShapeError> {
    let degree = c0.degree.max(c1.degree);
    let a = piecewise_bezier(c0, degree);
    let b = piecewise_bezier(c1, degree);
    let a = with_breaks_of(&a, &b)?;
    let b = with_breaks_of(&b, &a)?;
    let count = a.points.len();
    let points = a.points.iter().chain(&b.points).copied().collect();
    let s = NurbsSurface::new(
        degree,
        1,
        a.knots.clone(),
        vec![0.0, 0.0, 1.0, 1.0],
        count,
        2,
        points,
    )?;
    Ok((s, Default::default()))
}

/// The curve as Bézier segments elevated to `degree`, joined as a B-spline on [0, 1]
/// with interior knots of multiplicity `degree`.
fn piecewise_bezier(c: &NurbsCurve, degree: usize) -> NurbsCurve {
    let segments = c.bezier_segments();
    let (t0, t1) = (
        segments.first().map_or(0.0, |s| s.t0),
        segments.last().map_or(1.0, |s| s.t1),
    );
    let mut knots = vec![0.0; degree + 1];
    let mut points = Vec::new();
    for (k, seg) in segments.iter().enumerate() {
        let mut p = seg.points.clone();
        while p.len() <= degree {
            p = elevate(&p);
        }
        if k > 0 {
            p.remove(0);
        }
        points.extend(p);
        let end = if k + 1 == segments.len() {
            1.0
        } else {
            (seg.t1 - t0) / (t1 - t0)
        };
        let times = if k + 1 == segments.len() {
            degree + 1
        } else {
            degree
        };
        knots.extend(std::iter::repeat_n(end, times));
    }
    NurbsCurve {
        degree,
        knots,
        points,
    }
}

/// Degree elevation of one Bézier segment by one (The NURBS Book eq. 5.36), on
/// homogeneous points, so exact for rational segments.
fn elevate(p: &[DVec4]) -> Vec<DVec4> {
    let n = p.len(); // new degree
    (0..=n)
        .map(|i| {
            let a = i as f64 / n as f64;
            let left = if i > 0 { p[i - 1] * a } else { DVec4::ZERO };
            let right = if i < n { p[i] * (1.0 - a) } else { DVec4::ZERO };
            left + right
        })
        .collect()
}

/// `c` with every interior breakpoint of `other` inserted up to multiplicity `degree`.
fn with_breaks_of(c: &NurbsCurve, other: &NurbsCurve) -> Result<NurbsCurve, ShapeError> {
    let p = c.degree;
    let mut out = c.clone();
    let inner = &other.knots[p + 1..other.knots.len() - p - 1];
    let mut breaks: Vec<f64> = inner.to_vec();
    breaks.dedup();
    for t in breaks {
        let have = super::knots::multiplicity(&out.knots, t);
        if have < p {
            out = out
                .insert_knot(t, p - have)
                .map_err(|e| GeomError::Knots(e.to_string()))?;
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests;
