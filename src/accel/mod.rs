//! Acceleration structures over patch bounding boxes.
//!
//! - [`bvh`]: a SAH bounding volume hierarchy over tight patch boxes (LG90 §3.1 Fig. 2
//!   boxes; Dammertz §3.2), traversed nearest-first, serializable to a versioned file.

pub mod bvh;
pub mod scene;
