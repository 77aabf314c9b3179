//! The IGES 5.3 analytic surfaces (OpenCASCADE's `IGESSolid` surfaces and
//! `IGESToBRep_BasicSurface`): 190 plane, 192 right circular cylinder, 194 right circular
//! cone, 196 sphere, 198 torus (§4.38–4.42), each placed by a 116 point, a 123 axis and,
//! in form 1 (parameterised), a 123 reference direction that fixes where u = 0.
//!
//! The parameterisations of form 1, in the frame (X = reference direction made orthogonal
//! to the axis, Y = Z × X, Z = axis) about the location C, are those of ISO 10303-42, which
//! `geom::nurbs::analytic` builds (u the angle about Z from X in radians, v as below):
//! plane C + u X + v Y; cylinder C + R (cos u X + sin u Y) + v Z; cone
//! C + (R + v tan α)(cos u X + sin u Y) + v Z, α the semi-angle (written in degrees), R the
//! radius at C; sphere C + R cos v (cos u X + sin u Y) + R sin v Z, v the latitude in
//! [−π/2, π/2]; torus C + (R + r cos v)(cos u X + sin u Y) + r sin v Z. Form 0 has no
//! reference direction: any X orthogonal to the axis is as good (its trims are model-space
//! curves, or parameter curves of a surface whose u origin the writer chose the same way).
//!
//! Cylinders, cones and planes are unbounded: their NURBS patch covers the parameter box
//! of their trim loops (the control points' box, which holds the loops by the convex hull
//! property), at most one turn in angle.

use std::f64::consts::{FRAC_PI_2, PI, TAU};

use glam::{DAffine3, DVec2, DVec3};

use super::Model;
use super::entities::{Elementary, Entity};
use crate::geom::nurbs::analytic::{self, Frame, MappedSurface, Span};

/// A reference direction whose part orthogonal to the axis is below this fraction of its
/// length is taken as parallel: an X built from it would carry the writer's rounding
/// magnified a billion times, so form 1's u origin would be noise.
const PARALLEL: f64 = 1e-9;

/// A 190–198 surface in its definition space, and the transform into model space.
pub struct Placed {
    pub shape: Elementary,
    pub frame: Frame,
    /// Form 1: the parameterisation is the standard's, so parameter-space trims apply.
    pub parameterised: bool,
    pub to_model: DAffine3,
}

fn err(e: impl std::fmt::Display) -> String {
    e.to_string()
}

/// The location of a 116 (`point`: its transform applied) or the vector of a 123 (the
/// rotation of its transform only, §4.20).
fn placement(model: &Model, pointer: usize, point: bool) -> Result<DVec3, String> {
    let (entry, entity) = model.get(pointer)?;
    let m = model.transform(entry.transform)?;
    match (entity, point) {
        (Entity::Point(p), true) => Ok(m.transform_point3(*p)),
        (Entity::Direction(d), false) => Ok(m.transform_vector3(*d)),
        _ => Err(format!(
            "D {pointer} is entity {}, not a {}",
            entry.entity_type,
            if point {
                "point (116)"
            } else {
                "direction (123)"
            }
        )),
    }
}

/// The 190–198 entity at `pointer`, or `None` for any other entity.
pub fn placed(model: &Model, pointer: usize) -> Result<Option<Placed>, String> {
    let (entry, entity) = model.get(pointer)?;
    let Entity::Elementary {
        shape,
        location,
        axis,
        reference,
    } = entity
    else {
        return Ok(None);
    };
    let origin = placement(model, *location, true)?;
    // Form 0 of the sphere has no axis: any will do.
    let z = if *axis == 0 {
        DVec3::Z
    } else {
        placement(model, *axis, false)?
    };
    let x = if *reference == 0 {
        None
    } else {
        let r = placement(model, *reference, false)?;
        let zn = z.normalize_or_zero();
        if (r - zn * r.dot(zn)).length() <= PARALLEL * r.length() {
            return Err(format!(
                "the reference direction D {reference} is parallel to the axis"
            ));
        }
        Some(r)
    };
    let frame = Frame::new(origin, z, x).map_err(err)?;
    Ok(Some(Placed {
        shape: shape.clone(),
        frame,
        parameterised: *reference != 0,
        to_model: model.transform(entry.transform)?,
    }))
}

impl Placed {
    /// Which parameters are angles (periodic with period 2π).
    pub fn angular(&self) -> [bool; 2] {
        match self.shape {
            Elementary::Plane => [false, false],
            Elementary::Torus { .. } => [true, true],
            _ => [true, false],
        }
    }

    /// The whole surface's parameter box where it is bounded (sphere, torus).
    pub fn closed_box(&self) -> Option<[Span; 2]> {
        match self.shape {
            Elementary::Sphere { .. } => Some([[0.0, TAU], [-FRAC_PI_2, FRAC_PI_2]]),
            Elementary::Torus { .. } => Some([[0.0, TAU], [0.0, TAU]]),
            _ => None,
        }
    }

    /// The parameters of the model-space point `p` on the surface, in closed form (angles
    /// in (−π, π]); the inverse of the parameterisation on the surface.
    pub fn parameters_of(&self, p: DVec3) -> DVec2 {
        let l = self
            .frame
            .local(self.to_model.inverse().transform_point3(p));
        let around = l.y.atan2(l.x);
        let rho = l.x.hypot(l.y);
        match self.shape {
            Elementary::Plane => l.truncate(),
            Elementary::Cylinder { .. } | Elementary::Cone { .. } => DVec2::new(around, l.z),
            Elementary::Sphere { .. } => DVec2::new(around, l.z.atan2(rho)),
            Elementary::Torus { major, .. } => DVec2::new(around, l.z.atan2(rho - major)),
        }
    }

    /// The exact NURBS over the parameter box `u × v` (trim parameters), in model space,
    /// with the maps from its NURBS parameters to the trim parameters. The box is cut to
    /// one turn in angles and to [−π/2, π/2] in the sphere's latitude.
    pub fn surface(&self, mut u: Span, mut v: Span) -> Result<MappedSurface, String> {
        let [au, av] = self.angular();
        if au {
            u[1] = u[1].min(u[0] + TAU);
        }
        if av {
            v[1] = v[1].min(v[0] + TAU);
        }
        let f = &self.frame;
        let (mut s, maps) = match self.shape {
            Elementary::Plane => analytic::plane(f, u[0], u[1], v[0], v[1]),
            Elementary::Cylinder { radius } => analytic::cylinder(f, radius, u, v),
            Elementary::Cone { radius, semi_angle } => {
                analytic::cone(f, radius, semi_angle * (PI / 180.0), u, v)
            }
            Elementary::Sphere { radius } => {
                v = [v[0].max(-FRAC_PI_2), v[1].min(FRAC_PI_2)];
                analytic::sphere(f, radius, u, v)
            }
            Elementary::Torus { major, minor } => analytic::torus(f, major, minor, u, v),
        }
        .map_err(err)?;
        s.transform(&self.to_model);
        Ok((s, maps))
    }
}
