//! STAND-IN until the real kernel lands.
use glam::Vec3;

use crate::geom::Aabb;

pub const DEFAULT_ULPS: u32 = 7;

pub fn secondary_origin(hit_box: &Aabb, normal: Vec3, outside: bool, ulps: u32) -> Vec3 {
    let s = if outside { 1.0 } else { -1.0 };
    let pick = |i: usize| {
        let up = normal[i] * s >= 0.0;
        let c = if up { hit_box.max[i] } else { hit_box.min[i] };
        crate::geom::ulp::step_ulps(c, if up { ulps as i32 } else { -(ulps as i32) })
    };
    Vec3::new(pick(0), pick(1), pick(2))
}
