//! Surface trees (Lischinski & Gonczarowski 1990, §4.2, Fig. 4): the quadtree over a
//! patch's parameter domain that the regular subdivision of the search builds. A node
//! keeps its parameter box and the patch's bounding box over it; children are created when
//! a search first splits the node, so a tree grows where rays went and nowhere else.

use glam::DVec4;

use crate::geom::interval::{Interval, IntervalNet, ParamBox};
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
}

/// The cached tree of one patch, with a copy of the patch's net so that a tree is only
/// reused for the surface it was built on.
#[derive(Clone, Debug)]
pub struct SurfaceTree {
    points: Vec<DVec4>,
    nodes: Vec<Node>,
}

impl Weigh for SurfaceTree {
    fn bytes(&self) -> usize {
        std::mem::size_of::<SurfaceTree>()
            + self.points.capacity() * std::mem::size_of::<DVec4>()
            + self.nodes.capacity() * std::mem::size_of::<Node>()
    }
}

impl SurfaceTree {
    /// A tree holding only the root: the whole domain and the patch's box.
    pub fn new(patch: &BezierPatch, nets: &mut [IntervalNet; 2]) -> SurfaceTree {
        let [homogeneous, sub] = nets;
        SurfaceTree {
            points: patch.homogeneous_points().to_vec(),
            nodes: vec![Node {
                region: ParamBox::UNIT,
                bounds: enclosure_box(patch, &ParamBox::UNIT, homogeneous, sub),
                children: None,
                depth: 0,
            }],
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
        for region in quarters(&n.region)? {
            self.nodes.push(Node {
                region,
                bounds: enclosure_box(patch, &region, homogeneous, sub),
                children: None,
                depth: n.depth + 1,
            });
        }
        self.nodes[i as usize].children = Some(first);
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
    }
}
