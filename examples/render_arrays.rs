//! Spheres from arrays to a picture with the library's API, timed: the Rust side of the
//! arrays benchmark (`python/bench/bench_arrays.py`), and the example of how a
//! program builds a scene in code rather than reading a VRML file.
//!
//! ```text
//! cargo run --release --example render_arrays -- DIR
//! ```
//!
//! `DIR` holds three files of raw little-endian `f64` (what numpy's `tofile` writes):
//! `centers.f64` (`x, y, z` of each sphere), `radii.f64` (one radius per sphere, or a single
//! value for all of them) and `colors.f64` (`r, g, b` in `[0, 1]` per sphere).
//!
//! What it shows, step by step:
//!
//! 1. [`Scene::from_arrays`] turns flat arrays into a [`Scene`], checking every value
//!    (a bad one is an error naming the array, index and value). It copies what it needs,
//!    so the arrays can be dropped once the scene is built, as they are here.
//! 2. Lights are pushed onto `scene.lights`; the headlight (VRML's default) is switched off.
//! 3. [`render::prepare`] validates the scene and builds the BVH once; the [`Prepared`]
//!    scene can then be rendered from any number of cameras.
//! 4. [`render::render`] traces one picture into a [`Film`] on the current rayon pool. Here
//!    everything runs inside a pool of one thread (`pool.install`): the timings are of one
//!    core, like `gtsphere.render(..., threads=1)`.
//!
//! The scene matches the Python side of the benchmark: headlight off, a PointLight at
//! `(3, 3, 3)` and a DirectionalLight along `-(1, 1, 1)`; a perspective camera at `(0, 0, 4)`
//! looking at the origin with a field of view of pi/4; 512 x 512 pixels, one sample at each
//! pixel's centre, the exact integrator with `gtsphere.render`'s defaults (tolerance 1e-4,
//! seed 0, the per-pixel error channel kept).
//!
//! It prints one line of `key=value`: `n` (spheres), `build_s` (from_arrays and prepare),
//! `render_s` (render, wall time), `tile_s` (the film's own time of the tile loop),
//! `total_s` (from the start of from_arrays to the end of render; reading the files is not
//! included), `cpu_s` (the CPU time of all threads over `total_s`), `peak_rss_bytes`
//! (`VmHWM` of `/proc/self/status`) and `checksum`, the sum of every RGB value in pixel
//! order, to compare pictures bit for bit.

use std::error::Error;
use std::f64::consts::FRAC_PI_4;
use std::fs::File;
use std::io::{self, BufReader, Read};
use std::path::{Path, PathBuf};
use std::time::Instant;

use glam::DVec3;
use gtsphere::render::{
    self, Aovs, Camera, Film, Lens, PrepareOptions, Prepared, RenderOptions, SamplerKind,
};
use gtsphere::scene::{DirectionalLight, Light, PointLight, Radii, Scene, SphereArrays};

/// Errors of any kind, as a message; `Send` so that they leave the thread pool.
type Result<T> = std::result::Result<T, Box<dyn Error + Send + Sync>>;

/// The image size, both sides.
const SIZE: u32 = 512;

fn main() -> Result<()> {
    let dir = match std::env::args_os().nth(1) {
        Some(d) => PathBuf::from(d),
        None => {
            return Err("usage: render_arrays DIR (with centers.f64, radii.f64, colors.f64)".into())
        }
    };
    let centers = read_f64s(&dir.join("centers.f64"))?;
    let radii = read_f64s(&dir.join("radii.f64"))?;
    let colors = read_f64s(&dir.join("colors.f64"))?;
    let n = centers.len() / 3;

    // One worker thread: the render's tiles run on the pool that `install` enters.
    let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build()?;
    let (build_s, render_s, total_s, cpu_s, film) = pool.install(|| -> Result<_> {
        let start = Instant::now();
        let cpu_start = cpu_seconds()?;
        let prepared = build(centers, radii, colors)?;
        let build_s = start.elapsed().as_secs_f64();

        let camera = Camera::look_at(
            DVec3::new(0.0, 0.0, 4.0),
            DVec3::ZERO,
            DVec3::Y,
            Lens::Perspective { fov: FRAC_PI_4 },
        )?;
        let opts = RenderOptions {
            width: SIZE,
            height: SIZE,
            spp: 1,
            sampler: SamplerKind::Center,
            // gtsphere.render always returns the error channel; keep the work the same.
            aovs: Aovs {
                error: true,
                ..Aovs::default()
            },
            ..RenderOptions::default()
        };
        let before_render = Instant::now();
        // `&()` is "no progress reporting, never cancelled".
        let film = render::render(&prepared, &camera, &opts, &())?;
        let render_s = before_render.elapsed().as_secs_f64();
        let total_s = start.elapsed().as_secs_f64();
        Ok((build_s, render_s, total_s, cpu_seconds()? - cpu_start, film))
    })?;

    println!(
        "n={n} build_s={build_s:.6} render_s={render_s:.6} tile_s={:.6} total_s={total_s:.6} \
         cpu_s={cpu_s:.6} peak_rss_bytes={} checksum={:.16e}",
        film.seconds,
        peak_rss_bytes()?,
        checksum(&film),
    );
    Ok(())
}

/// The scene of the arrays with its lights, prepared for rendering. It takes the arrays by
/// value so that they are freed as soon as the scene holds its own copy of the spheres.
fn build(centers: Vec<f64>, radii: Vec<f64>, colors: Vec<f64>) -> Result<Prepared> {
    let mut scene = {
        let arrays = SphereArrays {
            centers: &centers,
            // A single value is the radius of every sphere.
            radii: match radii.as_slice() {
                &[r] => Radii::One(r),
                each => Radii::Each(each),
            },
            colors: Some(&colors),
            transparency: None,
            emissive: None,
        };
        Scene::from_arrays(&arrays)?
    };
    drop((centers, radii, colors));

    scene.headlight = false;
    scene.lights.push(Light::Point(PointLight {
        location: DVec3::new(3.0, 3.0, 3.0),
        ..PointLight::default()
    }));
    scene.lights.push(Light::Directional(DirectionalLight {
        direction: DVec3::new(-1.0, -1.0, -1.0).normalize(),
        ..DirectionalLight::default()
    }));
    Ok(render::prepare(scene, &PrepareOptions::default())?)
}

/// A file of raw little-endian `f64`s.
fn read_f64s(path: &Path) -> Result<Vec<f64>> {
    let file = File::open(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let bytes = file.metadata()?.len();
    if bytes % 8 != 0 {
        return Err(format!(
            "{}: {bytes} bytes is not a whole number of f64s",
            path.display()
        )
        .into());
    }
    let count = usize::try_from(bytes / 8)?;
    let mut reader = BufReader::new(file);
    let mut values = Vec::with_capacity(count);
    let mut word = [0u8; 8];
    for _ in 0..count {
        reader.read_exact(&mut word)?;
        values.push(f64::from_le_bytes(word));
    }
    Ok(values)
}

/// The sum of every RGB value, pixel after pixel, in order (a sequential sum, so that
/// another program summing in the same order gets the same bits).
fn checksum(film: &Film) -> f64 {
    film.rgb.iter().flatten().fold(0.0, |sum, &v| sum + v)
}

/// The CPU time the process's threads have had so far, in seconds: the sum of the first
/// field (nanoseconds on a CPU) of `/proc/self/task/*/schedstat`, Linux. Less disturbed than
/// wall time by other programs on a busy machine.
fn cpu_seconds() -> io::Result<f64> {
    let mut ns: u64 = 0;
    for task in std::fs::read_dir("/proc/self/task")? {
        let stat = std::fs::read_to_string(task?.path().join("schedstat"))?;
        ns += stat
            .split_whitespace()
            .next()
            .and_then(|v| v.parse::<u64>().ok())
            .ok_or_else(|| io::Error::other("unreadable /proc/self/task/*/schedstat"))?;
    }
    Ok(ns as f64 * 1e-9)
}

/// The process's peak resident set size (`VmHWM` in `/proc/self/status`, Linux), in bytes.
fn peak_rss_bytes() -> io::Result<u64> {
    let status = std::fs::read_to_string("/proc/self/status")?;
    status
        .lines()
        .find_map(|line| line.strip_prefix("VmHWM:"))
        .and_then(|v| v.trim().strip_suffix("kB"))
        .and_then(|kb| kb.trim().parse::<u64>().ok())
        .map(|kb| kb * 1024)
        .ok_or_else(|| io::Error::other("no VmHWM line in /proc/self/status"))
}
