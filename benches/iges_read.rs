//! IGES reading speed: a large file made at bench time by repeating the
//! hammer's entities (`testdata/gismo/hammer.iges`, 45 trimmed
//! surfaces over 128s, 1.0 MB) `COPIES` times with their pointers shifted, written to a
//! temporary file and read by `read_iges` (file read, syntax, entities, conversion, trims).
//! Target: a ~4 MB file with ~300 trimmed surfaces in under 0.5 s. Median of several
//! runs; wall time and this thread's CPU time (the machine is shared).
//!
//! `cargo bench --bench iges_read`.

use std::path::Path;
use std::time::Instant;

use patchtrace::formats::cad::iges::{directory, read_iges, records};

#[allow(dead_code)] // benches use a part of the test helpers
#[path = "../tests/lib/iges_support/mod.rs"]
mod iges_support;
use iges_support::{Entry, fixed_format};
#[path = "support/mod.rs"]
mod support;
use support::{median, thread_cpu_seconds as cpu_seconds};

const RUNS: usize = 7;

/// Parameter positions (1-based) that are directory pointers, for the entity types the
/// hammer holds (the lists of 144 holes and 102 parts run to the end).
fn pointer_positions(ty: i32, count: usize) -> Vec<usize> {
    match ty {
        144 => [1, 4].into_iter().chain(5..count).collect(),
        142 => vec![2, 3, 4],
        102 => (2..count).collect(),
        _ => Vec::new(),
    }
}

/// The hammer's entities (without its 402 group) repeated `copies` times, as IGES text.
fn repeated(src: &str, copies: usize) -> String {
    let path = Path::new("hammer.iges");
    let s = records::sections(path, src).unwrap();
    let (delims, _) = records::global(path, &s.global, &mut Vec::new()).unwrap();
    let entries = directory::entries(path, &s.directory).unwrap();
    let kept: Vec<&directory::DirEntry> = entries.iter().filter(|e| e.entity_type != 402).collect();
    let mut index = vec![0usize; 2 * entries.len() + 2];
    for (k, e) in kept.iter().enumerate() {
        index[e.sequence] = k;
    }
    let per_copy = kept.len();
    let mut out = Vec::new();
    for copy in 0..copies {
        for e in &kept {
            let first = e.param_start - 1;
            let tokens = records::parameters(
                path,
                &s.parameters[first..first + e.param_count],
                delims,
                &mut Vec::new(),
            )
            .unwrap();
            let pointers = pointer_positions(e.entity_type, tokens.len());
            let fields = tokens
                .iter()
                .enumerate()
                .skip(1)
                .map(|(i, t)| {
                    if pointers.contains(&i) {
                        let old: usize = t.written.parse().unwrap();
                        (2 * (copy * per_copy + index[old]) + 1).to_string()
                    } else {
                        t.written.clone()
                    }
                })
                .collect();
            out.push(Entry {
                ty: e.entity_type,
                form: e.form,
                fields,
                transform: 0,
                colour: 0,
                status: if e.entity_type == 144 {
                    "00000000"
                } else {
                    "00010000"
                }
                .into(),
            });
        }
    }
    let global = ",,3Hbig,7Hbig.igs,2Hpt,2Hpt,32,308,15,308,15,3Hbig,1.,2,2HMM,1,0.01,\
                  13H260101.000000,1.E-6,1.E5,1Hx,1Hx,11,0;";
    fixed_format(global, &out)
}

fn main() {
    let hammer = Path::new(env!("CARGO_MANIFEST_DIR")).join("testdata/gismo/hammer.iges");
    let src = std::fs::read_to_string(&hammer).expect("the hammer (testdata/gismo)");
    let dir = tempfile::tempdir().unwrap();
    for copies in [4, 7] {
        let text = repeated(&src, copies);
        let file = dir.path().join(format!("hammer_x{copies}.igs"));
        std::fs::write(&file, &text).unwrap();
        let first = read_iges(&file).unwrap();
        let trimmed = first
            .surfaces
            .iter()
            .filter(|d| !d.surface.trims.is_empty())
            .count();
        assert!(first.report.failed.is_empty(), "{:?}", first.report.failed);
        let mut wall = Vec::new();
        let mut cpu = Vec::new();
        for _ in 0..RUNS {
            let (t, c) = (Instant::now(), cpu_seconds());
            let r = read_iges(&file).unwrap();
            wall.push(t.elapsed().as_secs_f64());
            if let (Some(a), Some(b)) = (c, cpu_seconds()) {
                cpu.push(b - a);
            }
            assert_eq!(r.surfaces.len(), first.surfaces.len());
        }
        println!(
            "iges_read: {:.2} MB, {} trimmed surfaces, {} patches: median {:.3} s wall, {:.3} s CPU (min {:.3} s wall), {RUNS} runs",
            text.len() as f64 / 1e6,
            trimmed,
            first
                .surfaces
                .iter()
                .map(|d| match &d.surface.geometry {
                    patchtrace::scene::SurfaceGeometry::Nurbs(n) => n.to_bezier_patches().len(),
                    patchtrace::scene::SurfaceGeometry::Bezier(_) => 1,
                })
                .sum::<usize>(),
            median(wall.clone()),
            median(cpu),
            wall.iter().copied().fold(f64::INFINITY, f64::min),
        );
    }
}
