//! Our RON scene format: the serde mirror of the scene model, and its conversion to and
//! from [`Scene`](crate::scene::Scene). Geometry is referenced by file (relative to the
//! scene) or given inline.
//!
//! - `schema`: the serde types, one per thing a scene file holds.
//! - `read`: parsing, checking and building the scene, with the files it references.
//! - `surfaces`: inline Bézier and NURBS surfaces and their trims, both ways.
//! - `write`: a scene as RON text, all geometry inline.

mod read;
mod schema;
mod surfaces;
mod write;

pub use self::read::{
    MAX_TRACE_DEPTH, parse_scene_file, parsed_scene, read_scene, read_scene_keyed,
};
pub use self::schema::{
    AxisMapDef, CameraDef, GeometryDef, Highlight, KeyDef, LightDef, MaterialDef, ObjectDef,
    OrbitDef, SceneFile, SurfaceDef, TransformDef, TrimLoopDef, TrimSegmentDef,
};
pub use self::write::{scene_to_file, scene_to_ron};
