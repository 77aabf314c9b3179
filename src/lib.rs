//! patchtrace: ray tracing Bézier patches and NURBS surfaces directly, to the precision of
//! `f32` itself, without tessellating them first.
//!
//! Data flows one way: readers ([`formats`]) → scene model ([`scene`]) → (NURBS
//! conversion, [`geom::nurbs`]) → accelerator ([`accel`]) → kernels ([`kernel`]) →
//! integrator and film ([`render`]).
//! The command-line front end lives in [`cli`].

// Numeric kernels index control nets by (i, j) in lockstep across several arrays; index
// loops say that more plainly than zipped iterators.
#![allow(clippy::needless_range_loop)]

pub mod accel;
pub mod bench;
pub mod cli;
pub mod diff;
pub mod formats;
pub mod geom;
pub mod io;
pub mod kernel;
pub mod progress;
pub mod render;
pub mod scene;
pub mod tessellate;
