//! Benchmarks that are commands and produce reports rather than pass/fail: accuracy against
//! time ([`accuracy`], issue 5), the numerical stability suite ([`stability`], issue 7) and
//! the timing tests of LG90 §7 ([`lg90`], issue 6).

pub mod accuracy;
pub mod lg90;
pub mod stability;
