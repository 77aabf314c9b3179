//! The 4-wide form of the tree that traversal walks (a "QBVH": Dammertz, Hanika and Keller,
//! "Shallow Bounding Volume Hierarchies for Fast SIMD Ray Tracing of Incoherent Rays", 2008;
//! Embree's BVH4): every inner node holds the boxes of up to four children in
//! structure-of-arrays form, so that one SIMD slab test decides all four. It is derived from
//! the binary tree (which stays the stored and validated form) by pulling grandchildren up:
//! of a node's current children the inner one with the largest surface area is replaced by
//! its two children until there are four or only leaves remain (Dammertz et al. §2.1).

use glam::Vec4;

use super::{Node, build::area};
use crate::geom::Aabb;

/// Children per wide node: one SSE register of `f32` lanes.
pub(super) const WIDTH: usize = 4;

/// One child reference: an inner wide node (`count == 0`, `index` into the wide array) or a
/// leaf (`count > 0` primitives from `index` in the primitive index array).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Child {
    pub index: u32,
    pub count: u32,
}

/// A wide node: child box planes with one lane per child, `planes[axis]` the minima and
/// `planes[3 + axis]` the maxima (one array, so that traversal picks a ray's near and far
/// planes by an index computed once per ray), then the children. Unused lanes have the
/// empty box (`min = +inf`, `max = -inf`), which the slab test in `traverse` never enters,
/// so they need no mask.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C)]
pub(super) struct WideNode {
    pub planes: [Vec4; 6],
    pub children: [Child; WIDTH],
}

/// The wide tree of a valid binary tree `nodes` (root at 0), root at index 0; empty for no
/// nodes. A binary tree that is a single leaf becomes one wide node with that leaf as its
/// only child.
pub(super) fn collapse(nodes: &[Node]) -> Vec<WideNode> {
    let mut wide = Vec::with_capacity(nodes.len() / 2 + 1);
    if !nodes.is_empty() {
        push(nodes, &[0], &mut wide);
    }
    wide
}

/// Appends the wide node whose children are the binary nodes `start` (or their descendants,
/// pulled up) and its subtrees, returning its index.
fn push(nodes: &[Node], start: &[usize], wide: &mut Vec<WideNode>) -> u32 {
    // A fixed array, not a Vec: a 320,000-patch tree has about 120,000 wide nodes, and
    // `render --bvh` collapses the tree on every load.
    let mut kids = [0usize; WIDTH];
    let mut len = start.len();
    kids[..len].copy_from_slice(start);
    while len < WIDTH {
        let widest = (0..len)
            .filter(|&slot| !nodes[kids[slot]].is_leaf())
            .max_by(|&a, &b| area(&nodes[kids[a]].bounds).total_cmp(&area(&nodes[kids[b]].bounds)));
        let Some(slot) = widest else { break };
        let first = nodes[kids[slot]].first as usize;
        kids[slot] = first;
        kids[len] = first + 1;
        len += 1;
    }
    let kids = &kids[..len];
    let at = wide.len();
    wide.push(WideNode {
        planes: [
            Vec4::INFINITY,
            Vec4::INFINITY,
            Vec4::INFINITY,
            Vec4::NEG_INFINITY,
            Vec4::NEG_INFINITY,
            Vec4::NEG_INFINITY,
        ],
        children: [Child { index: 0, count: 0 }; WIDTH],
    });
    for (lane, &k) in kids.iter().enumerate() {
        let n = nodes[k];
        let child = if n.is_leaf() {
            Child {
                index: n.first,
                count: n.count,
            }
        } else {
            let inner = [n.first as usize, n.first as usize + 1];
            Child {
                index: push(nodes, &inner, wide),
                count: 0,
            }
        };
        let w = &mut wide[at];
        set_lane(w, lane, &n.bounds);
        w.children[lane] = child;
    }
    at as u32
}

fn set_lane(w: &mut WideNode, lane: usize, b: &Aabb) {
    for axis in 0..3 {
        w.planes[axis][lane] = b.min[axis];
        w.planes[3 + axis][lane] = b.max[axis];
    }
}
