//! The OBJ free-form writer: Bézier patches as `surf` elements, with their trim loops as
//! `curv2` curves under `trim` and `hole` (OBJ specification, Appendix B1, "Free-form
//! curve/surface attributes" and "Free-form curve/surface body statements").

use std::io::Write;

use crate::formats::sheet::Sheet;
use crate::geom::BezierPatch;
use crate::geom::trim::ParamCurve;

/// Writes patches as OBJ free-form Bézier surfaces, each over its own domain and untrimmed
/// (see [`write_obj_sheets`]).
pub fn write_obj_freeform(w: &mut dyn Write, patches: &[BezierPatch]) -> std::io::Result<()> {
    let sheets: Vec<Sheet> = patches
        .iter()
        .map(|p| {
            let d = p.domain();
            Sheet {
                object: 0,
                degree_u: p.degree_u(),
                degree_v: p.degree_v(),
                breaks_u: vec![d.u0, d.u1],
                breaks_v: vec![d.v0, d.v1],
                net: p.homogeneous_points().to_vec(),
                loops: Vec::new(),
            }
        })
        .collect();
    write_obj_sheets(w, &sheets)
}

/// Writes sheets of Bézier patches as OBJ free-form surfaces. Per sheet: its loops' curves
/// as `curv2` B-splines (`cstype [rat] bspline`, `deg p`, `vp u v [w]` points, `parm u`
/// knots), then the surface as `cstype [rat] bezier`, `deg du dv`, `v x y z [w]` points
/// (u fastest), `surf u0 u1 v0 v1 i...` over the whole domain, `parm u` and `parm v` with
/// the breakpoints (a piecewise Bézier surface, one patch per span), one `trim` (outer
/// loop) or `hole` statement per loop listing `t0 t1 curve` per segment, and `end`.
///
/// Numbers are written with Rust's shortest round-trip formatting, so non-rational points,
/// breakpoints, knots and ranges read back bit for bit. OBJ stores rational points as
/// Euclidean coordinates and a weight, so premultiplied coordinates come back within an ulp
/// or so (`(w x / w) · w` is not always `w x` in floating point).
pub fn write_obj_sheets(w: &mut dyn Write, sheets: &[Sheet]) -> std::io::Result<()> {
    let patches: usize = sheets
        .iter()
        .map(|s| (s.breaks_u.len() - 1) * (s.breaks_v.len() - 1))
        .sum();
    writeln!(w, "# {patches} Bézier patch(es) written by patchtrace")?;
    let mut counts = Counts {
        vertices: 0,
        params: 0,
        curves: 0,
    };
    for sheet in sheets {
        write_sheet(w, sheet, &mut counts)?;
    }
    Ok(())
}

/// Elements written so far, for 1-based indices.
struct Counts {
    vertices: usize,
    params: usize,
    curves: usize,
}

fn rat(rational: bool) -> &'static str {
    if rational { "rat " } else { "" }
}

fn write_sheet(w: &mut dyn Write, sheet: &Sheet, counts: &mut Counts) -> std::io::Result<()> {
    // The loops' curves first: `trim` refers to curves defined before it.
    let mut loop_curves = Vec::with_capacity(sheet.loops.len());
    for l in &sheet.loops {
        let mut indices = Vec::with_capacity(l.segments.len());
        for s in &l.segments {
            write_curve(w, &s.curve, counts)?;
            indices.push(counts.curves);
        }
        loop_curves.push(indices);
    }
    let rational = sheet.is_rational();
    for h in &sheet.net {
        let e = h.truncate() / h.w;
        if rational {
            writeln!(w, "v {} {} {} {}", e.x, e.y, e.z, h.w)?;
        } else {
            writeln!(w, "v {} {} {}", e.x, e.y, e.z)?;
        }
    }
    writeln!(w, "cstype {}bezier", rat(rational))?;
    writeln!(w, "deg {} {}", sheet.degree_u, sheet.degree_v)?;
    let d = sheet.domain();
    write!(w, "surf {} {} {} {}", d.u0, d.u1, d.v0, d.v1)?;
    for i in counts.vertices + 1..=counts.vertices + sheet.net.len() {
        write!(w, " {i}")?;
    }
    writeln!(w)?;
    counts.vertices += sheet.net.len();
    write_list(w, "parm u", &sheet.breaks_u)?;
    write_list(w, "parm v", &sheet.breaks_v)?;
    for (l, indices) in sheet.loops.iter().zip(&loop_curves) {
        write!(w, "{}", if l.hole { "hole" } else { "trim" })?;
        for (s, c) in l.segments.iter().zip(indices) {
            write!(w, " {} {} {c}", s.t0, s.t1)?;
        }
        writeln!(w)?;
    }
    writeln!(w, "end")
}

/// A parameter-space curve as a `curv2` B-spline element.
fn write_curve(w: &mut dyn Write, c: &ParamCurve, counts: &mut Counts) -> std::io::Result<()> {
    let rational = c.points.iter().any(|p| p.z != 1.0);
    for p in &c.points {
        if rational {
            writeln!(w, "vp {} {} {}", p.x / p.z, p.y / p.z, p.z)?;
        } else {
            writeln!(w, "vp {} {}", p.x, p.y)?;
        }
    }
    writeln!(w, "cstype {}bspline", rat(rational))?;
    writeln!(w, "deg {}", c.degree)?;
    write!(w, "curv2")?;
    for i in counts.params + 1..=counts.params + c.points.len() {
        write!(w, " {i}")?;
    }
    writeln!(w)?;
    counts.params += c.points.len();
    counts.curves += 1;
    write_list(w, "parm u", &c.knots)?;
    writeln!(w, "end")
}

fn write_list(w: &mut dyn Write, keyword: &str, values: &[f64]) -> std::io::Result<()> {
    write!(w, "{keyword}")?;
    for x in values {
        write!(w, " {x}")?;
    }
    writeln!(w)
}
