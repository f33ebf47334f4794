//! `gtsphere bench gas`: time against error for the three gas integrators on a lit gas scene
//! (issue 4): N gas spheres at S x S pixels, one ray (or, for mc, `spp` paths) through each
//! pixel centre, so that only the integration error is measured, against a reference
//! rendered by `exact` at a tolerance 1000 times tighter than the tightest one measured.
//! The measuring is `gtsphere bench`'s (src/cli/bench_report.rs), on this one scene.
//!
//! Scene: centres uniform in `[-1,1]^3` (SplitMix64 seeded with 7), radii `0.9 N^(-1/3)` times
//! a factor in [0.6, 1.4), transparency in [0.3, 0.9), emission a warm colour scaled by 0.3,
//! albedo 0.8; two opaque spheres; a PointLight at (0.3, 0.5, 0.2) inside the cloud and a
//! DirectionalLight along (-1, -0.6, -0.4); camera at (0, 0, 4.5) looking down -z,
//! fieldOfView 0.7; headlight off.

use std::process::ExitCode;

use glam::{DQuat, DVec3};

use super::bench_report::{goals, run_scene, table, BenchScene, Case};
use crate::error::Error;
use crate::scene::{
    DirectionalLight, Light, Material, Origin, PointLight, Scene, Sphere, Viewpoint,
};

/// The benchmark's lit gas scene with `n` gas spheres.
pub fn lit_gas(n: usize) -> Scene {
    gas_cloud(n, true)
}

/// `n` gas spheres as described above; without `lit`, no lights and no opaque spheres (only
/// emission and absorption: the `emission` scene of `gtsphere bench`).
pub fn gas_cloud(n: usize, lit: bool) -> Scene {
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
    if !lit {
        scene.viewpoints.push(bench_view());
        return scene;
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
    scene.viewpoints.push(bench_view());
    scene
}

fn bench_view() -> Viewpoint {
    Viewpoint {
        name: None,
        description: "bench".into(),
        position: DVec3::new(0.0, 0.0, 4.5),
        orientation: DQuat::IDENTITY,
        field_of_view: 0.7,
        origin: Origin::default(),
    }
}

pub fn run(n: usize, size: u32, threads: usize) -> Result<ExitCode, Error> {
    if n == 0 || size == 0 || threads == 0 {
        return Err(Error::Other(
            "--spheres, --size and --threads must be positive".into(),
        ));
    }
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
    print!("{}", goals(&rows));
    Ok(ExitCode::SUCCESS)
}
