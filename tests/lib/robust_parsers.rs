//! Parser robustness: valid files of every text format, mutated (bytes flipped,
//! lines dropped or repeated, numbers replaced by NaN, huge or empty values), never make a
//! parser panic: each mutation gives a scene or an error with a location.
//!
//! Cases per format: 300 in the default run; the full run is
//! `PATCHTRACE_FUZZ_CASES=10000 cargo test --release --test robust_parsers`.

use std::path::{Path, PathBuf};

use proptest::prelude::*;
use proptest::test_runner::{Config, TestRunner};

use patchtrace::scene::{ParseError, bpt, iges, obj, pbrt, rays, ron_format, step};

use crate::mutate;
use crate::step_support;

use mutate::{Mutation, apply, mutation};

fn cases() -> u32 {
    std::env::var("PATCHTRACE_FUZZ_CASES")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(300)
}

fn samples(ext: &str) -> Vec<(PathBuf, String)> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("testdata");
    let mut out: Vec<(PathBuf, String)> = std::fs::read_dir(&dir)
        .unwrap()
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == ext))
        .filter_map(|p| std::fs::read_to_string(&p).ok().map(|s| (p, s)))
        .collect();
    out.sort();
    out
}

/// A parse error must point into the text: line ≥ 1 and column ≥ 1.
fn located(e: &ParseError) -> bool {
    e.line >= 1 && e.column >= 1 && !e.message.is_empty()
}

fn fuzz<T>(ext: &str, parse: impl Fn(&Path, &str) -> Result<T, ParseError>) {
    fuzz_files(ext, samples(ext), parse)
}

fn fuzz_files<T>(
    ext: &str,
    files: Vec<(PathBuf, String)>,
    parse: impl Fn(&Path, &str) -> Result<T, ParseError>,
) {
    assert!(!files.is_empty(), "no .{ext} samples in testdata/");
    let mut runner = TestRunner::new(Config {
        cases: cases(),
        failure_persistence: None,
        ..Config::default()
    });
    let strategy = (0..files.len(), prop::collection::vec(mutation(), 1..4));
    runner
        .run(&strategy, |(f, muts)| {
            let (path, src) = &files[f];
            let text = apply(src, &muts);
            if let Err(e) = parse(path, &text) {
                prop_assert!(located(&e), "error without a location: {e}");
            }
            Ok(())
        })
        .unwrap();
}

#[test]
fn bpt_parser_survives_mutations() {
    fuzz("bpt", bpt::parse_bpt);
}

#[test]
fn obj_parser_survives_mutations() {
    fuzz("obj", |p, s| {
        if obj::is_freeform(s) {
            obj::parse_obj_freeform(p, s).map(|_| ())
        } else {
            Ok(())
        }
    });
}

#[test]
fn pbrt_parser_survives_mutations() {
    fuzz("pbrt", pbrt::parse_pbrt);
}

#[test]
fn ron_parser_survives_mutations() {
    fuzz("ron", ron_format::parse_scene_file);
}

#[test]
fn iges_parser_survives_mutations() {
    fuzz("igs", |p, s| iges::parse_iges(p, s).map(|_| ()));
}

#[test]
fn ray_file_parser_survives_mutations() {
    fuzz("rays", rays::parse_rays);
}

/// The STEP sample is the test part (every face kind, pcurves, seams, units), written by
/// the test writer rather than kept in testdata/.
#[test]
fn step_reader_survives_mutations() {
    let files = vec![(PathBuf::from("bracket.step"), step_support::bracket(1))];
    fuzz_files("step", files, step::read_step_str);
}

#[test]
fn mutations_do_change_the_text() {
    // The harness itself: a number replacement really replaces a number.
    let t = apply(
        "1 2.5 3",
        &[Mutation::ReplaceNumber {
            which: 1,
            with: "nan",
        }],
    );
    assert_eq!(t, "1 nan 3");
    assert_eq!(apply("a\nb\nc", &[Mutation::DropLine(1)]), "a\nc");
    assert_eq!(apply("a\nb", &[Mutation::RepeatLine(0)]), "a\na\nb");
}
