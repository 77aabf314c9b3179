//! `patchtrace bench lg90`: LG90's Tables 2–6 beside ours.

use std::io::Write;
use std::process::ExitCode;

use crate::bench::lg90::{self, CASES, Config, Method, report};
use crate::cli::args::Lg90Args;
use crate::cli::setup::thread_pool;
use crate::io::write_atomic;
use crate::kernel::cached::DEFAULT_CACHE_BYTES;

pub fn run(args: Lg90Args) -> anyhow::Result<ExitCode> {
    ensure_arg!(args.size > 0, "--size must be at least 1");
    for &c in &args.cases {
        ensure_arg!(
            CASES.iter().any(|case| case.number == c),
            "--cases: there is no test case {c}; Table 1 has cases 1 to 5"
        );
    }
    let methods = args
        .methods
        .iter()
        .map(|name| {
            Method::by_name(name).ok_or_else(|| {
                crate::cli::BadArgument(format!(
                    "--methods: unknown method `{name}`; expected TOTH, ISRT, SCAN, ITBUF or PEANO"
                ))
            })
        })
        .collect::<Result<Vec<_>, _>>()?;
    let pool = thread_pool(args.threads)?;
    let temp = match &args.scene_dir {
        Some(_) => None,
        None => Some(tempfile_dir()?),
    };
    ensure_arg!(
        args.cache_size != Some(0),
        "--cache-size must be at least 1 (MiB)"
    );
    let config = Config {
        cache_bytes: args
            .cache_size
            .map_or(DEFAULT_CACHE_BYTES, |mib| mib.saturating_mul(1 << 20)),
        size: args.size,
        cases: args.cases.clone(),
        methods,
        scene_dir: args
            .scene_dir
            .clone()
            .or_else(|| temp.clone())
            .unwrap_or_default(),
    };
    let bar = crate::progress::bar(args.quiet, "lg90");
    let results = pool.install(|| lg90::run(&config, &bar));
    if let Some(dir) = &temp {
        let _ = std::fs::remove_dir_all(dir);
    }
    let results = results?;
    if let Some(path) = &args.csv {
        let text = report::csv(&results);
        write_atomic(path, |w| w.write_all(text.as_bytes()))?;
    }
    write!(std::io::stdout().lock(), "{}", report::markdown(&results))?;
    Ok(ExitCode::SUCCESS)
}

/// A fresh directory under the system's temporary directory for the generated scenes.
fn tempfile_dir() -> anyhow::Result<std::path::PathBuf> {
    let dir = std::env::temp_dir().join(format!("patchtrace-lg90-{}", std::process::id()));
    std::fs::create_dir_all(&dir)?;
    Ok(dir)
}
