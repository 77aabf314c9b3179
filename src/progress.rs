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
/// profile, BENCHMARKS.md, CAD import), where a spinner would only flash.
pub const LARGE_INPUT_BYTES: u64 = 4 << 20;

/// How often a spinner redraws: often enough to show it is alive, rarely enough to cost
/// nothing.
const SPINNER_TICK: Duration = Duration::from_millis(120);

/// [`Batched`] passes counts on in steps of at least this many.
const BATCH: u64 = 256;

/// Advances a bar in steps of at least [`BATCH`], for loops whose items take well under a
/// microsecond. One [`ProgressBar::inc`] costs about 77 ns even on a hidden bar (it reads
/// the clock to rate-limit drawing; indicatif 0.18.6, 10^7 calls, release build, this
/// machine), which is about 2% of a 64,000-patch BVH build (0.30–0.43 s) when paid once
/// per patch and once per leaf. What is left is added when it is dropped.
pub struct Batched<'a> {
    bar: &'a ProgressBar,
    pending: u64,
}

impl<'a> Batched<'a> {
    pub fn new(bar: &'a ProgressBar) -> Self {
        Batched { bar, pending: 0 }
    }

    pub fn add(&mut self, n: u64) {
        self.pending += n;
        if self.pending >= BATCH {
            self.bar.inc(self.pending);
            self.pending = 0;
        }
    }
}

impl Drop for Batched<'_> {
    fn drop(&mut self) {
        self.bar.inc(self.pending);
    }
}

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
    fn batched_counts_reach_the_bar_in_steps_and_all_on_drop() {
        let bar = ProgressBar::hidden();
        let mut batched = Batched::new(&bar);
        for _ in 0..BATCH - 1 {
            batched.add(1);
        }
        assert_eq!(bar.position(), 0);
        batched.add(3);
        assert_eq!(bar.position(), BATCH + 2);
        batched.add(5);
        drop(batched);
        assert_eq!(bar.position(), BATCH + 7);
    }

    #[test]
    fn quiet_or_no_terminal_hides_every_kind() {
        assert!(bar(true, "x").is_hidden() && spinner(true, "x").is_hidden());
        // Under `cargo test` stderr is captured, not a terminal: hidden without --quiet.
        if !std::io::IsTerminal::is_terminal(&std::io::stderr()) {
            assert!(bar(false, "x").is_hidden() && spinner(false, "x").is_hidden());
        }
    }
}
