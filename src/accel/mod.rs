//! Acceleration structures over patch bounding boxes.
//!
//! - [`bvh`]: a SAH bounding volume hierarchy over tight patch boxes (LG90 §3.1 Fig. 2
//!   boxes; Dammertz §3.2), traversed nearest-first, serializable to a versioned file.
//! - [`mapped`]: a scene's BVH file, the tree and the prepared patches, mapped by
//!   `render --bvh`.
//! - [`grid`]: the uniform grid of LG90 §3.1 with `l_a(S)` registration, mailboxes and a
//!   3D DDA that stops after the voxel holding the closest hit.

pub mod bvh;
pub mod grid;
mod instance;
pub mod mapped;
mod patches;
pub mod scene;
