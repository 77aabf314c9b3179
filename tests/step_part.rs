//! A STEP part through the real binary: planar, cylindrical, toroidal (fillet) and B-spline
//! faces, a hole through the plate and seams (`step_support::bracket`). Rays aimed at the
//! middle of every face must hit that face (the hit point lies on the face's own surface,
//! where the closed form puts it); `info` reports what the reader found; malformed files
//! are located errors with exit code 2.

mod common;
mod step_support;

use common::{run, stderr, stdout};
use glam::DVec3;
use step_support::{FILLET, HOLE, PLATE, bracket};

struct Hit {
    point: DVec3,
}

fn trace(scene: &std::path::Path, rays: &[(DVec3, DVec3)]) -> Vec<Option<Hit>> {
    let dir = scene.parent().unwrap();
    let file = dir.join("rays.txt");
    let text: String = rays
        .iter()
        .map(|(o, d)| format!("{} {} {} {} {} {}\n", o.x, o.y, o.z, d.x, d.y, d.z))
        .collect();
    std::fs::write(&file, text).unwrap();
    let o = run(&[
        "trace",
        scene.to_str().unwrap(),
        "--rays",
        file.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    stdout(&o)
        .lines()
        .skip(1)
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            (f[1] == "1").then(|| Hit {
                point: DVec3::new(
                    f[7].parse().unwrap(),
                    f[8].parse().unwrap(),
                    f[9].parse().unwrap(),
                ),
            })
        })
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
            hit.point.distance(*want) < 1e-5,
            "{name}: hit {} expected {want}",
            hit.point
        );
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
    // Projected: top square and circle (5), fillet circles and seam (3), wall bottom and
    // top circles (2, the seam has pcurves), bottom square and circle (5), sides (16).
    assert!(out.contains("projected edges: 31,"), "{out}");
    // Loops: top 2, fillet 1, wall 1, bottom 2, sides 4.
    assert!(out.contains("10 trim loop(s)"), "{out}");
}

#[test]
fn unsupported_entities_are_counted_and_faces_named() {
    let dir = tempfile::tempdir().unwrap();
    let mut w = step_support::StepWriter::default();
    let ax = w.axis(DVec3::ZERO, DVec3::Z, DVec3::X);
    let plane = w.add(format!("PLANE('',#{ax})"));
    let offset = w.add(format!("OFFSET_SURFACE('',#{plane},1.,.F.)"));
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

#[test]
fn malformed_entities_are_located_errors_with_exit_2() {
    let dir = tempfile::tempdir().unwrap();
    let text = bracket(1);
    // A circle with a string for its radius: the error names the file, line, column,
    // instance and entity.
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
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    let err = stderr(&o);
    let id = bad[line].split('=').next().unwrap();
    let col = bad[line].rfind('\'').unwrap() - 1;
    let want = format!(
        "bad.step:{}:{}: {id} CIRCLE: expected a radius, found a string",
        line + 1,
        col
    );
    assert!(err.contains(&want), "{err}\nwanted {want}");
    // A dangling reference.
    let dangling = text.replacen("PLANE('',#", "PLANE('',#9999", 1);
    std::fs::write(&path, dangling).unwrap();
    let o = run(&["info", path.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("which is not defined in the file"),
        "{}",
        stderr(&o)
    );
}
