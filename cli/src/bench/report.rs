//! `gtsphere bench` (no subcommand): time against error of every integrator on four built-in
//! scenes, written to `--out` as `bench.csv`, `bench.md` (also printed) and `bench.png`.
//!
//! Scenes ([`scenes`]):
//! - `opaque`: random lit opaque spheres with shadows (`bench trace`'s scene). Without gas
//!   every integrator takes the same surface path (`render/integrators/mod.rs`), so there is
//!   one curve, `surface`: the stratified pixel sampler's `spp` swept against a render at a
//!   much higher `spp`. Its error is the pixel integral's (docs/model.md section 4), not a ray's.
//! - `emission`: a gas cloud without lights (emission and absorption only).
//! - `lit gas`: `bench gas`'s scene (gas lit by a point and a directional light, two opaque
//!   spheres).
//! - `profiled gas`: the same scene with density profiles (docs/model.md section 6).
//!
//! The gas scenes are traced with one ray through each pixel centre (mc: `spp` paths through
//! it), so only the integration error along a ray is measured, against `exact` at a much
//! tighter `--tol`: `exact` with a sweep of `tol`, `march` with a sweep of `step`, `mc` with a
//! sweep of `spp`. Errors are computed in f64 (`RenderOptions::film_f64`), so they can go
//! below f32 rounding. Rendering and timing are [`super::measure`]'s.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use clap::Args;

use super::measure::{run_scene, summary, table, BenchScene, Case, Row};
use gtsphere::bench::scenes::{gas_cloud, gas_cloud_with, random_spheres};
use gtsphere::error::Error;
use gtsphere::scene::{Profile, DEFAULT_WIDTH};

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
        BenchScene {
            name: "profiled gas",
            description: format!(
                "the lit gas scene with density profiles, linear, quadratic and gaussian (width \
                 1/3) in turn; {s_gas}x{s_gas} pixel centres, against exact at tol {ref_tol:e}"
            ),
            scene: gas_cloud_with(n_gas, true, |i| {
                [
                    Profile::Linear,
                    Profile::Quadratic,
                    Profile::Gaussian {
                        width: DEFAULT_WIDTH,
                    },
                ][i % 3]
            }),
            size: s_gas,
            reference: Case::exact(ref_tol),
            cases: gas_cases(&tols, &lit_steps),
        },
    ]
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

pub fn run(args: &ReportArgs) -> Result<ExitCode, Error> {
    if args.threads == 0 {
        return Err(Error::Other("--threads must be positive".into()));
    }
    let threads = crate::threads::capped(args.threads);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
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
            run_scene(s, threads, |r| {
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
    super::plot::plot(&rows, &scenes, &plot)?;
    let md = format!(
        "# gtsphere bench{}\n\n{} threads; seconds are the median wall time of the render loop.\n\n\
         {notes}\n{}\n## Throughput\n\n{throughput}\n## Summary\n\n{}\n## Plot (bench.png)\n\n{}",
        if args.quick { " --quick" } else { "" },
        threads,
        table(&rows),
        summary(&rows),
        super::plot::LEGEND
    );
    print!("{md}");
    let md_path = args.out.join("bench.md");
    std::fs::write(&md_path, &md).map_err(io(&md_path))?;
    let csv_path = args.out.join("bench.csv");
    std::fs::write(&csv_path, csv(&rows)).map_err(io(&csv_path))?;
    eprintln!("wrote {}, bench.md and bench.csv", plot.display());
    Ok(ExitCode::SUCCESS)
}
