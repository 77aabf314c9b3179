//! Preparing a scene's geometry: patches collected and bounded, instances placed, the
//! BVH or grid built over them.

use std::borrow::Cow;

use rayon::prelude::*;

use super::triangles::{Triangles, collect_triangles};
use super::{Accel, SceneGeometry};
use crate::accel::bvh::Bvh;
use crate::accel::grid::Grid;
use crate::accel::instance::Placement;
use crate::accel::patches::{OwnedPatches, PatchStore};
use crate::geom::trim::PatchTrim;
use crate::geom::{Aabb, BezierPatch, DAabb};
use crate::kernel::subdivision::PreparedPatch;
use crate::progress::{Batched, ProgressBar};
use crate::scene::{Geometry, Scene};

/// The scene's objects split for preparation: those placed in world space, and the
/// instances with the distinct geometry they share.
pub(super) struct Split<'a> {
    pub(super) own: Vec<(u32, &'a Geometry)>,
    /// (object, prototype, object to world) per instance.
    pub(super) instances: Vec<(u32, u32, glam::DAffine3)>,
    pub(super) prototypes: Vec<&'a Geometry>,
}

impl<'a> Split<'a> {
    pub(super) fn of(scene: &'a Scene) -> Split<'a> {
        let mut split = Split {
            own: Vec::new(),
            instances: Vec::new(),
            prototypes: Vec::new(),
        };
        // Shared geometry is one `Arc`: its address names it.
        let mut seen: Vec<*const Geometry> = Vec::new();
        for (o, object) in scene.objects.iter().enumerate() {
            match &object.geometry {
                Geometry::Instance(i) => {
                    let key = std::sync::Arc::as_ptr(&i.geometry);
                    let k = seen.iter().position(|&s| s == key).unwrap_or_else(|| {
                        seen.push(key);
                        split.prototypes.push(&i.geometry);
                        seen.len() - 1
                    });
                    split.instances.push((o as u32, k as u32, i.transform));
                }
                g => split.own.push((o as u32, g)),
            }
        }
        split
    }

    /// Each shared geometry prepared in object space with its own BVH.
    pub(super) fn prepare_prototypes(&self) -> Vec<SceneGeometry> {
        self.prototypes
            .iter()
            .map(|g| SceneGeometry::build_own(&[(0, g)], &[], Vec::new(), &ProgressBar::hidden()))
            .collect()
    }
}

impl SceneGeometry {
    /// Prepares the patches and builds the BVH, with instances under a top-level BVH.
    pub fn build(scene: &Scene) -> SceneGeometry {
        Self::build_with(scene, &ProgressBar::hidden())
    }

    /// [`build`](Self::build), advancing `progress` to twice the top-level primitive
    /// count: one step per primitive bounded (a trimmed patch's box is the costly part),
    /// one per primitive placed in a BVH leaf. Instances count as one primitive each.
    pub fn build_with(scene: &Scene, progress: &ProgressBar) -> SceneGeometry {
        let split = Split::of(scene);
        let prototypes = split.prepare_prototypes();
        SceneGeometry::build_own(&split.own, &split.instances, prototypes, progress)
    }

    /// The BVH over `own`'s primitives and the boxes of the instances `placed` (object,
    /// prototype, transform).
    pub(super) fn build_own(
        own: &[(u32, &Geometry)],
        placed: &[(u32, u32, glam::DAffine3)],
        prototypes: Vec<SceneGeometry>,
        progress: &ProgressBar,
    ) -> SceneGeometry {
        let patches = collect_patches(own);
        let triangles = collect_triangles(own);
        let instances = place(placed, &prototypes, patches.originals.len());
        let primitives = patches.originals.len() + triangles.corners.len() + instances.len();
        progress.set_length(2 * primitives as u64);
        // Bounding is independent per patch (a trimmed patch's box is the costly part), so
        // it runs on every core.
        let mut boxes: Vec<Aabb> = patches
            .originals
            .par_iter()
            .zip(&patches.trims)
            .map_init(
                || Batched::new(progress),
                |bounded, (p, trim)| {
                    bounded.add(1);
                    surviving_box(p, trim.as_deref()).to_f32_outward()
                },
            )
            .collect();
        boxes.extend(
            triangles
                .corners
                .iter()
                .map(|c| c.iter().copied().collect::<Aabb>()),
        );
        boxes.extend(instances.iter().map(|i| i.bounds));
        progress.inc((triangles.corners.len() + instances.len()) as u64);
        let bvh = Bvh::build_packed_with(&boxes, patches.originals.len(), progress);
        let accel = Accel::bvh(bvh, patches.originals.len(), &triangles);
        Self::with_accel(patches, triangles, accel, instances, prototypes)
    }

    /// Prepares the patches and builds the uniform grid of LG90 §3.1 within `budget_bytes`
    /// (see [`Grid::build`]).
    /// LG90's grid has no instances: they are prepared as placed copies.
    pub fn build_grid(scene: &Scene, budget_bytes: usize) -> SceneGeometry {
        let resolved: Vec<(u32, Cow<Geometry>)> = scene
            .objects
            .iter()
            .enumerate()
            .map(|(o, object)| (o as u32, object.geometry.resolved()))
            .collect();
        let own: Vec<(u32, &Geometry)> = resolved.iter().map(|(o, g)| (*o, g.as_ref())).collect();
        let patches = collect_patches(&own);
        let triangles = collect_triangles(&own);
        let grid = Grid::build(&patches.originals, &triangles.corners, budget_bytes);
        Self::with_accel(
            patches,
            triangles,
            Accel::Grid(grid),
            Vec::new(),
            Vec::new(),
        )
    }

    pub(super) fn with_accel(
        patches: Patches,
        triangles: Triangles,
        accel: Accel,
        instances: Vec<Placement>,
        prototypes: Vec<SceneGeometry>,
    ) -> SceneGeometry {
        let prepared = patches
            .originals
            .par_iter()
            .map(PreparedPatch::new)
            .collect();
        SceneGeometry {
            patches: PatchStore::Owned(OwnedPatches {
                prepared,
                originals: patches.originals,
                ids: patches.ids,
                trims: patches.trims,
            }),
            triangles,
            accel,
            instances,
            prototypes,
        }
    }
}

/// The placements of the instances `placed` (object, prototype, transform), leaving out
/// any whose transform has no inverse. Their patches are numbered after the scene's own
/// `own_patches`, a run per instance, so a hit names its surface of origin uniquely.
pub(super) fn place(
    placed: &[(u32, u32, glam::DAffine3)],
    prototypes: &[SceneGeometry],
    own_patches: usize,
) -> Vec<Placement> {
    let mut first = own_patches as u64;
    placed
        .iter()
        .filter_map(|&(object, k, to_world)| {
            let prototype = &prototypes[k as usize];
            let number = u32::try_from(first).ok();
            first += prototype.patches.len() as u64;
            Placement::new(k, object, prototype, to_world, number)
        })
        .collect()
}

/// The scene's patches as the accelerator indexes them.
pub(super) struct Patches {
    pub(super) originals: Vec<BezierPatch>,
    /// (object, patch within object) per patch.
    pub(super) ids: Vec<(u32, u32)>,
    /// Per patch, its trim where its loops cut it (Dammertz §2.6).
    pub(super) trims: Vec<Option<Box<PatchTrim>>>,
}

/// All Bézier patches of the scene in contract order, with their (object, patch) ids and
/// trims. Patches collapsed to a curve or a point are left out: they have no area, so no
/// ray hits them exactly, while rounding would let the `f32` kernel report hits on them
/// whose secondary rays, lacking a normal to leave along, re-hit the same curve.
/// So are patches their trim loops cut away wholly (culled).
pub(super) fn collect_patches(objects: &[(u32, &Geometry)]) -> Patches {
    let mut out = Patches {
        originals: Vec::new(),
        ids: Vec::new(),
        trims: Vec::new(),
    };
    // Objects convert independently (NURBS to Bézier, trims), on every core, and are
    // joined in order.
    let per_object: Vec<_> = objects
        .par_iter()
        .map(|&(o, geometry)| (o, geometry.trimmed_patches()))
        .collect();
    for (o, entries) in per_object {
        for (k, entry) in entries.into_iter().enumerate() {
            let Some((p, trim)) = entry else { continue };
            if p.has_zero_area() {
                continue;
            }
            out.originals.push(p);
            out.ids.push((o, k as u32));
            out.trims.push(trim);
        }
    }
    out
}

/// Quarterings of a trimmed patch when bounding the part its loops keep: 4 × 4 pieces.
const SURVIVING_BOX_LEVELS: u32 = 2;

/// The BVH box of a patch: its tight box, or for a patch its trim loops cut, the union of
/// the tight boxes of those of its 4 × 4 sub-patches (de Casteljau halvings) that keep any
/// of the surface ([`PatchTrim::keeps_any_of`]). A plate mostly cut away then no longer
/// sends every ray through its whole rectangle to the kernel; 16 sub-patches per cut patch
/// at load is cheap. The kernel still starts from the whole patch.
pub(super) fn surviving_box(p: &BezierPatch, trim: Option<&PatchTrim>) -> DAabb {
    let Some(trim) = trim else {
        return p.tight_box();
    };
    let mut parts = vec![p.clone()];
    for _ in 0..SURVIVING_BOX_LEVELS {
        parts = parts
            .iter()
            .flat_map(|q| {
                let (a, b) = q.split_u();
                let (a0, a1) = a.split_v();
                let (b0, b1) = b.split_v();
                [a0, a1, b0, b1]
            })
            .collect();
    }
    let kept = parts
        .iter()
        .filter(|q| trim.keeps_any_of(q.domain()))
        .fold(DAabb::EMPTY, |acc, q| acc.union(&q.tight_box()));
    if kept.is_empty() { p.tight_box() } else { kept }
}
