//! Ray space for primary rays: the control net is transformed once per ray–patch test into
//! a frame in which the ray is the z-axis, so the box test of every sub-patch is "its
//! (x, y) box contains the origin and its z range meets [tmin, tmax]".
//!
//! Why: Dammertz's box (§2.2) is axis-aligned in world space, so along a ray that runs
//! obliquely to the axes a sub-patch's box overlaps the ray far from the surface, and both
//! children of a split are often hit; each such false overlap costs a split and a pop. In
//! ray space the two coordinates across the ray bound the sub-patch's distance from the ray
//! itself. The search, the split heuristic and the termination are Dammertz's unchanged
//! (§2.2–2.3), applied to the transformed net: a convex combination of neighbouring floats
//! returns one of them (§2.3.3) in any frame, so "the L1 diameter stops shrinking" still
//! ends the search, and the parameter-cell depth limit ([`super::param`]) still bounds it.
//!
//! Frame. The axes are `e1 / |d|`, `e2 / |d|` and `d / |d|²` (`e1`, `e2` an orthonormal
//! basis across `d`, Duff et al. 2017, built in `f64` and rounded once), so a point
//! `o + t d` has z = t: a box's entry parameter is its z minimum, and all three coordinates
//! are in one unit (the frame is a rotation scaled by `1/|d|`), so the length heuristic and
//! the L1 diameter measure what they measure in world space.
//!
//! Crack freedom (§2.3.3). Neighbouring patches share their edge control points bit for
//! bit; every point is transformed by the same operations in the same frame, so the
//! transformed edges are bit-identical too, and the union of the transformed nets'
//! surfaces has no gap for the z-axis to pass through. This holds per ray, so a ray must
//! search every patch in the same space: ray space is a property of the ray
//! ([`super::SubdivisionConfig::ray_space`], on for primary and secondary rays), not of
//! the patch. The frame depends on the ray alone, so it is built once per ray
//! ([`super::KernelRay`]) for every patch the ray meets. The one per-patch exception is
//! [`MIN_RAY_SPACE_SCALE`]: a patch whose ray-space coordinates are all below
//! 2^-39 (geometry within about 2^-39 |d| of the ray origin, e.g. the teapot scaled by 1e-18
//! in front of a unit camera) is searched in world space. Two neighbours straddle that
//! threshold only at such scales, and only there can their shared edge differ by the
//! transform's rounding.
//!
//! Secondary rays (Dammertz §2.4) start at a corner of a world-space box that holds the
//! surface piece of their hit, moved a few ulps beyond it, into the hemisphere they leave
//! by. In their own ray space the net of the surface of origin is the world net rounded
//! once more, by at most [`TRANSFORM_ULPS`] ulps of its distance from the origin, which is
//! what the hit box's margins ([`super::widen_by_net_rounding`] and, for a hit found in ray
//! space, [`RayFrame::world_box`]'s padding) and the origin's own ulps must cover. Measured:
//! the stability suite (`patchtrace bench stability --full`) traces reflection, shadow and
//! refraction rays from every hit with the default configuration, so in ray space, and
//! counts 0 self-hits on every case.
//!
//! Kernel. The transformed points are rounded to ulps of their distance from the ray
//! origin, while the world net is exact only to ulps of its own coordinates: the end game
//! ([`super::search`]) stops at the larger of the two ([`RayFrame::world_length`]), so the
//! search never refines below the precision of the net it came from.
//!
//! Hit box. Secondary rays start from a corner of the world-space box of the hit (§2.4),
//! which must contain the surface piece. It is the final ray-space box mapped back to world
//! space ([`RayFrame::world_box`]) in `f64`, grown by a bound on the rounding of the
//! transform and of the ray-space net ([`TRANSFORM_ULPS`]) and rounded outward. (Restricting
//! the world net to the final parameter cell in `f64` gives a tighter box but cost a sixth
//! of the kernel's time on the teapot.)

use glam::DVec3;

use super::float::{GBox, GRay};
use super::search::SearchHit;
use crate::geom::DAabb;

/// How far, in `f32` ulps of the ray-space coordinate scale, the ray-space net's
/// surface can lie from the exactly transformed world net's: each point is `(p - o)` (one
/// rounding) and a three-term dot product (three products, two sums), at most 3.5 ulps of
/// the coordinate scale for an axis of norm `1 / |d|` applied to `|p - o|`, plus the
/// de Casteljau rounding of the ray-space splits (measured below 0.4 ulp for the world
/// nets, `super::NET_ROUNDING_ULPS`). 8 leaves room above 3.5 + 2.
pub const TRANSFORM_ULPS: f64 = 8.0;

/// How far, in `f32` ulps of a bound on the ray's distance to the geometry, a patch that
/// the ray hits in its ray space can lie outside the ray in world space: the accelerator
/// must not cull boxes nearer the ray than this ([`cull_margin`]).
///
/// Why: crack freedom holds in ray space (neighbours' transformed edges are bit-identical),
/// but a ray that passes a shared edge within the transform's rounding may be inside the
/// ray-space net of patch A and outside A's exact world box, while neighbour B's ray-space
/// net lets it through on A's side. Culling A by its world box then loses the hit, or
/// hands the ray to a surface behind (measured without the margin: 1 ray in 180,000 aimed
/// at the shared edges and extraordinary vertices of three subdivision surfaces went
/// through the cube's, `tests/lib/subdiv_surface.rs`). A ray-space coordinate is within [`TRANSFORM_ULPS`]
/// ulps of its exact value at the ray-space scale `|p - o| / |d|`, which is at most two
/// ulps of `|p - o|` back in world units, on each of the two axes across the ray: within
/// `2 √2 TRANSFORM_ULPS` ulps (about 22.6) of `|p - o|` of the ray. 32 also covers the
/// rounding of the margin's own arithmetic.
pub const CULL_MARGIN_ULPS: f32 = 32.0;

/// The margin by which an accelerator grows the boxes of patches for `ray` (see
/// [`CULL_MARGIN_ULPS`]), for geometry whose coordinates are at most `reach` in magnitude:
/// `|p - o| <= √3 (max |o| + reach)`, bounded by twice that sum. A few ulps of the scene's
/// scale, so it admits only boxes the ray passes within rounding of.
pub fn cull_margin(origin: [f32; 3], reach: f32) -> f32 {
    let o = origin.iter().fold(0f32, |m, c| m.max(c.abs()));
    let distance = 2.0 * (o + reach);
    let m = CULL_MARGIN_ULPS as f64 * crate::geom::ulp::ulp_of(distance);
    // An infinite reach or origin has no finite margin; traversal refuses such rays.
    if m.is_finite() { m as f32 } else { 0.0 }
}

/// Smallest ray-space coordinate scale (the largest magnitude of the patch's ray-space
/// box) searched in ray space: 2^-39, so that an edge of one ulp of that scale (2^-63)
/// still has a normal square (2^-126 = `f32::MIN_POSITIVE`) for the length heuristic.
/// Near the ray the ray-space coordinates approach 0 where world ones do not; below this
/// scale the heuristic's squares underflow there and the search degenerates (measured on
/// the teapot scaled by 1e-18 of the stability suite: 1.5e5 splits per ray).
pub const MIN_RAY_SPACE_SCALE: f32 = 1.0 / (1u64 << 39) as f32;

/// A search's hit with its final box in the space the search ran in: the ray space of the
/// query's frame when `ray_space_scale` is set (the net's coordinate scale there, which
/// [`RayFrame::world_box`] takes), world space otherwise. Only the nearest hit of a ray
/// needs its world box, so it is made once, at the end ([`super::KernelRay::hit_box`]).
#[derive(Clone, Copy, Debug)]
pub struct SpacedHit {
    pub hit: SearchHit<f32>,
    pub ray_space_scale: Option<f32>,
}

impl SpacedHit {
    pub fn world(hit: SearchHit<f32>) -> SpacedHit {
        SpacedHit {
            hit,
            ray_space_scale: None,
        }
    }
}

/// The transform of world points into ray space.
#[derive(Clone, Copy, Debug)]
pub struct RayFrame {
    pub origin: [f32; 3],
    /// `axes[r]`: ray-space axis `r` in world coordinates.
    pub axes: [[f32; 3]; 3],
    /// `1 / |d|`: a world length times this is a ray-space length.
    inv_len: f32,
    /// The inverse transform's columns `|d| e1`, `|d| e2`, `d`, in `f64`.
    inverse: [DVec3; 3],
}

impl RayFrame {
    pub fn new(ray: &GRay<f32>) -> RayFrame {
        let d = DVec3::from_array(ray.dir.map(f64::from));
        let len2 = d.length_squared();
        let len = len2.sqrt();
        let n = d / len;
        // Duff et al., "Building an Orthonormal Basis, Revisited" (JCGT 2017), listing 3.
        let sign = 1f64.copysign(n.z);
        let a = -1.0 / (sign + n.z);
        let b = n.x * n.y * a;
        let e1 = DVec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x) / len;
        let e2 = DVec3::new(b, sign + n.y * n.y * a, -n.y) / len;
        let e3 = d / len2;
        RayFrame {
            origin: ray.origin,
            axes: [e1, e2, e3].map(|e| e.as_vec3().to_array()),
            inv_len: (1.0 / len) as f32,
            inverse: [e1 * len2, e2 * len2, d],
        }
    }

    /// The ray itself in ray space: the z-axis from the origin, same `[tmin, tmax]`.
    pub fn axis_ray(&self, ray: &GRay<f32>) -> GRay<f32> {
        GRay::new([0.0; 3], [0.0, 0.0, 1.0], ray.tmin, ray.tmax)
    }

    /// The world box holding a ray-space box `local` of a net whose ray-space coordinates
    /// are at most `scale` in magnitude: see the module documentation.
    pub fn world_box(&self, local: &GBox<f32>, scale: f32) -> GBox<f32> {
        let to_world = |v: [f32; 3]| DVec3::from_array(v.map(f64::from));
        let (lo, hi) = (to_world(local.min), to_world(local.max));
        let (centre, half) = ((lo + hi) * 0.5, (hi - lo) * 0.5);
        // Columns of the inverse frame: `p - o = |d| (x e1 + y e2) + z d`.
        let columns = [self.inverse[0], self.inverse[1], self.inverse[2]];
        let mut mid = DVec3::from_array(self.origin.map(f64::from));
        let mut reach = DVec3::ZERO;
        for (c, col) in columns.iter().enumerate() {
            mid += *col * centre[c];
            reach += col.abs() * half[c];
        }
        let err = TRANSFORM_ULPS * crate::geom::ulp::ulp_of(scale) / self.inv_len as f64;
        let pad = reach + DVec3::splat(err * 3f64.sqrt());
        GBox::from_aabb(
            DAabb {
                min: mid - pad,
                max: mid + pad,
            }
            .to_f32_outward(),
        )
    }

    /// A world length in ray-space units.
    pub fn world_length(&self, world: f32) -> f32 {
        world * self.inv_len
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ray_points_map_to_the_z_axis() {
        let ray = GRay::new([1.0, -2.0, 0.5], [0.3, 2.0, -0.7], 0.0, f32::INFINITY);
        let f = RayFrame::new(&ray);
        for t in [0.0f32, 0.5, 3.0] {
            let p: [f32; 3] = std::array::from_fn(|c| ray.origin[c] + t * ray.dir[c]);
            let q = f
                .axes
                .map(|a| (0..3).map(|c| a[c] * (p[c] - f.origin[c])).sum::<f32>());
            assert!(q[0].abs() < 1e-5 && q[1].abs() < 1e-5, "{q:?}");
            assert!((q[2] - t).abs() < 1e-5 * (1.0 + t), "{q:?}");
        }
    }

    /// The world box of a ray-space box holds every world point that maps into it.
    #[test]
    fn world_box_holds_the_points_of_the_local_box() {
        let ray = GRay::new([1.0, -2.0, 0.5], [0.3, 2.0, -0.7], 0.0, f32::INFINITY);
        let f = RayFrame::new(&ray);
        let local = GBox {
            min: [-0.01, 0.02, 2.0],
            max: [0.03, 0.05, 2.01],
        };
        let b = f.world_box(&local, 2.5);
        let inverse = |q: [f64; 3]| {
            let o = DVec3::from_array(f.origin.map(f64::from));
            (0..3).fold(o, |p, c| p + f.inverse[c] * q[c])
        };
        let mut volume_corners = 0;
        for k in 0..8 {
            let q: [f64; 3] = std::array::from_fn(|c| {
                let (lo, hi) = (local.min[c] as f64, local.max[c] as f64);
                if k >> c & 1 == 0 { lo } else { hi }
            });
            let p = inverse(q);
            for c in 0..3 {
                assert!(
                    p[c] >= b.min[c] as f64 && p[c] <= b.max[c] as f64,
                    "{p:?} {b:?}"
                );
            }
            // And the forward transform of the world corner lands back on the local one.
            let back: [f64; 3] = std::array::from_fn(|r| {
                let a = DVec3::from_array(f.axes[r].map(f64::from));
                a.dot(p - DVec3::from_array(f.origin.map(f64::from)))
            });
            volume_corners += (0..3).all(|c| (back[c] - q[c]).abs() < 1e-6) as usize;
        }
        assert_eq!(volume_corners, 8);
        // Not much bigger than the local box scaled by |d| (about 2.1 here).
        let size: f32 = (0..3).map(|c| b.max[c] - b.min[c]).sum();
        assert!(size < 0.25, "{b:?}");
    }
}
