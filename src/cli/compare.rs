//! `patchtrace compare SCENE --triangles 512,4608,131072 --tolerance 0.001,0.05mm --against
//! MESH`: the direct render against triangle tessellations of the same scene (Dammertz
//! Fig. 2.1/2.2, Tables 2.1–2.4) by triangles per patch or by chord height, and against
//! meshes made elsewhere (a CAD system's STL export), as one table of cost and error, with
//! the images and heat maps written to `--out-dir`.

use std::fmt::Write as _;
use std::io::Write;
use std::path::Path;
use std::process::ExitCode;
use std::time::Instant;

use anyhow::Context;

use crate::bench::accuracy::patch_memory;
use crate::cli::args::{CompareArgs, Tolerance};
use crate::cli::setup::{build_bvh, load, tessellate, thread_pool};
use crate::diff::{DiffOptions, Image, diff_images};
use crate::formats::LoadError;
use crate::formats::load::load_geometry;
use crate::io::write_atomic;
use crate::kernel::Kernel;
use crate::kernel::secondary::DEFAULT_ULPS;
use crate::kernel::subdivision::SubdivisionConfig;
use crate::render::film::Film;
use crate::render::heatmap::heat_map;
use crate::render::integrator::{Integrator, TraceSettings};
use crate::render::order::SampleOrder;
use crate::render::plan::EffectPlan;
use crate::render::renderer::{RenderJob, render as render_job};
use crate::scene::{Geometry, Object, Scene, TriangleMesh};
use crate::tessellate::{TessellationMode, TessellationReport};

/// One line of the table.
struct Row {
    method: String,
    triangles: u64,
    memory_bytes: u64,
    build_seconds: f64,
    render_seconds: f64,
    rmse: f64,
    psnr: f64,
    flip_mean: f64,
    silhouette_pixels: u64,
    /// The largest gap between trimmed faces (tessellations only).
    trim_gap: Option<f64>,
    /// How far the mesh lies from the exact surface along the pixels' centre rays.
    surface_error: SurfaceError,
}

/// Distances along each pixel's centre ray between the exact surface's nearest hit and the
/// mesh's, over the pixels where both hit (pixels where only one does are the silhouette
/// count): the geometric error a viewer of the image sees, in model units.
#[derive(Clone, Copy, Default)]
struct SurfaceError {
    max: f64,
    p99: f64,
    mean: f64,
}

impl SurfaceError {
    /// The distances per pixel (`None` where either misses) and their summary.
    fn between(exact: &[Option<f64>], mesh: &[Option<f64>]) -> (Vec<Option<f64>>, SurfaceError) {
        let per_pixel: Vec<Option<f64>> = exact
            .iter()
            .zip(mesh)
            .map(|(a, b)| Some((a.as_ref()? - b.as_ref()?).abs()))
            .collect();
        let mut d: Vec<f64> = per_pixel.iter().flatten().copied().collect();
        if d.is_empty() {
            return (per_pixel, SurfaceError::default());
        }
        d.sort_by(f64::total_cmp);
        let p99 = d[((d.len() - 1) as f64 * 0.99).round() as usize];
        let mean = d.iter().sum::<f64>() / d.len() as f64;
        let summary = SurfaceError {
            max: d[d.len() - 1],
            p99,
            mean,
        };
        (per_pixel, summary)
    }
}

/// A render, its centre rays' hit distances (`None` for a miss), and the seconds spent
/// building the accelerator and rendering.
struct Rendering {
    film: Film,
    depth: Vec<Option<f64>>,
    build: f64,
    seconds: f64,
}

/// Builds the accelerator and renders, timing both.
fn render(scene: &Scene, quiet: bool, label: &str, pool: &rayon::ThreadPool) -> Rendering {
    let start = Instant::now();
    let geometry = build_bvh(scene, quiet);
    let build = start.elapsed().as_secs_f64();
    let integrator = Integrator {
        scene,
        geometry: &geometry,
        settings: TraceSettings {
            precision: Kernel::F32(SubdivisionConfig::default()),
            ulps: DEFAULT_ULPS,
            plan: EffectPlan::for_scene(scene),
        },
    };
    let bar = crate::progress::bar(quiet, label);
    let start = Instant::now();
    let job = RenderJob {
        hits: true,
        ..RenderJob::whole(&scene.camera, SampleOrder::default())
    };
    let rendered = pool.install(|| render_job(&integrator, &job, &bar));
    Rendering {
        film: rendered.film,
        depth: rendered.hits.iter().map(|h| h.map(|h| h.hit.t)).collect(),
        build,
        seconds: start.elapsed().as_secs_f64(),
    }
}

pub fn run(args: CompareArgs) -> anyhow::Result<ExitCode> {
    let pool = thread_pool(args.threads)?;
    let mut scene = load(&args.scene, &args.mesh, args.quiet)?;
    args.size.apply(&args.scene, &mut scene)?;
    // Direct and tessellated renders both at the scene's floating origin: the images, the
    // only outputs, are the same in either frame. Meshes given with --against move too.
    let origin = scene.floating_origin();
    scene.translate(-origin);
    crate::scene::check_film_pixels(scene.camera.width, scene.camera.height)
        .map_err(crate::cli::BadArgument)?;
    std::fs::create_dir_all(&args.out_dir)
        .with_context(|| format!("creating {}", args.out_dir.display()))?;
    if !args.quiet {
        eprintln!("{}", EffectPlan::for_scene(&scene));
    }

    let direct = render(&scene, args.quiet, "direct", &pool);
    direct.film.write(&args.out_dir.join("direct.png"))?;
    let reference = Image::from_film(&direct.film);
    let mut rows = vec![Row {
        method: "direct (f32 subdivision)".into(),
        triangles: 0,
        memory_bytes: patch_memory(&scene),
        build_seconds: direct.build,
        render_seconds: direct.seconds,
        rmse: 0.0,
        psnr: f64::INFINITY,
        flip_mean: 0.0,
        silhouette_pixels: 0,
        trim_gap: None,
        surface_error: SurfaceError::default(),
    }];

    let triangles =
        if args.triangles.is_empty() && args.tolerance.is_empty() && args.against.is_empty() {
            crate::bench::accuracy::DEFAULT_TRIANGLES.to_vec()
        } else {
            args.triangles.clone()
        };
    let size = scene.bounds().diagonal();
    let modes = triangles
        .iter()
        .map(|&n| {
            (
                format!("{n} triangles/patch"),
                (format!("tess{n}"), format!("flip{n}")),
                TessellationMode::TrianglesPerPatch(n),
            )
        })
        .chain(args.tolerance.iter().map(|t| {
            let (label, tolerance) = match *t {
                Tolerance::Relative(f) => (format!("chord {f} of the size"), f * size),
                // Millimetres in the scene's units, when it declares them.
                Tolerance::Absolute(d) => (
                    format!("chord {d} mm"),
                    d / scene.unit.as_ref().map_or(1.0, |u| u.millimetres),
                ),
            };
            let name = format!("chord{tolerance:.3e}");
            let names = (name.clone(), format!("flip-{name}"));
            (label, names, TessellationMode::Adaptive { tolerance })
        }));
    for (label, names, mode) in modes {
        let start = Instant::now();
        let (meshes, report) =
            tessellate(&scene, mode, args.quiet, &format!("tessellating, {label}"))?;
        let tessellate_seconds = start.elapsed().as_secs_f64();
        let against = Against {
            reference: &reference,
            depth: &direct.depth,
            out_dir: &args.out_dir,
            quiet: args.quiet,
            pool: &pool,
        };
        let mut row = against.row(&meshes, &label, &names)?;
        row.triangles = report.triangles;
        row.memory_bytes = report.bytes;
        row.build_seconds += tessellate_seconds;
        row.trim_gap = (report.trim_gaps.faces > 0).then_some(report.trim_gaps.largest);
        rows.push(row);
    }

    if !args.against.is_empty() {
        // External meshes carry no materials: both sides are rendered with one.
        let plain = one_material(&scene);
        let direct = render(&plain, args.quiet, "direct, one material", &pool);
        direct.film.write(&args.out_dir.join("direct-plain.png"))?;
        let reference = Image::from_film(&direct.film);
        let against = Against {
            reference: &reference,
            depth: &direct.depth,
            out_dir: &args.out_dir,
            quiet: args.quiet,
            pool: &pool,
        };
        for (k, path) in args.against.iter().enumerate() {
            let mesh = match load_geometry(path)? {
                Geometry::Mesh(m) => m,
                _ => {
                    return Err(LoadError::invalid(
                        path,
                        "--against takes a triangle mesh (.stl, .obj of faces, .gltf, .glb)",
                    )
                    .into());
                }
            };
            let (meshes, report) = with_mesh(&plain, mesh, origin);
            let label = path.file_name().map_or_else(
                || path.display().to_string(),
                |n| n.to_string_lossy().into_owned(),
            );
            let names = (format!("against{k}"), format!("flip-against{k}"));
            let mut row = against.row(&meshes, &label, &names)?;
            row.triangles = report.triangles;
            row.memory_bytes = report.bytes;
            rows.push(row);
        }
    }

    let markdown = markdown_table(&rows);
    let csv = csv_table(&rows);
    write_text(&args.out_dir.join("compare.md"), &markdown)?;
    write_text(&args.out_dir.join("compare.csv"), &csv)?;
    let mut out = std::io::stdout().lock();
    writeln!(out, "{markdown}")?;
    writeln!(out, "{csv}")?;
    if !args.quiet {
        eprintln!(
            "images, FLIP heat maps and the table are in {}",
            args.out_dir.display()
        );
    }
    Ok(ExitCode::SUCCESS)
}

/// What every compared render is measured against, and where its files go.
struct Against<'a> {
    reference: &'a Image,
    /// The direct render's centre-ray hit distances.
    depth: &'a [Option<f64>],
    out_dir: &'a Path,
    quiet: bool,
    pool: &'a rayon::ThreadPool,
}

impl Against<'_> {
    /// Renders `meshes`, writes the image, its FLIP heat map and the heat map of its
    /// surface error (scaled to the row's largest) as `<image>.png`, `<heat>.png` and
    /// `<image>-distance.png`, and returns its row (triangle counts and memory for the
    /// caller to fill in).
    fn row(
        &self,
        meshes: &Scene,
        label: &str,
        (image, heat): &(String, String),
    ) -> anyhow::Result<Row> {
        let mesh = render(meshes, self.quiet, label, self.pool);
        mesh.film
            .write(&self.out_dir.join(format!("{image}.png")))?;
        let d = diff_images(
            self.reference,
            &Image::from_film(&mesh.film),
            DiffOptions::default(),
        )?;
        heat_map(&d.maps.flip, d.width, d.height)
            .write_png(&self.out_dir.join(format!("{heat}.png")))?;
        let (per_pixel, surface_error) = SurfaceError::between(self.depth, &mesh.depth);
        let scale = if surface_error.max > 0.0 {
            surface_error.max
        } else {
            1.0
        };
        let shades: Vec<f32> = per_pixel
            .iter()
            .map(|e| e.map_or(0.0, |e| (e / scale) as f32))
            .collect();
        heat_map(&shades, d.width, d.height)
            .write_png(&self.out_dir.join(format!("{image}-distance.png")))?;
        Ok(Row {
            method: label.to_string(),
            triangles: 0,
            memory_bytes: 0,
            build_seconds: mesh.build,
            render_seconds: mesh.seconds,
            rmse: d.rmse,
            psnr: d.psnr,
            flip_mean: d.flip.mean,
            silhouette_pixels: d.coverage_mismatch.unwrap_or(0),
            trim_gap: None,
            surface_error,
        })
    }
}

/// `scene` with every object given its first material, so that it compares with a mesh
/// that has none.
fn one_material(scene: &Scene) -> Scene {
    let mut plain = scene.clone();
    for o in &mut plain.objects {
        o.material = 0;
    }
    plain
}

/// `scene`'s camera, lights and materials with `mesh` (in world space, moved by minus the
/// scene's floating `origin`) as its one object, and the mesh's counts.
fn with_mesh(
    scene: &Scene,
    mut mesh: TriangleMesh,
    origin: glam::DVec3,
) -> (Scene, TessellationReport) {
    mesh.transform(&glam::DAffine3::from_translation(-origin));
    let report = TessellationReport::of(&mesh);
    let mut s = scene.clone();
    s.objects = vec![Object {
        name: "mesh".into(),
        material: 0,
        geometry: Geometry::Mesh(mesh),
    }];
    (s, report)
}

fn write_text(path: &Path, text: &str) -> anyhow::Result<()> {
    write_atomic(path, |w| w.write_all(text.as_bytes()))?;
    Ok(())
}

const COLUMNS: [&str; 13] = [
    "method",
    "triangles",
    "memory (bytes)",
    "build (s)",
    "render (s)",
    "RMSE",
    "PSNR (dB)",
    "FLIP mean",
    "silhouette pixels",
    "trim gap",
    "surface error max",
    "surface error p99",
    "surface error mean",
];

fn cells(r: &Row) -> [String; 13] {
    [
        r.method.clone(),
        r.triangles.to_string(),
        r.memory_bytes.to_string(),
        format!("{:.3}", r.build_seconds),
        format!("{:.3}", r.render_seconds),
        format!("{:.6}", r.rmse),
        if r.psnr.is_finite() {
            format!("{:.2}", r.psnr)
        } else {
            "inf".into()
        },
        format!("{:.5}", r.flip_mean),
        r.silhouette_pixels.to_string(),
        r.trim_gap.map_or("-".into(), |g| format!("{g:.3e}")),
        format!("{:.3e}", r.surface_error.max),
        format!("{:.3e}", r.surface_error.p99),
        format!("{:.3e}", r.surface_error.mean),
    ]
}

fn markdown_table(rows: &[Row]) -> String {
    let mut s = format!(
        "| {} |\n|{}\n",
        COLUMNS.join(" | "),
        "---|".repeat(COLUMNS.len())
    );
    for r in rows {
        let _ = writeln!(s, "| {} |", cells(r).join(" | "));
    }
    s
}

fn csv_table(rows: &[Row]) -> String {
    let mut s = COLUMNS.join(",") + "\n";
    for r in rows {
        let _ = writeln!(s, "{}", cells(r).join(","));
    }
    s
}
