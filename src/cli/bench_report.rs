//! `gtsphere bench` (no subcommand): time against error of every integrator on three built-in
//! scenes, written to `--out` as `bench.csv`, `bench.md` (also printed) and `bench.png`.
//!
//! Scenes ([`scenes`]):
//! - `opaque`: random lit opaque spheres with shadows (`bench trace`'s scene). Without gas
//!   every integrator takes the same surface path (`render/integrators/mod.rs`), so there is
//!   one curve, `surface`: the stratified pixel sampler's `spp` swept against a render at a
//!   much higher `spp`. Its error is the pixel integral's (MODEL.md section 4), not a ray's.
//! - `emission`: a gas cloud without lights (emission and absorption only).
//! - `lit gas`: `bench gas`'s scene (gas lit by a point and a directional light, two opaque
//!   spheres).
//!
//! The gas scenes are traced with one ray through each pixel centre (mc: `spp` paths through
//! it), so only the integration error along a ray is measured, against `exact` at a much
//! tighter `--tol`: `exact` with a sweep of `tol`, `march` with a sweep of `step`, `mc` with a
//! sweep of `spp`. Errors are computed in f64 (`RenderOptions::film_f64`), so they can go
//! below f32 rounding. A render faster than [`REPEAT_BELOW`] seconds is repeated (up to
//! [`MAX_RUNS`] runs) and the median wall time of the tile loop is reported.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use clap::Args;

use super::bench::median;
use crate::error::Error;
use crate::render::{prepare, tiles::render, Counters, Integrator, RenderOptions, SamplerKind};
use crate::scene::Scene;
use crate::scenes::{gas_cloud, random_spheres};

/// Renders faster than this (seconds) are repeated for a median.
pub const REPEAT_BELOW: f64 = 0.3;
/// Most runs of one setting.
pub const MAX_RUNS: usize = 5;

/// `gtsphere bench` without a subcommand.
#[derive(Debug, Args)]
pub struct ReportArgs {
    /// Folder for bench.csv, bench.md and bench.png (created if missing).
    #[arg(long, default_value = "bench-report")]
    pub out: PathBuf,
    /// A reduced sweep (smaller images, fewer settings; about 20 s on 2 cores).
    #[arg(long)]
    pub quick: bool,
    /// Worker threads (throughput is also reported per thread).
    #[arg(long, default_value_t = 2)]
    pub threads: usize,
}

/// One measured setting of one integrator.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Case {
    pub integrator: Integrator,
    pub sampler: SamplerKind,
    pub spp: u32,
    pub tol: f64,
}

impl Case {
    pub fn exact(tol: f64) -> Case {
        Case {
            integrator: Integrator::Exact,
            sampler: SamplerKind::Center,
            spp: 1,
            tol,
        }
    }
    pub fn march(step: f64) -> Case {
        Case {
            integrator: Integrator::March { step },
            ..Case::exact(0.0)
        }
    }
    /// Monte Carlo with `spp` paths through each pixel centre.
    pub fn mc(spp: u32) -> Case {
        Case {
            integrator: Integrator::Mc,
            spp,
            ..Case::exact(0.0)
        }
    }
    /// The opaque path with `spp` stratified samples per pixel.
    pub fn surface(spp: u32) -> Case {
        Case {
            sampler: SamplerKind::Stratified,
            spp,
            ..Case::exact(1e-4)
        }
    }
    /// The curve this case belongs to.
    pub fn name(&self) -> &'static str {
        match (self.sampler, self.integrator) {
            (SamplerKind::Stratified, _) => "surface",
            (_, Integrator::Exact) => "exact",
            (_, Integrator::March { .. }) => "march",
            (_, Integrator::Mc) => "mc",
        }
    }
    /// The swept parameter: tol, step or spp.
    pub fn param(&self) -> f64 {
        match (self.sampler, self.integrator) {
            (SamplerKind::Center, Integrator::Exact) => self.tol,
            (SamplerKind::Center, Integrator::March { step }) => step,
            _ => f64::from(self.spp),
        }
    }
    pub fn setting(&self) -> String {
        match (self.sampler, self.integrator) {
            (SamplerKind::Center, Integrator::Exact) => format!("tol {:e}", self.tol),
            (SamplerKind::Center, Integrator::March { step }) => format!("step {step:e}"),
            _ => format!("spp {}", self.spp),
        }
    }
}

/// A scene and what to measure on it.
pub struct BenchScene {
    pub name: &'static str,
    pub description: String,
    pub scene: Scene,
    pub size: u32,
    pub reference: Case,
    pub cases: Vec<Case>,
}

/// The built-in scenes at full size, or reduced for `--quick`.
pub fn scenes(quick: bool) -> Vec<BenchScene> {
    let pick = |full: &[f64], q: &[f64]| if quick { q.to_vec() } else { full.to_vec() };
    let tols = pick(
        &[1e-1, 1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9],
        &[1e-2, 1e-4, 1e-6, 1e-8],
    );
    let steps = pick(
        &[0.2, 0.05, 0.0125, 3.125e-3, 7.8125e-4, 1.953125e-4],
        &[0.2, 0.05, 0.0125],
    );
    let spps: Vec<u32> = if quick {
        vec![1, 4, 16]
    } else {
        vec![1, 4, 16, 64, 256]
    };
    let gas_cases = |tols: &[f64], steps: &[f64]| {
        let mut v: Vec<Case> = tols.iter().map(|&t| Case::exact(t)).collect();
        v.extend(steps.iter().map(|&s| Case::march(s)));
        v.extend(spps.iter().map(|&n| Case::mc(n)));
        v
    };
    let (n_opaque, s_opaque, ref_spp) = if quick {
        (500, 48, 256)
    } else {
        (2000, 64, 1024)
    };
    let (n_gas, s_gas) = if quick { (300, 32) } else { (1000, 40) };
    // Emission alone is about 100 times cheaper a ray than lit gas: more pixels, so that
    // its times are not per-render overhead.
    let s_emis = 4 * s_gas;
    let ref_tol = 1e-11;
    let mut lit_steps = steps.clone();
    if !quick {
        // One step further on the lit scene, where march's time to 1e-4 is the question.
        lit_steps.push(4.8828125e-5);
    }
    vec![
        BenchScene {
            name: "opaque",
            description: format!(
                "{n_opaque} random opaque spheres, point + directional light with shadows; \
                 {s_opaque}x{s_opaque} pixels, stratified spp against spp {ref_spp}"
            ),
            scene: random_spheres(n_opaque),
            size: s_opaque,
            reference: Case::surface(ref_spp),
            cases: [1, 4, 16, 64]
                .into_iter()
                .filter(|&n| n < ref_spp / 8)
                .map(Case::surface)
                .collect(),
        },
        BenchScene {
            name: "emission",
            description: format!(
                "{n_gas} emitting gas spheres, no lights (emission and absorption only); \
                 {s_emis}x{s_emis} pixel centres, against exact at tol {ref_tol:e}"
            ),
            scene: gas_cloud(n_gas, false),
            size: s_emis,
            reference: Case::exact(ref_tol),
            cases: gas_cases(&tols, &steps),
        },
        BenchScene {
            name: "lit gas",
            description: format!(
                "{n_gas} gas spheres lit by a point and a directional light, 2 opaque spheres; \
                 {s_gas}x{s_gas} pixel centres, against exact at tol {ref_tol:e}"
            ),
            scene: gas_cloud(n_gas, true),
            size: s_gas,
            reference: Case::exact(ref_tol),
            cases: gas_cases(&tols, &lit_steps),
        },
    ]
}

/// One row of the report.
#[derive(Clone, Debug)]
pub struct Row {
    pub scene: &'static str,
    pub integrator: &'static str,
    pub setting: String,
    pub param: f64,
    /// Median wall time of the tile loop.
    pub seconds: f64,
    pub runs: usize,
    pub rel_rms: f64,
    pub rel_max: f64,
    pub counters: Counters,
    pub threads: usize,
}

impl Row {
    /// Camera rays (mc: paths; surface: samples) per second per thread.
    pub fn rays_per_s_per_core(&self) -> f64 {
        self.counters.camera_rays as f64 / self.seconds / self.threads as f64
    }
}

/// One setting's render.
pub struct Measured {
    /// The pixels in f64, row by row.
    pub rgb: Vec<[f64; 3]>,
    /// Median wall time of the tile loop over `runs` runs.
    pub seconds: f64,
    pub runs: usize,
    /// Work counters of one run.
    pub counters: Counters,
}

/// Renders `scene` with `case`, repeated while fast (see the module notes).
pub fn measure(scene: &Scene, size: u32, case: &Case) -> Result<Measured, Error> {
    let opts = RenderOptions {
        width: size,
        height: size,
        spp: case.spp,
        sampler: case.sampler,
        integrator: case.integrator,
        tol: case.tol,
        film_f64: true,
        ..RenderOptions::default()
    };
    let prep = prepare(scene.clone(), &opts).map_err(Error::Other)?;
    let mut times = Vec::new();
    let mut total = 0.0;
    loop {
        let done = render(&prep, &opts);
        times.push(done.seconds);
        total += done.seconds;
        if done.seconds >= REPEAT_BELOW || times.len() >= MAX_RUNS || total >= 1.0 {
            return Ok(Measured {
                rgb: done.rgb64,
                runs: times.len(),
                seconds: median(times),
                counters: done.counters,
            });
        }
    }
}

/// Relative RMS error over all channels: `sqrt(mean |x - ref|^2) / sqrt(mean |ref|^2)`.
pub fn relative_rms(img: &[[f64; 3]], reference: &[[f64; 3]]) -> f64 {
    let (mut num, mut den) = (0.0, 0.0);
    for (a, b) in img.iter().zip(reference) {
        for k in 0..3 {
            num += (a[k] - b[k]) * (a[k] - b[k]);
            den += b[k] * b[k];
        }
    }
    (num / den.max(f64::MIN_POSITIVE)).sqrt()
}

/// Largest relative error of one channel of one pixel, `|x - ref| / max(|ref|, floor)` with the
/// floor `1e-3 * rms(ref)` so that a near-black reference pixel does not dominate.
pub fn relative_max(img: &[[f64; 3]], reference: &[[f64; 3]]) -> f64 {
    let n = (reference.len() * 3).max(1) as f64;
    let rms = (reference.iter().flatten().map(|v| v * v).sum::<f64>() / n).sqrt();
    let floor = (1e-3 * rms).max(f64::MIN_POSITIVE);
    img.iter()
        .flatten()
        .zip(reference.iter().flatten())
        .map(|(a, b)| (a - b).abs() / b.abs().max(floor))
        .fold(0.0, f64::max)
}

/// Measures every case of `s` against its reference; `progress` is told of each row.
pub fn run_scene(
    s: &BenchScene,
    threads: usize,
    mut progress: impl FnMut(&Row),
) -> Result<(Vec<Row>, f64), Error> {
    let reference = measure(&s.scene, s.size, &s.reference)?;
    let mut rows = Vec::new();
    for case in &s.cases {
        let m = measure(&s.scene, s.size, case)?;
        let row = Row {
            scene: s.name,
            integrator: case.name(),
            setting: case.setting(),
            param: case.param(),
            seconds: m.seconds,
            runs: m.runs,
            rel_rms: relative_rms(&m.rgb, &reference.rgb),
            rel_max: relative_max(&m.rgb, &reference.rgb),
            counters: m.counters,
            threads,
        };
        progress(&row);
        rows.push(row);
    }
    Ok((rows, reference.seconds))
}

/// The Markdown table of `rows`.
pub fn table(rows: &[Row]) -> String {
    let mut t = String::from(
        "| scene | integrator | setting | seconds | runs | rel. RMS error | max rel. error | camera rays/s/core |\n\
         |---|---|---|---:|---:|---:|---:|---:|\n",
    );
    for r in rows {
        let _ = writeln!(
            t,
            "| {} | {} | {} | {:.4} | {} | {:.2e} | {:.2e} | {:.3e} |",
            r.scene,
            r.integrator,
            r.setting,
            r.seconds,
            r.runs,
            r.rel_rms,
            r.rel_max,
            r.rays_per_s_per_core()
        );
    }
    t
}

fn csv(rows: &[Row]) -> String {
    let mut t = String::from(
        "scene,integrator,setting,param,seconds,runs,rel_rms,rel_max,camera_rays,shadow_rays,quadrature_nodes,threads,camera_rays_per_s,camera_rays_per_s_per_core\n",
    );
    for r in rows {
        let _ = writeln!(
            t,
            "{},{},{},{:e},{:e},{},{:e},{:e},{},{},{},{},{:e},{:e}",
            r.scene,
            r.integrator,
            r.setting,
            r.param,
            r.seconds,
            r.runs,
            r.rel_rms,
            r.rel_max,
            r.counters.camera_rays,
            r.counters.shadow_rays,
            r.counters.quadrature_nodes,
            r.threads,
            r.counters.camera_rays as f64 / r.seconds,
            r.rays_per_s_per_core()
        );
    }
    t
}

/// Time for `integrator` on `scene` to reach relative RMS `target`: the fastest measured row
/// that reaches it, else a log-log extrapolation from the last two rows (flagged `true`).
pub fn time_to(rows: &[Row], scene: &str, integrator: &str, target: f64) -> Option<(f64, bool)> {
    let curve: Vec<&Row> = rows
        .iter()
        .filter(|r| r.scene == scene && r.integrator == integrator)
        .collect();
    let reached = curve
        .iter()
        .filter(|r| r.rel_rms <= target)
        .map(|r| r.seconds)
        .fold(f64::INFINITY, f64::min);
    if reached.is_finite() {
        return Some((reached, false));
    }
    // Error ~ time^slope through the two tightest settings.
    let [.., a, b] = curve.as_slice() else {
        return None;
    };
    let slope = (b.rel_rms.ln() - a.rel_rms.ln()) / (b.seconds.ln() - a.seconds.ln());
    (slope < 0.0 && slope.is_finite())
        .then(|| (b.seconds * (target / b.rel_rms).powf(1.0 / slope), true))
}

/// The goals on the lit gas scene, as lines of text.
pub fn goals(rows: &[Row]) -> String {
    let mut t = String::new();
    let fmt = |v: Option<(f64, bool)>| match v {
        Some((s, false)) => format!("{s:.3} s"),
        Some((s, true)) => format!("~{s:.3} s (extrapolated)"),
        None => "not reached".into(),
    };
    let ex = time_to(rows, "lit gas", "exact", 1e-4);
    let ma = time_to(rows, "lit gas", "march", 1e-4);
    let _ = write!(
        t,
        "- lit gas, time to 1e-4 relative RMS: exact {}, march {}",
        fmt(ex),
        fmt(ma)
    );
    if let (Some((e, _)), Some((m, _))) = (ex, ma) {
        let _ = write!(
            t,
            " -> march / exact = {:.1}x (goal >= 10x: {})",
            m / e,
            if m / e >= 10.0 {
                "holds"
            } else {
                "does NOT hold"
            }
        );
    }
    t.push('\n');
    let exact: Vec<&Row> = rows
        .iter()
        .filter(|r| r.scene == "lit gas" && r.integrator == "exact")
        .collect();
    let errs: Vec<String> = exact.iter().map(|r| format!("{:.1e}", r.rel_rms)).collect();
    let best = exact
        .iter()
        .map(|r| r.rel_rms)
        .fold(f64::INFINITY, f64::min);
    let _ = writeln!(
        t,
        "- lit gas, exact error as tol tightens: {}; smallest {:.1e} (goal <= 1e-8: {})",
        errs.join(", "),
        best,
        if best <= 1e-8 {
            "holds"
        } else {
            "does NOT hold"
        }
    );
    t
}

pub fn run(args: &ReportArgs) -> Result<ExitCode, Error> {
    if args.threads == 0 {
        return Err(Error::Other("--threads must be positive".into()));
    }
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(args.threads)
        .build()
        .map_err(|e| Error::Other(format!("cannot start worker threads: {e}")))?;
    let io = |p: &Path| {
        let p = p.display().to_string();
        move |e| Error::Io { path: p, source: e }
    };
    std::fs::create_dir_all(&args.out).map_err(io(&args.out))?;
    let scenes = scenes(args.quick);
    let mut rows = Vec::new();
    let mut notes = String::new();
    for s in &scenes {
        eprintln!("{}: {}", s.name, s.description);
        let (r, ref_s) = pool.install(|| {
            run_scene(s, args.threads, |r| {
                eprintln!(
                    "  {:<8} {:<18} {:>9.4} s  rel. RMS {:.2e}",
                    r.integrator, r.setting, r.seconds, r.rel_rms
                );
            })
        })?;
        let _ = writeln!(
            notes,
            "- **{}**: {} (reference {:.2} s).",
            s.name, s.description, ref_s
        );
        rows.extend(r);
    }
    let mut throughput = String::new();
    for s in &scenes {
        let best = rows
            .iter()
            .filter(|r| r.scene == s.name)
            .map(|r| (r.integrator, r.setting.as_str(), r.rays_per_s_per_core()))
            .collect::<Vec<_>>();
        let mut per: Vec<String> = Vec::new();
        for name in ["surface", "exact", "march", "mc"] {
            // The curve's middle setting: a stable figure to compare between versions.
            let c: Vec<_> = best.iter().filter(|b| b.0 == name).collect();
            if let Some(b) = c.get(c.len() / 2) {
                per.push(format!("{} ({}) {:.3e}", b.0, b.1, b.2));
            }
        }
        let _ = writeln!(
            throughput,
            "- {}: {} camera rays/s/core",
            s.name,
            per.join(", ")
        );
    }
    let plot = args.out.join("bench.png");
    super::bench_plot::plot(&rows, &scenes, &plot)?;
    let md = format!(
        "# gtsphere bench{}\n\n{} threads; seconds are the median wall time of the render loop.\n\n\
         {notes}\n{}\n## Throughput\n\n{throughput}\n## Goals\n\n{}\n## Plot (bench.png)\n\n{}",
        if args.quick { " --quick" } else { "" },
        args.threads,
        table(&rows),
        goals(&rows),
        super::bench_plot::LEGEND
    );
    print!("{md}");
    let md_path = args.out.join("bench.md");
    std::fs::write(&md_path, &md).map_err(io(&md_path))?;
    let csv_path = args.out.join("bench.csv");
    std::fs::write(&csv_path, csv(&rows)).map_err(io(&csv_path))?;
    eprintln!("wrote {}, bench.md and bench.csv", plot.display());
    Ok(ExitCode::SUCCESS)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(integrator: &'static str, seconds: f64, rel_rms: f64) -> Row {
        Row {
            scene: "lit gas",
            integrator,
            setting: String::new(),
            param: 0.0,
            seconds,
            runs: 1,
            rel_rms,
            rel_max: rel_rms,
            counters: Counters::default(),
            threads: 1,
        }
    }

    #[test]
    fn time_to_a_target_measured_or_extrapolated_along_the_curve() {
        // Error ~ 1 / time: 1e-2 at 1 s, 1e-3 at 10 s, so 1e-4 at 100 s.
        let rows = [
            row("march", 1.0, 1e-2),
            row("march", 10.0, 1e-3),
            row("exact", 0.5, 1e-9),
            row("exact", 0.4, 1e-8),
        ];
        let (t, extrapolated) = time_to(&rows, "lit gas", "march", 1e-4).unwrap();
        assert!(extrapolated && (t - 100.0).abs() < 1e-9, "{t}");
        assert_eq!(time_to(&rows, "lit gas", "exact", 1e-4), Some((0.4, false)));
        assert_eq!(time_to(&rows, "lit gas", "mc", 1e-4), None);
        assert!(goals(&rows).contains("march / exact = 250.0x (goal >= 10x: holds)"));
    }

    #[test]
    fn relative_errors_of_known_images() {
        let reference = [[1.0, 2.0, 2.0], [0.0, 0.0, 0.0]];
        assert_eq!(relative_rms(&reference, &reference), 0.0);
        let img = [[1.1, 2.0, 2.0], [0.0, 0.0, 0.0]];
        // sqrt(0.01 / 9)
        assert!((relative_rms(&img, &reference) - 0.1 / 3.0).abs() < 1e-12);
        assert!((relative_max(&img, &reference) - 0.1).abs() < 1e-12);
        // A black reference pixel is judged against the floor, not divided by zero.
        let img = [[1.0, 2.0, 2.0], [1e-6, 0.0, 0.0]];
        let floor = 1e-3 * (9.0f64 / 6.0).sqrt();
        assert!((relative_max(&img, &reference) - 1e-6 / floor).abs() < 1e-12);
    }
}
