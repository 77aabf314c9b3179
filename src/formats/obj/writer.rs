//! The OBJ free-form writer: Bézier patches as `surf` elements.

use std::io::Write;

use crate::geom::BezierPatch;

/// Writes patches as OBJ free-form Bézier surfaces: `cstype bezier` (or `cstype rat
/// bezier` when some weight is not 1), then per patch its control points as `v x y z [w]`
/// and `deg du dv`, `surf 0 1 0 1 i...` (u fastest), `parm u 0 1`, `parm v 0 1`, `end`.
///
/// Coordinates are written with Rust's shortest round-trip formatting, so reading the file
/// back gives the same non-rational patches bit for bit. OBJ stores rational points as
/// Euclidean coordinates and a weight, so a rational patch's premultiplied coordinates
/// come back within an ulp or so (`(w x / w) · w` is not always `w x` in floating point).
/// Patch domains are not written: every patch is read back with the unit domain.
pub fn write_obj_freeform(w: &mut dyn Write, patches: &[BezierPatch]) -> std::io::Result<()> {
    let rational = patches.iter().any(BezierPatch::is_rational);
    writeln!(
        w,
        "# {} Bézier patch(es) written by patchtrace",
        patches.len()
    )?;
    writeln!(w, "cstype {}bezier", if rational { "rat " } else { "" })?;
    let mut next_index = 1;
    for p in patches {
        for h in p.homogeneous_points() {
            let e = h.truncate() / h.w;
            if rational {
                writeln!(w, "v {} {} {} {}", e.x, e.y, e.z, h.w)?;
            } else {
                writeln!(w, "v {} {} {}", e.x, e.y, e.z)?;
            }
        }
        writeln!(w, "deg {} {}", p.degree_u(), p.degree_v())?;
        write!(w, "surf 0 1 0 1")?;
        for i in next_index..next_index + p.point_count() {
            write!(w, " {i}")?;
        }
        writeln!(w)?;
        writeln!(w, "parm u 0 1\nparm v 0 1\nend")?;
        next_index += p.point_count();
    }
    Ok(())
}
