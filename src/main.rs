//! The `patchtrace` binary: all work happens in the library; this only maps the outcome to
//! an exit status.

fn main() -> std::process::ExitCode {
    patchtrace::cli::main()
}
