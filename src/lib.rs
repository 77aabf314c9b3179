//! patchtrace: ray tracing Bézier patches and NURBS surfaces directly, to the precision of
//! `f32` itself, without tessellating them first.
//!
//! Data flows one way: parse ([`scene`]) → scene model → (NURBS conversion, [`geom::nurbs`])
//! → accelerator ([`accel`]) → kernels ([`kernel`]) → integrator and film ([`render`]).
//! The command-line front end lives in [`cli`].

pub mod accel;
pub mod cli;
pub mod geom;
pub mod kernel;
pub mod render;
pub mod scene;
pub mod tessellate;
