//! Reading speed of the STEP reader (a 5 MB file loads in under 1 s): the test
//! part of `tests/step_support` (8 faces: planes, a toroidal fillet, a cylinder with a
//! pcurve seam, a B-spline bottom with a hole) repeated side by side until the file
//! reaches 5 MB, written to a temporary file at bench time (not committed), then read
//! with `step::read_step` (file, Part 21 parse, entities, trim loops, exact NURBS).
//! Median of several runs after a warm-up, wall and on-CPU time of the whole process (the
//! faces convert in parallel).
//!
//! `cargo bench --bench step_read`

#[allow(dead_code)] // benches use a part of the test helpers
#[path = "../tests/lib/step_support/mod.rs"]
mod step_support;
#[path = "support/mod.rs"]
mod support;

use std::time::Instant;

use patchtrace::formats::cad::step::{read_step, records};
use support::{median, process_cpu_seconds as cpu_seconds};

const RUNS: usize = 5;
const TARGET_BYTES: usize = 5_000_000;

fn main() {
    let one = step_support::bracket(1).len();
    let copies = TARGET_BYTES.div_ceil(one);
    let text = step_support::bracket(copies);
    let dir = std::env::temp_dir().join(format!("patchtrace-step-bench-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("plates.step");
    std::fs::write(&path, &text).unwrap();
    let mut wall = Vec::new();
    let mut cpu = Vec::new();
    let mut parse = Vec::new();
    let mut faces = 0;
    for run in 0..=RUNS {
        let (t, c) = (Instant::now(), cpu_seconds());
        let model = read_step(&path).unwrap();
        let (dt, dc) = (
            t.elapsed().as_secs_f64(),
            cpu_seconds().zip(c).map(|(a, b)| a - b),
        );
        faces = model.parts.iter().map(|p| p.pieces.len()).sum::<usize>();
        let t = Instant::now();
        let ex = records::parse(&text).unwrap();
        let dp = t.elapsed().as_secs_f64();
        assert!(!ex.instances.is_empty());
        if run > 0 {
            wall.push(dt);
            cpu.extend(dc);
            parse.push(dp);
        }
    }
    std::fs::remove_dir_all(&dir).ok();
    println!(
        "step_read: {:.2} MB, {copies} parts, {faces} faces: read {:.3} s wall (median of {RUNS}, {:.3}..{:.3}), {} s CPU (all threads); Part 21 parse alone {:.3} s",
        text.len() as f64 / 1e6,
        median(wall.clone()),
        wall.iter().cloned().fold(f64::INFINITY, f64::min),
        wall.iter().cloned().fold(0.0, f64::max),
        if cpu.is_empty() {
            "-".to_string()
        } else {
            format!("{:.3}", median(cpu))
        },
        median(parse)
    );
}
