//! The in-memory scene: camera, lights, materials and objects. Geometry is kept in `f64`
//! exactly as read (after transforms); the renderer rounds it to `f32` once.

use std::borrow::Cow;
use std::sync::Arc;

use glam::{DAffine3, DVec3, Vec3};

use crate::geom::BezierPatch;
use crate::geom::bbox::DAabb;
use crate::geom::nurbs::NurbsSurface;
use crate::geom::subdiv::SubdivisionSurface;
use crate::geom::trim::{AxisMap, Coverage, PatchTrim, TrimError, TrimLoop, TrimRegion};

/// Camera per the DESIGN.md contract.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Camera {
    pub eye: DVec3,
    pub look_at: DVec3,
    pub up: DVec3,
    /// Vertical field of view in degrees.
    pub fov_y: f64,
    pub width: u32,
    pub height: u32,
}

/// Longest image edge, in pixels (2^15).
pub const MAX_IMAGE_EDGE: u32 = 1 << 15;

/// Largest film one render holds, in pixels: 2^26 (8192 × 8192). The film keeps an `f32`
/// RGBA value per pixel, 16 bytes, so this is 1 GiB; a 100000 × 100000 request asked for
/// 160 GB at once. Larger images are rendered in pieces (`--tile`, `--crop`).
pub const MAX_IMAGE_PIXELS: u64 = 1 << 26;

impl Camera {
    /// Refuses an image with a zero edge or an edge beyond [`MAX_IMAGE_EDGE`].
    pub fn check_size(&self) -> Result<(), String> {
        let (w, h) = (self.width, self.height);
        if w == 0 || h == 0 || w > MAX_IMAGE_EDGE || h > MAX_IMAGE_EDGE {
            return Err(format!(
                "width and height must be 1 to {MAX_IMAGE_EDGE}, found {w}x{h}"
            ));
        }
        Ok(())
    }
}

/// Refuses a film (the image, or the piece of it one render makes) of more than
/// [`MAX_IMAGE_PIXELS`], naming the budget.
pub fn check_film_pixels(width: u32, height: u32) -> Result<(), String> {
    let pixels = u64::from(width) * u64::from(height);
    if pixels > MAX_IMAGE_PIXELS {
        return Err(format!(
            "a {width}x{height} film has {pixels} pixels, above the budget of {MAX_IMAGE_PIXELS} (8192x8192: 1 GiB of f32 RGBA); render it in pieces with --tile K/N or --crop"
        ));
    }
    Ok(())
}

#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum Light {
    Point {
        position: DVec3,
        intensity: Vec3,
    },
    /// `direction` points from the light into the scene.
    Directional {
        direction: DVec3,
        intensity: Vec3,
    },
}

/// Whitted material. Highlight model is Phong unless `blinn` is set.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Material {
    pub name: String,
    pub diffuse: Vec3,
    pub specular: f32,
    pub shininess: f32,
    pub reflect: f32,
    pub transmit: f32,
    pub ior: f32,
    pub blinn: bool,
}

impl Material {
    pub fn default_named(name: &str) -> Self {
        Material {
            name: name.to_string(),
            diffuse: Vec3::splat(0.8),
            specular: 0.0,
            shininess: 32.0,
            reflect: 0.0,
            transmit: 0.0,
            ior: 1.5,
            blinn: false,
        }
    }
}

/// A free-form surface as read: a Bézier patch or a NURBS surface, with any trim loops.
#[derive(Clone, Debug, PartialEq)]
pub struct Surface {
    pub geometry: SurfaceGeometry,
    /// Trim loops in the surface's parameter domain, as mapped by `trim_space`; none means
    /// the whole domain.
    pub trims: Vec<TrimLoop>,
    /// For (u, v): how the NURBS parameter maps to the parameter the loops are written in
    /// (identity but for analytic surfaces read from CAD files).
    pub trim_space: [AxisMap; 2],
}

#[derive(Clone, Debug, PartialEq)]
pub enum SurfaceGeometry {
    Bezier(BezierPatch),
    Nurbs(NurbsSurface),
}

impl Surface {
    pub fn bezier(patch: BezierPatch) -> Self {
        Surface {
            geometry: SurfaceGeometry::Bezier(patch),
            trims: Vec::new(),
            trim_space: Default::default(),
        }
    }

    pub fn transform(&mut self, m: &glam::DAffine3) {
        match &mut self.geometry {
            SurfaceGeometry::Bezier(p) => p.transform(m),
            SurfaceGeometry::Nurbs(n) => n.transform(m),
        }
    }

    /// The same surface seen from its other side: u and v exchanged in the geometry, the
    /// loops and their parameter maps, so the normal `S_u × S_v` turns around and nothing
    /// else moves (a STEP face whose `same_sense` is false, ISO 10303-42 §5.4.23).
    pub fn flip_sides(&mut self) {
        self.geometry = match &self.geometry {
            SurfaceGeometry::Bezier(p) => SurfaceGeometry::Bezier(p.transposed()),
            SurfaceGeometry::Nurbs(n) => SurfaceGeometry::Nurbs(n.transposed()),
        };
        self.trims = self.trims.iter().map(TrimLoop::transposed).collect();
        self.trim_space.swap(0, 1);
    }

    /// The region the trim loops keep, `None` without loops; an error for loops that cannot
    /// be converted (the readers check this at load, [`crate::formats::check_trims`]).
    pub fn trim_region(&self) -> Result<Option<TrimRegion>, TrimError> {
        TrimRegion::new(&self.trims, &self.trim_space)
    }

    /// The surface's Bézier patches in contract order, each with what its trim loops leave
    /// of it ([`Coverage`]): a patch they cut away wholly is `Outside`.
    pub fn trimmed_patches(&self) -> Vec<(BezierPatch, Coverage)> {
        let patches = match &self.geometry {
            SurfaceGeometry::Bezier(p) => vec![p.clone()],
            SurfaceGeometry::Nurbs(n) => n.to_bezier_patches(),
        };
        // Loops that fail to convert were refused at load; were one to get here, the
        // surface is drawn untrimmed rather than not at all.
        match self.trim_region().ok().flatten() {
            None => patches.into_iter().map(|p| (p, Coverage::Inside)).collect(),
            Some(region) => patches
                .into_iter()
                .map(|p| {
                    let coverage = region.coverage(p.domain());
                    (p, coverage)
                })
                .collect(),
        }
    }
}

/// A patch ready for the renderer: its trim, where its loops cut it.
pub type TrimmedPatch = (BezierPatch, Option<Box<PatchTrim>>);

/// An indexed triangle mesh with optional per-vertex normals.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TriangleMesh {
    pub positions: Vec<DVec3>,
    pub normals: Vec<DVec3>,
    pub indices: Vec<[u32; 3]>,
}

impl TriangleMesh {
    pub fn transform(&mut self, m: &glam::DAffine3) {
        for p in &mut self.positions {
            *p = m.transform_point3(*p);
        }
        // Normals transform by the inverse transpose of the linear part.
        let nm = m.matrix3.inverse().transpose();
        for n in &mut self.normals {
            *n = (nm * *n).normalize_or_zero();
        }
    }
}

#[derive(Clone, Debug, PartialEq)]
pub enum Geometry {
    Surfaces(Vec<Surface>),
    Mesh(TriangleMesh),
    /// A Catmull–Clark control cage and the Bézier patches of its limit surface
    /// (Dammertz §2.9); its patches are numbered as [`SubdivisionSurface::patches`], and
    /// `trace` reports the quad after the first step instead ([`Object::trace_patch`]).
    Subdivision(SubdivisionSurface),
    /// Shared geometry placed by a transform (Dammertz §3.3).
    Instance(Instance),
}

/// One placement of shared geometry (Dammertz §3.3): the geometry in its own (object)
/// space and the affine map from there to world space. Objects holding the same `Arc`
/// share one prepared copy and one bottom-level BVH when rendered
/// ([`crate::accel::scene::SceneGeometry`]); everything else sees the placed copy
/// ([`Geometry::resolved`]). The shape IGES 408 and STEP assembly occurrences map onto:
/// a geometry and an affine transform. Never nested: [`Instance::new`] composes an instance
/// of an instance into one of the base geometry.
#[derive(Clone, Debug, PartialEq)]
pub struct Instance {
    pub geometry: Arc<Geometry>,
    /// Object space to world space.
    pub transform: DAffine3,
}

impl Instance {
    pub fn new(geometry: Arc<Geometry>, transform: DAffine3) -> Instance {
        match geometry.as_ref() {
            Geometry::Instance(inner) => Instance {
                geometry: inner.geometry.clone(),
                transform: transform * inner.transform,
            },
            _ => Instance {
                geometry,
                transform,
            },
        }
    }

    /// A copy of the geometry placed in world space: what the instance stands for.
    pub fn flattened(&self) -> Geometry {
        let mut g = (*self.geometry).clone();
        g.transform(&self.transform);
        g
    }
}

impl Geometry {
    pub fn transform(&mut self, m: &DAffine3) {
        match self {
            Geometry::Surfaces(s) => s.iter_mut().for_each(|s| s.transform(m)),
            Geometry::Mesh(mesh) => mesh.transform(m),
            Geometry::Subdivision(s) => s.transform(m),
            Geometry::Instance(i) => i.transform = *m * i.transform,
        }
    }

    /// The geometry in world space: an instance as its placed copy, anything else as is.
    /// Never an [`Geometry::Instance`].
    pub fn resolved(&self) -> Cow<'_, Geometry> {
        match self {
            Geometry::Instance(i) => Cow::Owned(i.flattened()),
            other => Cow::Borrowed(other),
        }
    }

    /// The geometry's Bézier patches in contract order: file order, with each NURBS
    /// surface expanded into its patches in span order, u spans fastest.
    pub fn bezier_patches(&self) -> Vec<BezierPatch> {
        match self {
            Geometry::Surfaces(surfaces) => surfaces
                .iter()
                .flat_map(|s| match &s.geometry {
                    SurfaceGeometry::Bezier(p) => vec![p.clone()],
                    SurfaceGeometry::Nurbs(n) => n.to_bezier_patches(),
                })
                .collect(),
            Geometry::Mesh(_) => Vec::new(),
            Geometry::Subdivision(s) => s.patches.clone(),
            Geometry::Instance(i) => i.flattened().bezier_patches(),
        }
    }

    /// The number of [`Geometry::bezier_patches`], without placing an instance's copy.
    pub fn patch_count(&self) -> usize {
        match self {
            Geometry::Instance(i) => i.geometry.patch_count(),
            other => other.bezier_patches().len(),
        }
    }

    /// The patches in contract order with their trims; `None` for a patch its trim loops
    /// cut away wholly (it keeps its number, as the contract numbers patches in file
    /// order).
    pub fn trimmed_patches(&self) -> Vec<Option<TrimmedPatch>> {
        match self {
            Geometry::Surfaces(surfaces) => surfaces
                .iter()
                .flat_map(|s| s.trimmed_patches())
                .map(|(p, coverage)| match coverage {
                    Coverage::Outside => None,
                    Coverage::Inside => Some((p, None)),
                    Coverage::Partial(trim) => Some((p, Some(trim))),
                })
                .collect(),
            Geometry::Subdivision(s) => s.patches.iter().map(|p| Some((p.clone(), None))).collect(),
            Geometry::Mesh(_) => Vec::new(),
            Geometry::Instance(i) => i.flattened().trimmed_patches(),
        }
    }

    pub fn bounds(&self) -> DAabb {
        match self {
            Geometry::Surfaces(surfaces) => surfaces
                .iter()
                .flat_map(|s| -> Vec<DVec3> {
                    match &s.geometry {
                        SurfaceGeometry::Bezier(p) => p.euclidean_points().collect(),
                        SurfaceGeometry::Nurbs(n) => {
                            n.points.iter().map(|p| p.truncate() / p.w).collect()
                        }
                    }
                })
                .collect(),
            Geometry::Mesh(m) => m.positions.iter().copied().collect(),
            // The limit surface lies in the convex hull of the cage.
            Geometry::Subdivision(s) => s.cage.points.iter().copied().collect(),
            // The placed corners of the shared geometry's box hold the placed geometry.
            Geometry::Instance(i) => i.geometry.bounds().transformed(&i.transform),
        }
    }

    /// The free-form surfaces, an instance's unplaced.
    pub fn surfaces(&self) -> &[Surface] {
        match self {
            Geometry::Surfaces(s) => s,
            Geometry::Instance(i) => i.geometry.surfaces(),
            Geometry::Mesh(_) | Geometry::Subdivision(_) => &[],
        }
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct Object {
    pub name: String,
    /// Index into [`Scene::materials`].
    pub material: usize,
    pub geometry: Geometry,
}

impl Object {
    /// The object's Bézier patches in contract order ([`Geometry::bezier_patches`]).
    pub fn bezier_patches(&self) -> Vec<BezierPatch> {
        self.geometry.bezier_patches()
    }

    /// The patch number and `(u, v)` that `trace` reports for a hit at `(u, v)` on patch
    /// `patch` (contract order): for a subdivision surface (an instance's too) the quad
    /// after the first Catmull–Clark step and its parameters (see
    /// [`crate::geom::subdiv`]), otherwise unchanged.
    pub fn trace_patch(&self, patch: u32, u: f64, v: f64) -> (u32, f64, f64) {
        let geometry = match &self.geometry {
            Geometry::Instance(i) => i.geometry.as_ref(),
            other => other,
        };
        match geometry {
            Geometry::Subdivision(s) => s.face_uv(patch as usize, u, v).unwrap_or((patch, u, v)),
            _ => (patch, u, v),
        }
    }

    /// Where patch `patch` of a subdivision surface lies in its quad after the first step,
    /// `None` for other geometry.
    pub fn subdivision_piece(&self, patch: u32) -> Option<crate::geom::subdiv::Piece> {
        match &self.geometry {
            Geometry::Subdivision(s) => s.pieces.get(patch as usize).copied(),
            _ => None,
        }
    }

    /// The object's patches with their trims ([`Geometry::trimmed_patches`]).
    pub fn trimmed_patches(&self) -> Vec<Option<TrimmedPatch>> {
        self.geometry.trimmed_patches()
    }

    pub fn bounds(&self) -> DAabb {
        self.geometry.bounds()
    }
}

/// Which coordinate axis of a model points up: glTF models are y-up by specification
/// (glTF 2.0 §3.4), CAD and our own formats z-up.
#[derive(
    Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum, serde::Serialize, serde::Deserialize,
)]
pub enum Axis {
    X,
    Y,
    Z,
}

impl Axis {
    /// The rotation taking this axis to +z, right-handed, the others cyclically (x-up: x
    /// → z, y → x; y-up: y → z, z → -y), so a model stands in a z-up scene.
    pub fn to_z_up(self) -> glam::DMat3 {
        match self {
            Axis::X => glam::DMat3::from_cols(DVec3::Z, DVec3::X, DVec3::Y),
            Axis::Y => glam::DMat3::from_rotation_x(std::f64::consts::FRAC_PI_2),
            Axis::Z => glam::DMat3::IDENTITY,
        }
    }

    /// A direction given in the z-up frame, in the frame where this axis is up.
    pub fn from_z_up(self, v: DVec3) -> DVec3 {
        self.to_z_up().transpose() * v
    }
}

#[cfg(test)]
mod axis_tests {
    use super::*;

    #[test]
    fn each_up_axis_turns_to_z_by_a_rotation_and_back() {
        for (axis, v) in [
            (Axis::X, DVec3::X),
            (Axis::Y, DVec3::Y),
            (Axis::Z, DVec3::Z),
        ] {
            let m = axis.to_z_up();
            assert!((m * v - DVec3::Z).length() < 1e-15, "{axis:?}");
            assert!((m.determinant() - 1.0).abs() < 1e-15);
            assert!((m * m.transpose()).abs_diff_eq(glam::DMat3::IDENTITY, 1e-15));
            assert!((axis.from_z_up(DVec3::Z) - v).length() < 1e-15);
        }
        // glTF's front (+z, y up) is the z-up scene's front (-y): the viewer looks at it.
        assert!((Axis::Y.to_z_up() * DVec3::Z - -DVec3::Y).length() < 1e-15);
    }
}

/// The most samples per pixel a scene or `render --spp` may ask for: a 2^16 net, far
/// beyond what a Whitted image needs, and small enough that a pixel's sum cannot lose a
/// sample's weight in f32.
pub const MAX_SAMPLES: u32 = 1 << 16;

/// Everything needed to render.
#[derive(Clone, Debug, PartialEq)]
pub struct Scene {
    pub camera: Camera,
    pub background: Vec3,
    /// Ambient term added to every lit surface, as a fraction of its diffuse colour.
    pub ambient: f32,
    /// Longest path of reflection and refraction bounces (the primary ray is depth 1).
    pub max_depth: u32,
    /// Samples per pixel, unless `render --spp` says otherwise (`None`: one).
    pub samples: Option<u32>,
    /// How the camera moves over the frames of an animation; `None`: it stands still.
    pub animation: Option<super::animation::CameraPath>,
    pub lights: Vec<Light>,
    pub materials: Vec<Material>,
    pub objects: Vec<Object>,
    /// For a bare file's scene read from its BVH file without the geometry
    /// ([`crate::scene::bare_shell`]), the bounds of that geometry, which framing uses;
    /// `None`: the objects' own.
    pub unread_bounds: Option<DAabb>,
    /// What reading the scene's files left out or tolerated, one line each, for the
    /// command line to print (the library prints nothing).
    pub warnings: Vec<String>,
    /// The camera is the file's own (a RON scene's, a USD `Camera` prim's), not one
    /// framing the geometry: new image sizes and `--up` do not move it.
    pub own_camera: bool,
    /// The length unit of the coordinates, when the file read declared one (a CAD file:
    /// millimetres; a USD stage: its `metersPerUnit`).
    pub unit: Option<SceneUnit>,
}

/// A scene's declared length unit.
#[derive(Clone, Debug, PartialEq)]
pub struct SceneUnit {
    /// Millimetres per coordinate unit: 1 for CAD files (read into millimetres), 1000 ·
    /// `metersPerUnit` for a USD stage (whose coordinates are kept as they are).
    pub millimetres: f64,
    /// The unit in words, and what the file declared, for `info` and writers to state.
    pub words: String,
}

/// Default recursion limit for reflection and refraction.
pub const DEFAULT_MAX_DEPTH: u32 = 5;
/// Default ambient fraction.
pub const DEFAULT_AMBIENT: f32 = 0.1;

impl Scene {
    pub fn bounds(&self) -> DAabb {
        self.unread_bounds.unwrap_or_else(|| {
            self.objects
                .iter()
                .fold(DAabb::EMPTY, |acc, o| acc.union(&o.bounds()))
        })
    }

    /// A scene for bare geometry, z up: a camera that frames it and one light
    /// ([`Scene::frame_bare`]).
    pub fn framing(objects: Vec<Object>) -> Scene {
        Scene::framing_up(objects, Axis::Z)
    }

    /// A scene for bare geometry whose `up` axis points up (DESIGN.md: bare geometry as a
    /// scene).
    pub fn framing_up(objects: Vec<Object>, up: Axis) -> Scene {
        let mut scene = Scene {
            camera: Camera {
                eye: DVec3::new(0.0, -5.0, 0.0),
                look_at: DVec3::ZERO,
                up: DVec3::Z,
                fov_y: 40.0,
                width: 512,
                height: 512,
            },
            background: Vec3::new(0.05, 0.05, 0.08),
            ambient: DEFAULT_AMBIENT,
            max_depth: DEFAULT_MAX_DEPTH,
            samples: None,
            animation: None,
            lights: Vec::new(),
            materials: vec![Material::default_named("default")],
            objects,
            unread_bounds: None,
            own_camera: false,
            warnings: Vec::new(),
            unit: None,
        };
        scene.frame_bare(up);
        scene
    }

    /// Points the camera at the geometry from the front-left and above, as seen with `up`
    /// pointing up, far enough that the bounding sphere fits the narrower field of view,
    /// and puts the one light above and beside the camera.
    pub fn frame_bare(&mut self, up: Axis) {
        let b = self.bounds();
        let (center, radius) = if b.is_empty() {
            (DVec3::ZERO, 1.0)
        } else {
            (b.center(), (0.5 * b.diagonal()).max(f64::MIN_POSITIVE))
        };
        // Distance at which a sphere of this radius fits the field of view: the vertical
        // one, or the horizontal one of a portrait image.
        let c = &self.camera;
        let half_y = c.fov_y.to_radians() * 0.5;
        let half = if c.width >= c.height {
            half_y
        } else {
            (half_y.tan() * c.width as f64 / c.height as f64).atan()
        };
        let distance = radius / half.sin() * 1.1;
        let view = up.from_z_up(DVec3::new(0.35, -1.0, 0.45)).normalize();
        self.camera.eye = center + view * distance;
        self.camera.look_at = center;
        self.camera.up = up.from_z_up(DVec3::Z);
        self.lights = vec![Light::Point {
            position: center + up.from_z_up(DVec3::new(1.0, -1.0, 1.5)).normalize() * distance,
            intensity: Vec3::ONE,
        }];
    }

    pub fn patch_count(&self) -> usize {
        self.objects.iter().map(|o| o.geometry.patch_count()).sum()
    }

    /// The number of trim loops over all surfaces.
    pub fn trim_loop_count(&self) -> usize {
        self.surfaces().map(|s| s.trims.len()).sum()
    }

    /// The same scene with every trim loop removed (`--ignore-trims`: to see what trimming
    /// removes).
    pub fn without_trims(mut self) -> Scene {
        fn strip(g: &mut Geometry) {
            if let Geometry::Surfaces(surfaces) = g {
                surfaces.iter_mut().for_each(|s| s.trims.clear());
            }
        }
        // Each shared geometry once, so its instances keep sharing it.
        let mut stripped: Vec<(*const Geometry, Arc<Geometry>)> = Vec::new();
        for o in &mut self.objects {
            match &mut o.geometry {
                Geometry::Instance(i) => {
                    let key = Arc::as_ptr(&i.geometry);
                    let shared = match stripped.iter().find(|(k, _)| *k == key) {
                        Some((_, g)) => g.clone(),
                        None => {
                            let mut g = (*i.geometry).clone();
                            strip(&mut g);
                            let g = Arc::new(g);
                            stripped.push((key, g.clone()));
                            g
                        }
                    };
                    i.geometry = shared;
                }
                g => strip(g),
            }
        }
        self
    }

    /// Every free-form surface of every object.
    pub fn surfaces(&self) -> impl Iterator<Item = &Surface> {
        self.objects.iter().flat_map(|o| o.geometry.surfaces())
    }
}
