//! The IGES 5.3 file layout (§2): 80-column records in five sections, Start (S), Global
//! (G), Directory Entry (D), Parameter Data (P) and Terminate (T), each record with its
//! section letter in column 73 and its sequence number within the section in columns
//! 74–80.

use std::io::Write;

/// Columns of data in a Start or Global record (§2.2.4.1).
const DATA_COLUMNS: usize = 72;
/// Columns of parameter data in a Parameter Data record; 65 is blank and 66–72 hold the
/// entity's directory pointer (§2.2.4.5.1).
const PARAMETER_COLUMNS: usize = 64;

/// One parameter of an entity or of the Global section, as written (§2.2.2).
#[derive(Clone, Debug, PartialEq)]
pub enum Param {
    Int(i64),
    Real(f64),
    /// A string, written as a Hollerith constant `nH…`.
    Text(String),
    /// A defaulted (empty) field.
    Default,
}

impl Param {
    fn text(&self) -> String {
        match self {
            Param::Int(i) => i.to_string(),
            Param::Real(x) => real(*x),
            Param::Text(s) => format!("{}H{s}", s.len()),
            Param::Default => String::new(),
        }
    }
}

/// A real constant (§2.2.2.3): always with a decimal point, in Rust's shortest round-trip
/// digits, so every `f64` reads back exactly; a `D` exponent (double precision) where the
/// plain form would be long.
pub fn real(x: f64) -> String {
    let plain = format!("{x}");
    if plain.len() <= 20 {
        return if plain.contains('.') {
            plain
        } else {
            plain + ".0"
        };
    }
    let e = format!("{x:e}");
    let (mantissa, exponent) = e.split_once('e').unwrap_or((&e, "0"));
    if mantissa.contains('.') {
        format!("{mantissa}D{exponent}")
    } else {
        format!("{mantissa}.0D{exponent}")
    }
}

/// A Directory Entry's fields (§2.2.4.4) that vary between the entities written here.
#[derive(Clone, Debug, PartialEq)]
pub struct Entry {
    pub kind: u32,
    pub form: u32,
    /// Status number field 9: blank status, subordinate switch, entity use flag and
    /// hierarchy, two digits each.
    pub status: [u8; 4],
    /// Field 13: 0 (none) or minus the directory pointer of a 314 colour.
    pub colour: i64,
    pub params: Vec<Param>,
}

/// The directory pointer (sequence number of its first Directory Entry record) of the
/// entity at `index` in file order.
pub fn pointer(index: usize) -> i64 {
    2 * index as i64 + 1
}

/// Records of free-format parameters (each followed by `delimiter`, the last by `;`)
/// packed `width` columns at most, breaking only between parameters.
fn pack(params: &[Param], width: usize) -> Vec<String> {
    let mut lines = vec![String::new()];
    for (k, p) in params.iter().enumerate() {
        let end = if k + 1 == params.len() { ';' } else { ',' };
        let token = format!("{}{end}", p.text());
        let line = lines.last_mut().expect("lines starts non-empty");
        if !line.is_empty() && line.len() + token.len() > width {
            lines.push(token);
        } else {
            line.push_str(&token);
        }
    }
    lines
}

/// A record: `data` padded to 72 columns, the section letter and the sequence number.
fn record(w: &mut dyn Write, data: &str, section: char, sequence: usize) -> std::io::Result<()> {
    writeln!(w, "{data:<DATA_COLUMNS$}{section}{sequence:>7}")
}

/// Writes a whole file: `start` lines of prose, the Global parameters, then the entities
/// in order (the Directory Entry section, then the Parameter Data section).
pub fn write_file(
    w: &mut dyn Write,
    start: &[String],
    global: &[Param],
    entries: &[Entry],
) -> std::io::Result<()> {
    for (k, line) in start.iter().enumerate() {
        record(w, line, 'S', k + 1)?;
    }
    let global_lines = pack(global, DATA_COLUMNS);
    for (k, line) in global_lines.iter().enumerate() {
        record(w, line, 'G', k + 1)?;
    }
    let parameter_lines: Vec<Vec<String>> = entries
        .iter()
        .map(|e| {
            let mut params = vec![Param::Int(i64::from(e.kind))];
            params.extend(e.params.iter().cloned());
            pack(&params, PARAMETER_COLUMNS)
        })
        .collect();
    let mut first_line = 1;
    for (k, (e, lines)) in entries.iter().zip(&parameter_lines).enumerate() {
        let status: String = e.status.iter().map(|s| format!("{s:02}")).collect();
        // Fields 1–9: type, parameter pointer, structure, line font, level, view,
        // transformation, label display, status.
        let one = format!(
            "{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}",
            e.kind, first_line, 0, 0, 0, 0, 0, 0, status
        );
        record(w, &one, 'D', 2 * k + 1)?;
        // Fields 10–18: type, line weight, colour, parameter line count, form, two reserved,
        // label, subscript.
        let two = format!(
            "{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}",
            e.kind,
            0,
            e.colour,
            lines.len(),
            e.form,
            "",
            "",
            "",
            0
        );
        record(w, &two, 'D', 2 * k + 2)?;
        first_line += lines.len();
    }
    let mut sequence = 0;
    for (k, lines) in parameter_lines.iter().enumerate() {
        for line in lines {
            sequence += 1;
            let data = format!("{line:<PARAMETER_COLUMNS$} {:>7}", pointer(k));
            record(w, &data, 'P', sequence)?;
        }
    }
    let terminate = format!(
        "S{:>7}G{:>7}D{:>7}P{:>7}",
        start.len(),
        global_lines.len(),
        2 * entries.len(),
        sequence
    );
    record(w, &terminate, 'T', 1)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reals_read_back_exactly_and_carry_a_decimal_point() {
        for x in [0.0, -0.0, 1.0, 0.1, -2.5e-300, 1e300, 123456.789, 1.0 / 3.0] {
            let s = real(x);
            assert!(s.contains('.'), "{s}");
            let back: f64 = s.replace('D', "E").parse().unwrap();
            assert_eq!(back.to_bits(), x.to_bits(), "{s}");
        }
    }

    #[test]
    fn every_record_is_80_columns_with_its_section_and_sequence() {
        let entries = vec![Entry {
            kind: 314,
            form: 0,
            status: [0, 0, 2, 0],
            colour: 0,
            params: (0..40).map(|k| Param::Real(k as f64 / 7.0)).collect(),
        }];
        let global = vec![Param::Text(",".into()), Param::Text(";".into())];
        let mut out = Vec::new();
        write_file(&mut out, &["made by a test".into()], &global, &entries).unwrap();
        let text = String::from_utf8(out).unwrap();
        let mut counts = std::collections::BTreeMap::new();
        for line in text.lines() {
            assert_eq!(line.len(), 80, "{line:?}");
            let section = line.as_bytes()[72] as char;
            let n = counts.entry(section).or_insert(0);
            *n += 1;
            assert_eq!(line[73..].trim().parse::<usize>().unwrap(), *n, "{line:?}");
            if section == 'P' {
                assert_eq!(&line[64..72], "       1");
            }
        }
        let p = counts[&'P'];
        assert!(p > 1);
        let last = text.lines().last().unwrap();
        assert_eq!(&last[..32], format!("S      1G      1D      2P{p:>7}"));
    }
}
