//! Units of a representation's context (ISO 10303-41 §18: GLOBAL_UNIT_ASSIGNED_CONTEXT with
//! SI_UNIT, CONVERSION_BASED_UNIT): the length unit in millimetres, which the reader scales
//! every model to, and the plane-angle unit in radians, in which pcurves on surfaces of
//! revolution and conic trims are written.

use super::entities::Resolver;
use super::records::{Instance, Record, Value};

/// A length or plane-angle unit: its name and its size in millimetres or radians.
#[derive(Clone, Debug, PartialEq)]
pub struct Unit {
    pub name: String,
    pub factor: f64,
}

/// The units of one context, and the distance within which it declares two points one.
#[derive(Clone, Debug, PartialEq)]
pub struct Units {
    pub length: Unit,
    pub angle: Unit,
    /// The context's length uncertainty in millimetres (ISO 10303-43 §4.2.2
    /// GLOBAL_UNCERTAINTY_ASSIGNED_CONTEXT: an UNCERTAINTY_MEASURE_WITH_UNIT of a length
    /// unit, the largest if it gives several), where the file declares one.
    pub uncertainty: Option<f64>,
}

impl Default for Units {
    /// ISO 10303-41 has no default; millimetres and radians are what CAD files write
    /// when they write nothing usable.
    fn default() -> Self {
        Units {
            length: Unit {
                name: "millimetre (assumed)".into(),
                factor: 1.0,
            },
            angle: Unit {
                name: "radian (assumed)".into(),
                factor: 1.0,
            },
            uncertainty: None,
        }
    }
}

/// The SI prefixes of ISO 10303-41 `si_prefix`.
fn prefix(name: &str) -> Option<f64> {
    Some(match name {
        "EXA" => 1e18,
        "PETA" => 1e15,
        "TERA" => 1e12,
        "GIGA" => 1e9,
        "MEGA" => 1e6,
        "KILO" => 1e3,
        "HECTO" => 1e2,
        "DECA" => 1e1,
        "DECI" => 1e-1,
        "CENTI" => 1e-2,
        "MILLI" => 1e-3,
        "MICRO" => 1e-6,
        "NANO" => 1e-9,
        "PICO" => 1e-12,
        "FEMTO" => 1e-15,
        "ATTO" => 1e-18,
        _ => return None,
    })
}

/// Longest chain of conversion-based units followed (inch defined by millimetre defined by
/// metre is two).
const MAX_CHAIN: usize = 8;

/// The size of unit `inst` (millimetres for lengths, radians for angles) and its name.
fn unit_size(res: &Resolver, inst: &Instance, depth: usize) -> Option<Unit> {
    if depth > MAX_CHAIN {
        return None;
    }
    if let Some(si) = inst.record("SI_UNIT") {
        // In the complex form SI_UNIT(prefix, name); as a simple instance NAMED_UNIT's
        // dimensions come first: SI_UNIT(*, prefix, name).
        let off = si.params.len().saturating_sub(2);
        let pre = match si.params.get(off).map(|p| &p.value) {
            Some(Value::Enumeration(e)) => Some(*e),
            _ => None,
        };
        let base = match si.params.get(off + 1).map(|p| &p.value) {
            Some(Value::Enumeration(e)) => *e,
            _ => return None,
        };
        let scale = match pre {
            Some(p) => prefix(p)?,
            None => 1.0,
        };
        let (size, word) = match base {
            "METRE" => (1000.0 * scale, "metre"),
            "RADIAN" => (scale, "radian"),
            _ => return None,
        };
        let name = format!("{}{word}", pre.map(str::to_lowercase).unwrap_or_default());
        return Some(Unit { name, factor: size });
    }
    let conv = inst.record("CONVERSION_BASED_UNIT")?;
    let name = match conv.params.first().map(|p| &p.value) {
        Some(Value::Str(s)) => s.to_lowercase(),
        _ => "unnamed".into(),
    };
    let Value::Ref(mwu) = conv.params.get(1)?.value else {
        return None;
    };
    let m = res.ex.get(mwu)?;
    let r = m
        .records
        .iter()
        .find(|r| r.name.ends_with("MEASURE_WITH_UNIT"))?;
    let value = measure_value(r)?;
    let Value::Ref(base) = r.params.get(1)?.value else {
        return None;
    };
    let base = unit_size(res, res.ex.get(base)?, depth + 1)?;
    let factor = value * base.factor;
    (factor.is_finite() && factor > 0.0).then_some(Unit { name, factor })
}

/// The value of a `*_MEASURE_WITH_UNIT` record's first parameter (typed or bare).
fn measure_value(r: &Record) -> Option<f64> {
    match &r.params.first()?.value {
        Value::Typed(_, inner) => match inner.value {
            Value::Real(x) => Some(x),
            Value::Integer(i) => Some(i as f64),
            _ => None,
        },
        Value::Real(x) => Some(*x),
        _ => None,
    }
}

/// The largest length uncertainty the context `ctx` assigns, in millimetres.
fn context_uncertainty(res: &Resolver, ctx: &Instance) -> Option<f64> {
    let guac = ctx.record("GLOBAL_UNCERTAINTY_ASSIGNED_CONTEXT")?;
    let Some(Value::List(list)) = guac.params.first().map(|p| &p.value) else {
        return None;
    };
    list.iter()
        .filter_map(|item| {
            let Value::Ref(id) = item.value else {
                return None;
            };
            let r = res.ex.get(id)?.record("UNCERTAINTY_MEASURE_WITH_UNIT")?;
            let Value::Ref(unit) = r.params.get(1)?.value else {
                return None;
            };
            let unit = res.ex.get(unit)?;
            unit.record("LENGTH_UNIT")?;
            let mm = measure_value(r)? * unit_size(res, unit, 0)?.factor;
            (mm.is_finite() && mm > 0.0).then_some(mm)
        })
        .reduce(f64::max)
}

/// The units assigned by the context `ctx` (GLOBAL_UNIT_ASSIGNED_CONTEXT, usually one
/// record of a complex context instance); what is missing keeps the default.
pub fn context_units(res: &Resolver, ctx: u64) -> Units {
    let mut units = Units::default();
    let Some(context) = res.ex.get(ctx) else {
        return units;
    };
    units.uncertainty = context_uncertainty(res, context);
    let Some(gua) = context.record("GLOBAL_UNIT_ASSIGNED_CONTEXT") else {
        return units;
    };
    let Some(Value::List(list)) = gua.params.first().map(|p| &p.value) else {
        return units;
    };
    for item in list {
        let Value::Ref(id) = item.value else { continue };
        let Some(u) = res.ex.get(id) else { continue };
        if u.record("LENGTH_UNIT").is_some() {
            if let Some(size) = unit_size(res, u, 0) {
                units.length = size;
            }
        } else if u.record("PLANE_ANGLE_UNIT").is_some()
            && let Some(size) = unit_size(res, u, 0)
        {
            units.angle = size;
        }
    }
    units
}

/// The units of the first context in the file that assigns any: the file's plane-angle
/// unit (one for all its entities), and the length unit of parts without their own.
pub fn file_units(res: &Resolver) -> Units {
    res.ex
        .instances
        .iter()
        .find(|i| i.record("GLOBAL_UNIT_ASSIGNED_CONTEXT").is_some())
        .map(|i| context_units(res, i.id))
        .unwrap_or_default()
}
