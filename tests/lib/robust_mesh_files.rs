//! Mutation runs over the binary and JSON formats: glTF documents changed
//! structurally (numbers replaced by huge, negative or out-of-range values, keys dropped,
//! children added to make cycles and second parents, accessor types swapped), GLB files
//! with flipped bytes, overwritten length words and truncations, and BVH files with
//! damaged words whose checksum is then made to match so that the tree validation is
//! reached. Every mutant must load or give an error with a place (line and column, or a
//! byte offset), without a panic, within 20 s, and the whole run within 2 GB.
//!
//! Cases per format: 300 in the default run; the full run is
//! `PATCHTRACE_FUZZ_CASES=10000 cargo test --release --test robust_mesh_files -- --nocapture`,
//! which prints the share of located errors per format.

use std::path::Path;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, Instant};

use proptest::prelude::*;
use proptest::test_runner::{Config, TestRunner};
use serde_json::Value;

use patchtrace::accel::bvh::{Bvh, checksum};
use patchtrace::geom::{Aabb, Ray};
use patchtrace::scene::LoadError;
use patchtrace::scene::gltf_mesh::read_gltf;

fn cases() -> u32 {
    std::env::var("PATCHTRACE_FUZZ_CASES")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(300)
}

/// Longest a single mutant may take (the limit for `info`).
const CASE_LIMIT: Duration = Duration::from_secs(20);

fn runner() -> TestRunner {
    TestRunner::new(Config {
        cases: cases(),
        failure_persistence: None,
        ..Config::default()
    })
}

/// Counts of outcomes, printed at the end of a run.
#[derive(Default)]
struct Tally {
    loaded: AtomicU64,
    located: AtomicU64,
}

impl Tally {
    fn report(&self, format: &str) {
        let (ok, located) = (
            self.loaded.load(Ordering::Relaxed),
            self.located.load(Ordering::Relaxed),
        );
        eprintln!(
            "{format}: {} mutants, {ok} loaded, {located} errors, all located (100 %)",
            ok + located
        );
    }
}

/// Checks one load: an error must carry a place.
fn check(result: Result<(), LoadError>, tally: &Tally) -> Result<(), TestCaseError> {
    match result {
        Ok(()) => {
            tally.loaded.fetch_add(1, Ordering::Relaxed);
        }
        Err(LoadError::Parse(p)) => {
            prop_assert!(p.line >= 1 && p.column >= 1 && !p.message.is_empty(), "{p}");
            tally.located.fetch_add(1, Ordering::Relaxed);
        }
        Err(LoadError::Binary { .. }) => {
            tally.located.fetch_add(1, Ordering::Relaxed);
        }
        Err(e) => prop_assert!(false, "error without a place: {e}"),
    }
    Ok(())
}

/// Peak resident memory of this process (Linux), in bytes.
fn peak_resident_bytes() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}

fn assert_memory_bounded() {
    if let Some(peak) = peak_resident_bytes() {
        assert!(peak < 2 << 30, "peak resident {peak} bytes");
    }
}

fn sample_gltf() -> Value {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("testdata/quad_mesh.gltf");
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// One structural change to a glTF document.
#[derive(Clone, Debug)]
enum Edit {
    /// Replace the `which`-th number (depth first) by `with`.
    Number { which: usize, with: Value },
    /// Remove the `which`-th object key.
    DropKey(usize),
    /// Give node `node` a child `child` (modulo one past the node count, so sometimes a
    /// missing node): cycles, second parents, self-parents.
    AddChild { node: usize, child: usize },
    /// Set the `which`-th accessor's `type` or a primitive's `mode`.
    Kind { which: usize, with: Value },
    /// Flip bits of one byte of the serialised text.
    Byte { at: usize, bits: u8 },
}

fn numbers() -> Vec<Value> {
    let big = |x: f64| serde_json::Number::from_f64(x).map_or(Value::Null, Value::Number);
    vec![
        0.into(),
        1.into(),
        (-1).into(),
        2.into(),
        3.into(),
        253.into(),
        65536.into(),
        (1u64 << 31).into(),
        (1u64 << 32).into(),
        (1u64 << 40).into(),
        u64::MAX.into(),
        big(1e30),
        big(-3.5e38),
        big(0.5),
        Value::String("x".into()),
        Value::Null,
    ]
}

fn kinds() -> Vec<Value> {
    ["SCALAR", "VEC2", "VEC3", "VEC4", "MAT4", "bogus"]
        .into_iter()
        .map(|s| Value::String(s.into()))
        .chain([0, 1, 4, 5, 7, 5126, 5121].map(Value::from))
        .collect()
}

fn edit() -> impl Strategy<Value = Edit> {
    prop_oneof![
        (any::<usize>(), prop::sample::select(numbers()))
            .prop_map(|(which, with)| Edit::Number { which, with }),
        any::<usize>().prop_map(Edit::DropKey),
        (any::<usize>(), any::<usize>()).prop_map(|(node, child)| Edit::AddChild { node, child }),
        (any::<usize>(), prop::sample::select(kinds()))
            .prop_map(|(which, with)| Edit::Kind { which, with }),
        (any::<usize>(), 1u8..=255).prop_map(|(at, bits)| Edit::Byte { at, bits }),
    ]
}

/// Replaces the `which`-th number of `v` (depth first) by `with`; false when there are
/// fewer numbers, with `which` reduced by their count.
fn replace_number(v: &mut Value, which: &mut usize, with: &Value) -> bool {
    match v {
        Value::Number(_) if *which == 0 => {
            *v = with.clone();
            true
        }
        Value::Number(_) => {
            *which -= 1;
            false
        }
        Value::Array(a) => a.iter_mut().any(|x| replace_number(x, which, with)),
        Value::Object(o) => o.values_mut().any(|x| replace_number(x, which, with)),
        _ => false,
    }
}

fn count_numbers(v: &Value) -> usize {
    match v {
        Value::Number(_) => 1,
        Value::Array(a) => a.iter().map(count_numbers).sum(),
        Value::Object(o) => o.values().map(count_numbers).sum(),
        _ => 0,
    }
}

fn drop_key(v: &mut Value, which: &mut usize) -> bool {
    match v {
        Value::Object(o) => {
            if *which < o.len() {
                let key = o.keys().nth(*which).cloned().unwrap_or_default();
                o.remove(&key);
                return true;
            }
            *which -= o.len();
            o.values_mut().any(|x| drop_key(x, which))
        }
        Value::Array(a) => a.iter_mut().any(|x| drop_key(x, which)),
        _ => false,
    }
}

/// Applies the edits; the result is the file's bytes.
fn apply(mut doc: Value, edits: &[Edit]) -> Vec<u8> {
    let mut flips = Vec::new();
    for e in edits {
        match e {
            Edit::Number { which, with } => {
                let mut w = which % count_numbers(&doc).max(1);
                replace_number(&mut doc, &mut w, with);
            }
            Edit::DropKey(which) => {
                let mut w = *which % 64;
                drop_key(&mut doc, &mut w);
            }
            Edit::AddChild { node, child } => {
                if let Some(nodes) = doc.get_mut("nodes").and_then(Value::as_array_mut) {
                    let n = nodes.len();
                    if n > 0 {
                        let child = (child % (n + 1)) as u64;
                        let target = &mut nodes[node % n];
                        if let Some(obj) = target.as_object_mut() {
                            let children = obj.entry("children").or_insert(Value::Array(vec![]));
                            if let Some(c) = children.as_array_mut() {
                                c.push(child.into());
                            }
                        }
                    }
                }
            }
            Edit::Kind { which, with } => {
                if which % 2 == 0 {
                    if let Some(a) = doc.get_mut("accessors").and_then(Value::as_array_mut)
                        && !a.is_empty()
                    {
                        let n = a.len();
                        a[(which / 2) % n]["type"] = with.clone();
                    }
                } else if let Some(p) = doc.pointer_mut("/meshes/0/primitives/0") {
                    p["mode"] = with.clone();
                }
            }
            Edit::Byte { at, bits } => flips.push((*at, *bits)),
        }
    }
    let mut bytes = serde_json::to_vec_pretty(&doc).unwrap();
    for (at, bits) in flips {
        let i = at % bytes.len();
        bytes[i] ^= bits;
    }
    bytes
}

fn load(dir: &Path, name: &str, bytes: &[u8]) -> Result<(), LoadError> {
    let path = dir.join(name);
    std::fs::write(&path, bytes).unwrap();
    read_gltf(&path).map(|_| ())
}

#[test]
fn gltf_documents_survive_structural_mutations() {
    let dir = tempfile::tempdir().unwrap();
    let doc = sample_gltf();
    let tally = Tally::default();
    runner()
        .run(&prop::collection::vec(edit(), 1..5), |edits| {
            let bytes = apply(doc.clone(), &edits);
            let start = Instant::now();
            let result = load(dir.path(), "m.gltf", &bytes);
            prop_assert!(start.elapsed() < CASE_LIMIT);
            check(result, &tally)
        })
        .unwrap();
    tally.report("glTF");
    assert_memory_bounded();
}

/// The sample as a GLB: the buffer moved from its data URI into the BIN chunk.
fn sample_glb() -> Vec<u8> {
    let mut doc = sample_gltf();
    let uri = doc["buffers"][0]["uri"].as_str().unwrap().to_string();
    let (_, b64) = uri.split_once(";base64,").unwrap();
    let mut bin = base64::decode(b64).unwrap();
    doc["buffers"][0].as_object_mut().unwrap().remove("uri");
    let mut json = serde_json::to_vec(&doc).unwrap();
    while !json.len().is_multiple_of(4) {
        json.push(b' ');
    }
    while !bin.len().is_multiple_of(4) {
        bin.push(0);
    }
    let mut out = b"glTF".to_vec();
    out.extend_from_slice(&2u32.to_le_bytes());
    let total = 12 + 8 + json.len() + 8 + bin.len();
    out.extend_from_slice(&(total as u32).to_le_bytes());
    out.extend_from_slice(&(json.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&json);
    out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
    out.extend_from_slice(b"BIN\0");
    out.extend_from_slice(&bin);
    out
}

/// One change to a binary file.
#[derive(Clone, Debug)]
enum ByteEdit {
    Flip {
        at: usize,
        bits: u8,
    },
    /// Overwrite the 4-byte word at `at` (rounded down to a multiple of 4).
    Word {
        at: usize,
        with: u32,
    },
    Truncate(usize),
}

fn byte_edit() -> impl Strategy<Value = ByteEdit> {
    let words = prop_oneof![
        Just(0u32),
        Just(1),
        Just(4),
        Just(1 << 31),
        Just(u32::MAX),
        any::<u32>()
    ];
    prop_oneof![
        (any::<usize>(), 1u8..=255).prop_map(|(at, bits)| ByteEdit::Flip { at, bits }),
        (any::<usize>(), words).prop_map(|(at, with)| ByteEdit::Word { at, with }),
        any::<usize>().prop_map(ByteEdit::Truncate),
    ]
}

fn apply_bytes(mut bytes: Vec<u8>, edits: &[ByteEdit]) -> Vec<u8> {
    for e in edits {
        if bytes.len() < 4 {
            break;
        }
        match *e {
            ByteEdit::Flip { at, bits } => {
                let i = at % bytes.len();
                bytes[i] ^= bits;
            }
            ByteEdit::Word { at, with } => {
                let i = (at % (bytes.len() - 3)) & !3;
                bytes[i..i + 4].copy_from_slice(&with.to_le_bytes());
            }
            ByteEdit::Truncate(n) => bytes.truncate(n % bytes.len()),
        }
    }
    bytes
}

#[test]
fn glb_files_survive_byte_mutations() {
    let dir = tempfile::tempdir().unwrap();
    let glb = sample_glb();
    // The harness starts from a file that loads.
    load(dir.path(), "ok.glb", &glb).unwrap();
    let tally = Tally::default();
    runner()
        .run(&prop::collection::vec(byte_edit(), 1..4), |edits| {
            let bytes = apply_bytes(glb.clone(), &edits);
            let start = Instant::now();
            let result = load(dir.path(), "m.glb", &bytes);
            prop_assert!(start.elapsed() < CASE_LIMIT);
            check(result, &tally)
        })
        .unwrap();
    tally.report("GLB");
    assert_memory_bounded();
}

#[test]
fn bvh_files_survive_mutations_behind_a_valid_checksum() {
    let boxes: Vec<Aabb> = (0..50)
        .map(|i| {
            let o = glam::Vec3::new(i as f32 * 0.7, (i % 7) as f32, (i % 3) as f32);
            Aabb::new(o, o + 0.5)
        })
        .collect();
    let bvh = Bvh::build(&boxes);
    let mut file = Vec::new();
    bvh.write(&mut file, 7).unwrap();
    assert_eq!(Bvh::read(&mut &file[..], 7).unwrap(), bvh);
    let ray = Ray {
        origin: glam::Vec3::new(-1.0, 0.2, 0.2),
        dir: glam::Vec3::new(1.0, 0.1, 0.05),
        tmin: 0.0,
        tmax: f32::INFINITY,
    };
    let (accepted, refused) = (AtomicU64::new(0), AtomicU64::new(0));
    runner()
        .run(&prop::collection::vec(byte_edit(), 1..4), |edits| {
            let mut bytes = apply_bytes(file.clone(), &edits);
            // Re-seal the checksum (of everything before it) so the damage reaches the
            // header checks and the tree validation.
            if bytes.len() >= 8 {
                let body = bytes.len() - 8;
                let sum = checksum(&bytes[..body]).to_le_bytes();
                bytes[body..].copy_from_slice(&sum);
            }
            match Bvh::read(&mut &bytes[..], 7) {
                Ok(tree) => {
                    // A tree that passed validation must traverse without a panic.
                    let mut seen = 0;
                    tree.traverse(&ray, |_, _| {
                        seen += 1;
                        None
                    });
                    prop_assert!(seen <= tree.prim_count());
                    accepted.fetch_add(1, Ordering::Relaxed);
                }
                Err(_) => {
                    refused.fetch_add(1, Ordering::Relaxed);
                }
            }
            Ok(())
        })
        .unwrap();
    eprintln!(
        "BVH: {} mutants accepted, {} refused",
        accepted.load(Ordering::Relaxed),
        refused.load(Ordering::Relaxed)
    );
}

#[test]
fn a_chain_of_nodes_each_listed_as_a_root_is_refused_at_once() {
    // Main: 30,000 nodes in a chain, each also listed as a scene root, took over a minute
    // (each root walked its whole subtree). glTF-Validator calls a child listed as a root
    // SCENE_NON_ROOT_NODE; it is refused at the first node reached twice.
    let mut doc = sample_gltf();
    let n = 30_000;
    let nodes: Vec<Value> = (0..n)
        .map(|i| {
            if i + 1 < n {
                serde_json::json!({"mesh": 0, "children": [i + 1]})
            } else {
                serde_json::json!({"mesh": 0})
            }
        })
        .collect();
    doc["nodes"] = Value::Array(nodes);
    doc["scenes"][0]["nodes"] = Value::Array((0..n).map(Value::from).collect());
    let dir = tempfile::tempdir().unwrap();
    let start = Instant::now();
    let e = load(dir.path(), "chain.gltf", &serde_json::to_vec(&doc).unwrap()).unwrap_err();
    assert!(start.elapsed() < Duration::from_secs(5));
    assert!(e.to_string().contains("is reached twice"), "{e}");
}
