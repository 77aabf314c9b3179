//! Straight segments in space: the distance of a point from one (polylines through curve
//! samples, edges of triangles).

use glam::DVec3;

/// Distance from `p` to the closed segment from `a` to `b` (its nearest point is the
/// projection onto the line, clamped to the ends).
pub fn distance_to_segment(p: DVec3, a: DVec3, b: DVec3) -> f64 {
    let ab = b - a;
    let len2 = ab.length_squared();
    let t = if len2 > 0.0 {
        ((p - a).dot(ab) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (p - (a + ab * t)).length()
}
