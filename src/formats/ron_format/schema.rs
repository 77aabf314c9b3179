//! The serde mirror of the scene model: what a RON scene file holds, field for field.

use std::collections::BTreeMap;

use glam::{DAffine3, DVec3, Vec3};
use serde::{Deserialize, Serialize};

use crate::scene::model::Axis;

/// A point or vector as the file writes it: `(x, y, z)`.
pub(super) type V3 = (f64, f64, f64);
/// A colour as the file writes it: `(r, g, b)`.
pub(super) type C3 = (f32, f32, f32);

#[derive(Debug, Serialize, Deserialize)]
#[serde(rename = "Scene", deny_unknown_fields)]
pub struct SceneFile {
    pub camera: CameraDef,
    #[serde(default = "default_background")]
    pub background: C3,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ambient: Option<f32>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_depth: Option<u32>,
    /// Samples per pixel (`render --spp` overrides it).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub samples: Option<u32>,
    #[serde(default)]
    pub lights: Vec<LightDef>,
    #[serde(default)]
    pub materials: BTreeMap<String, MaterialDef>,
    pub objects: Vec<ObjectDef>,
}

fn default_background() -> C3 {
    (0.05, 0.05, 0.08)
}

#[derive(Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraDef {
    pub eye: V3,
    pub look_at: V3,
    pub up: V3,
    pub fov_y: f64,
    pub width: u32,
    pub height: u32,
    /// A turntable: `orbit: (frames: 24, degrees: 360)` turns the eye about `look_at`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub orbit: Option<OrbitDef>,
    /// Keyframes: `keyframes: [(frame: 0, eye: (…)), (frame: 24, eye: (…), fov_y: 30)]`;
    /// fields a key leaves out are the camera's.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub keyframes: Vec<KeyDef>,
}

#[derive(Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OrbitDef {
    pub frames: u32,
    #[serde(default = "full_turn")]
    pub degrees: f64,
}

fn full_turn() -> f64 {
    360.0
}

#[derive(Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct KeyDef {
    pub frame: u32,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub eye: Option<V3>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub look_at: Option<V3>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub up: Option<V3>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fov_y: Option<f64>,
}

#[derive(Debug, Serialize, Deserialize)]
pub enum LightDef {
    Point {
        position: V3,
        #[serde(default = "white")]
        intensity: C3,
    },
    Directional {
        direction: V3,
        #[serde(default = "white")]
        intensity: C3,
    },
}

fn white() -> C3 {
    (1.0, 1.0, 1.0)
}

#[derive(Debug, Serialize, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct MaterialDef {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub diffuse: Option<C3>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub specular: Option<f32>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shininess: Option<f32>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reflect: Option<f32>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub transmit: Option<f32>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ior: Option<f32>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub highlight: Option<Highlight>,
}

#[derive(Debug, Serialize, Deserialize, Clone, Copy, PartialEq)]
pub enum Highlight {
    Phong,
    Blinn,
}

#[derive(Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ObjectDef {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    pub geometry: GeometryDef,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub material: Option<String>,
    /// The axis that is up in the object's geometry (`X`, `Y` or `Z`, default `Z`): a
    /// y-up model is turned to stand in the z-up scene before its transforms.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub up: Option<Axis>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub transform: Vec<TransformDef>,
}

#[derive(Debug, Serialize, Deserialize)]
pub enum GeometryDef {
    /// A geometry file (`.bpt`, `.obj`, `.pbrt`, `.gltf`, `.glb`), relative to the scene.
    File(String),
    /// Inline free-form surfaces.
    Surfaces(Vec<SurfaceDef>),
    /// A Catmull–Clark surface: `Subdivision(File("cage.obj"))`, a polygon mesh (OBJ or
    /// glTF) as the control cage, with sharp (`EDGE_ONLY`) boundaries.
    Subdivision(Box<GeometryDef>),
    /// The geometry of the earlier object named `of`, as read (before that object's own
    /// transform), placed by this object's `transform` (Dammertz §3.3). Every object that
    /// instances the same geometry shares one copy of it when rendered.
    Instance { of: String },
}

#[derive(Debug, Serialize, Deserialize)]
pub enum SurfaceDef {
    /// A Bézier patch: degrees (du, dv), `(du+1)(dv+1)` points u fastest, optional weights.
    Bezier {
        degree: (usize, usize),
        points: Vec<V3>,
        #[serde(default, skip_serializing_if = "Option::is_none")]
        weights: Option<Vec<f64>>,
        /// The rectangle `(u0, u1, v0, v1)` of its surface's parameters the patch covers,
        /// which its trim loops are written in; `[0,1]²` when absent.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        domain: Option<(f64, f64, f64, f64)>,
        /// Trim loops, as for `Nurbs`.
        #[serde(default, skip_serializing_if = "Vec::is_empty")]
        trims: Vec<TrimLoopDef>,
        #[serde(default, skip_serializing_if = "Option::is_none")]
        trim_space: Option<(AxisMapDef, AxisMapDef)>,
    },
    /// A NURBS surface: degrees, knot vectors, control net size (nu, nv), points u fastest.
    Nurbs {
        degree: (usize, usize),
        knots_u: Vec<f64>,
        knots_v: Vec<f64>,
        count: (usize, usize),
        points: Vec<V3>,
        #[serde(default, skip_serializing_if = "Option::is_none")]
        weights: Option<Vec<f64>>,
        /// Trim loops (even–odd over all loops) in the trim parameter space.
        #[serde(default, skip_serializing_if = "Vec::is_empty")]
        trims: Vec<TrimLoopDef>,
        /// How (u, v) map to the trim parameters; identity when absent.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        trim_space: Option<(AxisMapDef, AxisMapDef)>,
    },
}

/// A trim loop: the outer boundary or a hole.
#[derive(Debug, Serialize, Deserialize)]
pub struct TrimLoopDef {
    pub hole: bool,
    pub segments: Vec<TrimSegmentDef>,
}

/// A B-spline trim curve restricted to `[t0, t1]`: homogeneous points `(w u, w v, w)` and
/// `points + degree + 1` knots.
#[derive(Debug, Serialize, Deserialize)]
pub struct TrimSegmentDef {
    pub t0: f64,
    pub t1: f64,
    pub degree: usize,
    pub knots: Vec<f64>,
    pub points: Vec<V3>,
}

/// [`AxisMap`] in the file.
#[derive(Debug, Serialize, Deserialize)]
pub enum AxisMapDef {
    Identity,
    Arcs { breaks: Vec<f64>, angles: Vec<f64> },
}

/// Transforms, applied in the order listed.
#[derive(Debug, Serialize, Deserialize, Clone, Copy)]
pub enum TransformDef {
    Translate(f64, f64, f64),
    Scale(f64),
    ScaleXyz(f64, f64, f64),
    /// Degrees about the x, y or z axis (right-handed).
    RotateX(f64),
    RotateY(f64),
    RotateZ(f64),
    /// Degrees about an arbitrary axis.
    Rotate(V3, f64),
    /// A general affine map as its 3×4 matrix, row by row: `x' = m[0] x + m[1] y + m[2] z
    /// + m[3]`, and so on (what an imported scene's instance placements are written as).
    Matrix([f64; 12]),
}

impl TransformDef {
    pub(super) fn to_affine(self) -> DAffine3 {
        match self {
            TransformDef::Translate(x, y, z) => DAffine3::from_translation(DVec3::new(x, y, z)),
            TransformDef::Scale(s) => DAffine3::from_scale(DVec3::splat(s)),
            TransformDef::ScaleXyz(x, y, z) => DAffine3::from_scale(DVec3::new(x, y, z)),
            TransformDef::RotateX(d) => DAffine3::from_rotation_x(d.to_radians()),
            TransformDef::RotateY(d) => DAffine3::from_rotation_y(d.to_radians()),
            TransformDef::RotateZ(d) => DAffine3::from_rotation_z(d.to_radians()),
            TransformDef::Rotate(a, d) => {
                DAffine3::from_axis_angle(DVec3::from(a).normalize_or(DVec3::Z), d.to_radians())
            }
            TransformDef::Matrix(m) => DAffine3 {
                matrix3: glam::DMat3::from_cols_array(&[
                    m[0], m[4], m[8], m[1], m[5], m[9], m[2], m[6], m[10],
                ]),
                translation: DVec3::new(m[3], m[7], m[11]),
            },
        }
    }

    /// An affine map as [`TransformDef::Matrix`].
    pub fn matrix(a: &DAffine3) -> TransformDef {
        let (m, t) = (a.matrix3, a.translation);
        TransformDef::Matrix([
            m.x_axis.x, m.y_axis.x, m.z_axis.x, t.x, m.x_axis.y, m.y_axis.y, m.z_axis.y, t.y,
            m.x_axis.z, m.y_axis.z, m.z_axis.z, t.z,
        ])
    }
}

pub(super) fn v3(t: V3) -> DVec3 {
    DVec3::new(t.0, t.1, t.2)
}

pub(super) fn c3(t: C3) -> Vec3 {
    Vec3::new(t.0, t.1, t.2)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_matrix_transform_reads_back_as_the_map_it_was_written_from() {
        let a = DAffine3::from_scale_rotation_translation(
            DVec3::new(1.0, 2.0, 3.0),
            glam::DQuat::from_rotation_z(0.3),
            DVec3::new(4.0, 5.0, 6.0),
        );
        let p = DVec3::new(0.5, -1.5, 2.0);
        // Row 0 of the matrix applied by hand: x' = m0 x + m1 y + m2 z + m3.
        let TransformDef::Matrix(m) = TransformDef::matrix(&a) else {
            unreachable!()
        };
        let x = m[0] * p.x + m[1] * p.y + m[2] * p.z + m[3];
        assert!((x - a.transform_point3(p).x).abs() < 1e-12);
        let back = TransformDef::matrix(&a).to_affine();
        assert!((back.transform_point3(p) - a.transform_point3(p)).length() < 1e-12);
    }
}
