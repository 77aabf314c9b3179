//! Scene-level NURBS → Bézier conversion and its report (Dammertz §2.8, Table 2.13).

use serde::Serialize;

use super::model::{Geometry, Scene, Surface, SurfaceGeometry};

/// Bytes per homogeneous control point as we store it (four `f64`).
const BYTES_PER_POINT: usize = 4 * 8;
/// Bytes per knot (`f64`).
const BYTES_PER_KNOT: usize = 8;

/// What a conversion did: counts before and after, and the memory ratio of Table 2.13.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct ConversionReport {
    pub nurbs_surfaces: usize,
    pub nurbs_control_points: usize,
    /// Bézier patches produced from NURBS surfaces.
    pub bezier_patches_from_nurbs: usize,
    /// Control points of those patches.
    pub bezier_control_points_from_nurbs: usize,
    /// Bézier patches that were already Bézier in the input (copied unchanged).
    pub bezier_patches_unchanged: usize,
    /// Size of the NURBS data (control points and knots), bytes.
    pub nurbs_bytes: usize,
    /// Size of the Bézier patches made from it, bytes.
    pub bezier_bytes: usize,
    /// `bezier_bytes / nurbs_bytes`, the memory increase of Table 2.13 (0 without NURBS).
    pub memory_ratio: f64,
}

/// Replaces every NURBS surface with its Bézier patches, in span order (u spans fastest).
/// Each patch keeps the surface's trim loops: they are written in the surface's parameter
/// space, which each patch keeps as its domain rectangle, so culling and the trim test see
/// the same region as before.
pub fn convert_scene(scene: &Scene) -> (Scene, ConversionReport) {
    let mut report = ConversionReport::default();
    let mut out = scene.clone();
    for object in &mut out.objects {
        // An instance's shared surfaces are converted in its placed copy.
        if let Geometry::Instance(i) = &object.geometry {
            object.geometry = i.flattened();
        }
        let Geometry::Surfaces(surfaces) = &mut object.geometry else {
            continue;
        };
        let mut converted = Vec::with_capacity(surfaces.len());
        for s in surfaces.drain(..) {
            match s.geometry {
                SurfaceGeometry::Bezier(p) => {
                    report.bezier_patches_unchanged += 1;
                    converted.push(Surface {
                        geometry: SurfaceGeometry::Bezier(p),
                        trims: s.trims,
                        trim_space: s.trim_space,
                    });
                }
                SurfaceGeometry::Nurbs(n) => {
                    report.nurbs_surfaces += 1;
                    report.nurbs_control_points += n.points.len();
                    report.nurbs_bytes += n.points.len() * BYTES_PER_POINT
                        + (n.knots_u.len() + n.knots_v.len()) * BYTES_PER_KNOT;
                    for p in n.to_bezier_patches() {
                        report.bezier_patches_from_nurbs += 1;
                        report.bezier_control_points_from_nurbs += p.point_count();
                        report.bezier_bytes += p.point_count() * BYTES_PER_POINT;
                        converted.push(Surface {
                            geometry: SurfaceGeometry::Bezier(p),
                            trims: s.trims.clone(),
                            trim_space: s.trim_space.clone(),
                        });
                    }
                }
            }
        }
        *surfaces = converted;
    }
    if report.nurbs_bytes > 0 {
        report.memory_ratio = report.bezier_bytes as f64 / report.nurbs_bytes as f64;
    }
    (out, report)
}
