//! Byte offsets of top-level array elements in a glTF JSON text (`"accessors"` element 3),
//! so that errors found after deserialising (serde keeps no spans) point at the element
//! they are about. Strings are skipped with their escapes (RFC 8259 §7), so brackets inside
//! names do not count.

use super::super::text::quoted_end;

/// Offset of element `index` of the array under the top-level key `key`, or of the key
/// itself when the array is shorter, or `None` without the key.
pub fn element(json: &str, key: &str, index: usize) -> Option<usize> {
    let b = json.as_bytes();
    let mut depth = 0usize;
    let mut i = 0;
    // Inside the wanted array: its depth, the element count so far and the key's offset.
    let mut array: Option<(usize, usize, usize)> = None;
    let mut expect_element = false;
    while i < b.len() {
        let c = b[i];
        if c.is_ascii_whitespace() {
            i += 1;
            continue;
        }
        if let Some((d, n, _)) = array
            && expect_element
            && depth == d
            && c != b']'
        {
            if n == index {
                return Some(i);
            }
            expect_element = false;
        }
        match c {
            b'"' => {
                let end = quoted_end(b, i);
                if array.is_none()
                    && depth == 1
                    && &b[i + 1..end.saturating_sub(1).max(i + 1)] == key.as_bytes()
                {
                    let colon = b[end..].iter().position(|c| !c.is_ascii_whitespace());
                    if colon.is_some_and(|k| b[end + k] == b':') {
                        let open = b[end..].iter().position(|&c| c == b'[' || c == b'{');
                        if let Some(k) = open.filter(|&k| b[end + k] == b'[') {
                            array = Some((depth + 1, 0, i));
                            depth += 1;
                            expect_element = true;
                            i = end + k + 1;
                            continue;
                        }
                        return Some(i);
                    }
                }
                i = end;
                continue;
            }
            b'{' | b'[' => depth += 1,
            b'}' | b']' => {
                if let Some((d, _, at)) = array
                    && depth == d
                {
                    return Some(at);
                }
                depth = depth.saturating_sub(1);
            }
            b',' => {
                if let Some((d, n, at)) = array
                    && depth == d
                {
                    array = Some((d, n + 1, at));
                    expect_element = true;
                }
            }
            _ => {}
        }
        i += 1;
    }
    array.map(|(_, _, at)| at)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn elements_of_top_level_arrays_are_found_past_nested_ones_and_strings() {
        let json = r#"{"asset": {"accessors": [9]}, "nodes": [{"name": "a],["}, {"children": [1, 2]},  7], "accessors": [ {"count": 3}, {"count": 4} ]}"#;
        let at = |k, n| element(json, k, n).map(|i| &json[i..i + 5]);
        assert_eq!(at("nodes", 0), Some("{\"nam"));
        assert_eq!(at("nodes", 1), Some("{\"chi"));
        assert_eq!(at("nodes", 2), Some("7], \""));
        assert_eq!(at("accessors", 1), Some("{\"cou"));
        assert_eq!(element(json, "accessors", 1), json.rfind("{\"count\": 4}"));
        // Past the end: the key; no key: nothing.
        assert_eq!(at("accessors", 5), Some("\"acce"));
        assert_eq!(element(json, "accessors", 5), json.rfind("\"accessors\""));
        assert_eq!(element(json, "meshes", 0), None);
        // Broken texts end the scan without a panic.
        for broken in ["{\"nodes\": [", "{\"nodes\"", "\"", "{\"a\\"] {
            let _ = element(broken, "nodes", 1);
        }
    }
}
