//! Surfaces standing alone, outside any face: the elements of a GEOMETRIC_SET (AP214/AP242
//! surface models, GEOMETRICALLY_BOUNDED_SURFACE_SHAPE_REPRESENTATION) and of surface
//! models, as OpenCASCADE's StepToTopoDS_Builder reads them.
//!
//! - A bounded surface on its own (a B-spline, a sphere, a torus) is a face over its whole
//!   domain, as a face without bounds is.
//! - CURVE_BOUNDED_SURFACE (ISO 10303-42 §4.4.?: a basis surface and closed boundary
//!   curves, the surface lying to the left of each) becomes a face whose loops are the
//!   boundaries' composite-curve segments, read as edges: their pcurves on the basis where
//!   the file gives them, otherwise their 3D curves projected (`topology`, `geom::pcurve`).
//! - RECTANGULAR_TRIMMED_SURFACE (ISO 10303-42 §4.4.?: the basis between u1, u2 and v1,
//!   v2) becomes the exact NURBS of its basis over that rectangle.

use std::sync::Arc;

use super::entities::{Bound, Face, Rec, Resolver, SurfaceDef};
use super::geometry::surface_to_nurbs;
use super::records::Instance;
use crate::formats::error::ParseError;
use crate::geom::bezier::ParamRect;
use crate::scene::model::{Surface, SurfaceGeometry};

/// A surface standing alone, read.
#[derive(Clone, Debug)]
pub enum Standalone {
    /// Converted as a face (`topology::convert_face`): a bounded surface with no bounds,
    /// or a curve-bounded surface with its boundaries as loops.
    Face(Face),
    Patch(Patch),
}

/// A rectangle of a surface's parameters (RECTANGULAR_TRIMMED_SURFACE).
#[derive(Clone, Debug)]
pub struct Patch {
    pub surface: Arc<SurfaceDef>,
    pub u: [f64; 2],
    pub v: [f64; 2],
    /// The trimmed surface's normal is against its basis's.
    pub flip: bool,
}

/// Reads the standalone surface `inst`.
pub fn read(res: &Resolver, inst: &Instance) -> Result<Standalone, ParseError> {
    if let Some(r) = res.named(inst, "CURVE_BOUNDED_SURFACE") {
        return curve_bounded(res, &r).map(Standalone::Face);
    }
    if let Some(r) = res.named(inst, "RECTANGULAR_TRIMMED_SURFACE") {
        return rectangle(res, &r).map(Standalone::Patch);
    }
    let r = res.rec(inst);
    Ok(Standalone::Face(Face {
        id: inst.id,
        surface_id: inst.id,
        surface: res.surface_by_id(&r, inst.id)?,
        same_sense: true,
        bounds: Vec::new(),
    }))
}

/// Which parameters of `def` are angles (in the file's plane-angle unit in a
/// RECTANGULAR_TRIMMED_SURFACE): the turn of surfaces of revolution, both of a sphere and a
/// torus, and a conic profile's.
fn angular(def: &SurfaceDef) -> [bool; 2] {
    use super::entities::Curve;
    let conic = |c: &Curve| {
        matches!(
            c.space_curve(),
            Curve::Circle { .. } | Curve::Ellipse { .. }
        )
    };
    match def {
        SurfaceDef::Cylinder { .. } | SurfaceDef::Cone { .. } => [true, false],
        SurfaceDef::Sphere { .. } | SurfaceDef::Torus { .. } => [true, true],
        SurfaceDef::Revolution { profile, .. } => [true, conic(profile)],
        SurfaceDef::Extrusion { profile, .. } => [conic(profile), false],
        _ => [false, false],
    }
}

/// RECTANGULAR_TRIMMED_SURFACE(name, basis, u1, u2, v1, v2, usense, vsense). Along a
/// periodic parameter the senses choose the part kept, from u1 up to u2 (usense) or from
/// u2 up to u1, by whole periods; elsewhere the rectangle is between the two values, and a
/// parameter running from u1 down to u2 turns the normal (OpenCASCADE's
/// Geom_RectangularTrimmedSurface reads it the same way).
fn rectangle(res: &Resolver, r: &Rec) -> Result<Patch, ParseError> {
    let surface = res.surface_by_id(r, r.reference(1, "a basis surface")?)?;
    let angles = angular(&surface);
    let periods = surface.periods();
    let mut flip = false;
    let mut span = |axis: usize, first: usize| -> Result<[f64; 2], ParseError> {
        let scale = if angles[axis] { res.angle_unit } else { 1.0 };
        let a = r.real(first, "a parameter")? * scale;
        let b = r.real(first + 1, "a parameter")? * scale;
        let sense = r.boolean(6 + axis, "a sense")?;
        if !(a.is_finite() && b.is_finite()) || a == b {
            return Err(r.error(format!(
                "expected two different finite parameters, found {a} and {b}"
            )));
        }
        Ok(match periods[axis] {
            Some(p) => {
                let (lo, hi) = if sense { (a, b) } else { (b, a) };
                let d = (hi - lo).rem_euclid(p);
                [lo, lo + if d == 0.0 { p } else { d }]
            }
            None => {
                flip ^= a > b;
                [a.min(b), a.max(b)]
            }
        })
    };
    let u = span(0, 2)?;
    let v = span(1, 4)?;
    Ok(Patch {
        surface,
        u,
        v,
        flip,
    })
}

/// The patch as an exact NURBS surface (a B-spline basis cut to the rectangle by knot
/// insertion, which does not move it).
pub fn convert_patch(p: &Patch) -> Result<Surface, String> {
    let (nurbs, trim_space) = match &*p.surface {
        SurfaceDef::BSpline(n) => {
            let d = n.domain();
            let rect = ParamRect {
                u0: p.u[0].max(d.u0),
                u1: p.u[1].min(d.u1),
                v0: p.v[0].max(d.v0),
                v1: p.v[1].min(d.v1),
            };
            if !(rect.u0 < rect.u1 && rect.v0 < rect.v1) {
                return Err(format!(
                    "its rectangle [{}, {}] x [{}, {}] lies outside the B-spline's domain",
                    p.u[0], p.u[1], p.v[0], p.v[1]
                ));
            }
            (n.restricted(rect), Default::default())
        }
        def => surface_to_nurbs(def, p.u, p.v).map_err(|e| e.to_string())?,
    };
    let mut surface = Surface {
        geometry: SurfaceGeometry::Nurbs(nurbs),
        trims: Vec::new(),
        trim_space,
    };
    if p.flip {
        surface.flip_sides();
    }
    Ok(surface)
}

/// CURVE_BOUNDED_SURFACE(name, basis, boundaries, implicit_outer) as a face on its basis,
/// one bound per BOUNDARY_CURVE / OUTER_BOUNDARY_CURVE.
fn curve_bounded(res: &Resolver, r: &Rec) -> Result<Face, ParseError> {
    let surface_id = r.reference(1, "a basis surface")?;
    let surface = res.surface_by_id(r, surface_id)?;
    if r.boolean(3, "implicit_outer")? {
        return Err(res.unsupported(
            r,
            "explicit boundaries (implicit_outer .F.; the basis's natural bounds as the outer boundary are not read)",
        ));
    }
    let mut bounds = Vec::new();
    for id in r.references(2, "boundaries")? {
        let b = res.expect_type(r, id, &["OUTER_BOUNDARY_CURVE", "BOUNDARY_CURVE"], 2)?;
        bounds.push(res.deeper(&b, || boundary(res, &b))?);
    }
    Ok(Face {
        id: r.inst.id,
        surface_id,
        surface,
        same_sense: true,
        bounds,
    })
}

/// A boundary curve (a COMPOSITE_CURVE_ON_SURFACE: name, segments, self_intersect) as a
/// bound whose edges are its segments. ISO 10303-42 puts the surface to the left of its
/// boundaries, as a face lies to the left of a bound with orientation .T.
fn boundary(res: &Resolver, b: &Rec) -> Result<Bound, ParseError> {
    let mut edges = Vec::new();
    for id in b.references(1, "composite curve segments")? {
        edges.push(res.segment(b, id, None)?);
    }
    if edges.is_empty() {
        return Err(b.error("expected at least one segment"));
    }
    Ok(Bound {
        id: b.inst.id,
        outer: b.rec.name == "OUTER_BOUNDARY_CURVE",
        orientation: true,
        edges,
        vertex: None,
    })
}
