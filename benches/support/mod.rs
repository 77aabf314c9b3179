//! Timing helpers the hand-run benchmarks share: on this shared machine wall time counts
//! the waits for a core too, so the benchmarks report time on a CPU beside it.
#![allow(dead_code)] // each bench uses the helpers it needs

/// Seconds the calling thread has run on a CPU (Linux `/proc/thread-self/schedstat`, first
/// field in ns), or `None` elsewhere.
pub fn thread_cpu_seconds() -> Option<f64> {
    let s = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
    Some(s.split_whitespace().next()?.parse::<f64>().ok()? * 1e-9)
}

/// Seconds all threads of this process have run on a CPU (user + system, Linux
/// `/proc/self/stat`, in clock ticks of 1/100 s), or `None` elsewhere.
pub fn process_cpu_seconds() -> Option<f64> {
    let s = std::fs::read_to_string("/proc/self/stat").ok()?;
    // Fields after the command name, which is in parentheses and may hold spaces.
    let rest = &s[s.rfind(')')? + 2..];
    let f: Vec<&str> = rest.split_whitespace().collect();
    let ticks: f64 = f.get(11)?.parse::<f64>().ok()? + f.get(12)?.parse::<f64>().ok()?;
    Some(ticks / 100.0)
}

/// The median (the upper one of an even count), NaN for no values.
pub fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v.get(v.len() / 2).copied().unwrap_or(f64::NAN)
}
