//! A bounding volume hierarchy over primitive boxes (tight patch boxes, LG90 §3.1 Fig. 2),
//! the accelerator Dammertz 2005 §3.2 found fastest for patches: a binary tree of axis-aligned
//! boxes, traversed with the nearer child first so that a hit found early shortens the ray and
//! prunes the far subtrees.
//!
//! - [`build`](Bvh::build): top-down binned surface area heuristic (Wald, "On fast Construction
//!   of SAH-based Bounding Volume Hierarchies", 2007) in place of Dammertz's median cut.
//!   [`build_packed`](Bvh::build_packed) prices leaves of primitives tested in SIMD packs per
//!   started pack, so the heuristic fills packs.
//! - [`traverse`](Bvh::traverse) / [`traverse_any`](Bvh::traverse_any) /
//!   [`traverse_leaves`](Bvh::traverse_leaves): stack-based, nearest-entry child first, no
//!   allocation per ray, over a 4-wide form of the tree derived on construction (`wide`).
//! - [`write`](Bvh::write) / [`read`](Bvh::read): a versioned little-endian file with the
//!   key of the inputs it was built from and a [`checksum`], validated so that no file can
//!   make traversal panic or loop; a scene's file appends its prepared patches
//!   ([`crate::accel::mapped`]).

mod build;
mod file;
mod traverse;
mod wide;

pub use file::{BvhFileError, FORMAT_VERSION, MAGIC, checksum};
pub(crate) use file::{check_key, field};
pub use traverse::TraversalStats;

use crate::geom::Aabb;
use crate::progress::ProgressBar;

/// Deepest node level (the root is level 0) the builder creates; below it a subtree becomes a
/// leaf. Traversal keeps a fixed stack of this many entries, which suffices because it pushes
/// at most one entry per level. 64 levels hold far more primitives than a binary SAH tree over
/// real scenes needs (it is about 2 log2 n deep), so the limit only stops pathological inputs.
pub const MAX_DEPTH: usize = 64;

/// Largest leaf the builder makes unless the depth limit or identical centroids force a larger
/// one. Dammertz §3.2 keeps one patch per leaf; the SAH may group up to this many where that is
/// cheaper (a few box tests against one more level of nodes).
pub const MAX_LEAF_PRIMS: usize = 4;

/// One tree node, 32 bytes, stored in the file as is. An inner node (`count == 0`) has its two
/// children at `first` and `first + 1`, both after it in the array (so the tree has no
/// cycles); a leaf covers `prim_indices[first .. first + count]`.
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
#[repr(C)]
pub struct Node {
    pub bounds: Aabb,
    pub first: u32,
    pub count: u32,
}

impl Node {
    pub fn is_leaf(&self) -> bool {
        self.count > 0
    }
}

/// The hierarchy: nodes with the root at index 0 (no nodes for an empty scene) and the
/// primitive indices the leaves point into, a permutation of `0..primitive count`. The wide
/// form that traversal walks is derived from the nodes and never stored.
#[derive(Clone, Debug, PartialEq)]
pub struct Bvh {
    nodes: Vec<Node>,
    prim_indices: Vec<u32>,
    wide: Vec<wide::WideNode>,
}

impl Bvh {
    /// Builds the tree over `boxes`; primitive `i` is the one with box `boxes[i]`.
    pub fn build(boxes: &[Aabb]) -> Bvh {
        build::build(boxes, boxes.len(), &ProgressBar::hidden())
    }

    /// [`build`](Bvh::build) for a caller that tests primitives `first_packed..` in SIMD
    /// packs of [`PACK_WIDTH`](crate::kernel::triangle::PACK_WIDTH) (triangles): their leaves are priced per started pack, so the
    /// heuristic prefers full packs to more, emptier leaves.
    pub fn build_packed(boxes: &[Aabb], first_packed: usize) -> Bvh {
        Bvh::build_packed_with(boxes, first_packed, &ProgressBar::hidden())
    }

    /// [`build_packed`](Bvh::build_packed), advancing `progress` by one per primitive as
    /// the leaves are made.
    pub fn build_packed_with(boxes: &[Aabb], first_packed: usize, progress: &ProgressBar) -> Bvh {
        build::build(boxes, first_packed, progress)
    }

    /// Assembles a tree from its arrays (from another builder or a file), refusing any that
    /// breaks the invariants traversal relies on; see [`BvhFileError::Invalid`].
    pub fn from_parts(nodes: Vec<Node>, prim_indices: Vec<u32>) -> Result<Bvh, BvhFileError> {
        Bvh::validate(&nodes, &prim_indices).map_err(BvhFileError::Invalid)?;
        Ok(Bvh::with_wide(nodes, prim_indices))
    }

    /// The tree with its wide form; `nodes` must be valid.
    fn with_wide(nodes: Vec<Node>, prim_indices: Vec<u32>) -> Bvh {
        Bvh {
            wide: wide::collapse(&nodes),
            nodes,
            prim_indices,
        }
    }

    /// The box of everything ([`Aabb::EMPTY`] for no primitives).
    pub fn bounds(&self) -> Aabb {
        self.nodes.first().map_or(Aabb::EMPTY, |n| n.bounds)
    }

    pub fn node_count(&self) -> usize {
        self.nodes.len()
    }

    pub fn prim_count(&self) -> usize {
        self.prim_indices.len()
    }

    pub fn nodes(&self) -> &[Node] {
        &self.nodes
    }

    pub fn prim_indices(&self) -> &[u32] {
        &self.prim_indices
    }

    /// The surface area heuristic cost of the tree (MacDonald and Booth 1990): each node's
    /// area relative to the root's times its cost, [`build::TRAVERSAL_COST`] for an inner node
    /// and [`build::PRIM_COST`] per primitive for a leaf. Lower is better; for comparing
    /// builders over the same boxes.
    pub fn sah_cost(&self) -> f32 {
        let root = build::area(&self.bounds());
        let scale = if root > 0.0 && root.is_finite() {
            1.0 / root
        } else {
            1.0
        };
        let total: f64 = self
            .nodes
            .iter()
            .map(|n| {
                let cost = if n.is_leaf() {
                    build::PRIM_COST * f64::from(n.count)
                } else {
                    build::TRAVERSAL_COST
                };
                build::area(&n.bounds) * scale * cost
            })
            .sum();
        total as f32
    }

    /// Checks what traversal relies on: children after their parent and in range, every node
    /// but the root with exactly one parent, depth below [`MAX_DEPTH`], leaves in range of the
    /// index array, and the indices a permutation of `0..prim_count`.
    fn validate(nodes: &[Node], prim_indices: &[u32]) -> Result<(), String> {
        let n = nodes.len();
        let prims = prim_indices.len();
        if n == 0 {
            return if prims == 0 {
                Ok(())
            } else {
                Err(format!("no nodes but {prims} primitive indices"))
            };
        }
        let mut depth = vec![0usize; n];
        let mut parents = vec![0u8; n];
        let mut covered = vec![false; prims];
        for (i, node) in nodes.iter().enumerate() {
            if parents[i] != u8::from(i != 0) {
                return Err(format!(
                    "node {i} is not reached exactly once from the root"
                ));
            }
            let first = node.first as usize;
            if node.is_leaf() {
                let end = first
                    .checked_add(node.count as usize)
                    .filter(|&e| e <= prims);
                let Some(end) = end else {
                    return Err(format!(
                        "leaf {i} points past the {prims} primitive indices"
                    ));
                };
                for &p in &prim_indices[first..end] {
                    match covered.get_mut(p as usize) {
                        Some(seen @ false) => *seen = true,
                        Some(true) => return Err(format!("primitive {p} is in two leaves")),
                        None => return Err(format!("primitive index {p} out of range")),
                    }
                }
            } else {
                if first <= i || first + 1 >= n {
                    return Err(format!(
                        "node {i} has children {first} and {} out of order or range",
                        first + 1
                    ));
                }
                if depth[i] + 1 >= MAX_DEPTH {
                    return Err(format!("tree deeper than {MAX_DEPTH} levels"));
                }
                for c in [first, first + 1] {
                    depth[c] = depth[i] + 1;
                    parents[c] = parents[c].saturating_add(1);
                }
            }
        }
        match covered.iter().position(|&c| !c) {
            Some(p) => Err(format!("primitive {p} is in no leaf")),
            None => Ok(()),
        }
    }
}
