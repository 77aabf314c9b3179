//! `patchtrace bench stability`: the numerical stability suite.

use std::io::Write;
use std::process::ExitCode;

use crate::bench::stability::{self, KernelPath, SuiteSize, report};
use crate::cli::args::StabilityArgs;
use crate::scene::write::write_atomic;

pub fn stability(args: StabilityArgs) -> anyhow::Result<ExitCode> {
    let size = if args.full {
        SuiteSize::Full
    } else {
        SuiteSize::Reduced
    };
    let bar = crate::progress::bar(args.quiet, "stability");
    let results = stability::run_suite(size, args.seed, KernelPath::ALL, &bar);
    if let Some(path) = &args.csv {
        let text = report::csv(&results);
        write_atomic(path, |w| w.write_all(text.as_bytes()))?;
    }
    let mut out = std::io::stdout().lock();
    write!(out, "{}", report::markdown(&results))?;
    Ok(ExitCode::SUCCESS)
}
