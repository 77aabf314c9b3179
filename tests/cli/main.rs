//! Tests that drive the real `patchtrace` binary: every subcommand end to end, its
//! flags, its errors (located, exit status 2) and its output files, one module per subject.

#[path = "../support/common.rs"]
mod common;

mod aov;
mod batch;
mod bench_accuracy;
mod bench_lg90;
mod cad_occ;
mod compare;
mod convert;
mod convert_trims;
mod diff_cli;
mod errors;
mod examples;
mod floating_origin;
mod formats_cli;
mod frames;
mod hostile_input;
mod iges;
mod iges_writers;
mod instances;
mod lg6_cache_flags;
mod man_pages;
mod progress;
mod render;
mod stl;
mod subdiv_cli;
mod term_accuracy;
mod tess_trimmed;
mod trace;
mod trims_cli;
