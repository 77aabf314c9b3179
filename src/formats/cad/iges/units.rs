//! The file's length unit (IGES 5.3 §2.2.4.3, Global parameters 14 and 15), read as
//! OpenCASCADE's `IGESData_GlobalSection` and `IGESData_BasicEditor` read it, so that
//! patchtrace and OpenCASCADE put a file's geometry in the same millimetres.
//!
//! The unit flag (parameter 14) names the unit, except flags 3 ("the unit named in
//! parameter 15") and 0 or absent (not given), where the name decides; a file that gives
//! neither is in inches, the standard's default. Parameter 13, the model space scale, is
//! reported but not applied: OpenCASCADE's unit factor (`GlobalSection::UnitValue`) is
//! the unit's size alone (checked: a millimetre file with parameter 13 set to 2 reads to
//! the same box in OpenCASCADE 8.0).

/// A length unit as the file declares it, and its size in millimetres.
#[derive(Clone, Debug, PartialEq)]
pub struct LengthUnit {
    pub name: String,
    pub millimetres: f64,
}

/// The units of §2.2.4.3.14 by flag: name and size in millimetres.
const UNITS: [(i64, &str, f64); 10] = [
    (1, "INCH", 25.4),
    (2, "MM", 1.0),
    (4, "FT", 304.8),
    (5, "MI", 1_609_344.0),
    (6, "M", 1000.0),
    (7, "KM", 1_000_000.0),
    (8, "MIL", 0.0254),
    (9, "UM", 0.001),
    (10, "CM", 10.0),
    (11, "UIN", 0.0000254),
];

/// The unit a file declares by its flag (parameter 14, `None` when empty) and unit name
/// (parameter 15), and a warning when it is not clear which unit is meant.
pub fn length_unit(flag: Option<i64>, name: Option<&str>) -> (LengthUnit, Option<String>) {
    let by_flag = |f: i64| UNITS.iter().find(|u| u.0 == f);
    if let Some(&(_, name, mm)) = flag.and_then(by_flag) {
        return (unit(name, mm), None);
    }
    let given = name.map(str::trim).filter(|n| !n.is_empty());
    let Some(given) = given else {
        return match flag {
            None | Some(0) => (unit("INCH", 25.4), None),
            Some(f) => (
                unit("MM", 1.0),
                Some(format!(
                    "unit flag {f} (Global parameter 14) with no unit name: read as millimetres"
                )),
            ),
        };
    };
    let upper = given.to_ascii_uppercase();
    // OpenCASCADE's `UnitNameFlag` also takes IN for inches.
    let upper = if upper == "IN" { "INCH".into() } else { upper };
    match UNITS.iter().find(|u| u.1 == upper) {
        Some(&(_, name, mm)) => (unit(name, mm), None),
        None => (
            unit(given, 1.0),
            Some(format!(
                "unit `{given}` (Global parameter 15) is not an IGES unit name: read as millimetres, as OpenCASCADE reads it"
            )),
        ),
    }
}

fn unit(name: &str, millimetres: f64) -> LengthUnit {
    LengthUnit {
        name: name.to_string(),
        millimetres,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn flag_then_name_then_inches() {
        let mm = |f, n| length_unit(f, n).0.millimetres;
        // The flag decides, whatever the name says.
        assert_eq!(mm(Some(1), Some("MM")), 25.4);
        assert_eq!(mm(Some(10), None), 10.0);
        // Flag 3 or none: the name.
        assert_eq!(mm(Some(3), Some("in")), 25.4);
        assert_eq!(mm(None, Some("FT")), 304.8);
        assert_eq!(mm(Some(0), Some("M")), 1000.0);
        // Neither: inches.
        assert_eq!(mm(None, None), 25.4);
        let (u, w) = length_unit(Some(3), Some("furlong"));
        assert_eq!((u.name.as_str(), u.millimetres), ("furlong", 1.0));
        assert!(w.unwrap().contains("not an IGES unit name"));
    }
}
