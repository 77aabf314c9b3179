//! Benchmarks that are commands and produce reports rather than pass/fail: accuracy against
//! time ([`accuracy`]), the numerical stability suite ([`stability`]) and
//! the timing tests of LG90 §7 ([`lg90`]).

pub mod accuracy;
pub mod lg90;
pub mod stability;
