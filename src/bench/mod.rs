//! Benchmarks that produce reports rather than pass/fail: the numerical stability suite of
//! issue 7 ([`stability`]).

pub mod stability;
