//! The CAD exchange formats: IGES 5.3 ([`iges`]) and STEP AP203/AP214/AP242 ([`step`]),
//! read exactly (trimmed rational NURBS, no tessellation), in millimetres.

pub mod iges;
pub mod step;
