//! The CAD exchange formats: IGES 5.3 ([`iges`]) and STEP AP203/AP214/AP242 ([`step`]),
//! read exactly (trimmed rational NURBS, no tessellation), in millimetres, and the front
//! door ([`scene`]) that turns what any of them read into a scene.

pub mod iges;
pub mod scene;
pub mod step;
