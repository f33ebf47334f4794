//! `gtsphere occlusion`: each sphere's mean unoccluded fraction over its surface, as a table.

use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

use clap::Args;
use gtsphere::error::Error;
use gtsphere::output::write_table;
use gtsphere::render::particle_ao::{check_tol, particles_ao};
use gtsphere::render::{prepare, PrepareOptions};
use gtsphere::vrml::LoadOptions;

use crate::render::ao::WeightingArg;
use crate::render::progress::{TileBar, Words};

#[derive(Debug, Args)]
pub struct OcclusionArgs {
    /// Scene file (.wrl, .wrz, .wrl.gz).
    pub scene: PathBuf,
    /// The table: .csv (a header line, then one line per sphere) or .npy (an N x 7 float64
    /// array). Columns: index (the sphere's place in the scene, file order), x, y, z, radius,
    /// ao (the mean unoccluded fraction over its surface), error (its estimated absolute
    /// error).
    #[arg(short, long)]
    pub output: PathBuf,
    /// The distance within which an occluder occludes (world units; default: any distance).
    #[arg(long, value_name = "D", allow_negative_numbers = true)]
    pub ao_reach: Option<f64>,
    /// How directions of the hemisphere are weighted.
    #[arg(long, value_enum, default_value_t = WeightingArg::Cosine)]
    pub ao_weighting: WeightingArg,
    /// Target absolute error of each sphere's mean.
    #[arg(long, default_value_t = 1e-3)]
    pub tol: f64,
    /// Worker threads (default: one per core; more than four per core are lowered to that,
    /// with a warning).
    #[arg(long)]
    pub threads: Option<usize>,
    /// Print nothing but errors.
    #[arg(long, short)]
    pub quiet: bool,
    #[command(flatten)]
    pub geometry: crate::load_args::GeometryArgs,
}

pub fn run(args: &OcclusionArgs) -> Result<ExitCode, Error> {
    let t0 = Instant::now();
    let say = |m: String| {
        if !args.quiet {
            eprintln!("{m}");
        }
    };
    let bad = |m: String| Error::Other(m);
    // The library's rule, in the command line's words.
    check_tol(args.tol)
        .map_err(|_| bad(format!("--tol must be between 0 and 1 (got {})", args.tol)))?;
    let reach = crate::render::ao::reach_of(args.ao_reach).map_err(bad)?;
    let weighting = args.ao_weighting.weighting();
    let (threads, warning) = crate::threads::option(args.threads)?;
    if let Some(w) = warning {
        say(w);
    }
    let threads = threads.unwrap_or(0);
    // The table's format is checked before the work.
    match args.output.extension().and_then(|e| e.to_str()) {
        Some(e) if e.eq_ignore_ascii_case("csv") || e.eq_ignore_ascii_case("npy") => {}
        _ => {
            return Err(bad(format!(
                "{}: the table must be .csv or .npy",
                args.output.display()
            )))
        }
    }
    let load = LoadOptions {
        read_threads: threads,
        ..LoadOptions::default()
    };
    let (scene, _) = args.geometry.load(&args.scene, load, say)?;
    let in_scene = |e: Error| Error::Other(format!("{}: {e}", args.scene.display()));
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| Error::Other(format!("cannot start worker threads: {e}")))?;
    let prep = pool
        .install(|| prepare(scene, &PrepareOptions::default()))
        .map_err(in_scene)?;
    // Copies in one place are integrated once (the bar counts those integrated).
    let copies = match prep.copies_dropped() {
        0 => String::new(),
        n => format!(" ({n} coincident copies take the value of the sphere they repeat)"),
    };
    say(format!(
        "{} spheres{copies}; mean AO over each surface to {:e}, reach {}",
        prep.spheres,
        args.tol,
        if reach.is_finite() {
            format!("{reach}")
        } else {
            "unlimited".into()
        }
    ));
    let bar = TileBar::counting(
        !args.quiet,
        Words {
            unit: "spheres",
            doing: "integrating",
            done: "integrated",
        },
    );
    let ao = pool
        .install(|| particles_ao(&prep, (reach, weighting), args.tol, &bar))
        .map_err(in_scene)?;
    // The spheres in the scene's order, as the means are.
    let spheres = prep.scene_spheres();
    let rows: Vec<Vec<f64>> = spheres
        .iter()
        .zip(&ao)
        .enumerate()
        .map(|(k, (&(c, r), a))| vec![k as f64, c.x, c.y, c.z, r, a.mean, a.error])
        .collect();
    write_table(
        &args.output,
        &["index", "x", "y", "z", "radius", "ao", "error"],
        &rows,
    )?;
    let points: u64 = ao.iter().map(|a| a.points).sum();
    let worst = ao.iter().map(|a| a.error).fold(0.0, f64::max);
    say(format!(
        "wrote {} ({} spheres, {points} surface points, largest error estimate {worst:.1e}) in {:.2} s",
        args.output.display(),
        spheres.len(),
        t0.elapsed().as_secs_f64()
    ));
    Ok(ExitCode::SUCCESS)
}
