//! Wavefront OBJ free-form geometry (the "free-form curve/surface" part of the OBJ
//! specification, Appendix B of the Wavefront *Advanced Visualizer* manual): a reader for
//! Bézier and B-spline surfaces with trimming loops, and a writer for Bézier patches with
//! their trimming loops.
//! Polygonal OBJ files are read as triangle meshes by [`parse_obj_mesh`].

mod polygons;
mod reader;
mod writer;

pub use polygons::parse_obj_mesh;
pub use reader::parse_obj_freeform;
pub use writer::{write_obj_freeform, write_obj_sheets};

/// Statements that mark a file as free-form rather than a polygon mesh.
const FREEFORM_KEYWORDS: [&str; 3] = ["cstype", "surf", "curv2"];

/// True when the text holds free-form surface statements (`cstype`, `surf` or `curv2`).
pub fn is_freeform(src: &str) -> bool {
    src.lines()
        .any(|l| FREEFORM_KEYWORDS.contains(&l.split_whitespace().next().unwrap_or("")))
}
