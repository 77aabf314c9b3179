//! Origins of secondary rays (Dammertz §2.4): not a point on the surface but a corner of the
//! hit box chosen by the octant of the normal (§2.4.1), moved a few ulps further out
//! (§2.4.2), so no scene-dependent epsilon is needed.

use glam::Vec3;

use crate::geom::Aabb;
use crate::geom::ulp::step_ulps;

/// Ulps by which a secondary ray's origin is moved beyond the hit box (Dammertz §2.4.2:
/// "The value used in the implementation is 7").
pub const DEFAULT_ULPS: u32 = 7;

/// Largest `--ulps`: 2^12 ulps move an origin by 2^-11 of its coordinate, hundreds of
/// times the rounding error any kernel leaves (Dammertz §2.4.2 needs 7), while 2^32 moved
/// origins across the scene and cost seconds per pixel.
pub const MAX_ULPS: u32 = 1 << 12;

/// Origin of a secondary ray: the corner of the hit box chosen by the octant of the normal
/// (on the side the normal points to when `outside`, the opposite corner for refraction
/// rays going inside), each coordinate then moved `ulps` representable floats further in
/// that direction. Every point of the box then lies strictly behind the plane through the
/// origin with that normal, so a ray leaving into the normal's hemisphere cannot re-enter
/// the hit box.
pub fn secondary_origin(hit_box: &Aabb, normal: Vec3, outside: bool, ulps: u32) -> Vec3 {
    let n = if outside { normal } else { -normal };
    let steps = ulps.min(i32::MAX as u32) as i32;
    let pick = |n: f32, lo: f32, hi: f32| {
        if n >= 0.0 {
            step_ulps(hi, steps)
        } else {
            step_ulps(lo, -steps)
        }
    };
    Vec3::new(
        pick(n.x, hit_box.min.x, hit_box.max.x),
        pick(n.y, hit_box.min.y, hit_box.max.y),
        pick(n.z, hit_box.min.z, hit_box.max.z),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn corner_follows_the_normal_octant() {
        let b = Aabb::new(Vec3::new(1.0, -2.0, 3.0), Vec3::new(1.5, -1.0, 3.0));
        let o = secondary_origin(&b, Vec3::new(0.3, -0.2, 0.9), true, 7);
        assert_eq!(
            o,
            Vec3::new(step_ulps(1.5, 7), step_ulps(-2.0, -7), step_ulps(3.0, 7))
        );
        let i = secondary_origin(&b, Vec3::new(0.3, -0.2, 0.9), false, 7);
        assert_eq!(
            i,
            Vec3::new(step_ulps(1.0, -7), step_ulps(-1.0, 7), step_ulps(3.0, -7))
        );
        assert!(o.x > b.max.x && o.y < b.min.y && o.z > b.max.z);
    }
}
