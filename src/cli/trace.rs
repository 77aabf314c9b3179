//! `patchtrace trace SCENE --rays FILE`: the nearest hit per ray as CSV (DESIGN.md
//! contract: `ray,hit,t,object,patch,u,v,px,py,pz,nx,ny,nz`).

use std::io::Write;
use std::process::ExitCode;

use glam::DVec3;
use rayon::prelude::*;

use crate::accel::scene::{QueryStats, SceneGeometry, SceneHit};
use crate::cli::args::TraceArgs;
use crate::cli::setup::{precision, prepare, thread_pool};
use crate::formats::LoadError;
use crate::formats::rays::{RayChunks, RayQuery};
use crate::geom::Ray;
use crate::io::write_atomic;
use crate::kernel::Kernel;
use crate::scene::Scene;

/// The header line of the contract.
pub const TRACE_HEADER: &str = "ray,hit,t,object,patch,u,v,px,py,pz,nx,ny,nz";

/// Rays traced per chunk: the file is read, traced and written a chunk at a time, in
/// order, so memory stays at one chunk of rays and rows (a few MB) for any file size.
/// 2^16 rays keep both workers of a small machine busy between chunk boundaries.
pub const CHUNK_RAYS: usize = 1 << 16;

pub fn run(args: TraceArgs) -> anyhow::Result<ExitCode> {
    let file = std::fs::File::open(&args.rays).map_err(|e| LoadError::io(&args.rays, e))?;
    let mut rays = RayChunks::new(&args.rays, std::io::BufReader::new(file));
    let prepared = prepare(&args.scene, &args.mesh, &args.kernel, args.quiet, &|_| {
        Ok(())
    })?;
    let precision = precision(&args.kernel, &prepared.scene.camera)?;
    let pool = thread_pool(args.threads)?;
    // A bad line found mid-file stops the output; the error is kept here because the
    // writer can only return an io::Error.
    let mut failed: Option<LoadError> = None;
    let mut write = |w: &mut dyn Write| -> std::io::Result<()> {
        writeln!(w, "{TRACE_HEADER}")?;
        let mut first = 0;
        loop {
            let chunk = match rays.next_chunk(CHUNK_RAYS) {
                Ok(c) if c.is_empty() => break,
                Ok(c) => c,
                Err(e) => {
                    failed = Some(e);
                    return Err(std::io::Error::other("bad ray file"));
                }
            };
            let rows: Vec<String> = pool.install(|| {
                chunk
                    .par_iter()
                    .enumerate()
                    .map(|(i, q)| {
                        let hit = trace_one(&prepared.geometry, q, prepared.origin, &precision)
                            .map(|(h, o, d)| (in_contract_terms(&prepared.scene, h), o, d));
                        row(first + i, hit)
                    })
                    .collect()
            });
            for r in &rows {
                writeln!(w, "{r}")?;
            }
            first += chunk.len();
        }
        w.flush()
    };
    let result = match &args.output {
        Some(path) => write_atomic(path, &mut write).map_err(anyhow::Error::from),
        None => write(&mut std::io::stdout().lock()).map_err(anyhow::Error::from),
    };
    if let Some(e) = failed {
        return Err(e.into());
    }
    result?;
    Ok(ExitCode::SUCCESS)
}

/// Intersects one query with `geometry`, which is the scene moved by minus `origin` (the
/// floating origin, [`crate::scene::origin`]): the ray's origin is moved in `f64`, then the
/// `f32` path rounds the ray once to `f32`; the `f64` path uses it as moved. Returns the
/// hit and the world origin and direction the hit point refers to.
fn trace_one(
    geometry: &SceneGeometry,
    q: &RayQuery,
    origin: DVec3,
    precision: &Kernel,
) -> Option<(SceneHit, DVec3, DVec3)> {
    let mut stats = QueryStats::default();
    let moved = q.origin - origin;
    match precision {
        Kernel::F32(_) | Kernel::Toth(_) | Kernel::Cached(_) => {
            let ray = Ray {
                origin: moved.as_vec3(),
                dir: q.dir.as_vec3(),
                tmin: q.tmin as f32,
                tmax: q.tmax as f32,
            };
            let hit = geometry.intersect(&ray, precision, &mut stats)?;
            Some((hit, ray.origin.as_dvec3() + origin, ray.dir.as_dvec3()))
        }
        Kernel::F64(cfg) => {
            let hit = geometry.intersect_f64(moved, q.dir, q.tmin, q.tmax, cfg, &mut stats)?;
            Some((hit, moved + origin, q.dir))
        }
    }
}

/// The hit with the patch and (u, v) the contract reports: for a subdivision surface the
/// quad after the first Catmull–Clark step ([`crate::scene::Object::trace_patch`]).
fn in_contract_terms(scene: &Scene, mut hit: SceneHit) -> SceneHit {
    if let Some(object) = scene.objects.get(hit.object as usize) {
        (hit.patch, hit.u, hit.v) = object.trace_patch(hit.patch, hit.u, hit.v);
    }
    hit
}

fn row(index: usize, hit: Option<(SceneHit, DVec3, DVec3)>) -> String {
    match hit {
        None => format!("{index},0,,,,,,,,,,,"),
        Some((h, o, d)) => {
            let p = o + d * h.t;
            let n = h.normal;
            format!(
                "{index},1,{},{},{},{},{},{},{},{},{},{},{}",
                h.t, h.object, h.patch, h.u, h.v, p.x, p.y, p.z, n.x, n.y, n.z
            )
        }
    }
}
