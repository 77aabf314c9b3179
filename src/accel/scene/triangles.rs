//! Mesh triangles in `f32`, and again in BVH leaf order, four to a pack.

use glam::{DVec3, Vec3};

use crate::accel::bvh::Bvh;
use crate::kernel::triangle::{PACK_WIDTH, TrianglePack};
use crate::scene::Geometry;

/// Mesh triangles in `f32`, with per-corner shading normals when the mesh has them.
#[derive(Default)]
pub(super) struct Triangles {
    pub(super) corners: Vec<[Vec3; 3]>,
    pub(super) normals: Vec<Option<[DVec3; 3]>>,
    /// (object, triangle within object).
    pub(super) ids: Vec<(u32, u32)>,
}

/// The triangles again in BVH leaf order, four to a [`TrianglePack`], so that a leaf's
/// triangles are one contiguous run tested four at a time with no index indirection.
pub(super) struct LeafPacks {
    pub(super) packs: Vec<TrianglePack>,
    /// Triangle number (into [`Triangles`]) of each lane of each pack.
    pub(super) lanes: Vec<[u32; PACK_WIDTH]>,
    /// For the first position of each leaf's range in the BVH's primitive index array, and
    /// for the array's length, the index of the leaf's first pack: a leaf covering positions
    /// `a..b` has packs `start[a]..start[b]` (leaves tile the positions).
    pub(super) start: Vec<u32>,
}

impl LeafPacks {
    pub(super) fn new(bvh: &Bvh, patches: u32, corners: &[[Vec3; 3]]) -> LeafPacks {
        let triangles = patches..patches + corners.len() as u32;
        let mut leaves: Vec<(usize, usize)> = bvh
            .nodes()
            .iter()
            .filter(|n| n.is_leaf())
            .map(|n| (n.first as usize, n.count as usize))
            .collect();
        leaves.sort_unstable();
        let mut p = LeafPacks {
            packs: Vec::with_capacity(corners.len() / PACK_WIDTH + leaves.len()),
            lanes: Vec::new(),
            start: vec![0; bvh.prim_count() + 1],
        };
        let mut tris = Vec::with_capacity(PACK_WIDTH);
        for (first, count) in leaves {
            p.start[first] = p.packs.len() as u32;
            let in_leaf = &bvh.prim_indices()[first..first + count];
            let triangles: Vec<u32> = in_leaf
                .iter()
                .filter(|&&prim| triangles.contains(&prim))
                .map(|&prim| prim - patches)
                .collect();
            for chunk in triangles.chunks(PACK_WIDTH) {
                tris.clear();
                tris.extend(chunk.iter().map(|&k| corners[k as usize]));
                p.packs.push(TrianglePack::new(&tris));
                let mut lanes = [u32::MAX; PACK_WIDTH];
                lanes[..chunk.len()].copy_from_slice(chunk);
                p.lanes.push(lanes);
            }
        }
        p.start[bvh.prim_count()] = p.packs.len() as u32;
        p
    }

    /// The packs of the leaf covering `range` and their first pack's index.
    pub(super) fn of_leaf(&self, range: &std::ops::Range<usize>) -> (usize, &[TrianglePack]) {
        let (a, b) = (
            self.start[range.start] as usize,
            self.start[range.end] as usize,
        );
        (a, &self.packs[a..b])
    }
}

/// All mesh triangles of `objects` in order, rounded to `f32`.
pub(super) fn collect_triangles(objects: &[(u32, &Geometry)]) -> Triangles {
    let mut t = Triangles::default();
    for &(o, geometry) in objects {
        let Geometry::Mesh(mesh) = geometry else {
            continue;
        };
        let has_normals = mesh.normals.len() == mesh.positions.len();
        for (k, idx) in mesh.indices.iter().enumerate() {
            let [a, b, c] = idx.map(|i| mesh.positions[i as usize]);
            t.corners.push([a.as_vec3(), b.as_vec3(), c.as_vec3()]);
            t.normals
                .push(has_normals.then(|| idx.map(|i| mesh.normals[i as usize])));
            t.ids.push((o, k as u32));
        }
    }
    t
}
