//! The CAD exchange formats: IGES 5.3 ([`iges`]) and STEP AP203/AP214/AP242 ([`step`]),
//! read exactly (trimmed rational NURBS, no tessellation), in millimetres, and the front
//! door ([`scene`]) that turns what any of them read into a scene.

pub mod iges;
pub mod scene;
pub mod step;

/// Largest distance, relative to the model's (or surface's) size, between a trim curve
/// projected from model space and the surface image of the polyline that stands for it in
/// the domain, in every CAD reader: 1e-6 of the model, far below a pixel of any framing
/// view (a 4k image resolves 2.5e-4 of it) and ten times below the distance at which two
/// points are one ([`POINT_TOLERANCE`]), so a trim adds no gap a file does not have.
pub const CHORD_TOLERANCE: f64 = 1e-6;

/// Distance, relative to the model's (or surface's) size, within which two points of a
/// CAD model are one point: the ends of edges that meet, a surface closing on itself, a
/// periodic parameter collapsing at a pole. Files round their points to about this (CAD
/// systems' default modelling tolerances are 1e-5 to 1e-6 of a part).
pub const POINT_TOLERANCE: f64 = 1e-5;

/// The projection tolerances of a model (or surface) of size `size`.
pub fn projection_tolerance(size: f64) -> crate::geom::pcurve::Tolerance {
    crate::geom::pcurve::Tolerance {
        chord: CHORD_TOLERANCE * size,
        point: POINT_TOLERANCE * size,
    }
}
