//! A STEP part through the real binary: planar, cylindrical, toroidal (fillet) and B-spline
//! faces, a hole through the plate and seams (`step_support::bracket`). Rays aimed at the
//! middle of every face must hit that face (the hit point lies on the face's own surface,
//! where the closed form puts it); `info` reports what the reader found; malformed
//! entities cost their faces, named with located reasons, and broken files are located
//! errors with exit code 2.

use crate::common;
use crate::step_support;

use common::{run, stderr, stdout, trace_hits};
use glam::DVec3;
use step_support::{FILLET, HOLE, PLATE, bracket};

/// The hit point of each ray, `None` for a miss.
fn trace(scene: &std::path::Path, rays: &[(DVec3, DVec3)]) -> Vec<Option<DVec3>> {
    trace_hits(scene, rays)
        .into_iter()
        .map(|h| h.map(|(point, _)| point))
        .collect()
}

fn write_part(dir: &std::path::Path) -> std::path::PathBuf {
    let path = dir.join("bracket.step");
    std::fs::write(&path, bracket(1)).unwrap();
    path
}

/// Rays at the middle of every face, each with the point the face's definition puts
/// there.
#[test]
fn rays_at_the_middle_of_every_face_hit_that_face() {
    let dir = tempfile::tempdir().unwrap();
    let part = write_part(dir.path());
    let (p, a, f) = (PLATE, HOLE, FILLET);
    let v = 2.0 * std::f64::consts::PI / 3.0; // the fillet's middle latitude
    let fillet_r = a + f + f * v.cos();
    let fillet_z = 1.0 - f + f * v.sin();
    let s = 0.5f64.sqrt();
    let cases = [
        (
            "top plane",
            DVec3::new(1.5, 1.5, 3.0),
            -DVec3::Z,
            DVec3::new(1.5, 1.5, 1.0),
        ),
        (
            "B-spline bottom",
            DVec3::new(1.5, -1.5, -2.0),
            DVec3::Z,
            DVec3::new(1.5, -1.5, 0.0),
        ),
        (
            "side +x",
            DVec3::new(4.0, 0.5, 0.5),
            -DVec3::X,
            DVec3::new(p, 0.5, 0.5),
        ),
        (
            "side -x",
            DVec3::new(-4.0, -0.5, 0.5),
            DVec3::X,
            DVec3::new(-p, -0.5, 0.5),
        ),
        (
            "side +y",
            DVec3::new(0.3, 4.0, 0.5),
            -DVec3::Y,
            DVec3::new(0.3, p, 0.5),
        ),
        (
            "side -y",
            DVec3::new(-0.3, -4.0, 0.5),
            DVec3::Y,
            DVec3::new(-0.3, -p, 0.5),
        ),
        // The hole wall at its seam (angle 0) and across it.
        (
            "wall at the seam",
            DVec3::new(0.0, 0.0, 0.4),
            DVec3::X,
            DVec3::new(a, 0.0, 0.4),
        ),
        (
            "wall opposite",
            DVec3::new(0.0, 0.0, 0.4),
            -DVec3::X,
            DVec3::new(-a, 0.0, 0.4),
        ),
        (
            "wall diagonal",
            DVec3::new(0.0, 0.0, 0.2),
            DVec3::new(-s, -s, 0.0),
            DVec3::new(-a * s, -a * s, 0.2),
        ),
        // The fillet at its middle latitude, from the axis, at and away from its seam.
        (
            "fillet at the seam",
            DVec3::new(0.0, 0.0, fillet_z),
            DVec3::X,
            DVec3::new(fillet_r, 0.0, fillet_z),
        ),
        (
            "fillet opposite",
            DVec3::new(0.0, 0.0, fillet_z),
            -DVec3::Y,
            DVec3::new(0.0, -fillet_r, fillet_z),
        ),
    ];
    let rays: Vec<(DVec3, DVec3)> = cases.iter().map(|c| (c.1, c.2)).collect();
    let hits = trace(&part, &rays);
    for ((name, _, _, want), hit) in cases.iter().zip(&hits) {
        let hit = hit.as_ref().unwrap_or_else(|| panic!("{name}: missed"));
        // f32 rendering precision of a part 4 across: a few ulps of 4.
        assert!(
            hit.distance(*want) < 1e-5,
            "{name}: hit {} expected {want}",
            hit
        );
    }
}

/// Rays through the hole (the top plane's and the bottom B-spline's inner loops, the wall's
/// and fillet's seams) must pass: vertical rays on a polar grid inside the wall's radius,
/// seam angle included, both ways, and slanted rays through the hole's centre that stay
/// inside the wall and under the fillet (offset at most 0.8 · 0.5 = 0.4 < HOLE at z = 0
/// and z = 1). Rays just outside the fillet's outer circle must still hit the top plane.
#[test]
fn rays_through_the_hole_pass_and_just_outside_it_hit_the_top() {
    let dir = tempfile::tempdir().unwrap();
    let part = write_part(dir.path());
    let (a, f) = (HOLE, FILLET);
    let mut through = Vec::new();
    for i in 0..12 {
        let r = a * (0.02 + 0.96 * i as f64 / 11.0);
        for j in 0..16 {
            let t = std::f64::consts::TAU * j as f64 / 16.0;
            let (x, y) = (r * t.cos(), r * t.sin());
            through.push((DVec3::new(x, y, 3.0), -DVec3::Z));
            through.push((DVec3::new(x, y, -2.0), DVec3::Z));
        }
    }
    for j in 0..16 {
        let t = std::f64::consts::TAU * j as f64 / 16.0;
        let d = DVec3::new(0.8 * t.cos(), 0.8 * t.sin(), -1.0);
        let centre = DVec3::new(0.0, 0.0, 0.5);
        through.push((centre - 3.0 * d, d));
    }
    let hits = trace(&part, &through);
    for ((o, d), hit) in through.iter().zip(&hits) {
        assert!(
            hit.is_none(),
            "ray from {o} along {d} through the hole hit {}",
            hit.unwrap()
        );
    }
    // Just outside the fillet's outer circle (radius HOLE + FILLET), every 15 degrees.
    let outside: Vec<(DVec3, DVec3)> = (0..24)
        .map(|j| {
            let t = std::f64::consts::TAU * j as f64 / 24.0;
            let r = (a + f) * 1.01;
            (DVec3::new(r * t.cos(), r * t.sin(), 3.0), -DVec3::Z)
        })
        .collect();
    for ((o, _), hit) in outside.iter().zip(trace(&part, &outside)) {
        let hit = hit.unwrap_or_else(|| panic!("ray down at {o} missed the top plane"));
        assert!((hit.z - 1.0).abs() < 1e-5, "at {o}: hit {}", hit);
    }
}

/// `same_sense` false turns the face's normal around (ISO 10303-42 §5.4.23) and changes
/// nothing else: a plane z = 0 with normal +z, a square face with a square hole, read both
/// ways; the hit points agree, the normals are +z and −z, the hole stays a hole.
#[test]
fn same_sense_false_turns_the_normal_and_keeps_the_trims() {
    let dir = tempfile::tempdir().unwrap();
    let square = |h: f64| [(-h, -h), (h, -h), (h, h), (-h, h)].map(|(x, y)| DVec3::new(x, y, 0.0));
    let rays = [
        (DVec3::new(0.7, 0.2, 2.0), -DVec3::Z),
        (DVec3::new(-0.3, -0.8, -2.0), DVec3::Z),
        (DVec3::new(0.1, 0.1, 2.0), -DVec3::Z),
    ];
    let mut normals = Vec::new();
    for same_sense in [true, false] {
        let mut w = step_support::StepWriter::default();
        let ax = w.axis(DVec3::ZERO, DVec3::Z, DVec3::X);
        let plane = w.add(format!("PLANE('',#{ax})"));
        let outer = w.polygon_bound(&square(1.0), true);
        let hole = w.polygon_bound(&square(0.25), false);
        w.face_with_sense(&[outer, hole], plane, same_sense);
        let path = dir.path().join(format!("sense_{same_sense}.step"));
        std::fs::write(&path, w.finish()).unwrap();
        let hits = trace_hits(&path, &rays);
        for (k, want) in [DVec3::new(0.7, 0.2, 0.0), DVec3::new(-0.3, -0.8, 0.0)]
            .iter()
            .enumerate()
        {
            let (point, _) = hits[k].unwrap_or_else(|| panic!("ray {k} missed"));
            assert!(point.distance(*want) < 1e-6, "{point} vs {want}");
        }
        assert!(
            hits[2].is_none(),
            "the hole is kept with same_sense {same_sense}"
        );
        normals.push(hits[0].unwrap().1);
    }
    let want = [DVec3::Z, -DVec3::Z];
    for (n, w) in normals.iter().zip(want) {
        assert!(n.normalize().distance(w) < 1e-6, "normal {n}, expected {w}");
    }
}

#[test]
fn info_reports_units_faces_and_projections() {
    let dir = tempfile::tempdir().unwrap();
    let part = write_part(dir.path());
    let o = run(&["info", part.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let out = stdout(&o);
    assert!(out.contains("STEP schema: AUTOMOTIVE_DESIGN"), "{out}");
    assert!(out.contains("length unit: millimetre (1 mm)"), "{out}");
    assert!(out.contains("faces: 8 converted, 0 failed"), "{out}");
    // Projected: fillet circles and seam (3), wall bottom and top circles (2, the seam
    // has pcurves), the B-spline bottom's square and circle (5). The planes' edges (top
    // square and circle, the sides) map exactly through the plane's frame.
    assert!(
        out.contains("projected edges (no usable pcurve): 10;"),
        "{out}"
    );
    // Loops: top 2, fillet 1, wall 1, bottom 2, sides 4.
    assert!(out.contains("10 trim loop(s)"), "{out}");
}

#[test]
fn unsupported_entities_are_counted_and_faces_named() {
    let dir = tempfile::tempdir().unwrap();
    let mut w = step_support::StepWriter::default();
    let ax = w.axis(DVec3::ZERO, DVec3::Z, DVec3::X);
    let plane = w.add(format!("PLANE('',#{ax})"));
    // An offset of an extrusion, which is not read (offsets of the elementary surfaces
    // are, as the elementary surface they are).
    let line = w.line(DVec3::ZERO, DVec3::X);
    let up = w.dir(DVec3::Y);
    let v = w.add(format!("VECTOR('',#{up},1.)"));
    let ext = w.add(format!("SURFACE_OF_LINEAR_EXTRUSION('',#{line},#{v})"));
    let offset = w.add(format!("OFFSET_SURFACE('',#{ext},1.,.F.)"));
    let sq = [DVec3::ZERO, DVec3::X, DVec3::new(1.0, 1.0, 0.0), DVec3::Y];
    let b = w.polygon_bound(&sq, true);
    let bad = w.face(&[b], offset);
    let b = w.polygon_bound(&sq, true);
    w.face(&[b], plane);
    let path = dir.path().join("offset.step");
    std::fs::write(&path, w.finish()).unwrap();
    let o = run(&["info", path.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let out = stdout(&o);
    assert!(
        out.contains("unsupported entities: OFFSET_SURFACE x1"),
        "{out}"
    );
    assert!(out.contains(&format!("face #{bad} not converted")), "{out}");
    let err = stderr(&o);
    assert_eq!(
        err.lines().filter(|l| l.starts_with("warning:")).count(),
        1,
        "{err}"
    );
    assert!(err.contains(&format!("#{bad}")), "{err}");
}

/// A malformed entity costs the faces that use it, as OpenCASCADE reads such files: each
/// is named with the error located in the file, the rest of the part is read (exit 0). A
/// file whose structure is broken (a string running to its end) is refused, located, with
/// exit 2.
#[test]
fn malformed_entities_cost_their_faces_and_broken_files_exit_2() {
    let dir = tempfile::tempdir().unwrap();
    let text = bracket(1);
    // A circle with a string for its radius: the reason names the line, column, instance
    // and entity.
    let line = text.lines().position(|l| l.contains("=CIRCLE(")).unwrap();
    let bad: Vec<String> = text
        .lines()
        .enumerate()
        .map(|(k, l)| {
            if k == line {
                let cut = l.rfind(',').unwrap();
                format!("{},'x');", &l[..cut])
            } else {
                l.to_string()
            }
        })
        .collect();
    let path = dir.path().join("bad.step");
    std::fs::write(&path, bad.join("\n")).unwrap();
    let o = run(&["info", path.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let id = bad[line].split('=').next().unwrap();
    let col = bad[line].rfind('\'').unwrap() - 1;
    let want = format!(
        "not converted: {}:{}: {id} CIRCLE: expected a radius, found a string",
        line + 1,
        col
    );
    let out = stdout(&o);
    assert!(out.contains(&want), "{out}\nwanted {want}");
    let failed = out.lines().filter(|l| l.contains(&want)).count();
    assert!(failed >= 1);
    assert!(
        out.contains(&format!("faces: {} converted, {failed} failed", 8 - failed)),
        "{out}"
    );
    assert!(stderr(&o).contains("not converted"), "{}", stderr(&o));
    // A dangling reference.
    let dangling = text.replacen("PLANE('',#", "PLANE('',#9999", 1);
    std::fs::write(&path, dangling).unwrap();
    let o = run(&["info", path.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stdout(&o).contains("which is not defined in the file"),
        "{}",
        stdout(&o)
    );
    // A string left open runs to the end of the file.
    let cut = text.replacen(
        "ENDSEC;\nEND-ISO",
        "#99999=PRODUCT('open);\nENDSEC;\nEND-ISO",
        1,
    );
    let open = cut.lines().position(|l| l.starts_with("#99999=")).unwrap() + 1;
    std::fs::write(&path, cut).unwrap();
    let o = run(&["info", path.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    let want = format!("bad.step:{open}:16: string is never closed");
    assert!(stderr(&o).contains(&want), "{}\nwanted {want}", stderr(&o));
}
