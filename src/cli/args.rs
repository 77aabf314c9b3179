//! The clap definitions of every subcommand. Man pages are generated from these (see
//! `tests/cli/man_pages.rs`), so the help text here is the documentation.

use std::path::PathBuf;

use clap::{Args, Parser, Subcommand};

/// Ray trace Bézier patches and NURBS surfaces directly, to the precision of f32.
#[derive(Debug, Parser)]
#[command(name = "patchtrace", version, about, long_about = None, propagate_version = true)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Debug, Subcommand)]
pub enum Command {
    /// Describe a scene: objects, surfaces, patches, degrees, bounds, materials, lights.
    Info(InfoArgs),
    /// Read any supported input and write a RON scene, a .bpt file or OBJ free-form.
    Import(ImportArgs),
    /// Convert NURBS surfaces to Bézier patches exactly (knot insertion) and report counts.
    Convert(ConvertArgs),
    /// Build the BVH of a scene and write it, with the prepared patches where the scene
    /// has only untrimmed Bézier patches of the fast paths, to a file that `render --bvh`
    /// maps.
    Bvh(BvhArgs),
    /// Render a scene to PNG or EXR.
    Render(RenderArgs),
    /// Nearest hit per ray from a ray file, as CSV.
    Trace(TraceArgs),
    /// Tessellate free-form surfaces into a triangle mesh (OBJ, glTF, GLB or STL); trimmed
    /// ones in their parameter domain, joined along the edges they share, with the gaps
    /// between trimmed faces and the distance from the surfaces to the mesh reported.
    Tessellate(TessellateArgs),
    /// Compare two images (PNG or EXR): RMSE, PSNR, MAE, max error, FLIP, coverage.
    Diff(DiffArgs),
    /// Render the exact surfaces and triangle tessellations of a scene, diff them, and
    /// tabulate accuracy against cost.
    ///
    /// Besides the image metrics, each row gives the surface error: the distance along
    /// each pixel's centre ray between the exact surface's nearest hit and the mesh's,
    /// over the pixels both hit (max, 99th percentile and mean, in model units), drawn as
    /// `<image>-distance.png` scaled to the row's largest. Where a mesh edge covers a pixel
    /// the exact surface leaves to a farther face (an occluding contour, a crack), the
    /// whole depth step counts: the max then measures that step, the mean and percentile
    /// the surface.
    Compare(CompareArgs),
    /// Generate test scenes.
    #[command(subcommand)]
    Scene(SceneCommand),
    /// Measure the kernels: reports as tables.
    #[command(subcommand)]
    Bench(BenchCommand),
    /// Join pieces rendered with `render --tile K/N` or `--crop` into the whole image,
    /// after checking that they come from the same scene and settings and cover the
    /// image exactly once. The result is byte for byte the image rendered in one piece.
    Merge(MergeArgs),
    /// Write a shell completion script to stdout, e.g. `patchtrace completions bash >
    /// /etc/bash_completion.d/patchtrace` or `patchtrace completions zsh >
    /// ~/.zfunc/_patchtrace`.
    Completions(CompletionsArgs),
}

#[derive(Debug, Subcommand)]
pub enum BenchCommand {
    /// Every method against the f64 reference: hit and normal error, holes, false hits,
    /// time per ray and memory, as a table, CSV and a log-log plot with the Pareto front.
    Accuracy(AccuracyArgs),
    /// Numerical stability on hard cases (grazing, tangent and silhouette rays, shared edges,
    /// collapsed and folded patches, extreme scales and weights) against the f64
    /// reference: holes, false hits, self-hits, hit distance, splits and NaN pixels per
    /// kernel path, as a Markdown table on stdout.
    Stability(StabilityArgs),
    /// The timing tests of Lischinski & Gonczarowski 1990 (§7): the five teapot test cases
    /// of Table 1 on the uniform grid, rendered with TOTH, ISRT, SCAN, ITBUF and PEANO;
    /// each of Tables 2–6 printed beside the paper's numbers as Markdown, times normalized
    /// to TOTH.
    Lg90(Lg90Args),
}

#[derive(Debug, Args)]
pub struct Lg90Args {
    /// Image edge in pixels (the paper's is 512); smaller for quick runs.
    #[arg(long, default_value_t = crate::bench::lg90::PAPER_SIZE)]
    pub size: u32,
    /// Test cases to run (1–5, as in Table 1).
    #[arg(long, value_delimiter = ',', default_values_t = [1usize, 2, 3, 4, 5])]
    pub cases: Vec<usize>,
    /// Methods to run: TOTH, ISRT, SCAN, ITBUF, PEANO. Times are normalized to TOTH, so
    /// keep it in the list to get them.
    #[arg(long, value_delimiter = ',', default_values_t = ["TOTH", "ISRT", "SCAN", "ITBUF", "PEANO"].map(String::from))]
    pub methods: Vec<String>,
    /// Directory for the generated test scenes (default: a temporary one, removed after).
    #[arg(long, value_name = "DIR")]
    pub scene_dir: Option<PathBuf>,
    /// Worker threads (default: all cores).
    #[arg(long)]
    pub threads: Option<usize>,
    /// Surface-tree cache of the cached methods (SCAN, ITBUF, PEANO) per worker thread,
    /// in MiB (default: render's, 32). LG90 ran with caches smaller than the trees
    /// (Table 1: 500K–1000K), where the sampling order decides how often trees are
    /// rebuilt.
    #[arg(long, value_name = "MIB")]
    pub cache_size: Option<usize>,
    /// Also write the tables as CSV to this file.
    #[arg(long, value_name = "FILE")]
    pub csv: Option<PathBuf>,
    /// Hide the progress bar.
    #[arg(short, long)]
    pub quiet: bool,
}

#[derive(Debug, Args)]
pub struct StabilityArgs {
    /// Run the full suite (2000 rays per case, 64x64 renders) instead of the reduced one
    /// that `cargo test` runs (48 rays, 16x16).
    #[arg(long)]
    pub full: bool,
    /// Random seed: the same seed gives the same cases and rays.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Also write the table as CSV to this file.
    #[arg(long, value_name = "FILE")]
    pub csv: Option<PathBuf>,
    /// Hide the progress bar.
    #[arg(short, long)]
    pub quiet: bool,
}

#[derive(Debug, Subcommand)]
pub enum SceneCommand {
    /// Randomly scattered Utah teapots (LG90 §7): writes OUT.ron and teapot.bpt beside it.
    Teapots(TeapotsArgs),
}

#[derive(Debug, Args)]
pub struct TeapotsArgs {
    /// Number of teapots (32 bicubic patches each).
    #[arg(long, default_value_t = 50)]
    pub count: usize,
    /// Random seed: the same seed gives the same scene.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Give the teapots a reflective material (reflect 0.3).
    #[arg(long)]
    pub reflective: bool,
    /// Number of point lights.
    #[arg(long, default_value_t = 1)]
    pub lights: usize,
    /// Image width.
    #[arg(long, default_value_t = 512)]
    pub width: u32,
    /// Image height.
    #[arg(long, default_value_t = 512)]
    pub height: u32,
    /// Give every teapot its own copy of the geometry instead of making the others
    /// instances of the first (Dammertz §3.3): a scene of distinct patches.
    #[arg(long)]
    pub flatten: bool,
    /// Output scene (.ron).
    #[arg(short, long)]
    pub output: PathBuf,
}

#[derive(Debug, Args)]
pub struct InfoArgs {
    /// Scene (.ron, .usda, .usdc, .usdz) or bare geometry (.bpt, .obj, .pbrt, .gltf, .glb,
    /// .stl, .igs, .iges, .step, .stp). For IGES and STEP files also the units, what was
    /// not read (by type), surfaces not converted, and the largest error of projected trim
    /// curves.
    pub scene: PathBuf,
    #[command(flatten)]
    pub mesh: MeshArgs,
    /// Print JSON instead of text.
    #[arg(long)]
    pub json: bool,
    /// No progress bars.
    #[arg(short, long)]
    pub quiet: bool,
}

#[derive(Debug, Args)]
pub struct ImportArgs {
    /// Input scene or geometry file (any SCENE input, IGES, STEP and USD included).
    pub input: PathBuf,
    #[command(flatten)]
    pub mesh: MeshArgs,
    /// Output: .ron (scene, geometry inline, NURBS with their trim loops), .bpt
    /// (non-rational untrimmed patches), .obj (free-form Bézier patches with trims) or .igs
    /// (IGES 5.3 trimmed surfaces).
    #[arg(short, long)]
    pub output: PathBuf,
    /// No progress bars.
    #[arg(short, long)]
    pub quiet: bool,
}

#[derive(Debug, Args)]
pub struct ConvertArgs {
    /// Input with NURBS surfaces (.obj, .pbrt, .ron) or any other supported geometry.
    pub input: PathBuf,
    #[command(flatten)]
    pub mesh: MeshArgs,
    /// Output: .obj (free-form Bézier with trims), .igs (IGES 5.3: 128 under 144, mm,
    /// colours), .bpt (non-rational, untrimmed) or .ron.
    #[arg(short, long)]
    pub output: PathBuf,
    /// Print the report as JSON.
    #[arg(long)]
    pub json: bool,
    /// No progress bars.
    #[arg(short, long)]
    pub quiet: bool,
}

/// Intersection kernel.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum KernelChoice {
    /// Dammertz's float-precision subdivision (§2.2–2.3, §2.7).
    Subdivision,
    /// Toth's interval Newton with Krawczyk's operator (Lischinski & Gonczarowski §4.1).
    Toth,
    /// The same tests on regular quadtrees whose surface trees are cached per patch, LRU
    /// (Lischinski & Gonczarowski §4.2–4.3).
    Cached,
}

/// Arithmetic of the kernel.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum PrecisionChoice {
    /// f32, to the precision of f32 itself: the renderer.
    F32,
    /// The same algorithm in f64: the accuracy reference.
    F64,
}

/// Split direction heuristic of the subdivision kernel.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum HeuristicChoice {
    /// Split across the longer parameter direction of the control net (Dammertz §2.3.2).
    Length,
    /// Split by the cross-product heuristic (Dammertz §2.5.2).
    Cross,
}

/// Termination criterion of the subdivision kernel, as `--termination` reads it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TerminationChoice {
    /// `float`: subdivide until the box stops shrinking (Dammertz §2.3.3).
    Float,
    /// `depth:N`: stop after N splits in total (u and v together).
    Depth(u8),
    /// `adaptive`: stop when the box projects below half a pixel (Dammertz §2.5.3).
    Adaptive,
}

impl std::str::FromStr for TerminationChoice {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "float" => Ok(TerminationChoice::Float),
            "adaptive" => Ok(TerminationChoice::Adaptive),
            _ => {
                let n = s
                    .strip_prefix("depth:")
                    .ok_or_else(|| format!("expected float, adaptive or depth:N, found `{s}`"))?;
                match n.parse::<u8>() {
                    Ok(d) if (1..=MAX_DEPTH).contains(&d) => Ok(TerminationChoice::Depth(d)),
                    _ => Err(format!(
                        "depth:N needs N from 1 to {MAX_DEPTH}, found `{n}`"
                    )),
                }
            }
        }
    }
}

/// The deepest `--termination depth:N`: 2 × 32 splits is as far as the `f32` kernel's
/// parameter cells go per direction (`kernel::subdivision::param`).
pub const MAX_DEPTH: u8 = 64;

/// How bare mesh files are read, for every command that takes a scene.
#[derive(Debug, Args, Clone, Default)]
pub struct MeshArgs {
    /// Read a bare mesh file (OBJ polygons, glTF) as the control cage of a subdivision
    /// surface and use its limit surface (boundaries sharp, as OpenSubdiv's EDGE_ONLY).
    /// `trace` then reports as `patch` the quad after the first Catmull–Clark step (cage
    /// face f with n corners gives quads Σ_{g<f} n_g + 0..n, one per corner) and (u, v)
    /// in that quad. In a RON scene write `geometry: Subdivision(File("cage.obj"))`.
    #[arg(long, value_enum, value_name = "SCHEME")]
    pub subdivide: Option<SubdivideChoice>,
    /// USD stages: look through the `Camera` prim at this path (e.g. /World/Cam). Default:
    /// the stage's first camera in namespace order; a stage without one is framed like
    /// bare geometry.
    #[arg(long, value_name = "PRIM_PATH")]
    pub camera: Option<String>,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum SubdivideChoice {
    /// Catmull–Clark (1978), as Dammertz §2.9 ray traces it.
    CatmullClark,
}

impl MeshArgs {
    pub fn load_options(&self) -> crate::formats::LoadOptions {
        crate::formats::LoadOptions {
            subdivide: self.subdivide == Some(SubdivideChoice::CatmullClark),
            camera: self.camera.clone(),
        }
    }
}

/// Options shared by every command that intersects rays.
#[derive(Debug, Args, Clone)]
pub struct KernelArgs {
    /// Intersection kernel.
    #[arg(long, value_enum, default_value_t = KernelChoice::Subdivision)]
    pub kernel: KernelChoice,
    /// Kernel arithmetic: f32 (renderer) or f64 (reference).
    #[arg(long, value_enum, default_value_t = PrecisionChoice::F32)]
    pub precision: PrecisionChoice,
    /// Split direction heuristic.
    #[arg(long, value_enum, default_value_t = HeuristicChoice::Length)]
    pub heuristic: HeuristicChoice,
    /// When the subdivision stops: `float` (default) until the box stops shrinking in the
    /// kernel's float type (Dammertz §2.3.3); `depth:N` after N splits in total, u and v
    /// together (the recursion depth of Dammertz's algorithm 2.2.1), or earlier if the box
    /// stops shrinking; `adaptive` when the box projects below half a pixel of the scene
    /// camera (Dammertz §2.5.3). Adaptive applies to primary rays: render uses float
    /// precision for secondary rays, and trace treats every ray as starting at the camera.
    #[arg(long, value_name = "float|depth:N|adaptive", default_value = "float")]
    pub termination: TerminationChoice,
    /// Mantissa distance (ulps) at which subdivision of rational patches stops
    /// (Dammertz §2.7.2).
    #[arg(long, value_name = "ULPS")]
    pub rational_dist: Option<u32>,
    /// Improved treatment of secondary rays (Lischinski & Gonczarowski §6, the ISRT
    /// column): the three triviality tests on the surface a secondary ray leaves, and
    /// shadow rays stop at the first safe region, without Newton iteration. Only with
    /// `--kernel toth` or `--kernel cached`.
    #[arg(long)]
    pub isrt: bool,
    /// Surface-tree cache of `--kernel cached` per worker thread, in MiB (Lischinski &
    /// Gonczarowski §4.3; default 32). Only with `--kernel cached`.
    #[arg(long, value_name = "MIB")]
    pub cache_size: Option<usize>,
    /// Deepest cached level of the surface trees of `--kernel cached`; deeper boxes are
    /// searched but not kept (Lischinski & Gonczarowski §8; default 6). Only with
    /// `--kernel cached`.
    #[arg(long, value_name = "LEVELS")]
    pub cache_depth: Option<u8>,
    /// Render the surfaces untrimmed: read trim loops and drop them, to see what trimming
    /// removes (the effect line says "trims ignored").
    #[arg(long)]
    pub ignore_trims: bool,
    /// Load the BVH from this file (written by `patchtrace bvh`) instead of building it.
    /// A file that holds the prepared patches is mapped and the scene's geometry files (or
    /// a bare geometry file itself: the file keeps its framing) are not parsed, only
    /// hashed; a file built from other inputs (a geometry file's bytes, a transform,
    /// `--ignore-trims`, `--subdivide`) is refused.
    #[arg(long, value_name = "FILE")]
    pub bvh: Option<PathBuf>,
    /// Acceleration structure over the patches.
    #[arg(long, value_enum, default_value_t = AccelChoice::Bvh)]
    pub accel: AccelChoice,
    /// Memory budget of `--accel grid`, in MiB: voxels are made coarser until the grid
    /// fits (LG90 §3.1).
    #[arg(long, value_name = "MIB", default_value_t = crate::accel::grid::DEFAULT_BUDGET_BYTES >> 20)]
    pub grid_budget: usize,
}

/// Acceleration structure.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum AccelChoice {
    /// SAH bounding volume hierarchy over tight patch boxes (Dammertz §3.2).
    Bvh,
    /// Uniform grid with voxel lists and mailboxes (Lischinski & Gonczarowski 1990, §3.1).
    Grid,
}

#[derive(Debug, Args)]
pub struct RenderArgs {
    /// Scene (.ron, or a USD stage: .usda, .usdc, .usdz) or bare geometry.
    pub scene: PathBuf,
    #[command(flatten)]
    pub mesh: MeshArgs,
    /// Output image: .png (8-bit sRGB) or .exr (linear f32 RGBA).
    #[arg(short, long)]
    pub output: PathBuf,
    #[command(flatten)]
    pub kernel: KernelArgs,
    /// Ulps by which secondary ray origins are moved off the hit box (Dammertz §2.4.2),
    /// at most 4096.
    #[arg(long, default_value_t = crate::kernel::secondary::DEFAULT_ULPS,
          value_parser = clap::value_parser!(u32).range(0..=i64::from(crate::kernel::secondary::MAX_ULPS)))]
    pub ulps: u32,
    #[command(flatten)]
    pub size: ImageSizeArgs,
    /// Worker threads (default: all cores). The image is identical for any count.
    #[arg(long)]
    pub threads: Option<usize>,
    /// Order in which pixels are traced (LG90 §5). The image is identical for any order;
    /// the order matters for kernels that cache work between rays.
    #[arg(long, value_enum, default_value_t = crate::render::order::SampleOrder::Tiles)]
    pub order: crate::render::order::SampleOrder,
    /// Samples per pixel: N (stratified, a deterministic sequence per pixel, so the image
    /// is the same for any threads, order or tiles; 1 is the pixel centre), or
    /// `adaptive[:MAX]`: 4 samples everywhere and up to MAX (default 64) where they
    /// disagree (silhouettes, shadow and reflected edges), with a report of the pixels and
    /// samples used. Default: the scene's `samples`, else 1.
    #[arg(long, value_name = "N|adaptive[:MAX]")]
    pub spp: Option<crate::render::sampler::SampleCount>,
    /// Reconstruction filter of the samples, importance sampled so pixels stay independent.
    #[arg(long, value_enum, default_value_t = crate::render::sampler::Filter::Box)]
    pub filter: crate::render::sampler::Filter,
    /// Render only pixels X0..X1 × Y0..Y1 (upper bounds exclusive): an EXR gets them as its
    /// data window inside the whole image's display window, a PNG holds the window alone.
    /// `patchtrace merge` joins pieces.
    #[arg(long, value_name = "X0,X1,Y0,Y1", conflicts_with = "tile")]
    pub crop: Option<crate::render::window::Window>,
    /// Render the K-th (from 0) of N bands of rows that differ by at most one row, e.g.
    /// `--tile $SLURM_ARRAY_TASK_ID/$SLURM_ARRAY_TASK_COUNT`; `patchtrace merge` joins them.
    #[arg(long, value_name = "K/N")]
    pub tile: Option<crate::render::window::Tile>,
    /// Render this frame of the scene's camera animation (`orbit` or `keyframes`),
    /// from 0. Without an animation every frame is the still camera.
    #[arg(long, value_name = "N", conflicts_with = "frames")]
    pub frame: Option<u32>,
    /// Render frames A to B inclusive, every STEP-th (Blender's `-s A -e B -j STEP`),
    /// each to the output name with its last run of `#` replaced by the zero-padded frame
    /// number (`turn_####.png` → `turn_0007.png`). Frames are deterministic, so ranges can
    /// be split across processes or machines.
    #[arg(long, value_name = "A..B[:STEP]")]
    pub frames: Option<crate::scene::animation::FrameRange>,
    /// Print statistics as JSON on stdout (one document per frame).
    #[arg(long)]
    pub stats: bool,
    /// Extra layers, comma separated, or `all`: depth (`Z`), position (`P.X`, `P.Y`,
    /// `P.Z`), normal (`N.X`, …), uv (`UV.U`, `UV.V`), object and patch (`id.object`,
    /// `id.patch`, u32), effort (de Casteljau splits per pixel, also drawn as
    /// <name>-effort.png, Dammertz Fig. 2.9). They are channels of the output EXR, or of
    /// <name>-aov.exr beside a PNG. Geometric layers come from the pixel's centre ray; a
    /// miss has Z = inf and ids 4294967295.
    #[arg(long, value_enum, value_delimiter = ',', value_name = "LIST|all")]
    pub aov: Vec<Aov>,
    /// No progress bar.
    #[arg(short, long)]
    pub quiet: bool,
}

pub use crate::render::aov::Aov;

#[derive(Debug, Args)]
pub struct MergeArgs {
    /// Pieces rendered with `render --tile K/N` or `--crop`, all EXR or all PNG.
    #[arg(required = true)]
    pub pieces: Vec<PathBuf>,
    /// The whole image: .exr (from EXR pieces, with their AOV layers) or .png.
    #[arg(short, long)]
    pub output: PathBuf,
}

#[derive(Debug, Args)]
pub struct CompletionsArgs {
    /// The shell to write the completion script for.
    #[arg(value_enum)]
    pub shell: clap_complete::Shell,
}

#[derive(Debug, Args)]
pub struct TraceArgs {
    /// Scene (.ron, or a USD stage: .usda, .usdc, .usdz) or bare geometry.
    pub scene: PathBuf,
    #[command(flatten)]
    pub mesh: MeshArgs,
    /// Ray file: `ox oy oz dx dy dz [tmin [tmax]]` per line.
    #[arg(long)]
    pub rays: PathBuf,
    /// Write the CSV here instead of stdout.
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    #[command(flatten)]
    pub kernel: KernelArgs,
    /// Worker threads (default: all cores).
    #[arg(long)]
    pub threads: Option<usize>,
    /// No progress bars.
    #[arg(short, long)]
    pub quiet: bool,
}

#[derive(Debug, Args)]
pub struct BvhArgs {
    /// Scene (.ron, or a USD stage: .usda, .usdc, .usdz) or bare geometry.
    pub scene: PathBuf,
    #[command(flatten)]
    pub mesh: MeshArgs,
    /// Output BVH file.
    #[arg(short, long)]
    pub output: PathBuf,
    /// No progress bars.
    #[arg(short, long)]
    pub quiet: bool,
}

#[derive(Debug, Args)]
#[command(group(clap::ArgGroup::new("mode").args(["triangles_per_patch", "grid", "tolerance"])))]
pub struct TessellateArgs {
    /// Scene (.ron, or a USD stage: .usda, .usdc, .usdz) or bare geometry.
    pub scene: PathBuf,
    #[command(flatten)]
    pub mesh: MeshArgs,
    /// Output mesh: .obj, .gltf (buffer embedded), .glb or .stl (binary, coordinates in
    /// `f32`).
    #[arg(short, long)]
    pub output: PathBuf,
    /// Uniform grid per patch with this many triangles (an even number 2·u·v, e.g. 512,
    /// 4608 or 131072 as in Dammertz Tables 2.1–2.4). The default mode, with 512.
    #[arg(long, value_name = "N")]
    pub triangles_per_patch: Option<u32>,
    /// Uniform grid of U×V quads per patch. A Catmull–Clark cage (`--subdivide`,
    /// `Subdivision(..)`) is sampled per quad after the first step instead, on a square
    /// grid of the larger of U and V (its quads meet turned), at the limit surface.
    #[arg(long, value_name = "U,V", value_parser = parse_grid)]
    pub grid: Option<(u32, u32)>,
    /// Adaptive, crack-free tessellation with this chord-height tolerance (scene units):
    /// patch edges and trim curves are sampled until their chords are within it, and
    /// trimmed faces are refined until the surface is within 4/5 of it at thirteen probes
    /// of every triangle (the largest distance found is reported). Trimmed faces whose trim
    /// curves meet within 10⁻⁴ of the model's size share their samples and vertices there,
    /// so a closed solid's mesh is closed. A trimmed face whose control points say it would
    /// need more than 2^24 triangles (a damaged file, a tolerance far below the model) is
    /// refused before any work. For a Catmull–Clark cage the finest count any quad needs,
    /// on every quad.
    #[arg(long, value_name = "DISTANCE")]
    pub tolerance: Option<f64>,
    /// Print the report as JSON.
    #[arg(long)]
    pub json: bool,
    /// No progress bar.
    #[arg(short, long)]
    pub quiet: bool,
}

fn parse_grid(s: &str) -> Result<(u32, u32), String> {
    let (u, v) = s.split_once(',').ok_or("expected U,V such as 16,16")?;
    let p = |x: &str| {
        x.trim()
            .parse::<u32>()
            .map_err(|_| format!("expected a whole number, found `{x}`"))
    };
    Ok((p(u)?, p(v)?))
}
/// What a heat map shows.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum HeatmapChoice {
    /// The FLIP error map (perceptual, 0 to 1).
    Flip,
    /// The largest channel's absolute error, 0 to 1, in the space of the metrics.
    Abs,
}

#[derive(Debug, Args)]
pub struct DiffArgs {
    /// Reference image (.png or .exr).
    pub a: PathBuf,
    /// Test image (.png or .exr), the same size as A.
    pub b: PathBuf,
    /// A pixel counts toward `above` when its largest channel error exceeds this (values in
    /// [0, 1]: sRGB-encoded when both images are PNG, linear clamped to [0, 1] otherwise).
    #[arg(long, default_value_t = crate::diff::DEFAULT_THRESHOLD)]
    pub threshold: f64,
    /// Write the per-pixel error, colour-mapped (magma) above a 0-to-1 legend, as PNG.
    #[arg(long, value_name = "OUT.png")]
    pub heatmap: Option<PathBuf>,
    /// Error shown by the heat map.
    #[arg(long, value_enum, default_value_t = HeatmapChoice::Flip)]
    pub heatmap_metric: HeatmapChoice,
    /// Exit with status 1 when METRIC is greater than VALUE (repeatable). Metrics: rmse,
    /// mae, max, above (share of pixels, 0 to 1), coverage (pixels), flip-mean,
    /// flip-median, flip-max.
    #[arg(long, value_name = "METRIC=VALUE")]
    pub fail_above: Vec<crate::diff::Limit>,
    /// Print JSON instead of a table (PSNR of identical images is the string "inf").
    #[arg(long)]
    pub json: bool,
}

#[derive(Debug, Args)]
pub struct CompareArgs {
    /// Scene (.ron, or a USD stage: .usda, .usdc, .usdz) or bare geometry.
    pub scene: PathBuf,
    #[command(flatten)]
    pub mesh: MeshArgs,
    /// Triangles per patch of each tessellation to compare (even counts 2·u·v). Default
    /// 512,4608,131072 when neither --tolerance nor --against is given.
    #[arg(long, value_delimiter = ',')]
    pub triangles: Vec<u32>,
    /// Chord-height tolerances of adaptive, crack-free tessellations to compare, as CAD
    /// systems tessellate: a plain number is a fraction of the model's size (its bounding
    /// box diagonal), a number ending in `mm` an absolute length in millimetres when the
    /// scene declares its unit (CAD files, USD stages' metersPerUnit), else in scene
    /// units. Example: 0.01,0.001,0.05mm.
    #[arg(long, value_delimiter = ',', value_parser = parse_tolerance)]
    pub tolerance: Vec<Tolerance>,
    /// Meshes to compare with the direct render (.stl, .obj, .gltf, .glb), such as the one
    /// a CAD system exported for the same model, in the scene's coordinates. Each is
    /// rendered with the scene's camera and lights and one material, against the direct
    /// render with that same material.
    #[arg(long, value_delimiter = ',', value_name = "MESH")]
    pub against: Vec<PathBuf>,
    /// Directory for the images, FLIP and surface-error heat maps and the table (created
    /// if missing).
    #[arg(long, default_value = "compare-out")]
    pub out_dir: PathBuf,
    #[command(flatten)]
    pub size: ImageSizeArgs,
    /// Worker threads (default: all cores).
    #[arg(long)]
    pub threads: Option<usize>,
    /// No progress bars.
    #[arg(short, long)]
    pub quiet: bool,
}

#[derive(Debug, Args)]
pub struct AccuracyArgs {
    /// Scene (.ron, or a USD stage: .usda, .usdc, .usdz) or bare geometry.
    pub scene: PathBuf,
    #[command(flatten)]
    pub mesh: MeshArgs,
    /// Trace these rays (`ox oy oz dx dy dz [tmin [tmax]]` per line) instead of the
    /// camera's primary rays.
    #[arg(long)]
    pub rays: Option<PathBuf>,
    /// Trace an N×N image of camera rays instead of the camera's own size.
    #[arg(long, value_name = "N")]
    pub size: Option<u32>,
    /// Depths (total splits) of the fixed-depth rows.
    #[arg(long, value_delimiter = ',', default_values_t = crate::bench::accuracy::DEFAULT_DEPTHS)]
    pub depths: Vec<u8>,
    /// Mantissa distances (ulps) of the rational-dist rows (Dammertz Table 2.12); only run
    /// when the scene has rational patches.
    #[arg(long, value_delimiter = ',', default_values_t = crate::bench::accuracy::DEFAULT_DISTS)]
    pub dists: Vec<u32>,
    /// Triangles per patch of the tessellated methods.
    #[arg(long, value_delimiter = ',', default_values_t = crate::bench::accuracy::DEFAULT_TRIANGLES)]
    pub triangles: Vec<u32>,
    /// Directory for accuracy.md, accuracy.csv, accuracy.svg and accuracy.png.
    #[arg(long, default_value = "bench-out")]
    pub out_dir: PathBuf,
    /// Print the results as JSON instead of a table.
    #[arg(long)]
    pub json: bool,
    /// No progress messages.
    #[arg(short, long)]
    pub quiet: bool,
}

/// Overrides of the scene camera's image size, and of the up axis bare geometry is framed
/// with.
#[derive(Debug, Args, Clone, Copy)]
pub struct ImageSizeArgs {
    /// Bare geometry only: the axis that points up in the model, for the default camera
    /// (default: y for glTF, by its specification; z otherwise). In a RON scene, give the
    /// object `up: Y` instead.
    #[arg(long, value_enum)]
    pub up: Option<crate::scene::model::Axis>,
    /// Override the camera's image width (1 to 32768; a render holds at most 2^26 pixels).
    #[arg(long, value_parser = image_edge())]
    pub width: Option<u32>,
    /// Override the camera's image height (1 to 32768; a render holds at most 2^26 pixels).
    #[arg(long, value_parser = image_edge())]
    pub height: Option<u32>,
}

fn image_edge() -> clap::builder::RangedI64ValueParser<u32> {
    clap::value_parser!(u32).range(1..=i64::from(crate::scene::MAX_IMAGE_EDGE))
}

impl ImageSizeArgs {
    /// Applies the overrides to the scene read from `path`, refusing an edge beyond
    /// [`MAX_IMAGE_EDGE`](crate::scene::MAX_IMAGE_EDGE); bare geometry is framed again for
    /// the new size and `--up`.
    pub fn apply(
        &self,
        path: &std::path::Path,
        scene: &mut crate::scene::Scene,
    ) -> anyhow::Result<()> {
        let camera = &mut scene.camera;
        camera.width = self.width.unwrap_or(camera.width);
        camera.height = self.height.unwrap_or(camera.height);
        camera
            .check_size()
            .map_err(|e| crate::cli::BadArgument(format!("--width/--height: {e}")))?;
        crate::formats::load::reframe(path, scene, self.up)?;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn termination_values_parse_and_bad_ones_are_refused() {
        let parse = |s: &str| s.parse::<TerminationChoice>();
        assert_eq!(parse("float"), Ok(TerminationChoice::Float));
        assert_eq!(parse("adaptive"), Ok(TerminationChoice::Adaptive));
        assert_eq!(parse("depth:12"), Ok(TerminationChoice::Depth(12)));
        assert_eq!(parse("depth:64"), Ok(TerminationChoice::Depth(MAX_DEPTH)));
        for bad in ["depth:0", "depth:65", "depth:", "depth:x", "fixed", ""] {
            assert!(parse(bad).is_err(), "{bad} accepted");
        }
    }
}

/// A chord-height tolerance for `compare --tolerance`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Tolerance {
    /// A fraction of the model's bounding box diagonal.
    Relative(f64),
    /// A length in millimetres (scene units when the scene declares no unit).
    Absolute(f64),
}

fn parse_tolerance(s: &str) -> Result<Tolerance, String> {
    let (number, make): (&str, fn(f64) -> Tolerance) = match s.strip_suffix("mm") {
        Some(n) => (n.trim_end(), Tolerance::Absolute),
        None => (s, Tolerance::Relative),
    };
    match number.parse::<f64>() {
        Ok(x) if x.is_finite() && x > 0.0 => Ok(make(x)),
        _ => Err(format!(
            "expected a positive number (a fraction of the model's size) or a length such as 0.05mm, found `{s}`"
        )),
    }
}
