//! Benchmarks that are commands and produce reports rather than pass/fail: accuracy against
//! time ([`accuracy`], issue 5) and the numerical stability suite ([`stability`], issue 7).

pub mod accuracy;
pub mod stability;
