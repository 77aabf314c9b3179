//! Top-down binned SAH construction (Wald 2007, "On fast Construction of SAH-based Bounding
//! Volume Hierarchies", §3): primitives are binned by centroid along each axis, and the split
//! between bins with the lowest surface area heuristic cost (MacDonald and Booth 1990) wins,
//! unless a leaf is cheaper.
//!
//! Binning works in `f32` on primitive references that carry their box (Wald 2007 §3.2:
//! the partition moves the references themselves, so every pass reads memory in order),
//! and each bin also keeps the box of its centroids, so a child's box and centroid range
//! come out of its parent's bins with no pass of their own. Centroids are `min/2 + max/2`,
//! which cannot overflow near the `f32` range limit; areas and costs stay in `f64` (a few
//! dozen per node), so such boxes produce no NaN costs.
//!
//! Parallel on all cores (rayon) in the two ways Wald 2007 §4 names: ranges of at least
//! [`PARALLEL_BINNING`] primitives bin in chunks merged afterwards, and the two children of a
//! range of at least [`PARALLEL_SUBTREES`] primitives are built as two tasks, each into its
//! own node array, appended to the parent's with their indices shifted. Which ranges take
//! which path depends on their size only, and bin merges are exact (min, max and counts), so
//! the tree is the same for any thread count.

use glam::{UVec3, Vec3A, Vec4};
use rayon::prelude::*;

use super::{Bvh, MAX_DEPTH, MAX_LEAF_PRIMS, Node};
use crate::geom::Aabb;
use crate::kernel::triangle::PACK_WIDTH;
use crate::progress::{Batched, ProgressBar};

/// Centroid bins per axis. Wald 2007 §3.1 finds 16–32 bins within a few percent of the full
/// sweep SAH; the upper end costs little for patch counts.
const BINS: usize = 32;

/// Ranges at least this large are binned in parallel chunks of this size. Below it the
/// chunk bookkeeping (three times [`BINS`] bins per chunk) outweighs the pass.
const PARALLEL_BINNING: usize = 1 << 15;

/// Ranges at least this large build their two subtrees as parallel tasks. Below it a task
/// costs more than the work it moves to the other core (a 4096-primitive subtree takes about
/// a millisecond), and the shifted copy of the subtree's nodes is paid only at these levels.
const PARALLEL_SUBTREES: usize = 1 << 12;

/// SAH cost of visiting an inner node: one ray–box test per child, the unit of both costs.
pub(super) const TRAVERSAL_COST: f64 = 1.0;

/// SAH cost per primitive in a leaf, in the same unit: the caller's first step on a primitive
/// is the test against its own tight box (Dammertz §2.3), so about one box test; the deeper
/// patch work happens only for boxes the ray really hits, which no tree can avoid.
pub(super) const PRIM_COST: f64 = 1.0;

/// SAH cost per started pack of packed primitives: one pack test costs about one wide node
/// test (callgrind, BENCHMARKS.md, scenes at scale: ≈ 160 against ≈ 130 instructions), so a leaf of
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

/// A primitive as the builder moves it: its box as two SIMD registers, the primitive's index
/// in the spare lane of the lower corner (`f32` bits, only ever copied).
#[derive(Clone, Copy)]
struct PrimRef {
    lower: Vec4,
    upper: Vec4,
}

impl PrimRef {
    fn new(b: &Aabb, index: u32) -> PrimRef {
        PrimRef {
            lower: b.min.extend(f32::from_bits(index)),
            upper: b.max.extend(0.0),
        }
    }

    fn index(&self) -> u32 {
        self.lower.w.to_bits()
    }

    fn bounds(&self) -> Box3 {
        Box3 {
            lo: Vec3A::from_vec4(self.lower),
            hi: Vec3A::from_vec4(self.upper),
        }
    }
}

/// An axis-aligned box in SIMD registers; empty when `lo > hi`.
#[derive(Clone, Copy)]
struct Box3 {
    lo: Vec3A,
    hi: Vec3A,
}

impl Box3 {
    const EMPTY: Box3 = Box3 {
        lo: Vec3A::INFINITY,
        hi: Vec3A::NEG_INFINITY,
    };

    fn union(&self, o: &Box3) -> Box3 {
        Box3 {
            lo: self.lo.min(o.lo),
            hi: self.hi.max(o.hi),
        }
    }

    fn grow(&mut self, p: Vec3A) {
        self.lo = self.lo.min(p);
        self.hi = self.hi.max(p);
    }

    fn centroid(&self) -> Vec3A {
        self.lo * 0.5 + self.hi * 0.5
    }

    fn to_aabb(self) -> Aabb {
        Aabb {
            min: self.lo.into(),
            max: self.hi.into(),
        }
    }
}

/// What the builder knows of a set of primitives: their box, the box of their centroids,
/// how many there are and how many of them are tested in packs. A bin, and a node's range.
#[derive(Clone, Copy)]
struct Bin {
    bounds: Box3,
    centroids: Box3,
    count: u32,
    packed: u32,
}

const EMPTY_BIN: Bin = Bin {
    bounds: Box3::EMPTY,
    centroids: Box3::EMPTY,
    count: 0,
    packed: 0,
};

impl Bin {
    fn add(&mut self, b: &Box3, c: Vec3A, packed: bool) {
        self.bounds = self.bounds.union(b);
        self.centroids.grow(c);
        self.count += 1;
        self.packed += u32::from(packed);
    }

    /// Exact in any order (min, max and sums), so merged chunks give the same bins as one
    /// pass.
    fn merge(&self, o: &Bin) -> Bin {
        Bin {
            bounds: self.bounds.union(&o.bounds),
            centroids: self.centroids.union(&o.centroids),
            count: self.count + o.count,
            packed: self.packed + o.packed,
        }
    }

    /// Leaf cost times area: the SAH term of this set as one child.
    fn cost(&self) -> f64 {
        area(&self.bounds.to_aabb()) * leaf_cost(self.count as usize, self.packed as usize)
    }
}

/// The tree over `boxes`; primitives from `first_packed` on are priced in packs (see
/// [`PACK_COST`]). `progress` advances by the leaves' primitives as they are made, so it
/// reaches `boxes.len()` when the tree is done.
pub(super) fn build(boxes: &[Aabb], first_packed: usize, progress: &ProgressBar) -> Bvh {
    let n = boxes.len();
    // Indices are u32 in the file and the traversal callback.
    assert!(u32::try_from(n).is_ok(), "more than u32::MAX primitives");
    let builder = Builder {
        first_packed: first_packed.min(n) as u32,
        progress,
    };
    let mut refs: Vec<PrimRef> = boxes
        .par_iter()
        .enumerate()
        .map(|(i, b)| PrimRef::new(b, i as u32))
        .collect();
    let nodes = if n == 0 {
        Vec::new()
    } else {
        let info = builder.extent(&refs);
        let mut batch = Batched::new(progress);
        builder.subtree(&mut refs, info, 0, 0, &mut batch)
    };
    let prims = refs.par_iter().map(PrimRef::index).collect();
    Bvh::with_wide(nodes, prims)
}

struct Builder<'a> {
    /// Primitives with this index or above are tested in packs.
    first_packed: u32,
    progress: &'a ProgressBar,
}

/// Where to split a range: by bin along an axis, or in the middle of the range when all
/// centroids coincide (identical boxes) but the range is too big for a leaf.
enum Split {
    Bin {
        axis: usize,
        offset: f32,
        scale: f32,
        last_left: usize,
        left: Bin,
        right: Bin,
    },
    Middle,
}

/// Bins of the three axes, one pass for all three.
type Bins = [[Bin; BINS]; 3];

impl Builder<'_> {
    fn packed(&self, r: &PrimRef) -> bool {
        r.index() >= self.first_packed
    }

    /// The [`Bin`] of all of `refs`.
    fn extent(&self, refs: &[PrimRef]) -> Bin {
        let one = |chunk: &[PrimRef]| {
            chunk.iter().fold(EMPTY_BIN, |mut bin, r| {
                let b = r.bounds();
                bin.add(&b, b.centroid(), self.packed(r));
                bin
            })
        };
        if refs.len() < PARALLEL_BINNING {
            return one(refs);
        }
        refs.par_chunks(PARALLEL_BINNING)
            .map(one)
            .reduce(|| EMPTY_BIN, |a, b| a.merge(&b))
    }

    /// The subtree over `refs` (whose first element is at `start` in the primitive order)
    /// in a node array of its own, root at 0.
    fn subtree(
        &self,
        refs: &mut [PrimRef],
        info: Bin,
        depth: usize,
        start: usize,
        batch: &mut Batched,
    ) -> Vec<Node> {
        let mut nodes = Vec::with_capacity((2 * refs.len()).saturating_sub(1));
        nodes.push(Node {
            bounds: info.bounds.to_aabb(),
            first: 0,
            count: 0,
        });
        self.subdivide(&mut nodes, 0, refs, info, depth, start, batch);
        nodes
    }

    /// Makes `nodes[node]` the root of the tree over `refs`, appending its descendants.
    #[allow(clippy::too_many_arguments)]
    fn subdivide(
        &self,
        nodes: &mut Vec<Node>,
        node: usize,
        refs: &mut [PrimRef],
        info: Bin,
        depth: usize,
        start: usize,
        batch: &mut Batched,
    ) {
        let count = refs.len();
        let split = if count > 1 && depth + 1 < MAX_DEPTH {
            self.choose_split(refs, &info)
        } else {
            None
        };
        let Some(split) = split else {
            nodes[node] = Node {
                bounds: info.bounds.to_aabb(),
                first: start as u32,
                count: count as u32,
            };
            batch.add(count as u64);
            return;
        };
        let (mid, left, right) = match split {
            Split::Middle => {
                let mid = count / 2;
                (mid, self.extent(&refs[..mid]), self.extent(&refs[mid..]))
            }
            Split::Bin {
                axis,
                offset,
                scale,
                last_left,
                left,
                right,
            } => {
                let mid = partition(refs, |r| {
                    bin_of(r.bounds().centroid()[axis], offset, scale) <= last_left
                });
                (mid, left, right)
            }
        };
        let first = nodes.len();
        nodes[node] = Node {
            bounds: info.bounds.to_aabb(),
            first: first as u32,
            count: 0,
        };
        let (l, r) = refs.split_at_mut(mid);
        if count >= PARALLEL_SUBTREES {
            let (a, b) = rayon::join(
                || self.subtree(l, left, depth + 1, start, &mut Batched::new(self.progress)),
                || {
                    let mut batch = Batched::new(self.progress);
                    self.subtree(r, right, depth + 1, start + mid, &mut batch)
                },
            );
            append_children(nodes, a, b);
        } else {
            let placeholder = nodes[node];
            nodes.extend([placeholder; 2]);
            self.subdivide(nodes, first, l, left, depth + 1, start, batch);
            self.subdivide(nodes, first + 1, r, right, depth + 1, start + mid, batch);
        }
    }

    /// Bins `refs` along all three axes: bin `k` of an axis holds the centroids `c` with
    /// `(c - offset) * scale` in `[k, k + 1)`, clamped to the end bins ([`bin_of`] lane by
    /// lane).
    fn bin(&self, refs: &[PrimRef], offset: Vec3A, scale: Vec3A) -> Bins {
        let last = UVec3::splat(BINS as u32 - 1);
        let one = |chunk: &[PrimRef]| {
            let mut bins = [[EMPTY_BIN; BINS]; 3];
            for r in chunk {
                let b = r.bounds();
                let c = b.centroid();
                let packed = self.packed(r);
                let k = ((c - offset) * scale).as_uvec3().min(last);
                for (axis, axis_bins) in bins.iter_mut().enumerate() {
                    axis_bins[k[axis] as usize].add(&b, c, packed);
                }
            }
            bins
        };
        if refs.len() < PARALLEL_BINNING {
            return one(refs);
        }
        refs.par_chunks(PARALLEL_BINNING).map(one).reduce(
            || [[EMPTY_BIN; BINS]; 3],
            |mut a, b| {
                for (x, y) in a.iter_mut().flatten().zip(b.iter().flatten()) {
                    *x = x.merge(y);
                }
                a
            },
        )
    }

    /// The cheapest binned split, or `None` when a leaf is at least as cheap and allowed.
    fn choose_split(&self, refs: &[PrimRef], info: &Bin) -> Option<Split> {
        let count = refs.len();
        // Costs are compared without dividing by the parent's area, which may be 0.
        let parent_area = area(&info.bounds.to_aabb());
        let as_leaf = info.cost();
        let (cmin, cmax) = (info.centroids.lo, info.centroids.hi);
        let mut offset = cmin;
        let mut scale = Vec3A::ZERO;
        for axis in 0..3 {
            // The extent in f64: it may exceed the f32 range when both ends are near it.
            let extent = f64::from(cmax[axis]) - f64::from(cmin[axis]);
            if extent > 0.0 && extent.is_finite() {
                scale[axis] = (BINS as f64 / extent) as f32;
            } else {
                offset[axis] = 0.0;
            }
        }
        if scale == Vec3A::ZERO {
            return (count > MAX_LEAF_PRIMS).then_some(Split::Middle);
        }
        let bins = self.bin(refs, offset, scale);
        let mut best: Option<(f64, Split)> = None;
        for axis in (0..3).filter(|&a| scale[a] > 0.0) {
            let bins = &bins[axis];
            // Sweep from the right to get each suffix, then from the left to price each split.
            let mut suffix = [EMPTY_BIN; BINS];
            let mut suffix_cost = [0.0; BINS];
            let mut acc = EMPTY_BIN;
            for i in (1..BINS).rev() {
                if bins[i].count > 0 {
                    acc = acc.merge(&bins[i]);
                    suffix_cost[i] = acc.cost();
                } else if i + 1 < BINS {
                    suffix_cost[i] = suffix_cost[i + 1];
                }
                suffix[i] = acc;
            }
            let mut left = EMPTY_BIN;
            for i in 0..BINS - 1 {
                // An empty bin leaves the split where the last one put it, at the same cost;
                // the earlier of equal costs wins below, so skipping it changes nothing.
                if bins[i].count == 0 {
                    continue;
                }
                left = left.merge(&bins[i]);
                let right = &suffix[i + 1];
                if right.count == 0 {
                    break;
                }
                let cost = TRAVERSAL_COST * parent_area + left.cost() + suffix_cost[i + 1];
                if best.as_ref().is_none_or(|(c, _)| cost < *c) {
                    let split = Split::Bin {
                        axis,
                        offset: offset[axis],
                        scale: scale[axis],
                        last_left: i,
                        left,
                        right: *right,
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
}

/// Appends the subtrees `a` and `b` (each rooted at its index 0) as the two children of the
/// node whose `first` is `nodes.len()`: their roots first, then the rest of `a`, then the
/// rest of `b`, with inner nodes' child indices shifted to match.
fn append_children(nodes: &mut Vec<Node>, a: Vec<Node>, b: Vec<Node>) {
    let first = nodes.len();
    // Local index j >= 1 of `a` lands at first + 1 + j, of `b` at first + a.len() + j.
    let shift_a = (first + 1) as u32;
    let shift_b = (first + a.len()) as u32;
    let shifted = |n: &Node, by: u32| {
        if n.is_leaf() {
            *n
        } else {
            Node {
                first: n.first + by,
                ..*n
            }
        }
    };
    nodes.reserve(a.len() + b.len());
    nodes.push(shifted(&a[0], shift_a));
    nodes.push(shifted(&b[0], shift_b));
    nodes.extend(a[1..].iter().map(|n| shifted(n, shift_a)));
    nodes.extend(b[1..].iter().map(|n| shifted(n, shift_b)));
}

/// Moves the references satisfying `left` to the front and returns the first index of the
/// rest.
fn partition(refs: &mut [PrimRef], left: impl Fn(&PrimRef) -> bool) -> usize {
    let mut mid = 0;
    for i in 0..refs.len() {
        if left(&refs[i]) {
            refs.swap(i, mid);
            mid += 1;
        }
    }
    mid
}

/// The bin of a centroid coordinate; NaN and out-of-range values clamp to the end bins
/// (`as usize` saturates and maps NaN to 0). The same function bins and partitions, so the
/// partition agrees with the counts the split was priced by.
fn bin_of(c: f32, offset: f32, scale: f32) -> usize {
    (((c - offset) * scale) as u32).min(BINS as u32 - 1) as usize
}
