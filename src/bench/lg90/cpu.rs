//! CPU time of the whole process, all threads: LG90 §7.1 normalize "the total cpu time",
//! and on a shared machine wall-clock time measures the other jobs as much as ours.

use std::time::Instant;

/// Clock ticks per second of `/proc/<pid>/stat` times: Linux's `USER_HZ`, fixed at 100 for
/// user space (proc(5)).
const USER_HZ: f64 = 100.0;

/// A start point for [`Stopwatch::seconds`].
pub struct Stopwatch {
    wall: Instant,
    cpu: Option<f64>,
}

impl Stopwatch {
    pub fn start() -> Stopwatch {
        Stopwatch {
            wall: Instant::now(),
            cpu: process_cpu_seconds(),
        }
    }

    /// User plus system CPU seconds of the process since [`Stopwatch::start`], and whether
    /// they are CPU seconds: where `/proc/self/stat` cannot be read, wall-clock seconds.
    pub fn seconds(&self) -> (f64, bool) {
        match (self.cpu, process_cpu_seconds()) {
            (Some(a), Some(b)) => (b - a, true),
            _ => (self.wall.elapsed().as_secs_f64(), false),
        }
    }
}

/// `utime + stime` of `/proc/self/stat` (fields 14 and 15, counted after the command name,
/// which may itself hold spaces) in seconds.
fn process_cpu_seconds() -> Option<f64> {
    let stat = std::fs::read_to_string("/proc/self/stat").ok()?;
    let after_name = &stat[stat.rfind(')')? + 1..];
    let mut fields = after_name.split_whitespace().skip(11);
    let utime: u64 = fields.next()?.parse().ok()?;
    let stime: u64 = fields.next()?.parse().ok()?;
    Some((utime + stime) as f64 / USER_HZ)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Busy work shows as CPU time that grows (other test threads of this process may add
    /// to it, so only growth is checked), within a few seconds even on a loaded machine.
    #[test]
    fn busy_work_counts_as_cpu_time() {
        let w = Stopwatch::start();
        let wall = Instant::now();
        let mut x = 0u64;
        while w.seconds().0 <= 0.0 && wall.elapsed().as_secs_f64() < 5.0 {
            for _ in 0..100_000 {
                x = x.wrapping_mul(6364136223846793005).wrapping_add(1);
            }
        }
        std::hint::black_box(x);
        let (s, _) = w.seconds();
        assert!(s > 0.0, "{s}");
    }
}
