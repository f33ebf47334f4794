//! `gtsphere bench gas`: two measurements on lit gas.
//!
//! **Time against error** (the default): the three gas integrators on a lit gas
//! scene of N gas spheres at S x S pixels, one ray (or, for mc, `spp` paths) through each
//! pixel centre, so that only the integration error is measured, against a reference
//! rendered by `exact` at a tolerance 1000 times tighter than the tightest one measured.
//! The measuring is `gtsphere bench`'s ([`super::measure`]), on this one scene.
//!
//! Scene: [`gtsphere::bench::scenes::lit_gas`].
//!
//! **Scaling** (`--scaling`): how the exact integrator's cost per camera
//! ray grows with N, on the clouds [`gtsphere::bench::scenes::cloud`] at N = 1e3 ... 1e6, and what `march` needs for
//! the same error. See [`run_scaling`] for what is measured.
//! `--write DIR` writes the clouds as VRML, for timing a whole `gtsphere render` and for
//! benches/povray/.

use std::fmt::Write as _;
use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Args, ValueEnum};

use super::measure::{median, relative_rms, run_scene, summary, table, BenchScene, Case};
use gtsphere::bench::scenes::{cloud, lit_gas, Cloud};
use gtsphere::error::Error;
use gtsphere::render::{
    prepare, render, Aovs, Counters, Integrator, PrepareOptions, RenderOptions, SamplerKind,
};
use gtsphere::scene::Scene;

/// The time-against-error sweep on [`lit_gas`].
pub fn run_tradeoff(n: usize, size: u32, threads: usize) -> Result<ExitCode, Error> {
    if n == 0 || size == 0 || threads == 0 {
        return Err(Error::Other(
            "--spheres, --size and --threads must be positive".into(),
        ));
    }
    let threads = crate::threads::capped(threads);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| Error::Other(format!("cannot start worker threads: {e}")))?;
    let tightest = 1e-6;
    let mut cases: Vec<Case> = [1e-2, 1e-3, 1e-4, 1e-5, tightest]
        .into_iter()
        .map(Case::exact)
        .collect();
    cases.extend((0..7).map(|k| Case::march(0.2 / 4f64.powi(k))));
    cases.extend([4, 16, 64, 256].into_iter().map(Case::mc));
    let s = BenchScene {
        name: "lit gas",
        description: format!("{n} gas spheres, {size}x{size}, {threads} threads"),
        scene: lit_gas(n),
        size,
        reference: Case::exact(tightest * 1e-3),
        cases,
    };
    let (rows, ref_s) = pool.install(|| run_scene(&s, threads, |_| {}))?;
    println!(
        "reference: exact at tol {:e}, {ref_s:.1} s; {}\n",
        tightest * 1e-3,
        s.description
    );
    println!("{}", table(&rows));
    print!("{}", summary(&rows));
    Ok(ExitCode::SUCCESS)
}

/// `gtsphere bench gas`'s arguments.
#[derive(Debug, Args)]
pub struct GasArgs {
    /// Measure the scaling table on the clouds (cloud-N, thick and thin) instead of the
    /// time-against-error sweep.
    #[arg(long)]
    pub scaling: bool,
    /// With --scaling: N = 1e3 and 1e4 only, 32 x 32 pixels, march budget 2 s (a smoke test).
    #[arg(long, requires = "scaling")]
    pub quick: bool,
    /// Number of gas spheres of the time-against-error sweep.
    #[arg(long, default_value_t = 1000, conflicts_with = "scaling")]
    pub spheres: usize,
    /// Image width and height in pixels, one ray (or mc paths) through each pixel centre
    /// [default: 256; with --scaling 128, with --quick 32].
    #[arg(long)]
    pub size: Option<u32>,
    /// Worker threads [default: 2; with --scaling 1, so that rays/s are per core].
    #[arg(long)]
    pub threads: Option<usize>,
    /// Cloud sizes N for --scaling and --write, comma-separated; 1e6 or 1000000
    /// [default: 1e3,1e4,1e5,1e6; with --quick 1e3,1e4].
    #[arg(long, value_delimiter = ',', value_parser = parse_count)]
    pub sizes: Vec<usize>,
    /// Which clouds, for --scaling and --write.
    #[arg(long, value_enum, value_delimiter = ',', default_values_t = [CloudArg::Thick, CloudArg::Thin])]
    pub clouds: Vec<CloudArg>,
    /// Runs of each exact render at the default tol, the median time is reported
    /// [default: 3 for N <= 1e4, 1 above].
    #[arg(long)]
    pub runs: Option<usize>,
    /// With --scaling, seconds: march's step sweep stops when its next step would take longer
    /// than this, and the time it would need is projected [default: 120; with --quick 2]. The
    /// time-against-error sweep runs every step.
    #[arg(long)]
    pub march_budget: Option<f64>,
    /// With --scaling: give every cloud sphere this density profile, `NAME[:WIDTH]` as for
    /// `render --profile` (the same transparency, so the same diameter transmittance).
    #[arg(long, requires = "scaling", value_parser = crate::render::parse_profile)]
    pub profile: Option<gtsphere::scene::Profile>,
    /// Write the clouds as DIR/cloud-{thick,thin}-N.wrl (for --sizes and --clouds) and exit
    /// without measuring.
    #[arg(long, value_name = "DIR", conflicts_with = "scaling")]
    pub write: Option<PathBuf>,
}

/// `--clouds`: the two clouds of the scaling table ([`Cloud`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum CloudArg {
    /// Optical depth 4 along a diameter (transparency exp(-4)).
    Thick,
    /// Transparency 0.9 (optical depth 0.105 along a diameter).
    Thin,
}

impl From<CloudArg> for Cloud {
    fn from(a: CloudArg) -> Self {
        match a {
            CloudArg::Thick => Cloud::Thick,
            CloudArg::Thin => Cloud::Thin,
        }
    }
}

/// A count written as an integer or in exponent form (`1e6`).
pub fn parse_count(s: &str) -> Result<usize, String> {
    match s.parse::<usize>() {
        Ok(n) if n > 0 => return Ok(n),
        Ok(_) => return Err("0 is not a positive count".into()),
        Err(_) => {}
    }
    match s.parse::<f64>() {
        Ok(v) if v >= 1.0 && v.fract() == 0.0 && v <= 1e12 => Ok(v as usize),
        _ => Err(format!("'{s}' is not a positive whole number")),
    }
}

/// `--write DIR`: the clouds as VRML files.
fn write_clouds(dir: &std::path::Path, sizes: &[usize], clouds: &[CloudArg]) -> Result<(), Error> {
    std::fs::create_dir_all(dir).map_err(|e| Error::Io {
        path: dir.display().to_string(),
        source: e,
    })?;
    for &n in sizes {
        for &c in clouds {
            let c = Cloud::from(c);
            let path = dir.join(format!("cloud-{}-{n}.wrl", c.name()));
            gtsphere::vrml::write_scene_file(&path, &cloud(n, c))?;
            eprintln!("wrote {}", path.display());
        }
    }
    Ok(())
}

/// One render of a cloud, repeated `runs` times.
struct Shot {
    /// The pixels in f64, row by row.
    rgb: Vec<[f64; 3]>,
    /// The error AOV (the pixel's estimated absolute error), row by row; empty unless asked.
    error: Vec<f64>,
    /// Median wall time of the tile loop and the lights' grids, and the grids' (last run).
    seconds: f64,
    grid_seconds: f64,
    runs: usize,
    counters: Counters,
}

fn shoot(
    scene: &Scene,
    size: u32,
    integrator: Integrator,
    tol: f64,
    runs: usize,
    error_aov: bool,
) -> Result<Shot, Error> {
    let opts = RenderOptions {
        width: size,
        height: size,
        spp: 1,
        sampler: SamplerKind::Center,
        integrator,
        tol,
        aovs: Aovs {
            error: error_aov,
            ..Aovs::default()
        },
        ..RenderOptions::default()
    };
    let prep = prepare(scene.clone(), &PrepareOptions::default())?;
    let camera = prep.default_camera(size, size)?;
    let mut times = Vec::new();
    loop {
        let done = render(&prep, &camera, &opts, &())?;
        times.push(done.seconds);
        let grid_seconds = done.grid_seconds;
        if times.len() >= runs.max(1) {
            let error = done.error.unwrap_or_default();
            return Ok(Shot {
                rgb: done.rgb,
                error,
                runs: times.len(),
                seconds: median(times),
                grid_seconds,
                counters: done.counters,
            });
        }
    }
}

/// How the reported per-pixel error compares with the true one: the fraction of pixels
/// whose reported error is at least `max_c |pixel_c - reference_c|`, and the median of
/// reported / true over the pixels with a true error above 0.
pub fn error_coverage(img: &[[f64; 3]], reported: &[f64], reference: &[[f64; 3]]) -> (f64, f64) {
    let mut covered = 0usize;
    let mut ratios = Vec::new();
    for ((a, b), &e) in img.iter().zip(reference).zip(reported) {
        let truth = (0..3).map(|k| (a[k] - b[k]).abs()).fold(0.0, f64::max);
        covered += usize::from(e >= truth);
        if truth > 0.0 {
            ratios.push(e / truth);
        }
    }
    let frac = covered as f64 / img.len().max(1) as f64;
    let med = if ratios.is_empty() {
        f64::NAN
    } else {
        median(ratios)
    };
    (frac, med)
}

/// What march needs for a target error.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MarchNeed {
    /// The step, measured or projected.
    pub step: f64,
    /// Its render time (seconds), measured or projected.
    pub seconds: f64,
    /// Projected from the last two steps rather than measured.
    pub extrapolated: bool,
}

/// March's step and time for relative RMS `target`, from the steps measured so far
/// (`(step, rel_rms, seconds)`, coarsest first), if the last two allow a projection: the
/// error's order in the step from the last two (O(h) expected; it must be positive), the
/// time's growth as `h^-q` with q from the last two but at least 1 (march's work per ray is
/// proportional to 1 / h; at coarse steps fixed costs hide that).
pub fn march_projection(points: &[(f64, f64, f64)], target: f64) -> Option<MarchNeed> {
    let [.., (h1, e1, t1), (h2, e2, t2)] = points else {
        return None;
    };
    let order = (e1 / e2).ln() / (h1 / h2).ln();
    if !(order.is_finite() && order > 0.0) {
        return None;
    }
    let q = ((t2 / t1).ln() / (h1 / h2).ln()).max(1.0);
    let q = if q.is_finite() { q } else { 1.0 };
    let step = h2 * (target / e2).powf(1.0 / order);
    Some(MarchNeed {
        step,
        seconds: t2 * (h2 / step).powf(q),
        extrapolated: true,
    })
}

/// Steps `0.2 / 4^k` until march's relative RMS is at most `target`, or until the next step's
/// projected time exceeds `budget` (then the projection, [`march_projection`]).
fn march_to(
    scene: &Scene,
    size: u32,
    reference: &[[f64; 3]],
    target: f64,
    budget: f64,
) -> Result<Option<MarchNeed>, Error> {
    let mut points: Vec<(f64, f64, f64)> = Vec::new();
    for k in 0..12 {
        let step = 0.2 / 4f64.powi(k);
        let m = shoot(scene, size, Integrator::March { step }, 0.0, 1, false)?;
        let err = relative_rms(&m.rgb, reference);
        eprintln!(
            "    march step {step:.3e}: {:.3} s, rel. RMS {err:.2e}",
            m.seconds
        );
        if err <= target {
            return Ok(Some(MarchNeed {
                step,
                seconds: m.seconds,
                extrapolated: false,
            }));
        }
        points.push((step, err, m.seconds));
        if points.len() >= 2 {
            let next = march_projection(&points, target);
            let [.., (h1, _, t1), (h2, _, t2)] = points.as_slice() else {
                unreachable!()
            };
            let q = ((t2 / t1).ln() / (h1 / h2).ln()).max(1.0);
            let next_seconds = t2 * 4f64.powf(if q.is_finite() { q } else { 1.0 });
            if next.is_none() || next_seconds > budget {
                return Ok(next);
            }
        }
    }
    Ok(march_projection(&points, target))
}

/// One row of the scaling table.
#[derive(Clone, Debug)]
pub struct ScalingRow {
    pub n: usize,
    pub cloud: Cloud,
    /// Median render time of exact at the default tol (the lights' grids included), and the
    /// grids' build time.
    pub seconds: f64,
    pub grid_seconds: f64,
    pub runs: usize,
    pub counters: Counters,
    /// Relative RMS error against exact at the reference tol.
    pub rel_rms: f64,
    /// Fraction of pixels whose reported error covers the true error; median reported/true.
    pub covered: f64,
    pub ratio: f64,
    /// Reference render time.
    pub ref_seconds: f64,
    pub march: Option<MarchNeed>,
}

impl ScalingRow {
    pub fn seconds_per_ray(&self) -> f64 {
        self.seconds / self.counters.camera_rays.max(1) as f64
    }
    /// Time per shadowing sphere gathered: what a ray's light paths meet.
    pub fn seconds_per_shadower(&self) -> f64 {
        self.seconds / self.counters.shadow_candidates.max(1) as f64
    }
    fn per_ray(&self, v: u64) -> f64 {
        v as f64 / self.counters.camera_rays.max(1) as f64
    }
}

/// The default tol of `gtsphere render` and the reference's.
pub const DEFAULT_TOL: f64 = 1e-4;
pub const REFERENCE_TOL: f64 = 1e-8;

/// The scaling table (Markdown).
pub fn scaling_table(rows: &[ScalingRow]) -> String {
    let mut t = String::from(
        "| N | cloud | seconds | of which light grids | runs | camera rays/s | quadrature nodes / ray | shadowing spheres / ray | us / shadowing sphere | rel. RMS error | pixels whose reported error covers the true one | median reported / true | reference s | march step for that error | march seconds | march / exact |\n\
         |---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n",
    );
    for r in rows {
        let (step, ms, ratio) = match r.march {
            Some(m) => {
                let tilde = if m.extrapolated { "~" } else { "" };
                let note = if m.extrapolated {
                    " (extrapolated)"
                } else {
                    ""
                };
                (
                    format!("{tilde}{:.2e}", m.step),
                    format!("{tilde}{:.3}{note}", m.seconds),
                    format!("{tilde}{:.1}x", m.seconds / r.seconds),
                )
            }
            None => ("not reached".into(), "-".into(), "-".into()),
        };
        let _ = writeln!(
            t,
            "| {} | {} | {:.3} | {:.3} | {} | {:.3e} | {:.1} | {:.1} | {:.2} | {:.2e} | {:.1}% | {:.3} | {:.2} | {step} | {ms} | {ratio} |",
            r.n,
            r.cloud.name(),
            r.seconds,
            r.grid_seconds,
            r.runs,
            r.counters.camera_rays as f64 / r.seconds,
            r.per_ray(r.counters.quadrature_nodes),
            r.per_ray(r.counters.shadow_candidates),
            1e6 * r.seconds / r.counters.shadow_candidates.max(1) as f64,
            r.rel_rms,
            100.0 * r.covered,
            r.ratio,
            r.ref_seconds,
        );
    }
    t
}

/// `of(row)` at each N relative to N = 1e3, per cloud.
fn ratios(rows: &[ScalingRow], cloud: Cloud, of: fn(&ScalingRow) -> f64) -> Vec<(usize, f64)> {
    let Some(base) = rows.iter().find(|r| r.cloud == cloud && r.n == 1000) else {
        return Vec::new();
    };
    rows.iter()
        .filter(|r| r.cloud == cloud)
        .map(|r| (r.n, of(r) / of(base)))
        .collect()
}

/// The scaling rows as ratios: time per camera ray and per shadowing sphere against
/// N = 1e3, exact against march at equal error, the error estimate's coverage at N = 1e4.
pub fn scaling_summary(rows: &[ScalingRow]) -> String {
    let mut t = String::new();
    for c in [Cloud::Thick, Cloud::Thin] {
        for (what, of) in [
            (
                "camera ray",
                ScalingRow::seconds_per_ray as fn(&ScalingRow) -> f64,
            ),
            ("shadowing sphere", ScalingRow::seconds_per_shadower),
        ] {
            let r = ratios(rows, c, of);
            if !r.is_empty() {
                let list: Vec<String> = r.iter().map(|(n, v)| format!("N {n}: {v:.2}x")).collect();
                let _ = writeln!(
                    t,
                    "- {}: time per {what} relative to N = 1000: {}",
                    c.name(),
                    list.join(", ")
                );
            }
        }
    }
    for r in rows {
        if let Some(m) = r.march {
            let _ = writeln!(
                t,
                "- {} N {}: exact is {}{:.1}x faster than march at equal error ({:.2e})",
                r.cloud.name(),
                r.n,
                if m.extrapolated { "~" } else { "" },
                m.seconds / r.seconds,
                r.rel_rms
            );
        }
    }
    let at_1e4: Vec<&ScalingRow> = rows.iter().filter(|r| r.n == 10_000).collect();
    for r in at_1e4 {
        let _ = writeln!(
            t,
            "- {} N = 1e4: pixels whose reported error covers the true error {:.1}%; median \
             reported / true {:.3}",
            r.cloud.name(),
            100.0 * r.covered,
            r.ratio
        );
    }
    let worst = rows.iter().map(|r| r.rel_rms).fold(0.0, f64::max);
    let _ = writeln!(
        t,
        "- largest rel. RMS error at the default tol {DEFAULT_TOL:e}: {worst:.2e}"
    );
    t
}

/// The scaling table on cloud-N for every N in `sizes` and every cloud: exact at the default
/// tol (median of `runs` runs, one thread, S x S pixel centres, f64 film) against exact at
/// [`REFERENCE_TOL`]: time, camera rays/s, quadrature nodes and shadowing spheres per camera
/// ray (`Counters::shadow_candidates / camera_rays`), relative RMS error (over all pixels and
/// channels, divided by the reference's RMS), how well the error AOV covers the true error,
/// and the time march needs for the same error ([`march_to`]). Then the ratios.
pub fn run_scaling(args: &GasArgs) -> Result<ExitCode, Error> {
    let quick = args.quick;
    let sizes = if !args.sizes.is_empty() {
        args.sizes.clone()
    } else if quick {
        vec![1000, 10_000]
    } else {
        vec![1000, 10_000, 100_000, 1_000_000]
    };
    let size = args.size.unwrap_or(if quick { 32 } else { 128 });
    let threads = args.threads.unwrap_or(1);
    let budget = args.march_budget.unwrap_or(if quick { 2.0 } else { 120.0 });
    if size == 0 || threads == 0 || sizes.contains(&0) || args.runs == Some(0) {
        return Err(Error::Other(
            "--size, --threads, --sizes and --runs must be positive".into(),
        ));
    }
    let threads = crate::threads::capped(threads);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| Error::Other(format!("cannot start worker threads: {e}")))?;
    let mut rows = Vec::new();
    for &n in &sizes {
        for &c in &args.clouds {
            let c = Cloud::from(c);
            let mut scene = cloud(n, c);
            if let Some(profile) = args.profile {
                scene.materials.edit_records(|m| m.profile = profile);
            }
            let runs = args.runs.unwrap_or(if n <= 10_000 { 3 } else { 1 });
            eprintln!(
                "cloud-{}-{n}, {size}x{size}, {threads} thread(s):",
                c.name()
            );
            let row = pool.install(|| -> Result<ScalingRow, Error> {
                let reference = shoot(&scene, size, Integrator::Exact, REFERENCE_TOL, 1, false)?;
                eprintln!(
                    "    exact tol {REFERENCE_TOL:e} (reference): {:.3} s",
                    reference.seconds
                );
                let m = shoot(&scene, size, Integrator::Exact, DEFAULT_TOL, runs, true)?;
                let rel_rms = relative_rms(&m.rgb, &reference.rgb);
                eprintln!(
                    "    exact tol {DEFAULT_TOL:e}: {:.3} s (median of {}), rel. RMS {rel_rms:.2e}",
                    m.seconds, m.runs
                );
                let (covered, ratio) = error_coverage(&m.rgb, &m.error, &reference.rgb);
                let march = march_to(&scene, size, &reference.rgb, rel_rms, budget)?;
                Ok(ScalingRow {
                    n,
                    cloud: c,
                    seconds: m.seconds,
                    grid_seconds: m.grid_seconds,
                    runs: m.runs,
                    counters: m.counters,
                    rel_rms,
                    covered,
                    ratio,
                    ref_seconds: reference.seconds,
                    march,
                })
            })?;
            rows.push(row);
        }
    }
    println!(
        "bench gas --scaling: cloud-N{} at {size}x{size} pixel centres, {threads} thread(s), exact at tol {DEFAULT_TOL:e} against tol {REFERENCE_TOL:e}; march steps 0.2/4^k, budget {budget} s\n",
        args.profile.map_or(String::new(), |p| format!(" ({} profile)", p.name()))
    );
    println!("{}", scaling_table(&rows));
    print!("{}", scaling_summary(&rows));
    Ok(ExitCode::SUCCESS)
}

/// `gtsphere bench gas`.
pub fn run(args: &GasArgs) -> Result<ExitCode, Error> {
    if let Some(dir) = &args.write {
        let sizes = if args.sizes.is_empty() {
            vec![1000, 10_000, 100_000, 1_000_000]
        } else {
            args.sizes.clone()
        };
        write_clouds(dir, &sizes, &args.clouds)?;
        return Ok(ExitCode::SUCCESS);
    }
    if args.scaling {
        return run_scaling(args);
    }
    run_tradeoff(
        args.spheres,
        args.size.unwrap_or(256),
        args.threads.unwrap_or(2),
    )
}

#[cfg(test)]
mod tests;
