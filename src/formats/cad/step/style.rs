//! Colours of STEP presentation (ISO 10303-46, AP214 §4.2.?): STYLED_ITEM and
//! OVER_RIDING_STYLED_ITEM assign a PRESENTATION_STYLE_ASSIGNMENT to a solid, shell or face;
//! the surface colour sits a few references down (SURFACE_STYLE_USAGE → SURFACE_SIDE_STYLE →
//! SURFACE_STYLE_FILL_AREA → FILL_AREA_STYLE → FILL_AREA_STYLE_COLOUR → COLOUR_RGB or
//! DRAUGHTING_PRE_DEFINED_COLOUR). Writers differ in the chain, so the colour is found by
//! searching the style's references for the first colour, depth-bounded.

use std::collections::HashMap;

use glam::Vec3;

use super::records::{Exchange, Param, Value};

/// References followed from a style to its colour; real chains are six deep.
const MAX_DEPTH: usize = 12;

/// The colour an item is styled with.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Colour(pub Vec3);

fn predefined(name: &str) -> Option<Vec3> {
    Some(match name.to_ascii_lowercase().as_str() {
        "red" => Vec3::new(1.0, 0.0, 0.0),
        "green" => Vec3::new(0.0, 1.0, 0.0),
        "blue" => Vec3::new(0.0, 0.0, 1.0),
        "yellow" => Vec3::new(1.0, 1.0, 0.0),
        "magenta" => Vec3::new(1.0, 0.0, 1.0),
        "cyan" => Vec3::new(0.0, 1.0, 1.0),
        "black" => Vec3::ZERO,
        "white" => Vec3::ONE,
        _ => return None,
    })
}

fn colour_in(ex: &Exchange, p: &Param, depth: usize) -> Option<Vec3> {
    if depth > MAX_DEPTH {
        return None;
    }
    match &p.value {
        Value::List(items) => items.iter().find_map(|q| colour_in(ex, q, depth + 1)),
        Value::Ref(id) => {
            let inst = ex.get(*id)?;
            let r = &inst.records[0];
            let number = |k: usize| match r.params.get(k).map(|p| &p.value) {
                Some(Value::Real(x)) => Some(*x as f32),
                Some(Value::Integer(i)) => Some(*i as f32),
                _ => None,
            };
            match r.name {
                "COLOUR_RGB" => {
                    let c = Vec3::new(number(1)?, number(2)?, number(3)?);
                    c.is_finite().then(|| c.clamp(Vec3::ZERO, Vec3::ONE))
                }
                "DRAUGHTING_PRE_DEFINED_COLOUR" => match r.params.first().map(|p| &p.value) {
                    Some(Value::Str(s)) => predefined(s),
                    _ => None,
                },
                _ => r.params.iter().find_map(|q| colour_in(ex, q, depth + 1)),
            }
        }
        _ => None,
    }
}

/// Item id → colour for every styled item (an over-riding style wins over a plain one).
pub fn colours(ex: &Exchange) -> HashMap<u64, Colour> {
    let mut out = HashMap::new();
    for overriding in [false, true] {
        let name = if overriding {
            "OVER_RIDING_STYLED_ITEM"
        } else {
            "STYLED_ITEM"
        };
        for inst in &ex.instances {
            let Some(r) = inst.record(name) else { continue };
            let (Some(styles), Some(item)) = (r.params.get(1), r.params.get(2)) else {
                continue;
            };
            let Value::Ref(item) = item.value else {
                continue;
            };
            if let Some(c) = colour_in(ex, styles, 0) {
                out.insert(item, Colour(c));
            }
        }
    }
    out
}
