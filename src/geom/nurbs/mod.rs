//! NURBS surfaces: knot vectors, Cox–de Boor evaluation, Boehm knot insertion, clamping and
//! exact decomposition into Bézier patches (Piegl & Tiller, *The NURBS Book*, A2.1, A2.2,
//! A5.1, A5.6/A5.7), the conversion Dammertz 2005, §2.8 uses to ray trace NURBS as Bézier
//! patches.
//!
//! - `knots`: validation, multiplicity, domain.
//! - `basis`: FindSpan and BasisFuns.
//! - `curve`: the NURBS curve, the unit the row-by-row surface algorithms act on.
//! - `surface`: the NURBS surface, its validation and evaluation.
//! - `insert`: knot insertion and clamping.
//! - `decompose`: Bézier decomposition.
//! - `shapes`: exact torus and sphere built from the 9-point circle.
//! - `analytic`: analytic curves and surfaces (arcs, conics, planes, quadrics, tori,
//!   revolutions, extrusions, ruled surfaces) as exact rational NURBS for the CAD readers.
//! - `periodic`: a closed surface repeated over whole periods, for loops across its seam.
//! - `inversion`: the closest point of a surface to a point (The NURBS Book §6.1).

pub mod analytic;
pub mod basis;
pub mod curve;
pub mod decompose;
pub mod insert;
pub mod inversion;
pub mod knots;
pub mod periodic;
pub mod shapes;
pub mod surface;

#[cfg(test)]
mod testutil;

pub use curve::NurbsCurve;
pub use decompose::BezierSegment;
pub use knots::KnotError;
pub use surface::NurbsSurface;
