//! Surface trees (Lischinski & Gonczarowski 1990, §4.2, Fig. 4): the quadtree over a
//! patch's parameter domain that the regular subdivision of the search builds. A node
//! keeps its parameter box and the patch's bounding box over it; children are created when
//! a search first splits the node, so a tree grows where rays went and nowhere else.
//!
//! Beyond the paper's box, each leaf also keeps an enclosure of its homogeneous sub-net
//! ([`LeafNet`]): the node's box is computed from that sub-net anyway, and a ray that
//! reaches the leaf then projects the stored net into its frame instead of subdividing
//! the patch's net down to the leaf's box again (the most expensive step of a search
//! iteration). The sub-net is kept as `f32` centres with one radius per component, so a
//! bicubic leaf costs 272 bytes; internal nodes hand their slot on to a child.

use glam::{DVec4, Vec4};

use crate::geom::interval::{IPoint, Interval, IntervalNet, ParamBox};
use crate::geom::{Aabb, BezierPatch};
use crate::kernel::toth::search::enclosure_box;

use super::lru::Weigh;

/// A node of a surface tree.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Node {
    pub region: ParamBox,
    /// The patch over `region`, rounded outward to `f32`.
    pub bounds: Aabb,
    /// Index of the first of the four children, which are stored together; `None` for a
    /// leaf.
    pub children: Option<u32>,
    /// Depth below the root (the root is 0).
    pub depth: u8,
    /// Slot of the leaf's stored sub-net ([`SurfaceTree::leaf_net`]), [`NO_NET`] when it
    /// has none (an internal node, or a sub-net that was not finite).
    net: u32,
}

/// [`Node::net`] of a node without a stored sub-net.
const NO_NET: u32 = u32::MAX;

/// An enclosure of a leaf's homogeneous sub-net: every control point `H` of the exact
/// sub-net satisfies `|H_k − centres[i]_k| ≤ radius_k` in each component `k`.
#[derive(Clone, Copy, Debug)]
pub struct LeafNet<'a> {
    pub centres: &'a [Vec4],
    pub radius: Vec4,
}

/// The cached tree of one patch, with a copy of the patch's net so that a tree is only
/// reused for the surface it was built on.
#[derive(Clone, Debug)]
pub struct SurfaceTree {
    points: Vec<DVec4>,
    nodes: Vec<Node>,
    /// Leaf sub-nets, `points.len()` centres per slot, and one radius per slot.
    net_centres: Vec<Vec4>,
    net_radii: Vec<Vec4>,
}

impl Weigh for SurfaceTree {
    fn bytes(&self) -> usize {
        std::mem::size_of::<SurfaceTree>()
            + self.points.capacity() * std::mem::size_of::<DVec4>()
            + self.nodes.capacity() * std::mem::size_of::<Node>()
            + (self.net_centres.capacity() + self.net_radii.capacity())
                * std::mem::size_of::<Vec4>()
    }
}

impl SurfaceTree {
    /// A tree holding only the root: the whole domain and the patch's box.
    pub fn new(patch: &BezierPatch, nets: &mut [IntervalNet; 2]) -> SurfaceTree {
        let [homogeneous, sub] = nets;
        let bounds = enclosure_box(patch, &ParamBox::UNIT, homogeneous, sub);
        let mut tree = SurfaceTree {
            points: patch.homogeneous_points().to_vec(),
            nodes: Vec::new(),
            net_centres: Vec::new(),
            net_radii: Vec::new(),
        };
        let net = tree.store_net(NO_NET, sub);
        tree.nodes.push(Node {
            region: ParamBox::UNIT,
            bounds,
            children: None,
            depth: 0,
            net,
        });
        tree
    }

    /// The stored sub-net of leaf `i`, if it has one.
    pub fn leaf_net(&self, i: u32) -> Option<LeafNet<'_>> {
        let slot = self.nodes[i as usize].net;
        (slot != NO_NET).then(|| {
            let (n, s) = (self.points.len(), slot as usize);
            LeafNet {
                centres: &self.net_centres[s * n..(s + 1) * n],
                radius: self.net_radii[s],
            }
        })
    }

    /// Stores an enclosure of the interval net `sub` in `slot` (a new slot for
    /// [`NO_NET`]) and returns the slot, or [`NO_NET`] when `sub` is not finite (the
    /// caller then subdivides the patch's net as for an uncached box).
    fn store_net(&mut self, slot: u32, sub: &IntervalNet) -> u32 {
        let n = self.points.len();
        let centre = |p: &IPoint| Vec4::from_array(p.map(|c| c.mid() as f32));
        // The distances from each end to the centre, rounded up, then to f32 rounded up.
        let mut radius = [0.0f64; 4];
        for p in sub.points() {
            let c = centre(p).as_dvec4().to_array();
            for k in 0..4 {
                let r = (p[k].hi() - c[k])
                    .next_up()
                    .max((c[k] - p[k].lo()).next_up());
                radius[k] = radius[k].max(r);
            }
        }
        let radius = Vec4::from_array(radius.map(|r| {
            let f = r as f32;
            if (f as f64) < r { f.next_up() } else { f }
        }));
        if sub.points().len() != n || !radius.is_finite() {
            return NO_NET;
        }
        let centres = sub.points().iter().map(centre);
        if slot == NO_NET {
            let Ok(s) = u32::try_from(self.net_radii.len()) else {
                return NO_NET;
            };
            self.net_radii.push(radius);
            self.net_centres.extend(centres);
            s
        } else {
            let s = slot as usize;
            self.net_radii[s] = radius;
            for (d, c) in self.net_centres[s * n..(s + 1) * n].iter_mut().zip(centres) {
                *d = c;
            }
            slot
        }
    }

    /// Whether this tree was built on `patch`.
    pub fn is_of(&self, patch: &BezierPatch) -> bool {
        self.points == patch.homogeneous_points()
    }

    pub fn node(&self, i: u32) -> &Node {
        &self.nodes[i as usize]
    }

    pub fn len(&self) -> usize {
        self.nodes.len()
    }

    pub fn is_empty(&self) -> bool {
        self.nodes.is_empty()
    }

    /// The children of leaf `i`, created with their boxes (LG90 §4.2 step 8), or `None`
    /// when the leaf is too narrow to quarter in `f64`. Returns the first child's index.
    pub fn split(
        &mut self,
        i: u32,
        patch: &BezierPatch,
        nets: &mut [IntervalNet; 2],
    ) -> Option<u32> {
        let n = self.nodes[i as usize];
        if let Some(c) = n.children {
            return Some(c);
        }
        let first = u32::try_from(self.nodes.len()).ok()?;
        let [homogeneous, sub] = nets;
        // The first child takes over the parent's sub-net slot.
        let mut free = n.net;
        for region in quarters(&n.region)? {
            let bounds = enclosure_box(patch, &region, homogeneous, sub);
            let net = self.store_net(std::mem::replace(&mut free, NO_NET), sub);
            self.nodes.push(Node {
                region,
                bounds,
                children: None,
                depth: n.depth + 1,
                net,
            });
        }
        let parent = &mut self.nodes[i as usize];
        parent.children = Some(first);
        parent.net = NO_NET;
        Some(first)
    }
}

/// The four quarters of a box, halving both sides (LG90's regular subdivision), or `None`
/// when a side is too narrow for its midpoint to differ from both ends in `f64`.
pub fn quarters(b: &ParamBox) -> Option<[ParamBox; 4]> {
    let halves = |s: Interval| {
        let m = s.mid();
        (m > s.lo() && m < s.hi())
            .then(|| Some([Interval::new(s.lo(), m)?, Interval::new(m, s.hi())?]))
            .flatten()
    };
    let (us, vs) = (halves(b.u)?, halves(b.v)?);
    Some([
        ParamBox { u: us[0], v: vs[0] },
        ParamBox { u: us[1], v: vs[0] },
        ParamBox { u: us[0], v: vs[1] },
        ParamBox { u: us[1], v: vs[1] },
    ])
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    #[test]
    fn quarters_tile_the_box() {
        let q = quarters(&ParamBox::UNIT).unwrap();
        // The four combinations of the halves [0, ½] and [½, 1], each once.
        let halves = [(0.0, 0.5), (0.5, 1.0)];
        let mut seen: Vec<_> = q
            .iter()
            .map(|b| {
                let side = |s: Interval| halves.iter().position(|&h| h == (s.lo(), s.hi()));
                (side(b.u).unwrap(), side(b.v).unwrap())
            })
            .collect();
        seen.sort();
        assert_eq!(seen, [(0, 0), (0, 1), (1, 0), (1, 1)]);
        for (i, a) in q.iter().enumerate() {
            assert!(a.is_subset_of(&ParamBox::UNIT));
            for b in &q[i + 1..] {
                // Neighbours share at most an edge.
                let c = a.intersect(b).unwrap();
                assert!(c.u.lo() == c.u.hi() || c.v.lo() == c.v.hi());
            }
        }
        let p = Interval::point(0.5);
        assert!(quarters(&ParamBox { u: p, v: p }).is_none());
    }

    #[test]
    fn children_boxes_enclose_sampled_points_and_lie_in_the_parent() {
        let pts: Vec<DVec3> = (0..16)
            .map(|k| DVec3::new((k % 4) as f64, (k / 4) as f64, ((k * 7) % 5) as f64 - 2.0))
            .collect();
        let patch = BezierPatch::from_points(3, 3, &pts).unwrap();
        let mut nets = Default::default();
        let mut tree = SurfaceTree::new(&patch, &mut nets);
        assert!(tree.is_of(&patch));
        let first = tree.split(0, &patch, &mut nets).unwrap();
        assert_eq!((first, tree.len()), (1, 5));
        for c in first..first + 4 {
            let n = *tree.node(c);
            assert_eq!(n.depth, 1);
            let root = tree.node(0).bounds;
            assert!(root.contains(n.bounds.min) && root.contains(n.bounds.max));
            for s in 0..=4 {
                for t in 0..=4 {
                    let (u, v) = (
                        n.region.u.lo() + n.region.u.width() * s as f64 / 4.0,
                        n.region.v.lo() + n.region.v.width() * t as f64 / 4.0,
                    );
                    let p = patch.eval(u, v).as_vec3();
                    assert!(n.bounds.contains(p), "{p} outside {:?}", n.bounds);
                }
            }
        }
        // Splitting again returns the same children.
        assert_eq!(tree.split(0, &patch, &mut nets), Some(first));
        // The root hands its sub-net on; each leaf's stored net holds the sub-net that
        // subdividing the patch's exact net gives.
        assert!(tree.leaf_net(0).is_none());
        let exact = IntervalNet::from_patch(&patch);
        let mut sub = IntervalNet::default();
        for c in first..first + 4 {
            exact.subnet_into(&tree.node(c).region, &mut sub);
            let net = tree.leaf_net(c).unwrap();
            assert_eq!(net.centres.len(), sub.points().len());
            for (centre, p) in net.centres.iter().zip(sub.points()) {
                for k in 0..4 {
                    let (c, r) = (centre[k] as f64, net.radius[k] as f64);
                    assert!(
                        c - r <= p[k].lo() && p[k].hi() <= c + r,
                        "{:?} outside {c} ± {r}",
                        p[k]
                    );
                }
            }
        }
    }
}
