//! patchtrace against OpenCASCADE on the real CAD files in `../shared/testdata/external/cad`:
//! runs `bench/occ/run.sh` (Python, see `bench/occ/README.md`) with the release binary
//! cargo has just built for this bench, 1,000 rays per file. Prints a line per file and a
//! markdown table of holes, false hits and wrong hits; the evidence goes to
//! `target/occ-crosscheck/`. Skips, saying why, when the files or a Python with
//! OpenCASCADE are absent. Nothing here runs under `cargo test`.
//!
//! `cargo bench --bench occ` (extra arguments after `--` go to the cross-check, e.g.
//! `-- --rays 300`).

use std::process::{Command, ExitCode};

/// The exit code with which `bench/occ/run.sh` says it cannot run at all.
const UNAVAILABLE: i32 = 3;

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    // `cargo test --benches` runs bench targets too, without `--bench`: not a measurement.
    if !args.iter().any(|a| a == "--bench") {
        println!("occ: run with `cargo bench --bench occ`");
        return ExitCode::SUCCESS;
    }
    let root = env!("CARGO_MANIFEST_DIR");
    let status = Command::new("sh")
        .arg("bench/occ/run.sh")
        .args(["--patchtrace", env!("CARGO_BIN_EXE_patchtrace")])
        .args(args.iter().filter(|a| *a != "--bench"))
        .current_dir(root)
        .status();
    match status {
        Ok(s) if s.success() => ExitCode::SUCCESS,
        Ok(s) if s.code() == Some(UNAVAILABLE) => {
            println!("occ: skipped (the reason is above)");
            ExitCode::SUCCESS
        }
        Ok(s) => {
            eprintln!("occ: bench/occ/run.sh failed: {s}");
            ExitCode::FAILURE
        }
        Err(e) => {
            eprintln!("occ: cannot run bench/occ/run.sh: {e}");
            ExitCode::FAILURE
        }
    }
}
