//! The mutation run, through the real binary: for every input format, valid
//! files from `testdata/` (and its OpenCASCADE parts, the STEP test part, a GLB and a BVH file made by the binary
//! at start) damaged by the structured mutations of `tests/mutate` (bytes flipped, lines
//! dropped or repeated, numbers replaced by NaN, infinities, huge, tiny or empty values,
//! truncation), each run through `info`, `convert` and a 16×16 `render` (ray files through
//! `trace`, BVH files through `render --bvh`), each run under `/usr/bin/time` for its peak
//! resident memory and `timeout` as a backstop.
//!
//! It counts panics (exit 101 or "panicked at"), aborts (killed by a signal), runs over
//! 20 s, runs over 2 GB resident, and the share of refusals whose message carries a
//! location (`file:line:column`, or a byte offset for binary files).
//!
//! `cargo bench --bench mutation_run` (10,000 inputs per format);
//! `PATCHTRACE_MUTANTS=200 cargo bench --bench mutation_run` for a quick look;
//! `PATCHTRACE_FORMATS=step,igs` to run some formats only. Not a timed test: it runs by
//! hand (about an hour on two cores for every format).

#[allow(dead_code)] // benches use a part of the test helpers
#[path = "../tests/lib/mutate/mod.rs"]
mod mutate;
#[allow(dead_code)] // benches use a part of the test helpers
#[path = "../tests/lib/step_support/mod.rs"]
mod step_support;

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::{Duration, Instant};

use proptest::strategy::{Strategy, ValueTree};
use proptest::test_runner::TestRunner;

const BIN: &str = env!("CARGO_BIN_EXE_patchtrace");
/// The limits: no run over 20 s, none over 2 GB resident.
const SLOW: Duration = Duration::from_secs(20);
const HEAVY_KB: u64 = 2 * 1024 * 1024;
/// The backstop after which a run is killed (and counted as slow).
const KILL_AFTER_S: u32 = 30;

/// The 16×16 render, quiet, to a PNG beside the mutant.
const TINY_RENDER: [&str; 7] = ["--width", "16", "--height", "16", "-q", "-o", "{out}.png"];

/// How one format's mutants are run: the argument lists, with `{}` for the mutant and
/// `{out}` for an output path in the mutant's directory.
struct Format {
    name: &'static str,
    ext: &'static str,
    /// Binary files get only byte flips and truncation: line and number edits go through
    /// lossy UTF-8, which would replace every high byte and leave nothing to test but the
    /// magic number.
    binary: bool,
    samples: Vec<Vec<u8>>,
    commands: Vec<Vec<&'static str>>,
}

#[derive(Default)]
struct Tally {
    runs: usize,
    accepted: usize,
    refused: usize,
    located: usize,
    /// Refusals about the output rather than the input (`convert` of a mesh to RON).
    about_output: usize,
    panics: usize,
    aborts: usize,
    slow: usize,
    heavy: usize,
    max_seconds: f64,
    max_kb: u64,
    unlocated: Vec<String>,
    failures: Vec<String>,
}

fn testdata(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("testdata")
        .join(name)
}

/// The files with extension `ext` in `testdata/` (`dir` "") or one of its folders.
fn files_in(dir: &str, ext: &str) -> Vec<Vec<u8>> {
    let mut paths: Vec<PathBuf> = std::fs::read_dir(testdata(dir))
        .unwrap()
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == ext))
        .collect();
    paths.sort();
    paths.iter().map(|p| std::fs::read(p).unwrap()).collect()
}

fn samples_with(ext: &str) -> Vec<Vec<u8>> {
    files_in("", ext)
}

/// The real CAD files of `testdata/occ/` (written by OpenCASCADE).
fn occ(ext: &str) -> Vec<Vec<u8>> {
    files_in("occ", ext)
}

/// Runs the binary once to make an input the other formats cannot be mutated from.
fn made_by_binary(dir: &Path, args: &[&str], out: &str) -> Vec<u8> {
    let path = dir.join(out);
    let status = Command::new(BIN)
        .args(args)
        .arg(&path)
        .stderr(Stdio::null())
        .status()
        .unwrap();
    assert!(status.success(), "{args:?}");
    std::fs::read(path).unwrap()
}

fn formats(dir: &Path) -> Vec<Format> {
    let scene_commands = || {
        vec![
            vec!["info", "{}"],
            vec!["convert", "{}", "-o", "{out}.ron"],
            [&["render", "{}"][..], &TINY_RENDER].concat(),
        ]
    };
    let teapot = testdata("teapot.ron");
    let teapot: &'static str = Box::leak(teapot.to_string_lossy().into_owned().into_boxed_str());
    let glb = made_by_binary(
        dir,
        &["tessellate", "--tolerance", "0.05", teapot, "-o"],
        "teapot.glb",
    );
    let bvh = made_by_binary(dir, &["bvh", teapot, "-o"], "teapot.bvh");
    let scene = |name, ext, samples| Format {
        name,
        ext,
        binary: ext == "glb",
        samples,
        commands: scene_commands(),
    };
    vec![
        scene("bpt", "bpt", samples_with("bpt")),
        scene("obj", "obj", samples_with("obj")),
        scene("pbrt", "pbrt", samples_with("pbrt")),
        scene("ron", "ron", samples_with("ron")),
        scene("igs", "igs", [samples_with("igs"), occ("igs")].concat()),
        scene(
            "step",
            "step",
            [vec![step_support::bracket(1).into_bytes()], occ("step")].concat(),
        ),
        scene("gltf", "gltf", samples_with("gltf")),
        scene("glb", "glb", vec![glb]),
        Format {
            name: "rays",
            ext: "rays",
            binary: false,
            samples: samples_with("rays"),
            commands: vec![vec!["trace", teapot, "--rays", "{}"]],
        },
        Format {
            name: "bvh",
            ext: "bvh",
            binary: true,
            samples: vec![bvh],
            commands: vec![[&["render", teapot, "--bvh", "{}"][..], &TINY_RENDER].concat()],
        },
    ]
}

/// Whether a refusal names a place in the input: `path:line[:column]` or a byte offset.
fn located(stderr: &str, input: &str) -> bool {
    stderr.lines().any(|l| {
        let after_path = l.find(input).map(|i| &l[i + input.len()..]);
        let line_number = after_path.is_some_and(|rest| {
            rest.strip_prefix(':')
                .is_some_and(|r| r.starts_with(|c: char| c.is_ascii_digit()))
        });
        line_number || l.contains("byte ") || l.contains("offset ")
    })
}

/// One run of the binary; returns (exit code or None for a signal, seconds, peak KB, stderr).
fn run_once(args: &[String], work: &Path) -> (Option<i32>, f64, u64, String) {
    let rss_file = work.join("rss.txt");
    let t = Instant::now();
    let out = Command::new("/usr/bin/time")
        .arg("-f")
        .arg("%M")
        .arg("-o")
        .arg(&rss_file)
        .arg("timeout")
        .arg("-s")
        .arg("KILL")
        .arg(KILL_AFTER_S.to_string())
        .arg(BIN)
        .args(args)
        .current_dir(work)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .output()
        .unwrap();
    let seconds = t.elapsed().as_secs_f64();
    let report = std::fs::read_to_string(&rss_file).unwrap_or_default();
    let signalled = report.contains("terminated by signal");
    let kb = report
        .lines()
        .filter_map(|l| l.trim().parse::<u64>().ok())
        .next_back()
        .unwrap_or(0);
    // `timeout` passes a signal on as 128 + its number (137 when it had to kill the run).
    let code = out.status.code().filter(|&c| !signalled && c < 128);
    (
        code,
        seconds,
        kb,
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

fn run_format(f: &Format, cases: usize, root: &Path) -> Tally {
    let tally = Mutex::new(Tally::default());
    let next = AtomicUsize::new(0);
    let strategy = (
        0..f.samples.len(),
        proptest::collection::vec(mutate::mutation(), 1..4),
    );
    // The same mutants every run: one deterministic runner draws them all up front.
    let mut runner = TestRunner::deterministic();
    let mutants: Vec<Vec<u8>> = (0..cases)
        .map(|_| {
            let (k, mut muts) = strategy.new_tree(&mut runner).unwrap().current();
            if f.binary {
                muts = muts.into_iter().map(bytewise).collect();
            }
            mutate::apply_bytes(&f.samples[k], &muts)
        })
        .collect();
    let workers = std::thread::available_parallelism().map_or(2, |n| n.get());
    std::thread::scope(|s| {
        for w in 0..workers {
            let (tally, next, mutants) = (&tally, &next, &mutants);
            s.spawn(move || {
                let work = root.join(format!("{}-{w}", f.name));
                std::fs::create_dir_all(&work).unwrap();
                for entry in std::fs::read_dir(testdata("")).unwrap().flatten() {
                    if entry.path().is_file() {
                        let _ = std::fs::copy(entry.path(), work.join(entry.file_name()));
                    }
                }
                loop {
                    let i = next.fetch_add(1, Ordering::Relaxed);
                    if i >= mutants.len() {
                        break;
                    }
                    let name = format!("mutant.{}", f.ext);
                    let input = work.join(&name);
                    std::fs::write(&input, &mutants[i]).unwrap();
                    for cmd in &f.commands {
                        let args: Vec<String> = cmd
                            .iter()
                            .map(|a| a.replace("{out}", "out").replace("{}", &name))
                            .collect();
                        let (code, seconds, kb, err) = run_once(&args, &work);
                        let mut t = tally.lock().unwrap();
                        t.runs += 1;
                        t.max_seconds = t.max_seconds.max(seconds);
                        t.max_kb = t.max_kb.max(kb);
                        let what = format!("{} #{i}: {}", f.name, args.join(" "));
                        let keep = |t: &mut Tally, why: &str| {
                            t.failures.push(format!("{what}: {why}"));
                            let _ = std::fs::write(
                                root.join(format!("failure-{}-{i}.{}", f.name, f.ext)),
                                &mutants[i],
                            );
                        };
                        if seconds > SLOW.as_secs_f64() {
                            t.slow += 1;
                            keep(&mut t, &format!("{seconds:.1} s"));
                        }
                        if kb > HEAVY_KB {
                            t.heavy += 1;
                            keep(&mut t, &format!("{} MB", kb / 1024));
                        }
                        match code {
                            Some(0) => t.accepted += 1,
                            Some(101) => {
                                t.panics += 1;
                                keep(&mut t, err.lines().last().unwrap_or(""));
                            }
                            _ if err.contains("panicked at") => {
                                t.panics += 1;
                                keep(&mut t, err.lines().next().unwrap_or(""));
                            }
                            None => {
                                t.aborts += 1;
                                keep(&mut t, "killed by a signal");
                            }
                            Some(_) if err.starts_with("patchtrace: out.") => {
                                t.about_output += 1;
                            }
                            Some(_) => {
                                t.refused += 1;
                                if located(&err, &name) {
                                    t.located += 1;
                                } else if t.unlocated.len() < 12 {
                                    t.unlocated.push(format!("{what}: {}", err.trim()));
                                }
                            }
                        }
                    }
                }
            });
        }
    });
    tally.into_inner().unwrap()
}

fn main() {
    let cases: usize = std::env::var("PATCHTRACE_MUTANTS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(10_000);
    let only: Option<Vec<String>> = std::env::var("PATCHTRACE_FORMATS")
        .ok()
        .map(|s| s.split(',').map(str::to_string).collect());
    let root = std::env::temp_dir().join(format!("patchtrace-mutants-{}", std::process::id()));
    std::fs::create_dir_all(&root).unwrap();
    println!("mutation run: {cases} inputs per format, binary {BIN}");
    println!(
        "| format | inputs | runs | accepted | refused | located | output refused | panics | aborts | > 20 s | > 2 GB | slowest (s) | peak (MB) |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|---|");
    let mut bad = 0;
    let mut notes = Vec::new();
    for f in formats(&root) {
        if only
            .as_ref()
            .is_some_and(|o| !o.iter().any(|n| n == f.name))
        {
            continue;
        }
        let t = run_format(&f, cases, &root);
        let share = if t.refused == 0 {
            100.0
        } else {
            100.0 * t.located as f64 / t.refused as f64
        };
        println!(
            "| {} | {cases} | {} | {} | {} | {share:.1} % | {} | {} | {} | {} | {} | {:.2} | {} |",
            f.name,
            t.runs,
            t.accepted,
            t.refused,
            t.about_output,
            t.panics,
            t.aborts,
            t.slow,
            t.heavy,
            t.max_seconds,
            t.max_kb / 1024
        );
        bad += t.panics + t.aborts + t.slow + t.heavy;
        notes.extend(t.failures);
        notes.extend(t.unlocated.into_iter().map(|u| format!("unlocated: {u}")));
    }
    for n in &notes {
        println!("- {n}");
    }
    println!(
        "inputs kept in {} (failures as failure-FORMAT-N.EXT)",
        root.display()
    );
    if bad > 0 {
        std::process::exit(1);
    }
}

/// A mutation as a byte edit, for binary files: line and number edits become a flip of one
/// low bit at the same index.
fn bytewise(m: mutate::Mutation) -> mutate::Mutation {
    use mutate::Mutation;
    match m {
        Mutation::DropLine(at)
        | Mutation::RepeatLine(at)
        | Mutation::ReplaceNumber { which: at, .. } => Mutation::FlipByte { at, bits: 1 },
        m => m,
    }
}
