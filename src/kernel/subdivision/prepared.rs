//! The per-patch data of the `f32` kernel, built once per patch: an affine patch's closed
//! form, the bicubic or bilinear fast path's structure-of-arrays net, or the general
//! path's homogeneous net.

use super::affine::AffinePatch;
use super::bicubic::Net;
use super::bilinear::BilinearNet;
use super::general::{NetShape, net_box};
use super::register::LaneNet;
use crate::geom::{Aabb, BezierPatch};

/// Which path a patch takes (Dammertz §2.7.1: the choice is made once, before any ray).
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum Prepared {
    /// No search: the ray meets the patch's plane once ([`super::affine`]).
    Affine(AffinePatch),
    Bicubic(Net),
    Bilinear(BilinearNet),
    General {
        net: Vec<[f32; 4]>,
        shape: NetShape,
    },
}

/// A patch ready for the `f32` subdivision kernel.
#[derive(Clone, Debug, PartialEq)]
pub struct PreparedPatch {
    pub(crate) data: Prepared,
    pub(crate) bounds: Aabb,
}

impl PreparedPatch {
    pub fn new(patch: &BezierPatch) -> PreparedPatch {
        if let Some(affine) = AffinePatch::of(patch) {
            return PreparedPatch::affine(affine);
        }
        if patch.is_plain_bicubic() {
            let net = Net::from_patch(patch);
            return PreparedPatch {
                bounds: net.bounds().to_aabb(),
                data: Prepared::Bicubic(net),
            };
        }
        #[cfg(target_arch = "x86_64")]
        if super::avx512::available()
            && let Some(net) = Net::elevated_bilinear(patch)
        {
            // Where the AVX-512 path runs, bilinear patches take it as bicubics, in ray
            // space and with jumps (see `Net::elevated_bilinear`).
            return PreparedPatch {
                bounds: net.bounds().to_aabb(),
                data: Prepared::Bicubic(net),
            };
        }
        PreparedPatch::bilinear(patch).unwrap_or_else(|| PreparedPatch::general(patch))
    }

    /// The closed form of an affine patch.
    pub(crate) fn affine(affine: AffinePatch) -> PreparedPatch {
        PreparedPatch {
            bounds: affine.bounds(),
            data: Prepared::Affine(affine),
        }
    }

    /// The bilinear fast path, for bilinear integral patches.
    pub(crate) fn bilinear(patch: &BezierPatch) -> Option<PreparedPatch> {
        let net = BilinearNet::from_patch(patch)?;
        Some(PreparedPatch {
            bounds: net.bounds().to_aabb(),
            data: Prepared::Bilinear(net),
        })
    }

    /// The general path for any patch (Dammertz §2.7.2), also the reference the fast paths
    /// are tested against.
    pub(crate) fn general(patch: &BezierPatch) -> PreparedPatch {
        let shape = NetShape {
            nu: patch.degree_u() + 1,
            nv: patch.degree_v() + 1,
            rational: patch.is_rational(),
        };
        let net: Vec<[f32; 4]> = patch
            .homogeneous_points()
            .iter()
            .map(|p| p.as_vec4().to_array())
            .collect();
        PreparedPatch {
            bounds: net_box(&net, shape.rational).to_aabb(),
            data: Prepared::General { net, shape },
        }
    }

    /// The box of the `f32` control net: contains every point the kernel can report.
    pub fn bounds(&self) -> Aabb {
        self.bounds
    }
}
