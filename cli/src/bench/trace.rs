//! `gtsphere bench trace`: BVH build time, camera and shadow rays per second, and peak memory
//! on N random opaque spheres (the benchmark scene of `gtsphere::bench::scenes`).
//!
//! Scene: [`gtsphere::bench::scenes::random_spheres`] (the same as `benches/embree/`, so the two can be
//! run side by side), one ray through each pixel's centre.
//!
//! Camera rays and shadow rays are timed in separate passes on one thread (per-core
//! figures): pass 1 finds every camera hit, pass 2 traces one shadow ray per hit and light.
//! A third pass renders the full image (shading included) on `--threads` threads.

use std::process::ExitCode;

use super::measure::median;
use crate::memory::peak_rss_bytes;
use glam::DVec3;
use gtsphere::bench::scenes::random_spheres;
use gtsphere::bench::{ray_passes, RayPasses};
use gtsphere::error::Error;
use gtsphere::render::{prepare, render, Counters, PrepareOptions, RenderOptions, SamplerKind};
use gtsphere::scene::{Material, Scene};

/// One measured run.
struct Run {
    build: f64,
    camera_rps: f64,
    shadow_rps: f64,
    combined_rps: f64,
    /// BVH build plus both ray passes, seconds: what Embree's harness reports as
    /// build_s + cam_s + shadow_s.
    total_s: f64,
    render_rps: f64,
    hits: u64,
    peak_prepare: u64,
    lit: [u64; 2],
}

/// The benchmark scene; with `colour_per_sphere`, sphere i gets the colour (a, b, c) / 1e6 with
/// a, b, c read off i's bits, so that no two of the first 10^18 spheres share a colour.
fn scene(n: usize, colour_per_sphere: bool) -> Scene {
    let mut scene = random_spheres(n);
    if colour_per_sphere {
        for i in 0..scene.spheres.len() {
            let m = i as u64;
            let part = |k: u32| ((m / 1_000_000u64.pow(k)) % 1_000_000) as f64 / 1e6;
            let paint = scene.materials.add(&Material {
                diffuse: DVec3::new(part(0), part(1), 0.5 + 0.5 * part(2)),
                ..Material::default()
            });
            let s = &mut scene.spheres[i];
            (s.color, s.material) = (paint.color, paint.material);
        }
    }
    scene
}

fn one_run(n: usize, size: u32, threads: usize, colour_per_sphere: bool) -> Result<Run, Error> {
    let opts = RenderOptions {
        width: size,
        height: size,
        spp: 1,
        sampler: SamplerKind::Center,
        ..RenderOptions::default()
    };
    let prep = prepare(scene(n, colour_per_sphere), &PrepareOptions::default())?;
    let peak_prepare = peak_rss_bytes().unwrap_or(0);
    // Passes 1 and 2, one thread: camera rays, then one shadow ray per hit and light.
    let RayPasses {
        camera_seconds: camera_s,
        shadow_seconds: shadow_s,
        hits: hit_count,
        shadow_rays,
        lit,
    } = ray_passes(&prep, &opts)?;

    // Pass 3: the full render (shading, N.L culling of shadow rays) on `threads` threads.
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| Error::Other(format!("cannot start worker threads: {e}")))?;
    let camera = prep.default_camera(size, size)?;
    let done = pool.install(|| render(&prep, &camera, &opts, &()))?;
    let Counters {
        camera_rays,
        shadow_rays: shaded,
        ..
    } = done.counters;

    let camera_rays_1 = u64::from(size) * u64::from(size);
    Ok(Run {
        build: prep.bvh_build_time().as_secs_f64(),
        camera_rps: camera_rays_1 as f64 / camera_s,
        shadow_rps: shadow_rays as f64 / shadow_s,
        combined_rps: (camera_rays_1 + shadow_rays) as f64 / (camera_s + shadow_s),
        total_s: prep.bvh_build_time().as_secs_f64() + camera_s + shadow_s,
        render_rps: (camera_rays + shaded) as f64 / done.seconds / threads as f64,
        hits: hit_count,
        peak_prepare,
        lit,
    })
}

pub fn run(
    spheres: usize,
    size: u32,
    runs: usize,
    threads: usize,
    colour_per_sphere: bool,
) -> Result<ExitCode, Error> {
    if spheres == 0 || size == 0 || threads == 0 {
        return Err(Error::Other(
            "--spheres, --size and --threads must be positive".into(),
        ));
    }
    let threads = crate::threads::capped(threads);
    let mut all = Vec::new();
    for _ in 0..runs.max(1) {
        all.push(one_run(spheres, size, threads, colour_per_sphere)?);
    }
    let med = |f: fn(&Run) -> f64| median(all.iter().map(f).collect());
    let peak = peak_rss_bytes().unwrap_or(0) as f64;
    // The process's high-water mark only grows: after the first run it also holds that run's
    // render buffers, so only the first run's reading is the scene and BVH alone.
    let peak_prepare = all[0].peak_prepare as f64;
    let last = &all[all.len() - 1];
    println!(
        "| spheres | image | BVH build s | camera Mrays/s/core | shadow Mrays/s/core | camera+shadow Mrays/s/core | build + rays s (one thread) | full render Mrays/s/core ({threads} threads) | peak RSS B/sphere: scene + BVH | whole run |"
    );
    println!("|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|");
    println!(
        "| {} | {}x{} | {:.3} | {:.2} | {:.2} | {:.2} | {:.3} | {:.2} | {:.0} | {:.0} |",
        spheres,
        size,
        size,
        med(|r| r.build),
        med(|r| r.camera_rps) / 1e6,
        med(|r| r.shadow_rps) / 1e6,
        med(|r| r.combined_rps) / 1e6,
        med(|r| r.total_s),
        med(|r| r.render_rps) / 1e6,
        peak_prepare / spheres as f64,
        peak / spheres as f64
    );
    println!(
        "\ncamera hits {} of {}; unoccluded shadow rays: point light {}, directional light {}; {} runs, medians",
        last.hits,
        u64::from(size) * u64::from(size),
        last.lit[0],
        last.lit[1],
        all.len()
    );
    Ok(ExitCode::SUCCESS)
}
