//! Structured mutations of a valid input: bytes flipped, lines dropped or
//! repeated, numbers replaced by NaN, infinities, huge, tiny or empty values, truncation.
//! Shared by the in-process parser fuzzing (`tests/robust_parsers.rs`) and the hand-run
//! mutation run through the binary (`benches/mutation_run.rs`).

use proptest::prelude::*;

/// One way of damaging a text.
#[derive(Clone, Debug)]
pub enum Mutation {
    FlipByte { at: usize, bits: u8 },
    DropLine(usize),
    RepeatLine(usize),
    ReplaceNumber { which: usize, with: &'static str },
    Truncate(usize),
}

pub const REPLACEMENTS: &[&str] = &[
    "nan",
    "NaN",
    "inf",
    "-inf",
    "1e39",
    "-1e308",
    "",
    "0",
    "-0",
    "1e-45",
    "99999999999999999999",
    "-1",
    "x",
];

pub fn mutation() -> impl Strategy<Value = Mutation> {
    prop_oneof![
        (any::<usize>(), 1u8..=255).prop_map(|(at, bits)| Mutation::FlipByte { at, bits }),
        any::<usize>().prop_map(Mutation::DropLine),
        any::<usize>().prop_map(Mutation::RepeatLine),
        (any::<usize>(), prop::sample::select(REPLACEMENTS))
            .prop_map(|(which, with)| Mutation::ReplaceNumber { which, with }),
        any::<usize>().prop_map(Mutation::Truncate),
    ]
}

pub fn apply(src: &str, muts: &[Mutation]) -> String {
    String::from_utf8_lossy(&apply_bytes(src.as_bytes(), muts)).into_owned()
}

/// The mutations applied to raw bytes (binary files too: line and number edits see the
/// bytes as lossy UTF-8).
pub fn apply_bytes(src: &[u8], muts: &[Mutation]) -> Vec<u8> {
    let mut bytes = src.to_vec();
    for m in muts {
        if bytes.is_empty() {
            break;
        }
        match *m {
            Mutation::FlipByte { at, bits } => {
                let i = at % bytes.len();
                bytes[i] ^= bits;
            }
            Mutation::DropLine(k) | Mutation::RepeatLine(k) => {
                let text = String::from_utf8_lossy(&bytes).into_owned();
                let mut lines: Vec<&str> = text.split('\n').collect();
                let i = k % lines.len();
                if matches!(m, Mutation::DropLine(_)) {
                    lines.remove(i);
                } else {
                    lines.insert(i, lines[i]);
                }
                bytes = lines.join("\n").into_bytes();
            }
            Mutation::ReplaceNumber { which, with } => {
                let text = String::from_utf8_lossy(&bytes).into_owned();
                let numbers: Vec<(usize, usize)> = number_spans(&text);
                if numbers.is_empty() {
                    continue;
                }
                let (s, e) = numbers[which % numbers.len()];
                bytes = format!("{}{}{}", &text[..s], with, &text[e..]).into_bytes();
            }
            Mutation::Truncate(k) => {
                let n = k % bytes.len();
                bytes.truncate(n);
            }
        }
    }
    bytes
}

/// Byte spans of numeric words.
fn number_spans(text: &str) -> Vec<(usize, usize)> {
    let mut spans = Vec::new();
    let mut start = None;
    for (i, c) in text.char_indices() {
        let numeric = c.is_ascii_digit() || c == '.' || c == '-' || c == 'e' || c == '+';
        match (numeric, start) {
            (true, None) => start = Some(i),
            (false, Some(s)) => {
                spans.push((s, i));
                start = None;
            }
            _ => {}
        }
    }
    if let Some(s) = start {
        spans.push((s, text.len()));
    }
    spans
}
