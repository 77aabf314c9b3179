//! Catmull–Clark cages against their Bézier patches (speed item): OpenSubdiv's
//! `catmark_torus` (all regular) as a cage, the same surface as the Bézier patches
//! `patchtrace import torus.obj --subdivide catmull-clark -o torus_bez.bpt` writes (written
//! and read back here the same way), and `catmark_cube` (every quad at a valence-3 vertex,
//! refined at load time) as a cage. Each is rendered whole (Whitted, the default light,
//! one sample per pixel) at 512² on one thread, and its camera rays are traced alone for
//! the per-ray counters. Runs are interleaved (torus cage, torus Bézier, cube, repeated) so
//! that the other load on a shared machine falls on all three alike; times are the median
//! on-CPU seconds of the rendering thread (`/proc/thread-self/schedstat`), not wall time.
//!
//! `cargo bench --bench subdiv` (release profile). The load average is printed before and
//! after.

use std::path::{Path, PathBuf};
use std::time::Instant;

use patchtrace::accel::scene::{QueryStats, SceneGeometry};
use patchtrace::formats::write::write_scene_as;
use patchtrace::formats::{LoadOptions, load_scene_with};
use patchtrace::geom::Ray;
use patchtrace::kernel::Kernel;
use patchtrace::kernel::secondary::DEFAULT_ULPS;
use patchtrace::kernel::subdivision::SubdivisionConfig;
use patchtrace::progress::ProgressBar;
use patchtrace::render::camera::CameraRays;
use patchtrace::render::integrator::{Integrator, TraceSettings};
use patchtrace::render::plan::EffectPlan;
use patchtrace::render::renderer::render_image;
use patchtrace::scene::Scene;

const RUNS: usize = 5;
const SIZE: u32 = 512;

/// Seconds this thread has run on a CPU (Linux `/proc/thread-self/schedstat`, first field
/// in ns), or `None` elsewhere.
fn cpu_seconds() -> Option<f64> {
    let s = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
    Some(s.split_whitespace().next()?.parse::<f64>().ok()? * 1e-9)
}

/// On-CPU seconds of `f` on the current thread (wall seconds where unavailable).
fn timed<T>(f: impl FnOnce() -> T) -> (T, f64) {
    let (start, cpu) = (Instant::now(), cpu_seconds());
    let out = f();
    let wall = start.elapsed().as_secs_f64();
    (out, cpu_seconds().zip(cpu).map_or(wall, |(b, a)| b - a))
}

fn load_average() -> String {
    std::fs::read_to_string("/proc/loadavg")
        .map(|s| s.split_whitespace().take(3).collect::<Vec<_>>().join(" "))
        .unwrap_or_else(|_| "unknown".into())
}

struct Case {
    name: &'static str,
    scene: Scene,
    geometry: SceneGeometry,
    rays: Vec<Ray>,
    render: Vec<f64>,
    trace: Vec<f64>,
    stats: QueryStats,
}

impl Case {
    fn new(name: &'static str, scene: Scene) -> Case {
        let geometry = SceneGeometry::build(&scene);
        let cam = CameraRays::new(&scene.camera);
        let rays = (0..SIZE)
            .flat_map(|y| (0..SIZE).map(move |x| (x, y)))
            .map(|(x, y)| cam.ray(x, y))
            .collect();
        Case {
            name,
            scene,
            geometry,
            rays,
            render: Vec::new(),
            trace: Vec::new(),
            stats: QueryStats::default(),
        }
    }

    /// One render and one pass of the camera rays alone, each timed on the one thread
    /// of `pool`.
    fn run(&mut self, pool: &rayon::ThreadPool, precision: Kernel) {
        let integrator = Integrator {
            scene: &self.scene,
            geometry: &self.geometry,
            settings: TraceSettings {
                precision,
                ulps: DEFAULT_ULPS,
                plan: EffectPlan::for_scene(&self.scene),
            },
        };
        let (_, render) =
            pool.install(|| timed(|| render_image(&integrator, &ProgressBar::hidden())));
        self.render.push(render);
        let mut stats = QueryStats::default();
        let (_, trace) = timed(|| {
            for r in &self.rays {
                std::hint::black_box(self.geometry.intersect(r, &precision, &mut stats));
            }
        });
        self.trace.push(trace);
        self.stats = stats;
    }
}

fn median(v: &[f64]) -> f64 {
    let mut v = v.to_vec();
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("testdata/opensubdiv");
    let cage = |file: &str| {
        let mut s = load_scene_with(
            &data.join(file),
            LoadOptions {
                subdivide: true,
                ..LoadOptions::default()
            },
        )
        .unwrap_or_else(|e| panic!("{file}: {e}"));
        s.camera.width = SIZE;
        s.camera.height = SIZE;
        s
    };
    let torus = cage("catmark_torus.obj");
    // `import --subdivide catmull-clark -o torus_bez.bpt`, then the .bpt read as any
    // bare patch file, seen by the cage's camera.
    let dir = tempfile::tempdir().expect("a temporary directory");
    let bpt: PathBuf = dir.path().join("torus_bez.bpt");
    write_scene_as(&bpt, &torus).expect("writing the .bpt");
    let mut torus_bez = load_scene_with(&bpt, LoadOptions::default()).expect("reading it back");
    torus_bez.camera = torus.camera.clone();
    torus_bez.lights = torus.lights.clone();
    let mut cases = [
        Case::new("torus cage", torus),
        Case::new("torus as Bézier .bpt", torus_bez),
        Case::new("cube cage", cage("catmark_cube.obj")),
    ];
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("a one-thread pool");
    let precision = Kernel::F32(SubdivisionConfig::default());
    println!("load average before: {}", load_average());
    // A warm-up round, then RUNS interleaved rounds.
    for round in 0..=RUNS {
        for c in &mut cases {
            c.run(&pool, precision);
            if round == 0 {
                c.render.clear();
                c.trace.clear();
            }
        }
    }
    println!("load average after: {}", load_average());
    println!(
        "{SIZE}x{SIZE}, 1 thread, median of {RUNS} interleaved runs (on-CPU seconds of the thread)"
    );
    println!(
        "| scene | patches | render s | render runs | camera rays µs/ray | splits/ray | patch tests/ray | splits/patch test |"
    );
    println!("|---|---|---|---|---|---|---|---|");
    for c in &cases {
        let n = c.rays.len() as f64;
        let k = &c.stats.kernel;
        let runs: Vec<String> = c.render.iter().map(|s| format!("{s:.3}")).collect();
        println!(
            "| {} | {} | {:.3} | {} | {:.2} | {:.2} | {:.3} | {:.1} |",
            c.name,
            c.geometry.patch_count(),
            median(&c.render),
            runs.join(", "),
            median(&c.trace) / n * 1e6,
            k.splits as f64 / n,
            k.patch_tests as f64 / n,
            k.splits as f64 / k.patch_tests.max(1) as f64,
        );
    }
    let ratio = median(&cases[0].render) / median(&cases[1].render);
    println!("torus cage / torus Bézier render time: {ratio:.3} (done-when: <= 1.1)");
}
