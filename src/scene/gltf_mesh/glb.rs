//! The GLB container (glTF 2.0 §4.4 "Binary glTF Layout"): a 12-byte header (magic
//! `glTF`, version 2, total length), a JSON chunk, then an optional BIN chunk, each chunk a
//! length, a type and the data. Every length is checked against the bytes really there
//! before anything is sliced, so a header declaring 4 GB reads nothing (a
//! declared length of 1 allocated 4 GB in `gltf`).

use super::super::error::BinaryError;

const MAGIC: &[u8; 4] = b"glTF";
const JSON: u32 = 0x4E4F_534A;
const BIN: u32 = 0x004E_4942;
const HEADER: usize = 12;
const CHUNK_HEADER: usize = 8;

/// The chunks of a GLB file: the JSON text's bytes and where they start, and the binary
/// buffer if there is one.
#[derive(Debug)]
pub struct Glb<'a> {
    pub json: &'a [u8],
    pub json_start: usize,
    pub bin: Option<&'a [u8]>,
}

/// True when `bytes` start like a GLB file.
pub fn is_glb(bytes: &[u8]) -> bool {
    bytes.starts_with(MAGIC)
}

fn word(bytes: &[u8], at: usize) -> Option<u32> {
    let w = bytes.get(at..at + 4)?;
    Some(u32::from_le_bytes([w[0], w[1], w[2], w[3]]))
}

/// Splits a GLB file into its chunks; errors give the byte offset of the bad field.
pub fn split(bytes: &[u8]) -> Result<Glb<'_>, BinaryError> {
    let err = |offset: usize, m: String| BinaryError::new(offset, m);
    let version = word(bytes, 4).ok_or_else(|| err(0, "expected a 12-byte GLB header".into()))?;
    if version != 2 {
        return Err(err(4, format!("expected GLB version 2, found {version}")));
    }
    let length = word(bytes, 8).ok_or_else(|| err(8, "expected a 12-byte GLB header".into()))?;
    if length as usize != bytes.len() {
        return Err(err(
            8,
            format!(
                "the GLB header declares {length} bytes, but the file has {}",
                bytes.len()
            ),
        ));
    }
    let (json_type, json, json_start) = chunk(bytes, HEADER)?;
    if json_type != JSON {
        return Err(err(
            HEADER + 4,
            format!(
                "expected the JSON chunk first (type 0x{JSON:08x}), found type 0x{json_type:08x}"
            ),
        ));
    }
    let mut at = json_start + json.len();
    let mut bin = None;
    // Further chunks: at most one BIN, which must come second; chunks of other types are
    // to be ignored (§4.4.3).
    while at < bytes.len() {
        let (kind, data, start) = chunk(bytes, at)?;
        if kind == BIN {
            if bin.is_some() || at != json_start + json.len() {
                return Err(err(
                    at + 4,
                    "expected the BIN chunk once, right after the JSON chunk".into(),
                ));
            }
            bin = Some(data);
        }
        at = start + data.len();
    }
    Ok(Glb {
        json,
        json_start,
        bin,
    })
}

/// The chunk at `at`: its type, its data and where the data starts.
fn chunk(bytes: &[u8], at: usize) -> Result<(u32, &[u8], usize), BinaryError> {
    let (Some(len), Some(kind)) = (word(bytes, at), word(bytes, at + 4)) else {
        return Err(BinaryError::new(at, "expected an 8-byte chunk header"));
    };
    let start = at + CHUNK_HEADER;
    let data = start
        .checked_add(len as usize)
        .and_then(|end| bytes.get(start..end))
        .ok_or_else(|| {
            BinaryError::new(
                at,
                format!(
                    "the chunk declares {len} bytes, but only {} follow",
                    bytes.len() - start.min(bytes.len())
                ),
            )
        })?;
    Ok((kind, data, start))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn glb(json: &[u8], bin: Option<&[u8]>) -> Vec<u8> {
        let mut out = Vec::new();
        let mut chunks = Vec::new();
        chunks.extend_from_slice(&(json.len() as u32).to_le_bytes());
        chunks.extend_from_slice(&JSON.to_le_bytes());
        chunks.extend_from_slice(json);
        if let Some(b) = bin {
            chunks.extend_from_slice(&(b.len() as u32).to_le_bytes());
            chunks.extend_from_slice(&BIN.to_le_bytes());
            chunks.extend_from_slice(b);
        }
        out.extend_from_slice(MAGIC);
        out.extend_from_slice(&2u32.to_le_bytes());
        out.extend_from_slice(&((HEADER + chunks.len()) as u32).to_le_bytes());
        out.extend_from_slice(&chunks);
        out
    }

    #[test]
    fn chunks_are_found_and_lengths_checked_against_the_file() {
        let file = glb(b"{}  ", Some(b"abcd"));
        let g = split(&file).unwrap();
        assert_eq!(
            (g.json, g.json_start, g.bin),
            (&b"{}  "[..], 20, Some(&b"abcd"[..]))
        );
        // A declared total length of 1 or of more than the file.
        for bad in [1u32, file.len() as u32 + 1, u32::MAX] {
            let mut f = file.clone();
            f[8..12].copy_from_slice(&bad.to_le_bytes());
            assert_eq!(split(&f).unwrap_err().offset, 8);
        }
        // A chunk longer than what follows.
        let mut f = file.clone();
        f[12..16].copy_from_slice(&1000u32.to_le_bytes());
        assert_eq!(split(&f).unwrap_err().offset, 12);
        // Truncated headers.
        for n in [3, 4, 11, 12, 19] {
            assert!(split(&file[..n]).is_err());
        }
    }
}
