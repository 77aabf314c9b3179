//! The subdivision algorithm in `f64`: the accuracy reference of Dammertz §2.3.4 ("the
//! complete algorithm above has been implemented using double precision arithmetic") and
//! the `trace --precision f64` path. It runs the general path's search on the `f64`
//! homogeneous net, so it handles every degree and rational patches.

use glam::DVec3;

use crate::geom::trim::PatchTrim;

use super::config::SubdivisionConfig;
use super::float::GRay;
use super::general::{GeneralStack, NetShape, Scratch, net_box};
use super::search::search;
use crate::geom::{BezierPatch, DAabb};
use crate::kernel::KernelStats;

/// A hit of the `f64` path: as [`crate::kernel::PatchHit`], in `f64`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PatchHit64 {
    pub t: f64,
    pub u: f64,
    pub v: f64,
    pub hit_box: DAabb,
}

/// Nearest hit of `origin + t dir` with `t` in `[tmin, tmax]`, all in `f64`.
pub fn intersect_f64(
    patch: &BezierPatch,
    origin: DVec3,
    dir: DVec3,
    tmin: f64,
    tmax: f64,
    cfg: &SubdivisionConfig,
    trim: Option<&PatchTrim>,
) -> Option<PatchHit64> {
    let shape = NetShape {
        nu: patch.degree_u() + 1,
        nv: patch.degree_v() + 1,
        rational: patch.is_rational(),
    };
    let net: Vec<[f64; 4]> = patch
        .homogeneous_points()
        .iter()
        .map(|p| p.to_array())
        .collect();
    let root = net_box(&net, shape.rational);
    let ray = GRay::new(origin.to_array(), dir.to_array(), tmin, tmax);
    let mut scratch = Scratch::default();
    let mut nets = GeneralStack::new(&mut scratch.nets, &net, shape);
    let mut stats = KernelStats::default();
    // The reference runs to full precision on every ray, however long it takes.
    let cfg = SubdivisionConfig {
        full_precision_splits: None,
        ..*cfg
    };
    let h = search(
        &mut nets,
        &mut scratch.nodes,
        root,
        &ray,
        shape.rational,
        &cfg,
        false,
        trim,
        None,
        &mut stats,
    )?;
    let (u, v) = h.cell.centre();
    Some(PatchHit64 {
        t: h.t,
        u,
        v,
        hit_box: h.bbox.to_daabb(),
    })
}
