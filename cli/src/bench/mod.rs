//! `gtsphere bench` and its subcommands: one module per measurement, and the shared
//! measuring in [`measure`]. The scenes come from the library ([`gtsphere::bench::scenes`]), so that
//! `cargo bench` and the tests use the same ones.
//!
//! Dependency order: each module uses only the ones below it (and the library), never the
//! reverse, so there is no import cycle.
//!
//! ```text
//! mod (BenchCommand, dispatch)
//!  |-- parse     bench parse    (runs `gtsphere info --json` in child processes)
//!  |-- trace     bench trace
//!  |-- convert   bench convert
//!  |-- scale     bench scale    (convert's table, then `gtsphere render --stats` children)
//!  |-- gas       bench gas ------------------.
//!  `-- report    bench (no subcommand)       |
//!       |-- plot   bench.png ----------------|
//!       `-------------------------------- measure (Case, BenchScene, Row, measure,
//!                                            relative errors, table, summary, median)
//! (parse, trace and convert use measure::median; trace and convert also the command
//! line's memory::peak_rss_bytes, a leaf.)
//! ```

use std::path::PathBuf;
use std::process::ExitCode;

use clap::Subcommand;

use gtsphere::error::Error;

pub mod convert;
pub mod gas;
pub mod measure;
pub mod parse;
pub mod plot;
pub mod report;
pub mod scale;
pub mod trace;

#[derive(Debug, Subcommand)]
pub enum BenchCommand {
    /// Reading speed (MB/s) and peak memory on files of N particles (generated, converted
    /// from tables, or copies of a tool's export), by one reader and on several threads.
    Parse(parse::ParseArgs),
    /// BVH build time, camera and shadow rays per second per core, and peak memory on N random
    /// opaque spheres (centres uniform in a cube, radius 0.6 N^(-1/3), a PointLight and a
    /// DirectionalLight).
    Trace {
        /// Number of spheres.
        #[arg(long, default_value_t = 1_000_000)]
        spheres: usize,
        /// Image width and height in pixels (one ray through each pixel centre).
        #[arg(long, default_value_t = 1024)]
        size: u32,
        /// Runs (the median is reported).
        #[arg(long, default_value_t = 3)]
        runs: usize,
        /// Threads for the full-render pass (the ray passes use one thread).
        #[arg(long, default_value_t = 1)]
        threads: usize,
        /// Give every sphere a diffuse colour of its own (six decimals, as a colour map
        /// writes), instead of one colour for all.
        #[arg(long)]
        colour_per_sphere: bool,
    },
    /// `gtsphere convert` speed (rows/s, MB/s, one core) and peak memory on a generated
    /// particle CSV of N rows (x, y, z, radius, red, green, blue as 0-255).
    Convert {
        /// Number of rows.
        #[arg(long, default_value_t = 10_000_000)]
        rows: usize,
        /// Runs (the median is reported).
        #[arg(long, default_value_t = 3)]
        runs: usize,
        /// Where the generated table goes (kept for reuse). Default: the system temp folder.
        #[arg(long)]
        dir: Option<PathBuf>,
    },
    /// Lit gas: time against error of the gas integrators (exact, march, mc) on a lit gas
    /// scene; with --scaling, how exact's cost per ray grows with N on gas clouds, against
    /// march at equal error; with `--write DIR`, those clouds as .wrl files.
    Gas(gas::GasArgs),
    /// The whole path at growing N: a generated particle table converted to VRML, then
    /// `gtsphere render` of it (--size pixels square, 1 spp, shadows) in a child process:
    /// read, build and render seconds, particles read per second, and the command's peak
    /// memory per sphere. Files are kept in --dir and reused.
    Scale {
        /// Particle counts, comma-separated; 1e6 or 1000000.
        #[arg(long, value_delimiter = ',', value_parser = gas::parse_count, default_values_t = [1_000_000, 10_000_000])]
        sizes: Vec<usize>,
        /// Image width and height in pixels.
        #[arg(long, default_value_t = 512)]
        size: u32,
        /// Threads of the render command.
        #[arg(long, default_value_t = 1)]
        threads: usize,
        /// Where the generated files go (kept for reuse). Default: the system temp folder.
        #[arg(long)]
        dir: Option<PathBuf>,
    },
}

pub fn run(cmd: BenchCommand) -> Result<ExitCode, Error> {
    match cmd {
        BenchCommand::Parse(args) => parse::run(&args),
        BenchCommand::Trace {
            spheres,
            size,
            runs,
            threads,
            colour_per_sphere,
        } => trace::run(spheres, size, runs, threads, colour_per_sphere),
        BenchCommand::Gas(args) => gas::run(&args),
        BenchCommand::Convert { rows, runs, dir } => convert::run(rows, runs, dir),
        BenchCommand::Scale {
            sizes,
            size,
            threads,
            dir,
        } => scale::run(&sizes, size, threads, dir),
    }
}
