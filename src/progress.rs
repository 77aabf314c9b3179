//! Progress on stderr for the long steps: rendering, BVH and grid builds, reading large
//! files, tessellation, `compare` and the benches. One style and one rule for all of them:
//! nothing is drawn with `--quiet` or when stderr is not a terminal (a log file or a pipe
//! gets no carriage-return redraws), as cargo and ripgrep do. Library code takes a
//! [`ProgressBar`] and advances it; a hidden bar counts without drawing, so the same code
//! runs in tests and batch jobs.

use std::path::Path;
use std::time::Duration;

pub use indicatif::ProgressBar;
use indicatif::ProgressStyle;

/// Files at least this large get a spinner while they are read. Smaller ones read in well
/// under a quarter of a second (the IGES bench reads 7.27 MB in 0.235 s in the dev
/// profile, BENCHMARKS.md issue 16), where a spinner would only flash.
pub const LARGE_INPUT_BYTES: u64 = 4 << 20;

/// How often a spinner redraws: often enough to show it is alive, rarely enough to cost
/// nothing.
const SPINNER_TICK: Duration = Duration::from_millis(120);

/// Whether progress is drawn: not with `--quiet`, not when stderr is not a terminal.
fn shown(quiet: bool) -> bool {
    use std::io::IsTerminal;
    !quiet && std::io::stderr().is_terminal()
}

/// A bar for work of known length (set with [`ProgressBar::set_length`] once known),
/// labelled `message`; hidden unless [`shown`].
pub fn bar(quiet: bool, message: &str) -> ProgressBar {
    if !shown(quiet) {
        return ProgressBar::hidden();
    }
    // Built with `with_*`, which do not draw: a bar drawn before its length is set shows
    // 100% of nothing.
    let bar = ProgressBar::new(0).with_message(message.to_string());
    match ProgressStyle::with_template(
        "{msg} [{bar:40}] {percent:>3}% {elapsed_precise} (eta {eta})",
    ) {
        Ok(style) => bar.with_style(style.progress_chars("=> ")),
        Err(_) => bar,
    }
}

/// A spinner with the elapsed time, for work whose length is not known beforehand (a
/// reader going through a file); hidden unless [`shown`].
pub fn spinner(quiet: bool, message: &str) -> ProgressBar {
    if !shown(quiet) {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::new_spinner().with_message(message.to_string());
    let bar = match ProgressStyle::with_template("{spinner} {msg} {elapsed_precise}") {
        Ok(style) => bar.with_style(style),
        Err(_) => bar,
    };
    bar.enable_steady_tick(SPINNER_TICK);
    bar
}

/// Runs `read` (which reads `path`) under a spinner when the file is at least
/// [`LARGE_INPUT_BYTES`]; smaller files show nothing.
pub fn while_reading<T>(quiet: bool, path: &Path, read: impl FnOnce() -> T) -> T {
    let spinner = match std::fs::metadata(path) {
        Ok(m) if m.len() >= LARGE_INPUT_BYTES => spinner(
            quiet,
            &format!(
                "reading {} ({:.1} MB)",
                path.display(),
                m.len() as f64 / 1e6
            ),
        ),
        _ => ProgressBar::hidden(),
    };
    let value = read();
    spinner.finish_and_clear();
    value
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quiet_or_no_terminal_hides_every_kind() {
        assert!(bar(true, "x").is_hidden() && spinner(true, "x").is_hidden());
        // Under `cargo test` stderr is captured, not a terminal: hidden without --quiet.
        if !std::io::IsTerminal::is_terminal(&std::io::stderr()) {
            assert!(bar(false, "x").is_hidden() && spinner(false, "x").is_hidden());
        }
    }
}
