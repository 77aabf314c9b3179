//! Rendering: camera rays, the Whitted integrator with its effect plan, the film and image
//! output, sampling orders (LG90 §5), and statistics.

pub mod camera;
pub mod film;
pub mod integrator;
pub mod order;
pub mod plan;
pub mod renderer;
pub mod stats;
