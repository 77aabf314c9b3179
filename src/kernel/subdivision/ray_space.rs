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
//! search every patch in the same space: ray space is a property of the ray (primary rays,
//! [`super::SubdivisionConfig::ray_space`]), never of the patch. Secondary rays keep
//! Dammertz's world-space search, because their origins are corners of world-space hit
//! boxes (§2.4) whose subdivision must be the same for every ray.
//!
//! Precision. The transformed points are rounded to ulps of their distance from the ray
//! origin, while the world net is exact only to ulps of its own coordinates: the end game
//! ([`super::search`]) stops at the larger of the two ([`RayFrame::world_length`]), so the
//! search never refines below the precision of the net it came from.
//!
//! Hit box. Secondary rays start from a corner of the world-space box of the hit (§2.4),
//! which must contain the surface piece. It is computed once at the end from the final
//! parameter cell ([`cell_box`]): the world `f32` net restricted to the cell in `f64` (two
//! de Casteljau steps per direction), padded by a bound on the `f64` rounding and rounded
//! outward to `f32`. By the convex hull property it contains the `f32` net's surface over
//! the cell.

use glam::DVec3;

use super::float::{GBox, GRay};
use super::param::ParamCell;
use crate::geom::DAabb;

/// Relative `f64` rounding bound of [`cell_box`], in units of `f64::EPSILON` times the
/// largest coordinate magnitude: four de Casteljau passes of at most 3 levels (degree ≤ 3),
/// each level one rounded multiply-add pair (≤ 2 eps); 64 leaves a factor of 2.6 of room
/// and is still 2^-46, far below one `f32` ulp (2^-23).
const CELL_BOX_PAD_EPS: f64 = 64.0;

/// Smallest ray-space coordinate scale (the largest magnitude of the patch's ray-space
/// box) searched in ray space: 2^-39, so that an edge of one ulp of that scale (2^-63)
/// still has a normal square (2^-126 = `f32::MIN_POSITIVE`) for the length heuristic.
/// Near the ray the ray-space coordinates approach 0 where world ones do not; below this
/// scale the heuristic's squares underflow there and the search degenerates (measured on
/// the teapot scaled by 1e-18 of the stability suite: 1.5e5 splits per ray).
pub const MIN_RAY_SPACE_SCALE: f32 = 1.0 / (1u64 << 39) as f32;

/// The transform of world points into ray space.
#[derive(Clone, Copy, Debug)]
pub struct RayFrame {
    pub origin: [f32; 3],
    /// `axes[r]`: ray-space axis `r` in world coordinates.
    pub axes: [[f32; 3]; 3],
    /// `1 / |d|`: a world length times this is a ray-space length.
    inv_len: f32,
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
        }
    }

    /// The ray itself in ray space: the z-axis from the origin, same `[tmin, tmax]`.
    pub fn axis_ray(&self, ray: &GRay<f32>) -> GRay<f32> {
        GRay::new([0.0; 3], [0.0, 0.0, 1.0], ray.tmin, ray.tmax)
    }

    /// A world length in ray-space units.
    pub fn world_length(&self, world: f32) -> f32 {
        world * self.inv_len
    }
}

/// The world box of the net `rows` (`rows[j][i]` the point (i, j), degree `M - 1` in both
/// directions) restricted to `cell`: see the module documentation.
pub fn cell_box<const M: usize>(rows: &[[[f32; 3]; M]; M], cell: ParamCell) -> GBox<f32> {
    let (u0, v0, wu, wv) = cell.bounds();
    let mut net = rows.map(|row| row.map(|p| DVec3::from_array(p.map(f64::from))));
    let scale = net
        .iter()
        .flatten()
        .fold(0f64, |a, p| a.max(p.abs().max_element()));
    for row in net.iter_mut() {
        restrict(row, u0, wu);
    }
    for i in 0..M {
        let mut col: [DVec3; M] = std::array::from_fn(|j| net[j][i]);
        restrict(&mut col, v0, wv);
        (0..M).for_each(|j| net[j][i] = col[j]);
    }
    let mut b = DAabb::EMPTY;
    net.iter().flatten().for_each(|p| b.grow(*p));
    let pad = DVec3::splat(CELL_BOX_PAD_EPS * f64::EPSILON * scale);
    let padded = DAabb {
        min: b.min - pad,
        max: b.max + pad,
    };
    GBox::from_aabb(padded.to_f32_outward())
}

/// Replaces the control points of a Bézier curve over [0, 1] by those of its piece over
/// `[a, a + w]`: de Casteljau at `a` keeping the upper part, then at `w / (1 - a)` keeping
/// the lower.
fn restrict<const M: usize>(c: &mut [DVec3; M], a: f64, w: f64) {
    let n = M - 1;
    // Upper part at a: c[i] becomes the level-(n - i) value at index i.
    for r in 1..=n {
        for i in 0..=n - r {
            c[i] += a * (c[i + 1] - c[i]);
        }
    }
    // Lower part at s: c[k] becomes the level-k value at index 0 (top down, in place).
    let s = if a < 1.0 { w / (1.0 - a) } else { 1.0 };
    for r in 1..=n {
        for i in (r..=n).rev() {
            c[i] = c[i - 1] + s * (c[i] - c[i - 1]);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::BezierPatch;
    use crate::kernel::subdivision::param::Split;

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

    #[test]
    fn cell_box_contains_the_surface_over_the_cell() {
        let pts: Vec<DVec3> = (0..16)
            .map(|k| {
                let (i, j) = ((k % 4) as f64, (k / 4) as f64);
                DVec3::new(i + 0.3 * j, j - 0.2 * i * i, (i - j).sin())
            })
            .collect();
        let f32pts: Vec<[f32; 3]> = pts.iter().map(|q| q.as_vec3().to_array()).collect();
        let cell = ParamCell::ROOT
            .split(Split::U)
            .1
            .split(Split::V)
            .0
            .split(Split::U)
            .0;
        let rows: [[[f32; 3]; 4]; 4] =
            std::array::from_fn(|j| std::array::from_fn(|i| f32pts[j * 4 + i]));
        let b = cell_box(&rows, cell).to_aabb();
        let (u0, v0, wu, wv) = cell.bounds();
        // The surface of the f32 net (evaluated in f64) over the cell is inside; the
        // cell covers an eighth of the parameter square, so the box is much smaller.
        let f32_patch = BezierPatch::from_points(
            3,
            3,
            &f32pts
                .iter()
                .map(|q| DVec3::from_array(q.map(f64::from)))
                .collect::<Vec<_>>(),
        )
        .unwrap();
        for a in 0..=8 {
            for c in 0..=8 {
                let q = f32_patch.eval(u0 + wu * a as f64 / 8.0, v0 + wv * c as f64 / 8.0);
                for k in 0..3 {
                    assert!(
                        q[k] >= b.min[k] as f64 && q[k] <= b.max[k] as f64,
                        "{q:?} {b:?}"
                    );
                }
            }
        }
        let whole = f32_patch.control_box();
        assert!((b.max - b.min).element_sum() < 0.5 * (whole.max - whole.min).element_sum() as f32);
    }
}
