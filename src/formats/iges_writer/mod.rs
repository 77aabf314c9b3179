//! The IGES 5.3 writer: a scene's surfaces as rational B-spline surfaces (128), each a
//! sheet of Bézier patches ([`crate::formats::sheet`]) whose interior knots all have
//! multiplicity equal to the degree, trimmed (144) by curves on the surface (142) whose
//! parameter-space curves are composite curves (102) of one-span rational B-spline curves
//! (126), the rational Bézier pieces of each loop; colours as 314 entities; millimetres
//! (Global parameters 14 and 15). [`sections`] lays out the file.
//!
//! Status numbers (§2.2.4.4.9): a surface or curve that is part of another is physically
//! dependent (subordinate switch 01), which tells readers (ours, OpenCASCADE's) to draw
//! only the 144 and not its 128 as well; parameter-space curves have entity use 05
//! (2D parametric), colours 02 (definition).

pub mod sections;

use std::io::Write;

use glam::Vec3;

use self::sections::{Entry, Param, pointer, write_file};
use crate::formats::sheet::Sheet;
use crate::geom::trim::TrimLoop;
use crate::geom::trim::pieces::{Piece, loop_pieces};

/// IGES version flag for 5.3 (Global parameter 23, §2.2.4.3.23).
const VERSION_5_3: i64 = 11;
/// Unit flag for millimetres (Global parameter 14, §2.2.4.3.14).
const UNIT_MILLIMETRES: i64 = 2;
/// Minimum user-intended resolution (Global parameter 19) as a share of the largest
/// coordinate: readers take it as the file's precision when healing (OpenCASCADE's
/// `read.precision.mode` "File").
const RESOLUTION_SHARE: f64 = 1e-7;

/// Longest file name written in the Global section.
const MAX_NAME: usize = 60;

const INDEPENDENT: [u8; 4] = [0, 0, 0, 0];
const DEPENDENT: [u8; 4] = [0, 1, 0, 0];
const DEPENDENT_PARAMETRIC: [u8; 4] = [0, 1, 5, 0];
const DEFINITION: [u8; 4] = [0, 0, 2, 0];

/// What the Start and Global sections say about the file.
pub struct Header<'a> {
    /// The file's name (Global parameter 4) and product (3 and 12).
    pub file_name: &'a str,
    /// Date and time of writing, `YYYYMMDD.HHMMSS` (Global parameters 18 and 25).
    pub timestamp: &'a str,
}

/// Writes `sheets` as an IGES 5.3 file; `colours[k]` is the colour of object `k`.
/// Everything fallible was settled by the caller: this only fails on output.
pub fn write_iges(
    w: &mut dyn Write,
    header: &Header,
    sheets: &[Sheet],
    colours: &[Option<Vec3>],
) -> std::io::Result<()> {
    let mut entries: Vec<Entry> = Vec::new();
    // One 314 per distinct colour, first, so surfaces point back to them.
    let mut palette: Vec<(Vec3, i64)> = Vec::new();
    for c in colours.iter().flatten() {
        if !palette.iter().any(|(p, _)| p == c) {
            palette.push((*c, pointer(entries.len())));
            entries.push(colour_entry(*c));
        }
    }
    let colour_of = |object: usize| -> i64 {
        colours
            .get(object)
            .copied()
            .flatten()
            .and_then(|c| palette.iter().find(|(p, _)| *p == c))
            .map_or(0, |(_, d)| -d)
    };
    let mut largest: f64 = 0.0;
    for sheet in sheets {
        for h in &sheet.net {
            largest = largest.max((h.truncate() / h.w).abs().max_element());
        }
        let colour = colour_of(sheet.object);
        let trimmed = !sheet.loops.is_empty();
        let surface = pointer(entries.len());
        entries.push(surface_entry(sheet, colour, trimmed));
        if !trimmed {
            continue;
        }
        let mut outer = None;
        let mut inner = Vec::new();
        for l in &sheet.loops {
            let Some(curve) = loop_entries(l, surface, &mut entries) else {
                continue;
            };
            // The first outer loop bounds the surface; any further loop (holes, and
            // outer loops of a surface with several) is an inner boundary: the region is
            // the even–odd one either way, as readers of 144 build faces.
            if !l.hole && outer.is_none() {
                outer = Some(curve);
            } else {
                inner.push(curve);
            }
        }
        let mut params = vec![
            Param::Int(surface),
            Param::Int(i64::from(outer.is_some())),
            Param::Int(inner.len() as i64),
            Param::Int(outer.unwrap_or(0)),
        ];
        params.extend(inner.into_iter().map(Param::Int));
        entries.push(Entry {
            kind: 144,
            form: 0,
            status: INDEPENDENT,
            colour,
            params,
        });
    }
    let start = vec![
        "Bezier patches with their trims, written by patchtrace.".to_string(),
        "Units: millimetres.".to_string(),
    ];
    write_file(w, &start, &global(header, largest), &entries)
}

/// The Global section's 25 parameters (§2.2.4.3).
fn global(header: &Header, largest: f64) -> Vec<Param> {
    let text = |s: &str| Param::Text(s.to_string());
    // Hollerith strings count characters as bytes and a Global record holds 72 columns:
    // the name is kept to printable ASCII and to a length that fits a record.
    let name: String = header
        .file_name
        .chars()
        .map(|c| {
            if c.is_ascii_graphic() || c == ' ' {
                c
            } else {
                '_'
            }
        })
        .take(MAX_NAME)
        .collect();
    let version = concat!("patchtrace ", env!("CARGO_PKG_VERSION"));
    let largest = if largest > 0.0 { largest } else { 1.0 };
    vec![
        text(","),
        text(";"),
        text(&name),
        text(&name),
        text("patchtrace"),
        text(version),
        Param::Int(32),
        Param::Int(38),
        Param::Int(6),
        Param::Int(308),
        Param::Int(15),
        text(&name),
        Param::Real(1.0),
        Param::Int(UNIT_MILLIMETRES),
        text("MM"),
        Param::Int(1),
        Param::Real(1.0),
        text(header.timestamp),
        Param::Real(largest * RESOLUTION_SHARE),
        Param::Real(largest),
        Param::Default,
        Param::Default,
        Param::Int(VERSION_5_3),
        Param::Int(0),
        text(header.timestamp),
    ]
}

fn colour_entry(c: Vec3) -> Entry {
    // 314: red, green and blue in percent of full intensity (§4.74).
    let percent = |x: f32| Param::Real(f64::from(x.clamp(0.0, 1.0)) * 100.0);
    Entry {
        kind: 314,
        form: 0,
        status: DEFINITION,
        colour: 0,
        params: vec![percent(c.x), percent(c.y), percent(c.z)],
    }
}

/// 128 (§4.25): K1, K2, M1, M2, PROP1–5, knots in u then v, weights and points (u
/// fastest), and the parameter range.
fn surface_entry(sheet: &Sheet, colour: i64, trimmed: bool) -> Entry {
    let (cu, cv) = sheet.net_size();
    let polynomial = !sheet.is_rational();
    let mut params: Vec<Param> = [
        cu as i64 - 1,
        cv as i64 - 1,
        sheet.degree_u as i64,
        sheet.degree_v as i64,
        0,
        0,
        i64::from(polynomial),
        0,
        0,
    ]
    .into_iter()
    .map(Param::Int)
    .collect();
    let reals = |v: Vec<f64>| v.into_iter().map(Param::Real);
    params.extend(reals(crate::geom::nurbs::knots::bezier_knots(
        &sheet.breaks_u,
        sheet.degree_u,
    )));
    params.extend(reals(crate::geom::nurbs::knots::bezier_knots(
        &sheet.breaks_v,
        sheet.degree_v,
    )));
    params.extend(sheet.net.iter().map(|h| Param::Real(h.w)));
    for h in &sheet.net {
        let e = h.truncate() / h.w;
        params.extend(reals(vec![e.x, e.y, e.z]));
    }
    let d = sheet.domain();
    params.extend(reals(vec![d.u0, d.u1, d.v0, d.v1]));
    Entry {
        kind: 128,
        form: 0,
        status: if trimmed { DEPENDENT } else { INDEPENDENT },
        colour,
        params,
    }
}

/// The 126s of a loop's pieces, their 102 and the 142 on `surface`, appended to
/// `entries`; the 142's pointer, or `None` for a loop with no pieces.
fn loop_entries(l: &TrimLoop, surface: i64, entries: &mut Vec<Entry>) -> Option<i64> {
    // Loops were checked when the scene was read, so converting them cannot fail here.
    let pieces = loop_pieces(l).ok()?;
    if pieces.is_empty() {
        return None;
    }
    let mut members = vec![Param::Int(pieces.len() as i64)];
    for piece in &pieces {
        members.push(Param::Int(pointer(entries.len())));
        entries.push(piece_entry(piece));
    }
    let composite = pointer(entries.len());
    entries.push(Entry {
        kind: 102,
        form: 0,
        status: DEPENDENT_PARAMETRIC,
        colour: 0,
        params: members,
    });
    let curve = pointer(entries.len());
    // 142 (§4.32): created unspecified (0), surface, parameter-space curve, no model-space
    // curve, and the parameter-space curve preferred (1).
    entries.push(Entry {
        kind: 142,
        form: 0,
        status: DEPENDENT,
        colour: 0,
        params: [0, surface, composite, 0, 1]
            .into_iter()
            .map(Param::Int)
            .collect(),
    });
    Some(curve)
}

/// 126 (§4.23) of one rational Bézier piece in the parameter plane: K = M = degree,
/// planar, open, polynomial when the weights are equal, knots 0…0 1…1, weights, points
/// `(u, v, 0)`, range [0, 1] and the plane's normal +z.
fn piece_entry(piece: &Piece) -> Entry {
    let n = piece.points.len() as i64 - 1;
    let w0 = piece.points[0].z;
    let polynomial = piece.points.iter().all(|p| p.z == w0);
    let mut params: Vec<Param> = [n, n, 1, 0, i64::from(polynomial), 0]
        .into_iter()
        .map(Param::Int)
        .collect();
    let count = piece.points.len();
    params.extend((0..2 * count).map(|k| Param::Real(if k < count { 0.0 } else { 1.0 })));
    params.extend(piece.points.iter().map(|p| Param::Real(p.z)));
    for p in &piece.points {
        params.extend([p.x / p.z, p.y / p.z, 0.0].map(Param::Real));
    }
    params.extend([0.0, 1.0, 0.0, 0.0, 1.0].map(Param::Real));
    Entry {
        kind: 126,
        form: 0,
        status: DEPENDENT_PARAMETRIC,
        colour: 0,
        params,
    }
}

/// The time now in UTC as IGES writes dates, `YYYYMMDD.HHMMSS` (§2.2.4.3.18).
pub fn timestamp_now() -> String {
    let secs = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_secs());
    timestamp(secs)
}

/// `YYYYMMDD.HHMMSS` of seconds since 1970-01-01 UTC, by the days-to-civil conversion of
/// H. Hinnant, "chrono-Compatible Low-Level Date Algorithms" (proleptic Gregorian).
fn timestamp(secs: u64) -> String {
    let days = (secs / 86_400) as i64;
    let rest = secs % 86_400;
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let day = doy - (153 * mp + 2) / 5 + 1;
    let month = if mp < 10 { mp + 3 } else { mp - 9 };
    let year = yoe + era * 400 + i64::from(month <= 2);
    format!(
        "{year:04}{month:02}{day:02}.{:02}{:02}{:02}",
        rest / 3600,
        rest % 3600 / 60,
        rest % 60
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn timestamps_match_known_dates() {
        // `date -u -d @951827696 +%Y%m%d.%H%M%S` prints 20000229.123456.
        assert_eq!(timestamp(951_827_696), "20000229.123456");
        assert_eq!(timestamp(0), "19700101.000000");
        // `date -u -d @1798761599 +%Y%m%d.%H%M%S` prints 20261231.235959.
        assert_eq!(timestamp(1_798_761_599), "20261231.235959");
    }
}
