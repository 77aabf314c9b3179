//! Instances (Dammertz §3.3): objects that place the same geometry by different transforms
//! share one prepared copy of it and its bottom-level BVH, a [`SceneGeometry`] in object
//! space; the top-level BVH holds each instance's world box. A ray enters an instance
//! through the inverse transform, and the hit comes back to world space.
//!
//! Certification in world space. The `f32` kernel certifies a hit box in object space: it
//! holds the piece of the prototype's `f32` surface the object-space ray hit. The instance's
//! surface is that surface placed by the `f64` transform, so the world hit box is the object
//! box's eight corners mapped in `f64`, grown by a bound on that map's rounding and rounded
//! outward to `f32` ([`DAabb::transformed`]): it holds the placed piece. (Dammertz keeps the
//! box in object space and uses it only for rays re-entering the same instance; a world box
//! serves every instance and the stability checks alike.)
//!
//! A secondary ray leaves from a corner of the world leave box, which re-enters its own
//! instance rounded to `f32` again: its object-space origin moves by up to `e`, one ulp of
//! the prototype's largest coordinate (the ray starts within the prototype's box), so in
//! world space by up to `‖L‖∞ e` with `L` the linear part of object-to-world. The world
//! leave box is therefore grown by [`LEAVE_MARGIN_FACTOR`] `‖L‖∞ e` beyond the mapped object
//! leave box: a ray from its corner that does not enter the grown box (Dammertz §2.4's
//! corner argument) stays outside the mapped box after that rounding, so it cannot re-hit
//! the piece it left. Measured by the stability suite's instanced case (0 self-hits).
//!
//! What a hit reports: the instance's object number and the prototype's patch number, which
//! is the patch's number in the placed copy (the contract's order), `(u, v)` on the shared
//! patch (the same parameters), `t` of the object-space ray (the same parameter: an affine
//! map keeps it, up to the rounding of the ray), and the normal mapped by the inverse
//! transpose, turned by the sign of the determinant so it is `∂S/∂u × ∂S/∂v` of the placed
//! patch as for a copy.

use glam::{DAffine3, DMat3, DVec3, Vec3};

use super::scene::{SceneGeometry, SceneHit};
use crate::geom::bbox::DAabb;
use crate::geom::ulp::ulp_of;
use crate::geom::{Aabb, Ray};
use crate::kernel::subdivision::{ScreenFootprint, Termination};
use crate::kernel::{Kernel, SurfaceOrigin};

/// How many times the world-space image of the re-entry rounding the leave box is grown
/// by: the bound is reached only at once in every coordinate; twice leaves room for the
/// direction's own rounding (see the module comment).
pub const LEAVE_MARGIN_FACTOR: f64 = 2.0;

/// One instance: which prototype, placed how, and what its hits report.
pub(super) struct Placement {
    pub prototype: u32,
    /// The object the instance is (hits report it).
    pub object: u32,
    /// World to object space (`M` of Dammertz §3.3) and back.
    to_object: DAffine3,
    to_world: DAffine3,
    /// Maps object-space normals to world space: the inverse transpose of the linear part
    /// of `to_world` times the sign of its determinant.
    normal_map: DMat3,
    /// Per-axis growth of the world leave box (see the module comment).
    leave_margin: f64,
    /// The instance's world box, for the top-level BVH.
    pub bounds: Aabb,
    /// The accelerator number of the prototype's patch 0 in this instance: hits name
    /// `first_primitive + p` so secondary rays know their surface of origin
    /// ([`Kernel::leaving`]); `None` when the scene has more than `u32` numbers.
    first_primitive: Option<u32>,
}

impl Placement {
    /// The instance of `prototype` (number `index`) placed by `to_world`. `None` for a
    /// transform that cannot be inverted (a flat or non-finite one), whose instance has no
    /// area to be hit.
    pub fn new(
        index: u32,
        object: u32,
        prototype: &SceneGeometry,
        to_world: DAffine3,
        first_primitive: Option<u32>,
    ) -> Option<Placement> {
        let det = to_world.matrix3.determinant();
        if !(det.is_finite() && det != 0.0 && to_world.translation.is_finite()) {
            return None;
        }
        let to_object = to_world.inverse();
        let linear = to_world.matrix3;
        let proto = prototype.bounds();
        let scale = proto.min.abs().max(proto.max.abs()).max_element();
        let leave_margin = LEAVE_MARGIN_FACTOR * inf_norm(&linear) * ulp_of(scale);
        // The placed hull of the control points holds the placed surface (the convex hull
        // property), and is much tighter than the placed corners of the prototype's box
        // for a rotated instance. The margin covers the rounding of the points to `f32`
        // (half an ulp of the prototype's scale, placed).
        let hull = DAabb::of_mapped_points(prototype.hull_points(), &to_world);
        let bounds = grown(hull, leave_margin);
        Some(Placement {
            prototype: index,
            object,
            to_object,
            to_world,
            normal_map: linear.inverse().transpose() * det.signum(),
            leave_margin,
            bounds,
            first_primitive,
        })
    }

    /// `ray` in object space, rounded once to `f32`; `t` keeps its meaning.
    pub fn ray_to_object(&self, ray: &Ray) -> Ray {
        Ray {
            origin: self.point_to_object(ray.origin.as_dvec3()).as_vec3(),
            dir: self.vector_to_object(ray.dir.as_dvec3()).as_vec3(),
            ..*ray
        }
    }

    pub fn point_to_object(&self, p: DVec3) -> DVec3 {
        self.to_object.transform_point3(p)
    }

    pub fn vector_to_object(&self, v: DVec3) -> DVec3 {
        self.to_object.transform_vector3(v)
    }

    /// `precision` for the object-space ray: the adaptive criterion's footprint mapped
    /// into object space, and a surface of origin in this instance named by its number
    /// in the prototype (none elsewhere).
    pub fn precision_in_object(&self, precision: &Kernel, patches: u32) -> Kernel {
        let local = |origin: Option<u32>| {
            let (o, first) = (origin?, self.first_primitive?);
            o.checked_sub(first).filter(|&p| p < patches)
        };
        match *precision {
            Kernel::F32(mut cfg) => {
                if let Termination::Adaptive(fp) = cfg.termination {
                    cfg.termination =
                        Termination::Adaptive(footprint_in_object(fp, &self.to_world.matrix3));
                }
                cfg.surface_of_origin = cfg.surface_of_origin.and_then(|o| {
                    Some(SurfaceOrigin {
                        primitive: local(Some(o.primitive))?,
                        ..o
                    })
                });
                Kernel::F32(cfg)
            }
            Kernel::F64(cfg) => Kernel::F64(cfg),
            Kernel::Toth(mut cfg) => {
                cfg.surface_of_origin = local(cfg.surface_of_origin);
                Kernel::Toth(cfg)
            }
            Kernel::Cached(mut cfg) => {
                cfg.toth.surface_of_origin = local(cfg.toth.surface_of_origin);
                Kernel::Cached(cfg)
            }
        }
    }

    /// An object-space hit of this instance in world space (see the module comment).
    pub fn hit_to_world(&self, h: SceneHit) -> SceneHit {
        let normal = (self.normal_map * h.normal).normalize_or(h.normal);
        let shading_normal = (self.normal_map * h.shading_normal).normalize_or(normal);
        SceneHit {
            object: self.object,
            primitive: h
                .primitive
                .zip(self.first_primitive)
                .and_then(|(p, first)| first.checked_add(p)),
            hit_box: to_daabb(&h.hit_box)
                .transformed(&self.to_world)
                .to_f32_outward(),
            leave_box: grown(
                to_daabb(&h.leave_box).transformed(&self.to_world),
                self.leave_margin,
            ),
            normal,
            shading_normal,
            ..h
        }
    }
}

/// The adaptive criterion (Dammertz §2.5.3) for object-space boxes of an instance whose
/// object-to-world map has linear part `linear` (`L`): a world box is final when its L1
/// diameter `d_w ≤ c t (dir_w · f)`. As `dir_w · f = dir_o · (Lᵀ f)` and the world box of
/// an object box of L1 diameter `d_o` has `d_w ≤ ‖L‖₁ d_o` (its extents are `|L|` times the
/// object extents), testing `d_o ≤ (c / ‖L‖₁) t (dir_o · Lᵀ f)` never stops later than the
/// world test would; for a uniform scale alone it is the world test, a rotation tightens it
/// by the L1 growth of a rotated box.
fn footprint_in_object(fp: ScreenFootprint, linear: &DMat3) -> ScreenFootprint {
    let forward = linear.transpose() * Vec3::from(fp.forward).as_dvec3();
    let norm1 = inf_norm(&linear.transpose());
    ScreenFootprint {
        forward: forward.as_vec3().to_array(),
        half_pixel: (f64::from(fp.half_pixel) / norm1) as f32,
    }
}

/// `b` grown by `margin` on every side and rounded outward to `f32`.
fn grown(b: DAabb, margin: f64) -> Aabb {
    DAabb {
        min: b.min - DVec3::splat(margin),
        max: b.max + DVec3::splat(margin),
    }
    .to_f32_outward()
}

fn to_daabb(b: &Aabb) -> DAabb {
    if b.is_empty() {
        return DAabb::EMPTY;
    }
    b.to_f64()
}

/// The maximum absolute row sum of `m`: the operator norm for the ∞-norm.
fn inf_norm(m: &DMat3) -> f64 {
    let t = m.transpose();
    [t.x_axis, t.y_axis, t.z_axis]
        .iter()
        .map(|row| row.abs().element_sum())
        .fold(0.0, f64::max)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::generate::SplitMix64;
    use glam::DQuat;

    /// Whenever the object-space criterion ends a box, the world box of that box (its
    /// placed corners, [`DAabb::transformed`]) meets the world criterion, for random
    /// boxes, directions and transforms with uneven scales.
    #[test]
    fn object_space_footprint_never_stops_later_than_the_world_one() {
        let mut rng = SplitMix64::new(3);
        let fp = ScreenFootprint {
            forward: [0.3, 0.9, -0.3],
            half_pixel: 1e-2,
        };
        let mut ended = 0;
        for _ in 0..2000 {
            let scale = DVec3::new(
                rng.range(0.2, 5.0),
                rng.range(0.2, 5.0),
                rng.range(0.2, 5.0),
            );
            let q = DQuat::from_axis_angle(rng.direction(), rng.range(0.0, 6.0));
            let m = DAffine3::from_scale_rotation_translation(scale, q, rng.direction());
            let local = footprint_in_object(fp, &m.matrix3);
            let dir_o = rng.direction();
            let t = rng.range(1.0, 100.0);
            let lo = rng.direction();
            let b = DAabb {
                min: lo,
                max: lo + DVec3::new(rng.uniform(), rng.uniform(), rng.uniform()) * 0.05,
            };
            let d_o = b.extent().element_sum();
            let along_o = dir_o.dot(Vec3::from(local.forward).as_dvec3());
            if along_o <= 0.0 || d_o > f64::from(local.half_pixel) * t * along_o {
                continue;
            }
            ended += 1;
            let d_w = b.transformed(&m).extent().element_sum();
            let along_w = m
                .transform_vector3(dir_o)
                .dot(Vec3::from(fp.forward).as_dvec3());
            // The f32 rounding of the mapped footprint: a few parts in 1e7.
            assert!(d_w <= f64::from(fp.half_pixel) * t * along_w * (1.0 + 1e-6));
        }
        assert!(ended > 100, "only {ended} boxes ended");
    }

    /// Under a rotation with a uniform scale the object-space test is the world test
    /// tightened by the L1 growth of the rotated box.
    #[test]
    fn similarity_tightens_the_footprint_test_by_the_l1_growth() {
        let fp = ScreenFootprint {
            forward: [0.0, 1.0, 0.0],
            half_pixel: 2e-3,
        };
        let m = DAffine3::from_scale_rotation_translation(
            DVec3::splat(4.0),
            DQuat::from_rotation_z(0.5),
            DVec3::ZERO,
        );
        let local = footprint_in_object(fp, &m.matrix3);
        let dir_o = DVec3::new(0.2, 0.9, 0.1);
        let along_o = dir_o.dot(Vec3::from(local.forward).as_dvec3());
        let along_w = m.transform_vector3(dir_o).dot(DVec3::Y);
        // c_o t along_o = c_w t along_w / ‖L‖₁, and ‖L‖₁ = 4 (cos 0.5 + sin 0.5) here, the
        // L1 growth of a rotated box.
        let norm1 = 4.0 * (0.5f64.cos() + 0.5f64.sin());
        let (k_o, k_w) = (f64::from(local.half_pixel) * along_o, 2e-3 * along_w);
        assert!((k_o * norm1 / k_w - 1.0).abs() < 1e-6, "{k_o} {k_w}");
    }
}
