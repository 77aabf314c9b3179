//! glTF 2.0 and GLB triangle meshes: positions, normals and indices of every triangle
//! primitive in the default scene, with node transforms applied. The document is read with
//! `gltf-json`'s types straight from `serde_json` (whose errors carry a line and column)
//! and validated here before any index is followed, instead of going through the `gltf`
//! crate's iterators, which index unchecked: an attribute pointing past the accessor list
//! panicked in `gltf-json`, an unexpected accessor type reached `unreachable!` in `gltf`,
//! and declared counts allocated gigabytes.
//!
//! - [`glb`]: the binary container (§4.4), lengths checked against the file.
//! - [`data`]: buffers and accessors (§3.6), bounds checked against the bytes.
//! - Nodes (§3.5.2) must form disjoint trees: each node is visited once, and a node reached
//!   a second time (a cycle, two parents, or a child listed as a scene root, which
//!   glTF-Validator reports as `SCENE_NON_ROOT_NODE`) is refused, so the walk is linear in
//!   the node count.
//!
//! Errors in a `.gltf` say `file:line:column` of the JSON element they are about; in a
//! `.glb` they give the byte offset in the file.

mod data;
mod glb;
mod json_locate;

use std::path::Path;

use glam::{DAffine3, DMat4, DQuat, DVec3};
use gltf_json::Root;
use gltf_json::mesh::{Mode, Semantic};
use gltf_json::validation::Checked;

use super::error::{BinaryError, LoadError, ParseError};
use super::mesh::{append, finish};
use super::model::TriangleMesh;
use data::Located;

/// Most triangles a glTF scene may expand to (nodes can instance one mesh many times):
/// 2^24, about 1 GB as `f64` vertices and `u32` indices.
pub const MAX_TRIANGLES: usize = 1 << 24;

/// The JSON text and where errors in it are reported.
struct Source<'a> {
    path: &'a Path,
    json: &'a str,
    /// Offset of the JSON chunk in a GLB file; `None` for a `.gltf` text.
    glb_offset: Option<usize>,
}

impl Source<'_> {
    /// An error at byte `at` of the JSON text.
    fn error(&self, at: usize, message: String) -> LoadError {
        match self.glb_offset {
            Some(start) => LoadError::binary(self.path, BinaryError::new(start + at, message)),
            None => ParseError::at_byte(self.path, self.json, at, message).into(),
        }
    }

    fn located(&self, e: Located) -> LoadError {
        let at = json_locate::element(self.json, e.key, e.index).unwrap_or(0);
        self.error(at, e.message)
    }

    fn at(&self, key: &'static str, index: usize, message: String) -> LoadError {
        self.located(Located {
            key,
            index,
            message,
        })
    }
}

/// Reads a glTF (`.gltf` with embedded or external buffers) or GLB file as one mesh.
pub fn read_gltf(path: &Path) -> Result<TriangleMesh, LoadError> {
    let bytes = std::fs::read(path).map_err(|e| LoadError::io(path, e))?;
    let (json, glb_offset, bin) = if glb::is_glb(&bytes) {
        let g = glb::split(&bytes).map_err(|e| LoadError::binary(path, e))?;
        (g.json, Some(g.json_start), g.bin)
    } else {
        (&bytes[..], None, None)
    };
    let text = match std::str::from_utf8(json) {
        Ok(t) => t,
        Err(e) => {
            let valid = std::str::from_utf8(&json[..e.valid_up_to()]).unwrap_or_default();
            let src = Source {
                path,
                json: valid,
                glb_offset,
            };
            return Err(src.error(
                e.valid_up_to(),
                format!(
                    "expected UTF-8 JSON text, found byte 0x{:02x}",
                    json[e.valid_up_to()]
                ),
            ));
        }
    };
    let src = Source {
        path,
        json: text,
        glb_offset,
    };
    let root: Root = serde_json::from_str(text).map_err(|e| {
        let message = e.to_string();
        let message = message
            .rfind(" at line ")
            .map_or(message.as_str(), |k| &message[..k]);
        let at = byte_of(text, e.line(), e.column());
        src.error(at, format!("expected a glTF JSON document: {message}"))
    })?;
    let base = path.parent().unwrap_or(Path::new("."));
    let buffers = data::load_buffers(&root, bin, base).map_err(|e| src.located(e))?;
    let mut mesh = TriangleMesh::default();
    let scene = match root.scene {
        Some(s) => Some(s.value()),
        None => (!root.scenes.is_empty()).then_some(0),
    };
    let roots: &[gltf_json::Index<gltf_json::Node>] = match scene {
        Some(s) => match root.scenes.get(s) {
            Some(scene) => &scene.nodes,
            None => {
                return Err(src.error(
                    json_locate::element(text, "scene", 0).unwrap_or(0),
                    format!("scene {s} does not exist ({} scenes)", root.scenes.len()),
                ));
            }
        },
        None => &[],
    };
    let mut seen = vec![false; root.nodes.len()];
    let mut stack: Vec<(usize, DMat4)> = Vec::with_capacity(roots.len());
    let scene_index = scene.unwrap_or(0);
    for r in roots {
        let i = r.value();
        visit(&src, &mut seen, i, ("scenes", scene_index))?;
        stack.push((i, DMat4::IDENTITY));
    }
    while let Some((i, parent)) = stack.pop() {
        let node = &root.nodes[i];
        let world = parent * local_matrix(node);
        for c in node.children.iter().flatten() {
            visit(&src, &mut seen, c.value(), ("nodes", i))?;
            stack.push((c.value(), world));
        }
        if let Some(m) = node.mesh {
            add_mesh(&src, &root, &buffers, m.value(), &world, &mut mesh).map_err(|e| match e {
                MeshError::Located(e) => src.located(e),
                MeshError::Load(e) => e,
            })?;
            if mesh.indices.len() > MAX_TRIANGLES {
                return Err(src.at("nodes", i, format!(
                    "node {i} brings the scene to {} triangles, above the budget of {MAX_TRIANGLES} (2^24)",
                    mesh.indices.len()
                )));
            }
        }
    }
    finish(path, mesh, "triangle primitives").map_err(|e| match e {
        LoadError::Invalid { message, .. } => {
            let at = json_locate::element(text, "meshes", 0).unwrap_or(0);
            src.error(at, message)
        }
        other => other,
    })
}

/// Marks node `i`, referred to by element `from`, as visited, refusing a node that does not
/// exist or was reached before.
fn visit(
    src: &Source,
    seen: &mut [bool],
    i: usize,
    from: (&'static str, usize),
) -> Result<(), LoadError> {
    let n = seen.len();
    match seen.get_mut(i) {
        None => Err(src.at(from.0, from.1, format!("node {i} does not exist ({n} nodes)"))),
        Some(true) => Err(src.at(from.0, from.1, format!(
            "node {i} is reached twice: nodes must form disjoint trees, without cycles, second parents or children listed as scene roots (glTF 2.0 §3.5.2)"
        ))),
        Some(s) => {
            *s = true;
            Ok(())
        }
    }
}

/// A node's local transform: `matrix` (column-major) or translation · rotation · scale.
fn local_matrix(node: &gltf_json::Node) -> DMat4 {
    if let Some(m) = node.matrix {
        return DMat4::from_cols_array(&m.map(f64::from));
    }
    let t = node.translation.unwrap_or([0.0; 3]).map(f64::from);
    let r = node
        .rotation
        .map_or([0.0, 0.0, 0.0, 1.0], |q| q.0)
        .map(f64::from);
    let s = node.scale.unwrap_or([1.0; 3]).map(f64::from);
    DMat4::from_scale_rotation_translation(
        DVec3::from(s),
        DQuat::from_xyzw(r[0], r[1], r[2], r[3]),
        DVec3::from(t),
    )
}

enum MeshError {
    Located(Located),
    Load(LoadError),
}

impl From<Located> for MeshError {
    fn from(e: Located) -> Self {
        MeshError::Located(e)
    }
}

/// Appends the triangle primitives of mesh `m`, transformed by `world`.
fn add_mesh(
    src: &Source,
    root: &Root,
    buffers: &[Vec<u8>],
    m: usize,
    world: &DMat4,
    mesh: &mut TriangleMesh,
) -> Result<(), MeshError> {
    let err = |message: String| data::Located {
        key: "meshes",
        index: m,
        message,
    };
    let Some(def) = root.meshes.get(m) else {
        return Err(err(format!(
            "mesh {m} does not exist ({} meshes)",
            root.meshes.len()
        ))
        .into());
    };
    let name = def.name.as_deref().unwrap_or("");
    for (k, primitive) in def.primitives.iter().enumerate() {
        let label = format!("glTF mesh {m} (\"{name}\") primitive {k}");
        match primitive.mode {
            Checked::Valid(Mode::Triangles) => {}
            Checked::Valid(mode) => {
                return Err(
                    err(format!("{label}: expected triangles, found mode {mode:?}")).into(),
                );
            }
            Checked::Invalid => {
                return Err(err(format!("{label}: expected a primitive mode 0 to 6")).into());
            }
        }
        let attribute = |s: Semantic| {
            primitive
                .attributes
                .get(&Checked::Valid(s))
                .map(|a| a.value())
        };
        let Some(position) = attribute(Semantic::Positions) else {
            return Err(err(format!("{label}: expected a POSITION attribute")).into());
        };
        let positions: Vec<DVec3> = data::vec3(root, buffers, position)?
            .into_iter()
            .map(|p| glam::Vec3::from(p).as_dvec3())
            .collect();
        let normals: Vec<DVec3> = match attribute(Semantic::Normals) {
            Some(n) => data::vec3(root, buffers, n)?
                .into_iter()
                .map(|n| glam::Vec3::from(n).as_dvec3())
                .collect(),
            None => Vec::new(),
        };
        let flat: Vec<u32> = match primitive.indices {
            Some(i) => data::indices(root, buffers, i.value())?,
            None => {
                let n = u32::try_from(positions.len())
                    .map_err(|_| err(format!("{label}: more than 2^32 vertices")))?;
                (0..n).collect()
            }
        };
        if mesh.indices.len() + flat.len() / 3 > MAX_TRIANGLES {
            return Err(err(format!(
                "{label} brings the scene to more than {MAX_TRIANGLES} triangles (2^24), the budget"
            ))
            .into());
        }
        let mut part = TriangleMesh {
            positions,
            normals,
            indices: flat.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect(),
        };
        part.transform(&DAffine3::from_mat4(*world));
        // The shared checks (indices in range, finite positions) name no place; here
        // they are about this mesh.
        append(src.path, mesh, part, &label).map_err(|e| match e {
            LoadError::Invalid { message, .. } => MeshError::Located(err(message)),
            other => MeshError::Load(other),
        })?;
    }
    Ok(())
}

/// The byte offset of 1-based `line` and `column` (in characters; serde_json counts bytes
/// on the line, the same for ASCII) in `text`, clamped to the text.
fn byte_of(text: &str, line: usize, column: usize) -> usize {
    let start = text
        .split_inclusive('\n')
        .take(line.saturating_sub(1))
        .map(str::len)
        .sum::<usize>();
    (start + column.saturating_sub(1)).min(text.len())
}
