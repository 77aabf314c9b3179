//! `patchtrace bench lg90`: the timing tests of Lischinski & Gonczarowski 1990, §7. The
//! five test cases of Table 1 (generated teapot scenes, uniform grid, §3.1) are rendered
//! with the methods TOTH, ISRT, SCAN, ITBUF and PEANO, and each of Tables 2–6 is printed
//! beside the paper's numbers ([`paper`]), times normalized to TOTH.

pub mod cpu;
pub mod paper;
pub mod report;

use std::path::{Path, PathBuf};

use indicatif::ProgressBar;

use crate::accel::grid::DEFAULT_BUDGET_BYTES;
use crate::accel::scene::SceneGeometry;
use crate::formats::{LoadError, load_scene};
use crate::io::OutputError;
use crate::io::write_atomic;
use crate::kernel::Kernel;
use crate::kernel::cached::{CachedConfig, DEFAULT_MAX_DEPTH};
use crate::kernel::secondary::DEFAULT_ULPS;
use crate::kernel::toth::TothConfig;
use crate::render::integrator::{Integrator, TraceSettings};
use crate::render::order::SampleOrder;
use crate::render::plan::EffectPlan;
use crate::render::renderer::render_image_in_order;
use crate::render::stats::RayReport;
use crate::scene::generate::{TEAPOT_BPT, TeapotsSpec, teapots_scene};
use paper::PaperTable;

/// Seed of every generated test scene: test cases 2–4 are "the same environment" (§7.2),
/// so they share it.
pub const SCENE_SEED: u64 = 1990;

/// Image edge of Table 1 ("resolution 512").
pub const PAPER_SIZE: u32 = 512;

/// One test case of Table 1.
pub struct Case {
    /// Number in the paper, 1–5.
    pub number: usize,
    pub teapots: usize,
    pub reflective: bool,
    pub lights: usize,
    /// "max. ray tree depth" of Table 1.
    pub depth: u32,
    /// The paper's table of this case (Tables 2–6).
    pub table: &'static PaperTable,
}

/// The five test cases of Table 1.
pub const CASES: [Case; 5] = [
    Case {
        number: 1,
        teapots: 1,
        reflective: true,
        lights: 1,
        depth: 5,
        table: &paper::TABLE_2,
    },
    Case {
        number: 2,
        teapots: 50,
        reflective: false,
        lights: 1,
        depth: 1,
        table: &paper::TABLE_3,
    },
    Case {
        number: 3,
        teapots: 50,
        reflective: true,
        lights: 1,
        depth: 5,
        table: &paper::TABLE_4,
    },
    Case {
        number: 4,
        teapots: 50,
        reflective: true,
        lights: 6,
        depth: 5,
        table: &paper::TABLE_5,
    },
    Case {
        number: 5,
        teapots: 100,
        reflective: true,
        lights: 1,
        depth: 5,
        table: &paper::TABLE_6,
    },
];

/// Which intersection kernel a method uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MethodKernel {
    /// Toth's method (§4.1).
    Toth,
    /// Toth's method with the improved secondary rays of §6.
    Isrt,
    /// Cached surface trees (§4.2–4.3).
    Cached,
}

/// One column of Tables 2–6: a kernel and a sampling order.
#[derive(Clone, Copy, Debug)]
pub struct Method {
    pub name: &'static str,
    pub kernel: MethodKernel,
    pub order: SampleOrder,
}

/// The methods of §7.1, in the paper's column order.
pub const METHODS: [Method; 5] = [
    Method {
        name: "TOTH",
        kernel: MethodKernel::Toth,
        order: SampleOrder::Scanline,
    },
    Method {
        name: "ISRT",
        kernel: MethodKernel::Isrt,
        order: SampleOrder::Scanline,
    },
    Method {
        name: "SCAN",
        kernel: MethodKernel::Cached,
        order: SampleOrder::Scanline,
    },
    Method {
        name: "ITBUF",
        kernel: MethodKernel::Cached,
        order: SampleOrder::Itembuffer,
    },
    Method {
        name: "PEANO",
        kernel: MethodKernel::Cached,
        order: SampleOrder::Hilbert,
    },
];

impl Method {
    /// The kernel path this method runs, a cached one with `cache_bytes` per worker; a cached method gets a fresh cache (a new
    /// [`CachedConfig`] empties the workers' caches), so cases do not share trees. The
    /// cached methods include ISRT's treatment of secondary rays, as the paper's do (their
    /// Newton starts per ray equal ISRT's in every table).
    pub fn precision(&self, cache_bytes: usize) -> Kernel {
        let toth = |isrt| {
            Kernel::Toth(TothConfig {
                isrt,
                ..TothConfig::default()
            })
        };
        match self.kernel {
            MethodKernel::Toth => toth(false),
            MethodKernel::Isrt => toth(true),
            MethodKernel::Cached => Kernel::Cached(CachedConfig::new(
                TothConfig {
                    isrt: true,
                    ..TothConfig::default()
                },
                cache_bytes,
                DEFAULT_MAX_DEPTH,
            )),
        }
    }

    /// The method named `name` (case-insensitive).
    pub fn by_name(name: &str) -> Option<Method> {
        METHODS
            .iter()
            .find(|m| m.name.eq_ignore_ascii_case(name))
            .copied()
    }
}

/// What to run.
pub struct Config {
    /// Surface-tree cache of the cached methods per worker thread, in bytes.
    pub cache_bytes: usize,
    /// Image edge (the paper's is [`PAPER_SIZE`]).
    pub size: u32,
    /// Case numbers, 1–5.
    pub cases: Vec<usize>,
    pub methods: Vec<Method>,
    /// Directory for the generated scenes.
    pub scene_dir: PathBuf,
}

/// One method's run on one case.
pub struct Run {
    pub method: Method,
    pub report: RayReport,
    /// Render seconds, excluding scene loading and grid building (as in §7.1): CPU
    /// seconds of all threads when `cpu`, else wall-clock ([`cpu::Stopwatch`]).
    pub seconds: f64,
    pub cpu: bool,
}

/// All runs of one case.
pub struct CaseResult {
    pub case: &'static Case,
    pub size: u32,
    pub patches: usize,
    pub runs: Vec<Run>,
}

/// Writes the generated scene of `case` at `size`² into `dir`, returning its path.
pub fn write_case_scene(case: &Case, size: u32, dir: &Path) -> Result<PathBuf, OutputError> {
    std::fs::create_dir_all(dir).map_err(|e| OutputError::io(dir, e))?;
    let bpt = dir.join("teapot.bpt");
    write_atomic(&bpt, |w| w.write_all(TEAPOT_BPT.as_bytes()))?;
    let spec = TeapotsSpec {
        count: case.teapots,
        seed: SCENE_SEED,
        reflective: case.reflective,
        lights: case.lights,
        width: size,
        height: size,
        // LG90's grid has no instances: each teapot its own copy, as in their tests.
        flatten: true,
    };
    let path = dir.join(format!("lg90-case{}.ron", case.number));
    write_atomic(&path, |w| w.write_all(teapots_scene(&spec).as_bytes()))?;
    Ok(path)
}

/// Writing a case's scene or reading it back failed.
#[derive(Debug, thiserror::Error)]
pub enum CaseError {
    #[error(transparent)]
    Write(#[from] OutputError),
    #[error(transparent)]
    Load(#[from] LoadError),
}

/// Renders every selected case with every selected method on the current rayon pool.
/// `progress` advances once per render.
pub fn run(config: &Config, progress: &ProgressBar) -> Result<Vec<CaseResult>, CaseError> {
    progress.set_length((config.cases.len() * config.methods.len()) as u64);
    let mut results = Vec::new();
    for case in CASES.iter().filter(|c| config.cases.contains(&c.number)) {
        let path = write_case_scene(case, config.size, &config.scene_dir)?;
        let mut scene = load_scene(&path)?;
        scene.max_depth = case.depth;
        let geometry = SceneGeometry::build_grid(&scene, DEFAULT_BUDGET_BYTES);
        let plan = EffectPlan::for_scene(&scene);
        let mut runs = Vec::new();
        for method in &config.methods {
            progress.set_message(format!("case {} {}", case.number, method.name));
            let precision = method.precision(config.cache_bytes);
            let integrator = Integrator {
                scene: &scene,
                geometry: &geometry,
                settings: TraceSettings {
                    precision,
                    ulps: DEFAULT_ULPS,
                    plan,
                },
            };
            let start = cpu::Stopwatch::start();
            let rendered = render_image_in_order(&integrator, method.order, &ProgressBar::hidden());
            let (seconds, cpu) = start.seconds();
            runs.push(Run {
                method: *method,
                report: rendered.tally.report(),
                seconds,
                cpu,
            });
            progress.inc(1);
        }
        results.push(CaseResult {
            case,
            size: config.size,
            patches: geometry.patch_count(),
            runs,
        });
    }
    progress.finish_and_clear();
    Ok(results)
}
