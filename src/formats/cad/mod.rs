//! The CAD exchange formats: IGES 5.3 ([`iges`]) and STEP AP203/AP214/AP242 ([`step`]),
//! read exactly (trimmed rational NURBS, no tessellation), in millimetres, and the front
//! door ([`scene`]) that turns what any of them read into a scene.

pub mod iges;
pub mod scene;
pub mod step;

/// Largest distance, relative to the model's (or surface's) size, between a trim curve
/// projected from model space and the surface image of the polyline that stands for it in
/// the domain, in every CAD reader: 1e-5 of the model is well below a pixel of any framing
/// view (a 4k image resolves 2.5e-4 of it).
pub const CHORD_TOLERANCE: f64 = 1e-5;
