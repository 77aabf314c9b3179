//! How `render` scales with threads on this machine, against the machine's own ceiling
//!. The ceiling is a trivially parallel loop: independent items of pure
//! arithmetic, no memory traffic, no shared state, split over a rayon pool of N threads;
//! its speed-up over one thread is the most any program can get here (two cores that are
//! hyper-threads of one, or a noisy neighbour, show up as a ceiling below N). Then the
//! whole `patchtrace render` process on the bundled scenes with `--threads N`, and
//! POV-Ray 3.7 with `+WTN` where it is installed, so both are compared with the same
//! ceiling. Runs are interleaved; medians of wall time.
//!
//! `cargo bench --bench thread_scaling` (set `PATCHTRACE_SCALING_RUNS`, default 5). Run it
//! on an idle machine: with other work on the cores, a second thread finds no free core.

#[path = "support/mod.rs"]
mod support;

use std::path::Path;
use std::process::{Command, Stdio};
use std::time::Instant;

use rayon::prelude::*;
use support::median;

/// Items of the ceiling loop, and the arithmetic per item: about one second on one core.
const ITEMS: u64 = 4096;
const STEPS_PER_ITEM: u32 = 40_000;

/// One item of the ceiling loop: a chain of dependent multiply-adds and square roots that
/// the compiler cannot fold, kept in registers.
fn arithmetic(seed: u64) -> f64 {
    let mut x = (seed as f64 + 1.0) * 1e-3;
    for _ in 0..STEPS_PER_ITEM {
        x = (x * 1.000_000_1 + 0.5).sqrt();
    }
    x
}

/// Wall seconds of the ceiling loop on a pool of `threads`.
fn ceiling_seconds(threads: usize) -> f64 {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("a thread pool");
    let start = Instant::now();
    let sum: f64 = pool.install(|| (0..ITEMS).into_par_iter().map(arithmetic).sum());
    let seconds = start.elapsed().as_secs_f64();
    assert!(sum.is_finite());
    seconds
}

/// Wall seconds of one whole process, or `None` if it could not run or failed.
fn process_seconds(program: &str, args: &[&str], dir: &Path) -> Option<f64> {
    let start = Instant::now();
    let status = Command::new(program)
        .args(args)
        .current_dir(dir)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
        .ok()?;
    status.success().then(|| start.elapsed().as_secs_f64())
}

fn main() {
    let runs: usize = std::env::var("PATCHTRACE_SCALING_RUNS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(5);
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let exe = env!("CARGO_BIN_EXE_patchtrace");
    let work = std::env::temp_dir().join(format!("patchtrace-scaling-{}", std::process::id()));
    std::fs::create_dir_all(&work).expect("a temporary directory");
    let povray = prepare_povray(root, &work);
    let cores = std::thread::available_parallelism().map_or(1, |c| c.get());
    let threads: Vec<usize> = (1..=cores.max(2)).chain([2 * cores.max(2)]).collect();

    // Per thread count: ceiling, then each scene by both programs, all interleaved.
    let scenes = ["teapot", "glass_teapot"];
    let mut ceiling = vec![Vec::new(); threads.len()];
    let mut ours = vec![vec![Vec::new(); threads.len()]; scenes.len()];
    let mut theirs = vec![vec![Vec::new(); threads.len()]; scenes.len()];
    for _ in 0..runs {
        for (k, &n) in threads.iter().enumerate() {
            ceiling[k].push(ceiling_seconds(n));
            for (s, scene) in scenes.iter().enumerate() {
                let input = root.join(format!("testdata/{scene}.ron"));
                let output = work.join(format!("{scene}.png"));
                let n_arg = n.to_string();
                let args = [
                    "render",
                    input.to_str().unwrap(),
                    "-o",
                    output.to_str().unwrap(),
                    "-q",
                    "--threads",
                    &n_arg,
                ];
                ours[s][k].extend(process_seconds(exe, &args, &work));
                if povray {
                    let args = [
                        format!("+I{scene}.pov"),
                        format!("+O{scene}-pov.png"),
                        "+W512".into(),
                        "+H512".into(),
                        format!("+WT{n}"),
                        "-D".into(),
                        "-V".into(),
                        "-GA".into(),
                        "+FN".into(),
                    ];
                    let args: Vec<&str> = args.iter().map(String::as_str).collect();
                    theirs[s][k].extend(process_seconds("povray", &args, &work));
                }
            }
        }
    }
    std::fs::remove_dir_all(&work).ok();

    println!(
        "thread_scaling: {cores} cores reported, {runs} interleaved runs, median wall seconds and speed-up over 1 thread"
    );
    println!();
    println!(
        "| threads | ceiling loop | speed-up | {} |",
        scene_columns(&scenes, povray)
    );
    println!(
        "|---|---|---|{}",
        "---|".repeat(scenes.len() * if povray { 4 } else { 2 })
    );
    let base = |v: &Vec<Vec<f64>>| median(v[0].clone());
    let c1 = base(&ceiling);
    for (k, &n) in threads.iter().enumerate() {
        let c = median(ceiling[k].clone());
        let mut row = format!("| {n} | {c:.3} | {:.2}× |", c1 / c);
        for s in 0..scenes.len() {
            let t = median(ours[s][k].clone());
            row += &format!(
                " {t:.3} | {:.2}× ({:.0}% of ceiling) |",
                base(&ours[s]) / t,
                100.0 * (base(&ours[s]) / t) / (c1 / c)
            );
            if povray {
                let t = median(theirs[s][k].clone());
                row += &format!(
                    " {t:.3} | {:.2}× ({:.0}% of ceiling) |",
                    base(&theirs[s]) / t,
                    100.0 * (base(&theirs[s]) / t) / (c1 / c)
                );
            }
        }
        println!("{row}");
    }
}

/// The table's column headings after the ceiling's.
fn scene_columns(scenes: &[&str], povray: bool) -> String {
    let mut names = Vec::new();
    for scene in scenes {
        names.push(format!("{scene}, patchtrace (s) | speed-up"));
        if povray {
            names.push(format!("{scene}, POV-Ray (s) | speed-up"));
        }
    }
    names.join(" | ")
}

/// Copies the POV-Ray scenes of `bench/povray/` into `work` (the teapot converted by its
/// awk script); false when POV-Ray or awk is missing, and the table leaves POV-Ray out.
fn prepare_povray(root: &Path, work: &Path) -> bool {
    let here = root.join("bench/povray");
    for name in ["common.inc", "teapot.pov", "glass_teapot.pov"] {
        if std::fs::copy(here.join(name), work.join(name)).is_err() {
            return false;
        }
    }
    let converted = Command::new("awk")
        .arg("-f")
        .arg(here.join("bpt2pov.awk"))
        .arg(root.join("testdata/teapot.bpt"))
        .output();
    let Ok(out) = converted else { return false };
    out.status.success()
        && std::fs::write(work.join("teapot.inc"), out.stdout).is_ok()
        && Command::new("povray")
            .arg("--version")
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .status()
            .is_ok()
}
