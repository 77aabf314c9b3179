//! Library-level tests: geometry, kernels, accelerators, readers and writers, checked
//! against independent computations (f64 references, closed forms, other algorithms), one
//! module per subject.

mod bvh_support;
#[path = "../support/common.rs"]
mod common;
mod iges_support;
mod kernel_common;
mod mutate;
mod step_support;
mod subdiv_common;
mod toth_common;

mod bvh_build;
mod bvh_file;
mod bvh_mapped;
mod bvh_packed;
mod bvh_traverse;
mod cached_agreement;
mod cached_render;
mod cad_front_door;
mod diff_metrics;
mod formats_iges;
mod formats_mesh;
mod formats_obj;
mod formats_pbrt;
mod formats_usd;
mod grid_accel;
mod kernel_newton;
mod kernel_reference;
mod kernel_teapot;
mod lg6_trivial;
mod robust_mesh_files;
mod robust_parsers;
mod stability_suite;
mod step_assembly;
mod step_damage;
mod step_entities;
mod step_faces;
mod step_part;
mod step_sets;
mod subdiv_surface;
mod subdiv_tessellate;
mod tess_closed_solids;
mod tess_mesh;
mod tess_watertight;
mod toth_agreement;
mod toth_render;
mod trims;
mod trims_hammer;
