//! Gaps between neighbouring trimmed faces. Two faces that share a trim curve in the model
//! each have their own copy of it in their own parameters (CAD exporters fit them
//! separately, to the exporter's tolerance); where the copies meet within the join distance
//! the faces share their samples ([`super::shared`]) and the gap is zero, elsewhere the two
//! meshes meet only approximately. The gap at a boundary sample of
//! one face is its distance to the nearest boundary polyline of any other face; samples with
//! no other face within [`NEIGHBOUR_FRACTION`] of the model's size lie on a free edge (or
//! next to an untrimmed surface) and are counted apart, not mixed into the gap.

use glam::DVec3;
use serde::Serialize;

use super::cubes::Cubes;
use crate::geom::segment::distance_to_segment;

/// How near (as a fraction of the diagonal of all trimmed boundaries' box) another face's
/// boundary must come for a sample to count as shared with it. CAD exchange tolerances are
/// 10⁻⁶ to 10⁻⁴ of a part's size (IGES 5.3 §2.2.4.3 global parameter 19, "minimum
/// resolution"); 10⁻³ counts gaps up to ten times the loosest of them as gaps and still
/// tells a free edge from a shared one on any part whose features are not that thin.
pub const NEIGHBOUR_FRACTION: f64 = 1e-3;

/// The gaps between trimmed faces (module docs). A gap counts as open when it is wider
/// than one `f32` rounding step of the sample's coordinates: the triangle path renders from
/// `f32` positions, so anything narrower is not there once the mesh is stored.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct TrimGaps {
    /// Trimmed faces measured.
    pub faces: u64,
    /// Boundary samples with another face's boundary within the neighbour radius.
    pub shared_samples: u64,
    /// Of those, samples farther than `f32` rounding from the other face.
    pub open_samples: u64,
    /// Boundary samples with no other face within the neighbour radius.
    pub free_samples: u64,
    /// The widest gap at a shared sample (scene units).
    pub largest: f64,
    /// The neighbour radius used (scene units).
    pub radius: f64,
}

/// Measures the gaps between `faces`, each given as its boundary polylines.
pub fn measure(faces: &[Vec<Vec<DVec3>>]) -> TrimGaps {
    let all = faces.iter().flatten().flatten().filter(|p| p.is_finite());
    let (lo, hi) = all.fold(
        (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
        |(lo, hi), &p| (lo.min(p), hi.max(p)),
    );
    let mut gaps = TrimGaps {
        faces: faces.len() as u64,
        ..TrimGaps::default()
    };
    let diagonal = (hi - lo).length();
    if !(diagonal.is_finite() && diagonal > 0.0) {
        return gaps;
    }
    gaps.radius = diagonal * NEIGHBOUR_FRACTION;
    let grid = SegmentGrid::new(faces, gaps.radius, lo);
    for (face, lines) in faces.iter().enumerate() {
        for &p in lines.iter().flatten().filter(|p| p.is_finite()) {
            match grid.nearest_other(p, face) {
                Some(d) if d <= gaps.radius => {
                    gaps.shared_samples += 1;
                    if d > f32::EPSILON as f64 * p.abs().max_element() {
                        gaps.open_samples += 1;
                    }
                    gaps.largest = gaps.largest.max(d);
                }
                _ => gaps.free_samples += 1,
            }
        }
    }
    gaps
}

/// Boundary segments hashed into cubes of twice the neighbour radius, each segment into the
/// cubes of points along it at most half a radius apart: a point within the radius of a
/// segment is then within 1¼ radii of one of those points, so in its own cube or a
/// neighbouring one.
struct SegmentGrid<'a> {
    faces: &'a [Vec<Vec<DVec3>>],
    cubes: Cubes<(u32, u32, u32)>,
}

impl<'a> SegmentGrid<'a> {
    fn new(faces: &'a [Vec<Vec<DVec3>>], radius: f64, origin: DVec3) -> Self {
        let mut cubes = Cubes::new(2.0 * radius, origin);
        for (f, lines) in faces.iter().enumerate() {
            for (l, line) in lines.iter().enumerate() {
                for (s, w) in line.windows(2).enumerate() {
                    if w[0].is_finite() && w[1].is_finite() {
                        cubes.insert_segment(
                            w[0],
                            w[1],
                            0.5 * radius,
                            (f as u32, l as u32, s as u32),
                        );
                    }
                }
            }
        }
        SegmentGrid { faces, cubes }
    }

    /// The distance from `p` to the nearest segment of a face other than `face` in `p`'s
    /// cube and its neighbours.
    fn nearest_other(&self, p: DVec3, face: usize) -> Option<f64> {
        let mut best: Option<f64> = None;
        self.cubes.visit_near(p, |(f, l, s)| {
            if f as usize != face {
                let line = &self.faces[f as usize][l as usize];
                let d = distance_to_segment(p, line[s as usize], line[s as usize + 1]);
                best = Some(best.map_or(d, |b| b.min(d)));
            }
        });
        best
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn two_faces_a_known_distance_apart_have_that_gap() {
        // Face 0's edge along x at y = 0; face 1's along x at y = h, sampled differently;
        // face 2 far away is free. The gap at every shared sample is h (closed form).
        let h = 1e-3;
        let line = |y: f64, n: usize| -> Vec<DVec3> {
            (0..=n)
                .map(|k| DVec3::new(k as f64 / n as f64, y, 0.0))
                .collect()
        };
        let faces = vec![
            vec![line(0.0, 7)],
            vec![line(h, 5)],
            vec![vec![DVec3::new(0.5, 5.0, 0.0), DVec3::new(0.6, 5.0, 0.0)]],
        ];
        let g = measure(&faces);
        assert_eq!(g.faces, 3);
        assert_eq!(g.shared_samples, 8 + 6);
        assert_eq!(g.open_samples, 14);
        assert_eq!(g.free_samples, 2);
        assert!((g.largest - h).abs() < 1e-15, "{}", g.largest);
    }

    #[test]
    fn coincident_boundaries_have_no_open_gap() {
        let a: Vec<DVec3> = (0..=4).map(|k| DVec3::new(k as f64, 1.0, 2.0)).collect();
        let mut b = a.clone();
        b.reverse();
        let g = measure(&[vec![a], vec![b]]);
        assert_eq!(
            (g.shared_samples, g.open_samples, g.free_samples),
            (10, 0, 0)
        );
        assert_eq!(g.largest, 0.0);
    }
}
