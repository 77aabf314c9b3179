//! Rendering: camera rays, pixel samples and filters, the Whitted integrator with its
//! effect plan, the film and image output (with the colour-mapped heat maps the effort
//! AOV and `diff` draw), sampling orders (LG90 §5), windows and tiles,
//! and statistics.

pub mod aov;
pub mod camera;
pub mod film;
pub mod heatmap;
pub mod integrator;
pub mod order;
pub mod piece;
pub mod plan;
pub mod renderer;
pub mod sampler;
pub mod stats;
pub mod window;
