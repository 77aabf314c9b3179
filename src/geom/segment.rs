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

/// Distance from `p` to the closed triangle `a b c`: the nearest point found by the
/// Voronoi-region walk of Ericson, *Real-Time Collision Detection* (2005), §5.1.5
/// (`ClosestPtPointTriangle`); a degenerate triangle falls back to its edges.
pub fn distance_to_triangle(p: DVec3, a: DVec3, b: DVec3, c: DVec3) -> f64 {
    let (ab, ac, ap) = (b - a, c - a, p - a);
    if ab.cross(ac).length_squared() == 0.0 {
        return distance_to_segment(p, a, b)
            .min(distance_to_segment(p, b, c))
            .min(distance_to_segment(p, c, a));
    }
    let (d1, d2) = (ab.dot(ap), ac.dot(ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return ap.length();
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(bp), ac.dot(bp));
    if d3 >= 0.0 && d4 <= d3 {
        return bp.length();
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return (p - (a + ab * (d1 / (d1 - d3)))).length();
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(cp), ac.dot(cp));
    if d6 >= 0.0 && d5 <= d6 {
        return cp.length();
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return (p - (a + ac * (d2 / (d2 - d6)))).length();
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0 {
        return (p - (b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6))))).length();
    }
    let denom = 1.0 / (va + vb + vc);
    (p - (a + ab * (vb * denom) + ac * (vc * denom))).length()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn triangle_distance_in_each_region_matches_the_closed_form() {
        // The unit right triangle in z = 0: above its inside the distance is the height,
        // beyond a corner the distance to that corner, beyond an edge to that edge.
        let (a, b, c) = (DVec3::ZERO, DVec3::X, DVec3::Y);
        let d = |p: DVec3| distance_to_triangle(p, a, b, c);
        assert_eq!(d(DVec3::new(0.25, 0.25, 2.0)), 2.0);
        assert_eq!(d(DVec3::new(-3.0, -4.0, 0.0)), 5.0);
        assert_eq!(d(DVec3::new(4.0, 0.0, 4.0)), 5.0);
        assert_eq!(d(DVec3::new(0.5, -2.0, 0.0)), 2.0);
        assert!((d(DVec3::new(1.0, 1.0, 0.0)) - 0.5f64.sqrt()).abs() < 1e-15);
        assert_eq!(d(DVec3::new(-1.0, 0.5, 0.0)), 1.0);
    }
}
