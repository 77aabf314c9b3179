//! Rendering: camera rays, the Whitted integrator with its effect plan, the film and image
//! output, and statistics.

pub mod camera;
pub mod film;
pub mod integrator;
pub mod plan;
pub mod renderer;
pub mod stats;
