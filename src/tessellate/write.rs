//! Writing tessellated scenes as Wavefront OBJ (positions, normals, faces; full `f64`
//! precision) or glTF 2.0 via `gltf-json` (`f32` positions and normals, `u32` indices):
//! `.gltf` with the buffer embedded as a base64 data URI, or `.glb` with a binary chunk.
//! Files are written under a temporary name and renamed ([`write_atomic`]).

use std::borrow::Cow;
use std::collections::BTreeMap;
use std::io::Write;
use std::path::Path;

use gltf_json as json;
use json::validation::Checked::Valid;
use json::validation::USize64;

use crate::io::OutputError;
use crate::io::write_atomic;
use crate::scene::model::{Geometry, Scene, TriangleMesh};

/// Output formats of `tessellate`, by extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MeshFormat {
    Obj,
    Gltf,
    Glb,
    Stl,
}

impl MeshFormat {
    pub fn of(path: &Path) -> Option<MeshFormat> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        match ext.as_str() {
            "obj" => Some(MeshFormat::Obj),
            "gltf" => Some(MeshFormat::Gltf),
            "glb" => Some(MeshFormat::Glb),
            "stl" => Some(MeshFormat::Stl),
            _ => None,
        }
    }
}

/// Writes every mesh object of `scene` (one OBJ object or glTF mesh and node each) in the
/// format named by the extension, and returns the size of the written file in bytes.
/// Objects that are still free-form surfaces are an error: tessellate them first.
pub fn write_mesh_scene(path: &Path, scene: &Scene) -> Result<u64, OutputError> {
    let format = MeshFormat::of(path).ok_or_else(|| {
        OutputError::invalid(
            path,
            "unsupported mesh output: expected .obj, .gltf, .glb or .stl",
        )
    })?;
    let mut meshes = Vec::with_capacity(scene.objects.len());
    for o in &scene.objects {
        match &o.geometry {
            Geometry::Mesh(m) => meshes.push((o.name.as_str(), m)),
            Geometry::Surfaces(_) | Geometry::Subdivision(_) | Geometry::Instance(_) => {
                return Err(OutputError::invalid(
                    path,
                    format!(
                        "object {:?} is not a triangle mesh; tessellate it first",
                        o.name
                    ),
                ));
            }
        }
    }
    match format {
        MeshFormat::Obj => write_atomic(path, |w| write_obj(w, &meshes))?,
        MeshFormat::Stl => write_atomic(path, |w| crate::formats::stl::write_stl(w, &meshes))?,
        MeshFormat::Gltf | MeshFormat::Glb => {
            let bytes = gltf_bytes(&meshes, format == MeshFormat::Glb)
                .map_err(|m| OutputError::invalid(path, m))?;
            write_atomic(path, |w| w.write_all(&bytes))?;
        }
    }
    std::fs::metadata(path)
        .map(|m| m.len())
        .map_err(|e| OutputError::io(path, e))
}

fn write_obj(w: &mut dyn Write, meshes: &[(&str, &TriangleMesh)]) -> std::io::Result<()> {
    writeln!(w, "# written by patchtrace tessellate")?;
    let mut base = 1usize; // OBJ indices are 1-based and global over the file
    for (name, m) in meshes {
        writeln!(w, "o {}", if name.is_empty() { "mesh" } else { name })?;
        for p in &m.positions {
            writeln!(w, "v {} {} {}", p.x, p.y, p.z)?;
        }
        for n in &m.normals {
            writeln!(w, "vn {} {} {}", n.x, n.y, n.z)?;
        }
        let with_normals = m.normals.len() == m.positions.len();
        for t in &m.indices {
            let [a, b, c] = t.map(|i| i as usize + base);
            if with_normals {
                writeln!(w, "f {a}//{a} {b}//{b} {c}//{c}")?;
            } else {
                writeln!(w, "f {a} {b} {c}")?;
            }
        }
        base += m.positions.len();
    }
    Ok(())
}

/// The whole `.gltf` (JSON with an embedded buffer) or `.glb` file.
fn gltf_bytes(meshes: &[(&str, &TriangleMesh)], binary: bool) -> Result<Vec<u8>, String> {
    let mut root = json::Root::default();
    let mut bin: Vec<u8> = Vec::new();
    let buffer = json::Index::new(0);
    let mut nodes = Vec::new();
    for (name, m) in meshes {
        let positions: Vec<[f32; 3]> = m.positions.iter().map(|p| p.as_vec3().to_array()).collect();
        let (min, max) = positions.iter().fold(
            ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]),
            |(lo, hi), p| {
                (
                    std::array::from_fn(|k| lo[k].min(p[k])),
                    std::array::from_fn(|k| hi[k].max(p[k])),
                )
            },
        );
        let mut attributes = BTreeMap::new();
        let pos = push_accessor(
            &mut root,
            &mut bin,
            buffer,
            bytemuck::cast_slice(&positions),
            positions.len(),
            AccessorKind::Vec3 {
                min: Some((min, max)),
            },
        );
        attributes.insert(Valid(json::mesh::Semantic::Positions), pos);
        if m.normals.len() == m.positions.len() {
            let normals: Vec<[f32; 3]> = m.normals.iter().map(|n| n.as_vec3().to_array()).collect();
            let nrm = push_accessor(
                &mut root,
                &mut bin,
                buffer,
                bytemuck::cast_slice(&normals),
                normals.len(),
                AccessorKind::Vec3 { min: None },
            );
            attributes.insert(Valid(json::mesh::Semantic::Normals), nrm);
        }
        let indices = push_accessor(
            &mut root,
            &mut bin,
            buffer,
            bytemuck::cast_slice(&m.indices),
            m.indices.len() * 3,
            AccessorKind::Index,
        );
        let mesh = root.push(json::Mesh {
            extensions: None,
            extras: Default::default(),
            name: Some(name.to_string()),
            primitives: vec![json::mesh::Primitive {
                attributes,
                extensions: None,
                extras: Default::default(),
                indices: Some(indices),
                material: None,
                mode: Valid(json::mesh::Mode::Triangles),
                targets: None,
            }],
            weights: None,
        });
        nodes.push(root.push(json::Node {
            mesh: Some(mesh),
            name: Some(name.to_string()),
            ..Default::default()
        }));
    }
    let uri = (!binary).then(|| {
        format!(
            "data:application/octet-stream;base64,{}",
            base64::encode(&bin)
        )
    });
    root.push(json::Buffer {
        byte_length: USize64::from(bin.len()),
        extensions: None,
        extras: Default::default(),
        name: None,
        uri,
    });
    let scene = root.push(json::Scene {
        extensions: None,
        extras: Default::default(),
        name: None,
        nodes,
    });
    root.scene = Some(scene);
    let text = root.to_string().map_err(|e| e.to_string())?;
    if !binary {
        return Ok(text.into_bytes());
    }
    let glb = gltf::binary::Glb {
        header: gltf::binary::Header {
            magic: *b"glTF",
            version: 2,
            length: 0, // recomputed by `to_vec`
        },
        json: Cow::Owned(text.into_bytes()),
        bin: Some(Cow::Owned(bin)),
    };
    glb.to_vec().map_err(|e| e.to_string())
}

enum AccessorKind {
    /// `f32` triples, with the position bounds glTF requires for POSITION.
    Vec3 { min: Option<([f32; 3], [f32; 3])> },
    /// `u32` triangle indices.
    Index,
}

/// Appends `data` (a multiple of 4 bytes, so every view stays 4-byte aligned) to the buffer
/// as its own view, and an accessor over it.
fn push_accessor(
    root: &mut json::Root,
    bin: &mut Vec<u8>,
    buffer: json::Index<json::Buffer>,
    data: &[u8],
    count: usize,
    kind: AccessorKind,
) -> json::Index<json::Accessor> {
    let offset = bin.len();
    bin.extend_from_slice(data);
    let (target, component, type_, bounds) = match kind {
        AccessorKind::Vec3 { min } => (
            json::buffer::Target::ArrayBuffer,
            json::accessor::ComponentType::F32,
            json::accessor::Type::Vec3,
            min,
        ),
        AccessorKind::Index => (
            json::buffer::Target::ElementArrayBuffer,
            json::accessor::ComponentType::U32,
            json::accessor::Type::Scalar,
            None,
        ),
    };
    let view = root.push(json::buffer::View {
        buffer,
        byte_length: USize64::from(data.len()),
        byte_offset: Some(USize64::from(offset)),
        byte_stride: None,
        extensions: None,
        extras: Default::default(),
        name: None,
        target: Some(Valid(target)),
    });
    root.push(json::Accessor {
        buffer_view: Some(view),
        byte_offset: Some(USize64(0)),
        count: USize64::from(count),
        component_type: Valid(json::accessor::GenericComponentType(component)),
        extensions: None,
        extras: Default::default(),
        type_: Valid(type_),
        min: bounds.map(|(lo, _)| json::Value::from(lo.to_vec())),
        max: bounds.map(|(_, hi)| json::Value::from(hi.to_vec())),
        name: None,
        normalized: false,
        sparse: None,
    })
}
