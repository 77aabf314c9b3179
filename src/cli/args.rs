//! The clap definitions of every subcommand. Man pages are generated from these (see
//! `tests/man_pages.rs`), so the help text here is the documentation.

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
}

#[derive(Debug, Args)]
pub struct InfoArgs {
    /// Scene (.ron) or bare geometry (.bpt, .obj, .pbrt, .gltf, .glb).
    pub scene: PathBuf,
    /// Print JSON instead of text.
    #[arg(long)]
    pub json: bool,
}

#[derive(Debug, Args)]
pub struct ImportArgs {
    /// Input scene or geometry file.
    pub input: PathBuf,
    /// Output: .ron (scene, geometry inline), .bpt (non-rational patches) or .obj
    /// (free-form Bézier patches).
    #[arg(short, long)]
    pub output: PathBuf,
}

#[derive(Debug, Args)]
pub struct ConvertArgs {
    /// Input with NURBS surfaces (.obj, .pbrt, .ron) or any other supported geometry.
    pub input: PathBuf,
    /// Output: .obj (free-form Bézier), .bpt (non-rational only) or .ron.
    #[arg(short, long)]
    pub output: PathBuf,
    /// Print the report as JSON.
    #[arg(long)]
    pub json: bool,
}
