//! Benchmarks that are commands: accuracy against time (`bench accuracy`).

pub mod accuracy;
