//! The `gtsphere` command: command-line arguments (clap), the subcommands, progress bars and
//! plots, over the `gtsphere` library. Raw arguments are turned into library options here; the
//! library never sees clap (see `gtsphere --help`).

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};

use gtsphere::error::Error;

mod bench;
#[cfg(test)]
mod cli_docs;
mod compare;
mod convert_csv;
mod convert_vrml;
mod info;
mod load_args;
mod memory;
mod merge;
mod occlusion;
mod render;
mod signals;
mod threads;

#[derive(Debug, Parser)]
#[command(
    name = "gtsphere",
    version,
    about = "Ground-truth renderer for particle data drawn as spheres"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Read a VRML97 scene and report what it holds: spheres, other surfaces, materials,
    /// lights, viewpoints, skipped nodes, bounds, memory, parse speed, notes and every warning.
    Info {
        /// Scene file (.wrl, .wrz, .wrl.gz; gzip is detected by content).
        scene: PathBuf,
        /// Print one JSON object instead of text.
        #[arg(long)]
        json: bool,
        /// Turn every warning of the reader into an error.
        #[arg(long)]
        strict: bool,
        /// Do not read other files (Inline nodes, EXTERNPROTO files).
        #[arg(long)]
        no_inline: bool,
        #[command(flatten)]
        geometry: load_args::GeometryArgs,
    },
    /// Render a scene to an image (.png, .exr, .pfm or .npy).
    Render(render::RenderArgs),
    /// Each sphere's ambient occlusion, the mean unoccluded fraction over its surface (the
    /// value per particle that OVITO and QuteMol shade with), integrated to --tol from the
    /// exact AO of its surface points, written as a table (.csv or .npy).
    Occlusion(occlusion::OcclusionArgs),
    /// Compare an image with a reference (PNG, EXR, PFM or NPY): RMSE, relative RMSE, PSNR, the
    /// largest error and where it is; optionally a false-colour heat map of the error.
    Compare {
        /// The image to judge (for example a real-time renderer's output).
        image: PathBuf,
        /// The reference (for example `gtsphere render`'s output).
        reference: PathBuf,
        /// Write the per-pixel error (largest over R, G, B) in false colour, above a legend
        /// strip, to this image (.png, .exr, .pfm or .npy).
        #[arg(long)]
        heatmap: Option<PathBuf>,
        /// The error at the top of the heat map's colour scale (default: the largest error).
        #[arg(long, requires = "heatmap")]
        heatmap_max: Option<f64>,
        /// Exit with code 1 when the RMSE exceeds this.
        #[arg(long)]
        max_rmse: Option<f64>,
    },
    /// Convert a particle table (CSV, TSV, white-space columns, XYZ; gzip is detected) to
    /// VRML97, or write a VRML97 scene back out as the renderer sees it (flattened to world
    /// coordinates, materials DEF'd once, DirectionalLight scopes kept).
    ///
    /// Particle columns are found by header name: x, y, z; radius or r (or diameter);
    /// red, green, blue or r, g, b (0-1 floats or 0-255 integers); optional density (or
    /// sigma), opacity or transparency; emission or emission_red/green/blue; element (a van
    /// der Waals radius and CPK colour where the table gives none); profile and width (a gas
    /// sphere's density profile). Other names are mapped with --columns. Bad rows stop the
    /// conversion with `file:LINE:FIELD: message` and no output file (--skip-bad skips them).
    Convert(convert_csv::ConvertArgs),
    /// Assemble the parts of a picture rendered with `render --region` or `--tile` (EXR) into
    /// the whole; every pixel must come from exactly one part.
    Merge {
        /// The parts (.exr).
        #[arg(required = true)]
        parts: Vec<PathBuf>,
        /// The whole picture (.png, .exr, .pfm or .npy).
        #[arg(short, long)]
        output: PathBuf,
    },
    /// Benchmarks. Without a subcommand: time against error of every integrator on built-in
    /// scenes, written to `--out` as bench.csv, bench.md (also printed) and bench.png.
    #[command(args_conflicts_with_subcommands = true)]
    Bench {
        #[command(subcommand)]
        what: Option<bench::BenchCommand>,
        #[command(flatten)]
        report: bench::report::ReportArgs,
    },
}

fn run(cli: Cli) -> Result<ExitCode, Error> {
    match cli.command {
        Command::Info {
            scene,
            json,
            strict,
            no_inline,
            geometry,
        } => info::run(&scene, json, strict, no_inline, &geometry),
        Command::Render(args) => render::run(&args),
        Command::Occlusion(args) => occlusion::run(&args),
        Command::Compare {
            image,
            reference,
            heatmap,
            heatmap_max,
            max_rmse,
        } => compare::run(&image, &reference, heatmap.as_ref(), heatmap_max, max_rmse),
        Command::Merge { parts, output } => merge::run(&parts, &output),
        Command::Convert(args) => convert_csv::run(&args),
        Command::Bench {
            what: Some(what), ..
        } => bench::run(what),
        Command::Bench { what: None, report } => bench::report::run(&report),
    }
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    if let Err(e) = signals::install() {
        eprintln!("cannot watch for SIGINT and SIGTERM: {e}");
        return ExitCode::from(1);
    }
    match run(cli) {
        Ok(code) => code,
        Err(e) => {
            let code = signals::exit_code_for(&e);
            eprintln!("{e}");
            code
        }
    }
}
