//! Top-down binned SAH construction (Wald 2007, "On fast Construction of SAH-based Bounding
//! Volume Hierarchies", §3): primitives are binned by centroid along each axis, and the split
//! between bins with the lowest surface area heuristic cost (MacDonald and Booth 1990) wins,
//! unless a leaf is cheaper. Centroids and areas are computed in `f64` so that boxes near the
//! `f32` range limit neither overflow nor produce NaN costs.

use glam::DVec3;

use super::{Bvh, MAX_DEPTH, MAX_LEAF_PRIMS, Node};
use crate::geom::Aabb;
use crate::kernel::triangle::PACK_WIDTH;
use crate::progress::{Batched, ProgressBar};

/// Centroid bins per axis. Wald 2007 §3.1 finds 16–32 bins within a few percent of the full
/// sweep SAH; the upper end costs little for patch counts.
const BINS: usize = 32;

/// SAH cost of visiting an inner node: one ray–box test per child, the unit of both costs.
pub(super) const TRAVERSAL_COST: f64 = 1.0;

/// SAH cost per primitive in a leaf, in the same unit: the caller's first step on a primitive
/// is the test against its own tight box (Dammertz §2.3), so about one box test; the deeper
/// patch work happens only for boxes the ray really hits, which no tree can avoid.
pub(super) const PRIM_COST: f64 = 1.0;

/// SAH cost per started pack of packed primitives: one pack test costs about one wide node
/// test (callgrind, BENCHMARKS.md issue 4: ≈ 160 against ≈ 130 instructions), so a leaf of
/// one to four packed primitives costs what a lone primitive does and the heuristic keeps
/// packs full instead of splitting them into half-empty ones.
pub(super) const PACK_COST: f64 = 1.0;

/// Cost per unit area of a leaf with `count` primitives of which `packed` are tested in
/// packs of [`PACK_WIDTH`].
fn leaf_cost(count: usize, packed: usize) -> f64 {
    PRIM_COST * (count - packed) as f64 + PACK_COST * packed.div_ceil(PACK_WIDTH) as f64
}

/// Surface area in `f64` (0 for an empty box).
pub(super) fn area(b: &Aabb) -> f64 {
    if b.is_empty() {
        return 0.0;
    }
    let e = b.max.as_dvec3() - b.min.as_dvec3();
    2.0 * (e.x * e.y + e.y * e.z + e.z * e.x)
}

/// The tree over `boxes`; primitives from `first_packed` on are priced in packs (see
/// [`PACK_COST`]). `progress` advances by the leaves' primitives as they are made, so it
/// reaches `boxes.len()` when the tree is done.
pub(super) fn build(boxes: &[Aabb], first_packed: usize, progress: &ProgressBar) -> Bvh {
    let n = boxes.len();
    // Indices are u32 in the file and the traversal callback.
    assert!(u32::try_from(n).is_ok(), "more than u32::MAX primitives");
    let mut builder = Builder {
        boxes,
        centroids: boxes
            .iter()
            .map(|b| (b.min.as_dvec3() + b.max.as_dvec3()) * 0.5)
            .collect(),
        prims: (0..n as u32).collect(),
        first_packed: first_packed.min(n) as u32,
        nodes: Vec::with_capacity((2 * n).saturating_sub(1)),
        progress: Batched::new(progress),
    };
    if n > 0 {
        builder.nodes.push(Node {
            bounds: Aabb::EMPTY,
            first: 0,
            count: 0,
        });
        builder.subdivide(0, 0, n, 0);
    }
    Bvh::with_wide(builder.nodes, builder.prims)
}

struct Builder<'a> {
    boxes: &'a [Aabb],
    centroids: Vec<DVec3>,
    prims: Vec<u32>,
    /// Primitives with this index or above are tested in packs.
    first_packed: u32,
    nodes: Vec<Node>,
    progress: Batched<'a>,
}

#[derive(Clone, Copy)]
struct Bin {
    bounds: Aabb,
    count: usize,
    /// Of `count`, the primitives tested in packs.
    packed: usize,
}

const EMPTY_BIN: Bin = Bin {
    bounds: Aabb::EMPTY,
    count: 0,
    packed: 0,
};

/// Where to split `prims[start..end]`: by bin along an axis, or in the middle of the range when
/// all centroids coincide (identical boxes) but the range is too big for a leaf.
enum Split {
    Bin {
        axis: usize,
        offset: f64,
        scale: f64,
        last_left: usize,
    },
    Middle,
}

impl Builder<'_> {
    fn subdivide(&mut self, node: usize, start: usize, end: usize, depth: usize) {
        let bounds = self.prims[start..end]
            .iter()
            .fold(Aabb::EMPTY, |b, &p| b.union(&self.boxes[p as usize]));
        let count = end - start;
        let split = if count > 1 && depth + 1 < MAX_DEPTH {
            self.choose_split(start, end, &bounds)
        } else {
            None
        };
        let Some(split) = split else {
            self.nodes[node] = Node {
                bounds,
                first: start as u32,
                count: count as u32,
            };
            self.progress.add(count as u64);
            return;
        };
        let mid = match split {
            Split::Middle => start + count / 2,
            Split::Bin {
                axis,
                offset,
                scale,
                last_left,
            } => self.partition(start, end, |c| bin_of(c[axis], offset, scale) <= last_left),
        };
        let first = self.nodes.len();
        self.nodes[node] = Node {
            bounds,
            first: first as u32,
            count: 0,
        };
        let placeholder = self.nodes[node];
        self.nodes.extend([placeholder; 2]);
        self.subdivide(first, start, mid, depth + 1);
        self.subdivide(first + 1, mid, end, depth + 1);
    }

    /// The cheapest binned split, or `None` when a leaf is at least as cheap and allowed.
    fn choose_split(&self, start: usize, end: usize, bounds: &Aabb) -> Option<Split> {
        let prims = &self.prims[start..end];
        let count = prims.len();
        let (cmin, cmax) = prims.iter().fold(
            (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
            |(lo, hi), &p| {
                let c = self.centroids[p as usize];
                (lo.min(c), hi.max(c))
            },
        );
        let packed = prims.iter().filter(|&&p| p >= self.first_packed).count();
        // Costs are compared without dividing by the parent's area, which may be 0.
        let as_leaf = leaf_cost(count, packed) * area(bounds);
        let mut best: Option<(f64, Split)> = None;
        for axis in 0..3 {
            let extent = cmax[axis] - cmin[axis];
            if !(extent > 0.0 && extent.is_finite()) {
                continue;
            }
            let offset = cmin[axis];
            let scale = BINS as f64 / extent;
            let mut bins = [EMPTY_BIN; BINS];
            for &p in prims {
                let b = &mut bins[bin_of(self.centroids[p as usize][axis], offset, scale)];
                b.bounds = b.bounds.union(&self.boxes[p as usize]);
                b.count += 1;
                b.packed += usize::from(p >= self.first_packed);
            }
            // Sweep from the right to get each suffix, then from the left to price each split.
            let mut right_area = [0.0; BINS];
            let mut acc = EMPTY_BIN;
            for i in (1..BINS).rev() {
                acc.bounds = acc.bounds.union(&bins[i].bounds);
                acc.count += bins[i].count;
                acc.packed += bins[i].packed;
                right_area[i] = area(&acc.bounds) * leaf_cost(acc.count, acc.packed);
            }
            let mut left = EMPTY_BIN;
            for i in 0..BINS - 1 {
                left.bounds = left.bounds.union(&bins[i].bounds);
                left.count += bins[i].count;
                left.packed += bins[i].packed;
                if left.count == 0 || left.count == count {
                    continue;
                }
                let cost = TRAVERSAL_COST * area(bounds)
                    + area(&left.bounds) * leaf_cost(left.count, left.packed)
                    + right_area[i + 1];
                if best.as_ref().is_none_or(|(c, _)| cost < *c) {
                    let split = Split::Bin {
                        axis,
                        offset,
                        scale,
                        last_left: i,
                    };
                    best = Some((cost, split));
                }
            }
        }
        match best {
            Some((cost, _)) if cost >= as_leaf && count <= MAX_LEAF_PRIMS => None,
            Some((_, split)) => Some(split),
            None if count > MAX_LEAF_PRIMS => Some(Split::Middle),
            None => None,
        }
    }

    /// Moves the primitives whose centroid satisfies `left` to the front of the range and
    /// returns the first index of the rest.
    fn partition(&mut self, start: usize, end: usize, left: impl Fn(DVec3) -> bool) -> usize {
        let mut mid = start;
        for i in start..end {
            if left(self.centroids[self.prims[i] as usize]) {
                self.prims.swap(i, mid);
                mid += 1;
            }
        }
        mid
    }
}

/// The bin of a centroid coordinate; NaN and out-of-range values clamp to the end bins
/// (`as usize` saturates and maps NaN to 0).
fn bin_of(c: f64, offset: f64, scale: f64) -> usize {
    (((c - offset) * scale) as usize).min(BINS - 1)
}
