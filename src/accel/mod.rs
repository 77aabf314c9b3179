//! Acceleration structures over patch bounding boxes, and the scene's geometry as queries
//! see it.
//!
//! - [`scene`]: the scene's prepared geometry (`SceneGeometry`): the build, one query
//!   through the BVH or grid (nearest or any hit), the `f64` reference path, hit finishing
//!   and secondary-ray origins, triangle packs, and the BVH file's geometry.
//! - [`bvh`]: a SAH bounding volume hierarchy over tight patch boxes (LG90 §3.1 Fig. 2
//!   boxes; Dammertz §3.2), traversed nearest-first, serializable to a versioned file.
//! - [`mapped`]: a scene's BVH file, the tree and the prepared patches, mapped by
//!   `render --bvh`.
//! - [`grid`]: the uniform grid of LG90 §3.1 with `l_a(S)` registration, mailboxes and a
//!   3D DDA that stops after the voxel holding the closest hit.
//! - `instance`: placements of shared geometry (Dammertz §3.3): rays into object space,
//!   hits back to world space with a rounding bound.
//! - `patches`: the prepared patches, owned or mapped from a BVH file.

pub mod bvh;
pub mod grid;
mod instance;
pub mod mapped;
mod patches;
pub mod scene;
