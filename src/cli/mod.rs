//! The command-line interface: one file per subcommand. Flags are parsed by clap, turned
//! into a validated configuration, and handed to the library. Errors are printed once,
//! with their chain, and mapped to exit codes: 2 for bad input (parse errors, unreadable
//! or invalid files, flags the command cannot honour), 1 for other failures.

/// `anyhow::ensure!` for a flag, a flag combination or an input the command cannot honour:
/// returns a [`BadArgument`] (exit status 2) with the message when `cond` is false.
macro_rules! ensure_arg {
    ($cond:expr, $($fmt:tt)+) => {
        if !$cond {
            return Err($crate::cli::BadArgument(format!($($fmt)+)).into());
        }
    };
}

pub mod args;
mod bench;
mod bench_accuracy;
mod bench_lg90;
mod bvh;
mod compare;
mod completions;
mod convert;
mod diff;
mod import;
mod info;
pub mod man;
mod merge;
mod render;
mod scene_gen;
mod setup;
mod tessellate;
pub mod trace;

use std::process::ExitCode;

use clap::Parser;

pub use args::{Cli, Command};

/// Exit status for bad input: parse errors, unreadable files, invalid content.
pub const EXIT_BAD_INPUT: u8 = 2;
/// Exit status for any other failure.
pub const EXIT_FAILURE: u8 = 1;

/// A flag value the command cannot honour (a limit or budget exceeded): bad input, exit 2
/// like clap's own argument errors.
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct BadArgument(pub String);

/// Parses the command line, runs the command and prints any error.
pub fn main() -> ExitCode {
    let cli = Cli::parse();
    match run(cli) {
        Ok(code) => code,
        Err(err) => {
            if is_broken_pipe(&err) {
                return ExitCode::SUCCESS;
            }
            let message = err.to_string();
            eprintln!("patchtrace: {message}");
            // Causes whose text the message already includes (a path-prefixed I/O error)
            // are not repeated.
            for cause in err.chain().skip(1) {
                let text = cause.to_string();
                if !message.contains(&text) {
                    eprintln!("  caused by: {text}");
                }
            }
            ExitCode::from(exit_code_for(&err))
        }
    }
}

/// Runs one parsed command.
pub fn run(cli: Cli) -> anyhow::Result<ExitCode> {
    match cli.command {
        Command::Info(a) => info::run(a),
        Command::Import(a) => import::run(a),
        Command::Convert(a) => convert::run(a),
        Command::Bvh(a) => bvh::run(a),
        Command::Render(a) => render::run(a),
        Command::Trace(a) => trace::run(a),
        Command::Tessellate(a) => tessellate::run(a),
        Command::Diff(a) => diff::run(a),
        Command::Compare(a) => compare::run(a),
        Command::Bench(args::BenchCommand::Accuracy(a)) => bench_accuracy::run(a),
        Command::Scene(args::SceneCommand::Teapots(a)) => scene_gen::teapots(a),
        Command::Bench(args::BenchCommand::Stability(a)) => bench::stability(a),
        Command::Bench(args::BenchCommand::Lg90(a)) => bench_lg90::run(a),
        Command::Merge(a) => merge::run(a),
        Command::Completions(a) => completions::run(a),
    }
}

fn exit_code_for(err: &anyhow::Error) -> u8 {
    if err.downcast_ref::<crate::formats::LoadError>().is_some()
        || err.downcast_ref::<crate::formats::ParseError>().is_some()
        || err.downcast_ref::<crate::io::OutputError>().is_some()
        || err
            .downcast_ref::<crate::bench::lg90::CaseError>()
            .is_some()
        || err.downcast_ref::<BadArgument>().is_some()
        || err
            .downcast_ref::<crate::tessellate::TessellateError>()
            .is_some()
    {
        EXIT_BAD_INPUT
    } else {
        EXIT_FAILURE
    }
}

fn is_broken_pipe(err: &anyhow::Error) -> bool {
    err.chain().any(|e| {
        e.downcast_ref::<std::io::Error>()
            .is_some_and(|io| io.kind() == std::io::ErrorKind::BrokenPipe)
    })
}
