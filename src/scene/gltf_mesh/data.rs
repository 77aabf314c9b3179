//! Buffers and accessors (glTF 2.0 §3.6 "Binary Data Storage"), checked against the bytes
//! really there before anything is allocated or indexed: every index in range, every
//! `byteOffset + byteLength` inside its buffer, strides at least one element and within
//! 4..=252 (§3.6.2.4), and `offset + stride · (count - 1) + element size` inside the buffer
//! view, so a declared `count` can never ask for more than the file holds (an
//! accessor count beyond its buffer allocated 3.7 GB and aborted in `gltf`).

use std::path::Path;

use gltf_json::Root;
use gltf_json::accessor::{ComponentType, Type};
use gltf_json::validation::Checked;

/// An error about element `index` of the top-level array `key` (`"accessors"`, 3).
#[derive(Debug)]
pub struct Located {
    pub key: &'static str,
    pub index: usize,
    pub message: String,
}

fn at(key: &'static str, index: usize, message: String) -> Located {
    Located {
        key,
        index,
        message,
    }
}

/// The bytes of every buffer: the GLB's BIN chunk for a first buffer without `uri`,
/// base64 `data:` URIs, or files relative to `base`.
pub fn load_buffers(root: &Root, bin: Option<&[u8]>, base: &Path) -> Result<Vec<Vec<u8>>, Located> {
    let mut out = Vec::with_capacity(root.buffers.len());
    for (i, b) in root.buffers.iter().enumerate() {
        let bytes = match b.uri.as_deref() {
            None => match (i, bin) {
                (0, Some(bin)) => bin.to_vec(),
                _ => {
                    return Err(at(
                        "buffers",
                        i,
                        format!(
                            "buffer {i} has no uri, which only the first buffer of a GLB file with a BIN chunk may omit"
                        ),
                    ));
                }
            },
            Some(uri) if uri.starts_with("data:") => {
                let (_, payload) = uri.split_once(";base64,").ok_or_else(|| {
                    at(
                        "buffers",
                        i,
                        format!("buffer {i}: expected a base64 data URI (data:...;base64,...)"),
                    )
                })?;
                base64::decode(payload).map_err(|e| {
                    let what = match e {
                        base64::DecodeError::InvalidByte(n, byte) => format!(
                            "invalid base64 digit {:?} at character {n} of the data",
                            char::from(byte)
                        ),
                        other => other.to_string(),
                    };
                    at(
                        "buffers",
                        i,
                        format!("buffer {i}: expected base64 data: {what}"),
                    )
                })?
            }
            Some(uri) if uri.contains("://") => {
                return Err(at(
                    "buffers",
                    i,
                    format!(
                        "buffer {i}: uri \"{uri}\": only data: URIs and files beside the glTF file are read"
                    ),
                ));
            }
            Some(uri) => {
                let file = base.join(uri);
                std::fs::read(&file).map_err(|e| {
                    at(
                        "buffers",
                        i,
                        format!(
                            "buffer {i} refers to file \"{uri}\": {}: {e}",
                            file.display()
                        ),
                    )
                })?
            }
        };
        if (bytes.len() as u64) < b.byte_length.0 {
            return Err(at(
                "buffers",
                i,
                format!(
                    "buffer {i} declares byteLength {} but holds {} bytes",
                    b.byte_length.0,
                    bytes.len()
                ),
            ));
        }
        out.push(bytes);
    }
    Ok(out)
}

/// The elements of an accessor: the bytes from its first element, the stride between
/// elements, how many there are and their component type.
struct Elements<'a> {
    bytes: &'a [u8],
    stride: usize,
    count: usize,
    component: ComponentType,
}

fn component_size(c: ComponentType) -> usize {
    match c {
        ComponentType::I8 | ComponentType::U8 => 1,
        ComponentType::I16 | ComponentType::U16 => 2,
        ComponentType::U32 | ComponentType::F32 => 4,
    }
}

/// Validates accessor `index` as `ty` with one of `components` and finds its elements.
fn elements<'a>(
    root: &Root,
    buffers: &'a [Vec<u8>],
    index: usize,
    ty: Type,
    components: &[ComponentType],
) -> Result<Elements<'a>, Located> {
    let err = |m: String| at("accessors", index, format!("accessor {index}: {m}"));
    let a = root.accessors.get(index).ok_or_else(|| {
        err(format!(
            "does not exist ({} accessors)",
            root.accessors.len()
        ))
    })?;
    if a.sparse.is_some() {
        return Err(err("sparse accessors are not supported".into()));
    }
    match a.type_ {
        Checked::Valid(t) if t == ty => {}
        Checked::Valid(t) => return Err(err(format!("expected type {ty:?}, found {t:?}"))),
        Checked::Invalid => return Err(err(format!("expected type {ty:?}"))),
    }
    let component = match a.component_type {
        Checked::Valid(c) if components.contains(&c.0) => c.0,
        Checked::Valid(c) => {
            return Err(err(format!(
                "expected component type {components:?}, found {:?}",
                c.0
            )));
        }
        Checked::Invalid => return Err(err(format!("expected component type {components:?}"))),
    };
    let per = match ty {
        Type::Scalar => 1,
        Type::Vec2 => 2,
        Type::Vec3 => 3,
        _ => 4,
    };
    let element = per * component_size(component);
    let view_index = a
        .buffer_view
        .ok_or_else(|| err("expected a bufferView (accessors of zeros are not supported)".into()))?
        .value();
    let v = root.buffer_views.get(view_index).ok_or_else(|| {
        err(format!(
            "buffer view {view_index} does not exist ({} views)",
            root.buffer_views.len()
        ))
    })?;
    let verr = |m: String| {
        at(
            "bufferViews",
            view_index,
            format!("buffer view {view_index}: {m}"),
        )
    };
    let buffer = buffers.get(v.buffer.value()).ok_or_else(|| {
        verr(format!(
            "buffer {} does not exist ({} buffers)",
            v.buffer.value(),
            buffers.len()
        ))
    })?;
    let declared = root.buffers[v.buffer.value()].byte_length.0;
    let start = v.byte_offset.map_or(0, |o| o.0);
    let end = start
        .checked_add(v.byte_length.0)
        .filter(|&e| e <= declared)
        .ok_or_else(|| {
            verr(format!(
                "bytes {start} + {} run past the {declared} bytes of buffer {}",
                v.byte_length.0,
                v.buffer.value()
            ))
        })?;
    let stride = match v.byte_stride {
        None => element,
        Some(s) if (4..=252).contains(&s.0) && s.0 % 4 == 0 && s.0 >= element => s.0,
        Some(s) => {
            return Err(verr(format!(
                "expected byteStride a multiple of 4 from max(4, {element}) to 252, found {}",
                s.0
            )));
        }
    };
    let view = &buffer[start as usize..end as usize];
    let offset = a.byte_offset.map_or(0, |o| o.0);
    let count = a.count.0;
    // offset + stride (count - 1) + element <= view length, in u128 so nothing wraps.
    let needed = if count == 0 {
        0
    } else {
        u128::from(offset) + stride as u128 * u128::from(count - 1) + element as u128
    };
    if needed > view.len() as u128 {
        return Err(err(format!(
            "{count} elements of {element} bytes (stride {stride}) from byte {offset} need {needed} bytes, but buffer view {view_index} has {}",
            view.len()
        )));
    }
    Ok(Elements {
        bytes: &view[(offset as usize).min(view.len())..],
        stride,
        count: count as usize,
        component,
    })
}

/// Accessor `index` as `f32` triples (POSITION, NORMAL: §3.7.2.1 requires VEC3 float).
pub fn vec3(root: &Root, buffers: &[Vec<u8>], index: usize) -> Result<Vec<[f32; 3]>, Located> {
    let e = elements(root, buffers, index, Type::Vec3, &[ComponentType::F32])?;
    Ok((0..e.count)
        .map(|i| {
            let b = &e.bytes[i * e.stride..];
            [0, 1, 2]
                .map(|k| f32::from_le_bytes([b[4 * k], b[4 * k + 1], b[4 * k + 2], b[4 * k + 3]]))
        })
        .collect())
}

/// Accessor `index` as vertex indices (§3.7.2.1: unsigned byte, short or int scalars).
pub fn indices(root: &Root, buffers: &[Vec<u8>], index: usize) -> Result<Vec<u32>, Located> {
    let e = elements(
        root,
        buffers,
        index,
        Type::Scalar,
        &[ComponentType::U8, ComponentType::U16, ComponentType::U32],
    )?;
    Ok((0..e.count)
        .map(|i| {
            let b = &e.bytes[i * e.stride..];
            match e.component {
                ComponentType::U8 => u32::from(b[0]),
                ComponentType::U16 => u32::from(u16::from_le_bytes([b[0], b[1]])),
                _ => u32::from_le_bytes([b[0], b[1], b[2], b[3]]),
            }
        })
        .collect())
}
