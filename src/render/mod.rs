//! Rendering: camera rays, the Whitted integrator with its effect plan, the film and image
//! output, and statistics.

pub mod camera;
