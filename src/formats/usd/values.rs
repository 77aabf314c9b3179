//! Attribute values of a composed USD prim as plain numbers, and a prim's local transform
//! from its `xformOp:*` attributes in `xformOpOrder` (UsdGeomXformable).

use glam::{DAffine3, DMat3, DMat4, DQuat, DVec3};
use openusd::sdf::Value;
use openusd::usd::Prim;

/// A prim's attribute as read: its name, for messages.
pub type Attr<'a> = (&'a Prim, &'a str);

/// Reading an attribute went wrong: the attribute's path and why.
#[derive(Debug)]
pub struct ValueError(pub String);

fn error((prim, name): Attr, why: impl std::fmt::Display) -> ValueError {
    ValueError(format!("{}.{name}: {why}", prim.path()))
}

/// The attribute's composed default value, `None` when no layer authors one. A value
/// authored only as time samples is read at its earliest sample (scenes are still).
pub fn raw(attr: Attr) -> Result<Option<Value>, ValueError> {
    let a = attr.0.attribute(attr.1);
    let value = a.get::<Value>().map_err(|e| error(attr, e))?;
    if value.is_some() {
        return Ok(value);
    }
    a.get_at::<Value>(openusd::usd::TimeCode::EARLIEST)
        .map_err(|e| error(attr, e))
}

/// Every number a value holds, in order, as `f64`: scalars, vectors, matrices (row by
/// row, as USD writes them), quaternions (w first, `GfQuat`'s real part) and arrays of
/// them; `None` for non-numeric values.
pub fn flatten(value: &Value) -> Option<Vec<f64>> {
    use Value as V;
    fn f<T: Copy + Into<f64>>(v: &[T]) -> Vec<f64> {
        v.iter().map(|&x| x.into()).collect()
    }
    // Half floats, whose type is openusd's dependency's, not ours.
    macro_rules! h {
        ($v:expr) => {
            $v.iter()
                .map(|x| f64::from(x.to_f32()))
                .collect::<Vec<f64>>()
        };
    }
    Some(match value {
        V::Bool(b) => vec![f64::from(u8::from(*b))],
        V::Int(x) => vec![f64::from(*x)],
        V::IntVec(v) => f(v),
        V::Uint(x) => vec![f64::from(*x)],
        V::UintVec(v) => f(v),
        V::Int64(x) => vec![*x as f64],
        V::Int64Vec(v) => v.iter().map(|&x| x as f64).collect(),
        V::Half(x) => vec![f64::from(x.to_f32())],
        V::HalfVec(v) => h!(v),
        V::Float(x) => vec![f64::from(*x)],
        V::FloatVec(v) => f(v),
        V::Double(x) => vec![*x],
        V::DoubleVec(v) => v.clone(),
        V::Vec2f(v) => f(&[v.x, v.y]),
        V::Vec2d(v) => vec![v.x, v.y],
        V::Vec2fVec(v) => v.iter().flat_map(|p| [p.x, p.y]).map(f64::from).collect(),
        V::Vec2dVec(v) => v.iter().flat_map(|p| [p.x, p.y]).collect(),
        V::Vec3h(v) => h!([v.x, v.y, v.z]),
        V::Vec3f(v) => f(&[v.x, v.y, v.z]),
        V::Vec3d(v) => vec![v.x, v.y, v.z],
        V::Vec3hVec(v) => v.iter().flat_map(|p| h!([p.x, p.y, p.z])).collect(),
        V::Vec3fVec(v) => v
            .iter()
            .flat_map(|p| [p.x, p.y, p.z])
            .map(f64::from)
            .collect(),
        V::Vec3dVec(v) => v.iter().flat_map(|p| [p.x, p.y, p.z]).collect(),
        V::Quath(q) => h!([q.w, q.x, q.y, q.z]),
        V::Quatf(q) => f(&[q.w, q.x, q.y, q.z]),
        V::Quatd(q) => vec![q.w, q.x, q.y, q.z],
        V::QuathVec(v) => v.iter().flat_map(|q| h!([q.w, q.x, q.y, q.z])).collect(),
        V::QuatfVec(v) => v.iter().flat_map(|q| f(&[q.w, q.x, q.y, q.z])).collect(),
        V::QuatdVec(v) => v.iter().flat_map(|q| [q.w, q.x, q.y, q.z]).collect(),
        V::Matrix4d(m) => m.0.to_vec(),
        V::Matrix4dVec(v) => v.iter().flat_map(|m| m.0).collect(),
        _ => return None,
    })
}

/// The attribute's numbers, `None` when unauthored; an error for a non-numeric value.
pub fn numbers(attr: Attr) -> Result<Option<Vec<f64>>, ValueError> {
    match raw(attr)? {
        None => Ok(None),
        Some(v) => flatten(&v)
            .map(Some)
            .ok_or_else(|| error(attr, format!("expected numbers, found {v:?}"))),
    }
}

/// The attribute's numbers as a whole number of `width`-tuples.
pub fn tuples(attr: Attr, width: usize) -> Result<Option<Vec<f64>>, ValueError> {
    match numbers(attr)? {
        Some(v) if v.len() % width != 0 => Err(error(
            attr,
            format!("{} numbers do not make {width}-tuples", v.len()),
        )),
        other => Ok(other),
    }
}

/// The attribute's points (any 3-vector array).
pub fn points(attr: Attr) -> Result<Option<Vec<DVec3>>, ValueError> {
    Ok(tuples(attr, 3)?.map(|v| v.chunks(3).map(DVec3::from_slice).collect()))
}

/// One number (the first of the value's).
pub fn scalar(attr: Attr) -> Result<Option<f64>, ValueError> {
    Ok(numbers(attr)?.and_then(|v| v.first().copied()))
}

/// A whole number, refused when negative or fractional.
pub fn count(attr: Attr) -> Result<Option<usize>, ValueError> {
    match scalar(attr)? {
        Some(x) if x >= 0.0 && x.fract() == 0.0 => Ok(Some(x as usize)),
        Some(x) => Err(error(attr, format!("expected a count, found {x}"))),
        None => Ok(None),
    }
}

/// Whole numbers, each refused when negative or fractional.
pub fn counts(attr: Attr) -> Result<Option<Vec<usize>>, ValueError> {
    let Some(v) = numbers(attr)? else {
        return Ok(None);
    };
    v.iter()
        .map(|&x| {
            if x >= 0.0 && x.fract() == 0.0 {
                Ok(x as usize)
            } else {
                Err(error(attr, format!("expected counts, found {x}")))
            }
        })
        .collect::<Result<_, _>>()
        .map(Some)
}

/// A token or string attribute.
pub fn token(attr: Attr) -> Result<Option<String>, ValueError> {
    Ok(match raw(attr)? {
        Some(Value::Token(t)) => Some(t.as_str().to_string()),
        Some(Value::String(s)) => Some(s),
        Some(v) => return Err(error(attr, format!("expected a token, found {v:?}"))),
        None => None,
    })
}

/// A token array attribute (`xformOpOrder`).
pub fn tokens(attr: Attr) -> Result<Option<Vec<String>>, ValueError> {
    Ok(match raw(attr)? {
        Some(Value::TokenVec(t)) => Some(t.iter().map(|t| t.as_str().to_string()).collect()),
        Some(Value::StringVec(s)) => Some(s),
        Some(v) => return Err(error(attr, format!("expected tokens, found {v:?}"))),
        None => None,
    })
}

/// USD's row-vector 4×4 matrix (translation in the last row) as an affine map of column
/// vectors: the transpose, which is what reading the rows as glam's columns gives.
pub fn affine_of_rows(m: &[f64]) -> DAffine3 {
    let mut a = [0.0; 16];
    a.copy_from_slice(&m[..16]);
    DAffine3::from_mat4(DMat4::from_cols_array(&a))
}

/// The prim's local transform (to its parent's space) and whether `!resetXformStack!`
/// says to ignore the parents' transforms. Ops compose in `xformOpOrder`, the first the
/// outermost (UsdGeomXformable: "the xformOps are applied to points in the reverse order
/// of xformOpOrder"); `!invert!` inverts an op. Rotation angles are in degrees;
/// `rotateXYZ` turns about x first, then y, then z.
pub fn local_transform(prim: &Prim) -> Result<(DAffine3, bool), ValueError> {
    let Some(order) = tokens((prim, "xformOpOrder"))? else {
        return Ok((DAffine3::IDENTITY, false));
    };
    let mut m = DAffine3::IDENTITY;
    let mut reset = false;
    for op in &order {
        if op == "!resetXformStack!" {
            // Ops before it still apply (UsdGeomXformable: it "is only valid as the first
            // element"); a file putting it later is read the same way.
            m = DAffine3::IDENTITY;
            reset = true;
            continue;
        }
        let (invert, name) = match op.strip_prefix("!invert!") {
            Some(n) => (true, n),
            None => (false, op.as_str()),
        };
        let attr = (prim, name);
        let v = numbers(attr)?.ok_or_else(|| error(attr, "in xformOpOrder but not authored"))?;
        let kind = name
            .strip_prefix("xformOp:")
            .and_then(|k| k.split(':').next())
            .ok_or_else(|| error(attr, "not an xformOp"))?;
        let need = |n: usize| -> Result<(), ValueError> {
            if v.len() < n {
                Err(error(
                    attr,
                    format!("expected {n} numbers, found {}", v.len()),
                ))
            } else {
                Ok(())
            }
        };
        let axis_turn = |axis: char, deg: f64| match axis {
            'X' => DMat3::from_rotation_x(deg.to_radians()),
            'Y' => DMat3::from_rotation_y(deg.to_radians()),
            _ => DMat3::from_rotation_z(deg.to_radians()),
        };
        let step = match kind {
            "translate" => {
                need(3)?;
                DAffine3::from_translation(DVec3::from_slice(&v))
            }
            "scale" => {
                need(3)?;
                DAffine3::from_scale(DVec3::from_slice(&v))
            }
            "rotateX" | "rotateY" | "rotateZ" => {
                need(1)?;
                DAffine3::from_mat3(axis_turn(kind.chars().last().unwrap_or('Z'), v[0]))
            }
            "orient" => {
                need(4)?;
                DAffine3::from_quat(DQuat::from_xyzw(v[1], v[2], v[3], v[0]).normalize())
            }
            "transform" => {
                need(16)?;
                affine_of_rows(&v)
            }
            k if k.len() == 9 && k.starts_with("rotate") => {
                need(3)?;
                // rotateABC: about A by v[0] first, then B by v[1], then C by v[2].
                let axes: Vec<char> = k[6..].chars().collect();
                DAffine3::from_mat3(
                    axis_turn(axes[2], v[2]) * axis_turn(axes[1], v[1]) * axis_turn(axes[0], v[0]),
                )
            }
            _ => return Err(error(attr, "unknown xformOp kind")),
        };
        m *= if invert { step.inverse() } else { step };
    }
    Ok((m, reset))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn usd_row_matrices_become_the_transposed_affine_map() {
        // A translation by (1, 2, 3) and a scale by 2, as USD writes it: translation in the
        // last row.
        let m = [
            2.0, 0.0, 0.0, 0.0, 0.0, 2.0, 0.0, 0.0, 0.0, 0.0, 2.0, 0.0, 1.0, 2.0, 3.0, 1.0,
        ];
        let a = affine_of_rows(&m);
        assert_eq!(a.transform_point3(DVec3::ONE), DVec3::new(3.0, 4.0, 5.0));
    }
}
