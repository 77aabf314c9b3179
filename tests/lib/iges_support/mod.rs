//! A minimal IGES 5.3 fixed-format writer (§2): Start, Global, Directory Entry, Parameter
//! Data and Terminate sections, parameters wrapped at column 64 after a delimiter. Shared
//! by the IGES tests and the IGES reading benchmark (`#[path]`).

/// One entity to write: type, form, its parameters as written (after the type),
/// transform pointer, colour number and the eight status digits.
pub struct Entry {
    pub ty: i32,
    pub form: i32,
    pub fields: Vec<String>,
    pub transform: usize,
    pub colour: i64,
    pub status: String,
}

/// The file: `global` is the Global section's free-format text (with its `;`).
pub fn fixed_format(global: &str, entries: &[Entry]) -> String {
    let mut out = format!("{:<72}S{:>7}\n", "patchtrace test", 1);
    let g: Vec<String> = global
        .as_bytes()
        .chunks(72)
        .map(|c| String::from_utf8_lossy(c).into_owned())
        .collect();
    for (i, line) in g.iter().enumerate() {
        out += &format!("{line:<72}G{:>7}\n", i + 1);
    }
    let mut d = String::new();
    let mut p = String::new();
    let mut pline = 1;
    for (k, e) in entries.iter().enumerate() {
        let seq = 2 * k + 1;
        let mut fields = vec![e.ty.to_string()];
        fields.extend(e.fields.iter().cloned());
        let mut lines: Vec<String> = vec![String::new()];
        for (i, f) in fields.iter().enumerate() {
            let token = format!("{f}{}", if i + 1 == fields.len() { ';' } else { ',' });
            if lines.last().unwrap().len() + token.len() > 64 {
                lines.push(String::new());
            }
            *lines.last_mut().unwrap() += &token;
        }
        d += &format!(
            "{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}D{:>7}\n",
            e.ty, pline, 0, 0, 0, 0, e.transform, 0, e.status, seq
        );
        d += &format!(
            "{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}D{:>7}\n",
            e.ty,
            0,
            e.colour,
            lines.len(),
            e.form,
            "",
            "",
            "",
            0,
            seq + 1
        );
        for l in &lines {
            p += &format!("{l:<64}{seq:>8}P{pline:>7}\n");
            pline += 1;
        }
    }
    out += &d;
    out += &p;
    out += &format!(
        "S{:>7}G{:>7}D{:>7}P{:>7}{:40}T{:>7}\n",
        1,
        g.len(),
        2 * entries.len(),
        pline - 1,
        "",
        1
    );
    out
}
