//! STEP (ISO 10303-21 exchange structure, AP203/AP214/AP242 B-rep models), layered like
//! OpenCASCADE's reader (StepData / StepGeom / StepToGeom):
//!
//! - `lexer`, `records`: Part 21 syntax, every token with its line and column.
//! - `entities`: typed, validated ISO 10303-42 geometry and topology.
//! - `geometry`: curves and surfaces evaluated by their definitions, converted to exact
//!   rational NURBS through the shared `geom::nurbs::analytic`.
//! - `topology`: faces and their bounds to trim loops in each surface's parameter domain.
//! - `assembly`, `units`, `style`: placements of parts, length units, colours.

pub mod entities;
pub mod lexer;
pub mod records;
