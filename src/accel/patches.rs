//! The scene's patches as the accelerator indexes them: built in memory from the scene, or
//! mapped from a BVH file ([`super::mapped`]). Either way a patch is reached by its number,
//! and the kernels get the same `PreparedPatch` and `BezierPatch` values: borrowed from
//! memory, or made on the stack from the file's record (no allocation except the `f64`
//! patch, which only a final hit's normal and the `f64`/LG90 kernels need).

use std::borrow::Cow;

use super::mapped::MappedPatches;
use crate::geom::trim::PatchTrim;
use crate::geom::{Aabb, BezierPatch};
use crate::kernel::subdivision::PreparedPatch;

/// Patches built from the scene.
pub(super) struct OwnedPatches {
    pub prepared: Vec<PreparedPatch>,
    pub originals: Vec<BezierPatch>,
    /// (object, patch within object) per patch.
    pub ids: Vec<(u32, u32)>,
    /// Per patch, its trim where its loops cut it (Dammertz §2.6).
    pub trims: Vec<Option<Box<PatchTrim>>>,
}

pub(super) enum PatchStore {
    Owned(OwnedPatches),
    Mapped(MappedPatches),
}

impl PatchStore {
    pub fn len(&self) -> usize {
        match self {
            PatchStore::Owned(p) => p.prepared.len(),
            PatchStore::Mapped(m) => m.len(),
        }
    }

    /// Patch `i` prepared for the `f32` kernel.
    #[inline]
    pub fn prepared(&self, i: usize) -> Cow<'_, PreparedPatch> {
        match self {
            PatchStore::Owned(p) => Cow::Borrowed(&p.prepared[i]),
            PatchStore::Mapped(m) => Cow::Owned(m.prepared(i)),
        }
    }

    /// The box of patch `i`'s `f32` control net ([`PreparedPatch::bounds`]).
    #[inline]
    pub fn bounds(&self, i: usize) -> Aabb {
        match self {
            PatchStore::Owned(p) => p.prepared[i].bounds(),
            PatchStore::Mapped(m) => m.bounds(i),
        }
    }

    /// Patch `i` in `f64`, as read.
    pub fn original(&self, i: usize) -> Cow<'_, BezierPatch> {
        match self {
            PatchStore::Owned(p) => Cow::Borrowed(&p.originals[i]),
            PatchStore::Mapped(m) => Cow::Owned(m.original(i)),
        }
    }

    /// (object, patch within object) of patch `i`.
    #[inline]
    pub fn id(&self, i: usize) -> (u32, u32) {
        match self {
            PatchStore::Owned(p) => p.ids[i],
            PatchStore::Mapped(m) => m.id(i),
        }
    }

    /// Patch `i`'s trim, `None` where its loops do not cut it (mapped patches never are).
    #[inline]
    pub fn trim(&self, i: usize) -> Option<&PatchTrim> {
        match self {
            PatchStore::Owned(p) => p.trims[i].as_deref(),
            PatchStore::Mapped(_) => None,
        }
    }
}
