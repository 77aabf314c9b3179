use super::*;
use crate::geom::nurbs::NurbsSurface;
use crate::geom::trim::{ParamCurve, TrimLoop};
use crate::scene::model::{Geometry, Object, SurfaceGeometry};
use crate::tessellate::{TessellationMode, tessellate_object};
use std::f64::consts::PI;

/// The even-odd test against a polygon, independent of the trim code.
fn in_polygon(p: DVec2, poly: &[DVec2]) -> bool {
    let mut odd = false;
    for k in 0..poly.len() {
        let (a, b) = (poly[k], poly[(k + 1) % poly.len()]);
        if (a.y > p.y) != (b.y > p.y) && p.x < a.x + (p.y - a.y) * (b.x - a.x) / (b.y - a.y) {
            odd = !odd;
        }
    }
    odd
}

fn distance_to_polygon(p: DVec2, poly: &[DVec2]) -> f64 {
    (0..poly.len())
        .map(|k| {
            let (a, b) = (poly[k].extend(0.0), poly[(k + 1) % poly.len()].extend(0.0));
            crate::geom::segment::distance_to_segment(p.extend(0.0), a, b)
        })
        .fold(f64::INFINITY, f64::min)
}

fn dense_circle(c: DVec2, r: f64) -> Vec<DVec2> {
    (0..4096)
        .map(|k| c + r * DVec2::from_angle(2.0 * PI * k as f64 / 4096.0))
        .collect()
}

/// A curved biquadratic NURBS over [0, 2]² with 2 × 2 spans, cut by an outer square, a
/// round hole across the middle knot lines and a clockwise square island in the hole.
fn bent_surface() -> (Surface, Vec<Vec<DVec2>>) {
    let n = 4;
    let mut points = Vec::new();
    for j in 0..n {
        for i in 0..n {
            let (x, y) = (i as f64 * 2.0 / 3.0, j as f64 * 2.0 / 3.0);
            let z = 0.3 * ((i * j) % 3) as f64 - 0.2 * (i as f64 - 1.5).powi(2);
            points.push(DVec4::new(x, y, z, 1.0));
        }
    }
    let knots = vec![0.0, 0.0, 0.0, 1.0, 2.0, 2.0, 2.0];
    let nurbs = NurbsSurface::new(2, 2, knots.clone(), knots, n, n, points).unwrap();
    let (c, r) = (DVec2::new(1.0, 0.9), 0.5);
    let to2 =
        |q: &[(f64, f64)]| -> Vec<DVec2> { q.iter().map(|&(x, y)| DVec2::new(x, y)).collect() };
    let outer = to2(&[(0.1, 0.1), (1.9, 0.1), (1.9, 1.9), (0.1, 1.9)]);
    let island = to2(&[(0.9, 0.8), (0.9, 1.0), (1.1, 1.0), (1.1, 0.8)]);
    let surface = Surface {
        geometry: SurfaceGeometry::Nurbs(nurbs),
        trims: vec![
            TrimLoop::closed(ParamCurve::polygon(&outer), false),
            TrimLoop::closed(ParamCurve::circle(c, r), true),
            TrimLoop::closed(ParamCurve::polygon(&island), false),
        ],
        trim_space: Default::default(),
    };
    let loops = vec![outer, dense_circle(c, r), island];
    (surface, loops)
}

fn param_triangulation(surface: &Surface, mode: TessellationMode) -> ParamTriangulation {
    let plan = Plan::new(mode).unwrap();
    let region = surface.trim_region().unwrap().unwrap();
    let budget = Budget {
        object: "",
        triangles: MAX_TRIANGLES,
    };
    let face = Face::new(surface, region, plan).unwrap().unwrap();
    face.triangulate(plan, budget, 0).unwrap().0
}

#[test]
fn every_triangle_centre_lies_inside_the_loops() {
    let (surface, loops) = bent_surface();
    for mode in [
        TessellationMode::TrianglesPerPatch(128),
        TessellationMode::Adaptive { tolerance: 2e-3 },
    ] {
        let tri = param_triangulation(&surface, mode);
        // Away from the loops by more than their sampling error: the circle's chords are
        // within r (1 - cos(π/32)) = 2.4e-3 of it in the grid mode (8 segments per
        // quarter at least) and about the tolerance in the adaptive one.
        let margin = 1e-2;
        let mut checked = 0;
        let mut area = 0.0;
        for t in &tri.triangles {
            let [a, b, c] = t.map(|i| tri.params[i as usize]);
            let twice = (b - a).perp_dot(c - a);
            assert!(twice > 0.0, "{mode:?}: clockwise or flat triangle");
            area += 0.5 * twice;
            let centre = (a + b + c) / 3.0;
            if loops
                .iter()
                .any(|l| distance_to_polygon(centre, l) < margin)
            {
                continue;
            }
            let parity = loops.iter().filter(|l| in_polygon(centre, l)).count();
            assert_eq!(parity % 2, 1, "{mode:?}: centre {centre} is trimmed away");
            checked += 1;
        }
        assert!(checked > 200, "{mode:?}: {checked}");
        // The kept area in the parameter plane: square, less the disc, plus the island.
        let want = 1.8 * 1.8 - PI * 0.25 + 0.2 * 0.2;
        assert!(
            (area - want).abs() < 0.01,
            "{mode:?}: area {area} vs {want}"
        );
    }
}

#[test]
fn a_plate_with_a_round_hole_misses_the_holes_area() {
    // The plane z = 0 over [0, 1]² (x = u, y = v), a hole of radius r: the mesh's area is
    // 1 - π r² up to the polygon inscribed in the circle, whose area falls short of the
    // disc's by less than its perimeter times the chord height, i.e. 2π r · tolerance.
    let plate = BezierPatch::from_points(
        1,
        1,
        &[
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(0.0, 1.0, 0.0),
            DVec3::new(1.0, 1.0, 0.0),
        ],
    )
    .unwrap();
    let r = 0.3;
    for tolerance in [1e-2, 1e-4] {
        let surface = Surface {
            trims: vec![
                TrimLoop::closed(
                    ParamCurve::polygon(&[DVec2::ZERO, DVec2::X, DVec2::ONE, DVec2::Y]),
                    false,
                ),
                TrimLoop::closed(ParamCurve::circle(DVec2::new(0.45, 0.55), r), true),
            ],
            ..Surface::bezier(plate.clone())
        };
        let object = Object {
            name: "plate".into(),
            material: 0,
            geometry: Geometry::Surfaces(vec![surface]),
        };
        let (mesh, report) =
            tessellate_object(&object, TessellationMode::Adaptive { tolerance }).unwrap();
        let Geometry::Mesh(mesh) = mesh.geometry else {
            panic!("not a mesh")
        };
        let area: f64 = mesh
            .indices
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| mesh.positions[i as usize]);
                0.5 * (b - a).cross(c - a).length()
            })
            .sum();
        let exact = 1.0 - PI * r * r;
        assert!(area >= exact - 1e-12, "{tolerance}: {area} < {exact}");
        assert!(
            area - exact <= 2.0 * PI * r * tolerance,
            "{tolerance}: {area} vs {exact}"
        );
        assert!(mesh.positions.iter().all(|p| p.z == 0.0));
        assert_eq!(report.trim_gaps.faces, 1);
    }
}
