//! `gtsphere bench gas`: time against error for the three gas integrators on a lit gas scene
//! (issue 4): N gas spheres at S x S pixels, one ray (or, for mc, `spp` paths) through each
//! pixel centre, so that only the integration error is measured, against a reference
//! rendered by `exact` at a tolerance 1000 times tighter than the tightest one measured.
//!
//! Scene: centres uniform in `[-1,1]^3` (SplitMix64 seeded with 7), radii `0.9 N^(-1/3)` times
//! a factor in [0.6, 1.4), transparency in [0.3, 0.9), emission a warm colour scaled by 0.3,
//! albedo 0.8; two opaque spheres; a PointLight at (0.3, 0.5, 0.2) inside the cloud and a
//! DirectionalLight along (-1, -0.6, -0.4); camera at (0, 0, 4.5) looking down -z,
//! fieldOfView 0.7; headlight off.

use std::process::ExitCode;

use glam::{DQuat, DVec3};

use crate::error::Error;
use crate::output::Image;
use crate::render::{prepare, tiles::render, Integrator, RenderOptions, SamplerKind};
use crate::scene::{
    DirectionalLight, Light, Material, Origin, PointLight, Scene, Sphere, Viewpoint,
};

/// The benchmark's lit gas scene with `n` gas spheres.
pub fn lit_gas(n: usize) -> Scene {
    let mut state: u64 = 7;
    let mut next = || {
        state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        (crate::render::sampler::mix(state) >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    };
    let mut scene = Scene {
        headlight: false,
        background: DVec3::new(0.02, 0.02, 0.03),
        ..Scene::default()
    };
    scene.materials.push(Material::unlit());
    let opaque = Material {
        diffuse: DVec3::new(0.8, 0.8, 0.8),
        specular: DVec3::splat(0.3),
        ..Material::default()
    };
    scene.materials.push(opaque);
    let base = 0.9 * (n.max(1) as f64).powf(-1.0 / 3.0);
    for _ in 0..n {
        let c = DVec3::new(next(), next(), next()) * 2.0 - 1.0;
        let radius = base * (0.6 + 0.8 * next());
        let warm = DVec3::new(1.0, 0.55 + 0.3 * next(), 0.2 + 0.3 * next());
        scene.materials.push(Material {
            diffuse: DVec3::splat(0.8),
            emissive: warm * 0.3,
            specular: DVec3::ZERO,
            shininess: 0.2,
            ambient_intensity: 0.2,
            transparency: 0.3 + 0.6 * next(),
            unlit: false,
        });
        scene.spheres.push(Sphere {
            center: c,
            radius,
            material: scene.materials.len() as u32 - 1,
            ellipsoid: crate::scene::NO_ELLIPSOID,
            origin: Origin::default(),
        });
    }
    for (c, r) in [
        (DVec3::new(-0.4, -0.3, 0.1), 0.3),
        (DVec3::new(0.5, 0.2, -0.5), 0.25),
    ] {
        scene.spheres.push(Sphere {
            center: c,
            radius: r,
            material: 1,
            ellipsoid: crate::scene::NO_ELLIPSOID,
            origin: Origin::default(),
        });
    }
    scene.lights.push(Light::Point(PointLight {
        location: DVec3::new(0.3, 0.5, 0.2),
        color: DVec3::new(1.0, 0.9, 0.8),
        intensity: 1.0,
        ambient_intensity: 0.0,
        attenuation: DVec3::new(1.0, 0.0, 0.0),
        radius: 100.0,
        on: true,
        origin: Origin::default(),
    }));
    scene.lights.push(Light::Directional(DirectionalLight {
        direction: DVec3::new(-1.0, -0.6, -0.4).normalize(),
        color: DVec3::new(0.7, 0.8, 1.0),
        intensity: 1.0,
        ambient_intensity: 0.1,
        on: true,
        scope: (0, u32::MAX),
        origin: Origin::default(),
    }));
    scene.viewpoints.push(Viewpoint {
        name: None,
        description: "bench".into(),
        position: DVec3::new(0.0, 0.0, 4.5),
        orientation: DQuat::IDENTITY,
        field_of_view: 0.7,
        origin: Origin::default(),
    });
    scene
}

/// Renders the bench scene; returns the image and the wall time of the tile loop.
fn run_one(
    n: usize,
    size: u32,
    integrator: Integrator,
    tol: f64,
    spp: u32,
) -> Result<(Image, f64), Error> {
    let opts = RenderOptions {
        width: size,
        height: size,
        spp,
        sampler: SamplerKind::Center,
        integrator,
        tol,
        ..RenderOptions::default()
    };
    let prep = prepare(lit_gas(n), &opts).map_err(Error::Other)?;
    let done = render(&prep, &opts);
    Ok((done.image, done.seconds))
}

/// Relative RMS error of `img` against `reference`: sqrt(mean |x - ref|^2) / sqrt(mean |ref|^2)
/// over all channels.
pub fn relative_rms(img: &Image, reference: &Image) -> f64 {
    let (mut num, mut den) = (0.0, 0.0);
    for (a, b) in img.rgb.iter().zip(&reference.rgb) {
        for k in 0..3 {
            let (x, y) = (f64::from(a[k]), f64::from(b[k]));
            num += (x - y) * (x - y);
            den += y * y;
        }
    }
    (num / den.max(f64::MIN_POSITIVE)).sqrt()
}

pub fn run(n: usize, size: u32, threads: usize) -> Result<ExitCode, Error> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| Error::Other(format!("cannot start worker threads: {e}")))?;
    pool.install(|| {
        let tightest = 1e-6;
        let (reference, ref_s) = run_one(n, size, Integrator::Exact, tightest * 1e-3, 1)?;
        println!(
            "reference: exact at tol {:e}, {:.1} s; {n} gas spheres, {size}x{size}, {threads} threads\n",
            tightest * 1e-3,
            ref_s
        );
        println!("| integrator | parameter | seconds | relative RMS error |");
        println!("|---|---|---:|---:|");
        let mut rows: Vec<(String, f64, f64)> = Vec::new();
        for tol in [1e-2, 1e-3, 1e-4, 1e-5, tightest] {
            let (img, s) = run_one(n, size, Integrator::Exact, tol, 1)?;
            let e = relative_rms(&img, &reference);
            println!("| exact | tol {tol:e} | {s:.2} | {e:.2e} |");
            rows.push(("exact".into(), s, e));
        }
        let mut step = 0.2;
        for _ in 0..7 {
            let (img, s) = run_one(n, size, Integrator::March { step }, 0.0, 1)?;
            let e = relative_rms(&img, &reference);
            println!("| march | step {step} | {s:.2} | {e:.2e} |");
            rows.push(("march".into(), s, e));
            step /= 4.0;
        }
        for spp in [4, 16, 64, 256] {
            let (img, s) = run_one(n, size, Integrator::Mc, 0.0, spp)?;
            let e = relative_rms(&img, &reference);
            println!("| mc | {spp} paths/pixel | {s:.2} | {e:.2e} |");
            rows.push(("mc".into(), s, e));
        }
        let first = |name: &str| {
            rows.iter()
                .filter(|r| r.0 == name && r.2 <= 1e-4)
                .map(|r| r.1)
                .fold(f64::INFINITY, f64::min)
        };
        let (ex, ma) = (first("exact"), first("march"));
        println!(
            "\ntime to reach 1e-4 relative RMS error: exact {}, march {}{}",
            if ex.is_finite() { format!("{ex:.2} s") } else { "not reached".into() },
            if ma.is_finite() { format!("{ma:.2} s") } else { "not reached in the steps tried".into() },
            if ex.is_finite() && ma.is_finite() {
                format!(" (march / exact = {:.1}x)", ma / ex)
            } else {
                String::new()
            }
        );
        Ok(ExitCode::SUCCESS)
    })
}
