//! The generated scenes of the benchmarks, in one place: `gtsphere bench` and its
//! subcommands, `cargo bench` and the tests all build them from here, so a number measured
//! by one is about the scene the others check. Each is deterministic (a fixed seed), the same
//! on every call and every machine.
//!
//! - [`write_particles`]: `bench parse`'s VRML text of N particles, in a [`Layout`].
//! - [`write_table`]: `bench convert`'s particle CSV of N rows.
//! - [`random_spheres`]: `bench trace`'s N random opaque spheres (also benches/embree's).
//! - [`gas_cloud`], [`lit_gas`]: `bench gas`'s lit gas scene, and `gtsphere bench`'s emission
//!   scene.
//! - [`cloud`]: `bench gas --scaling`'s clouds of N gas spheres, [`Cloud::Thick`] or
//!   [`Cloud::Thin`].

use std::io::Write;

use glam::{DQuat, DVec3};

use crate::render::sampler::mix;
use crate::scene::{
    DirectionalLight, Light, Material, MaterialTable, Origin, Paint, PointLight, Profile, Scene,
    Viewpoint,
};

/// How the particles are laid out in the file.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Layout {
    /// A million top-level Transforms.
    Flat,
    /// A million children of one Group (what VMD-style exporters write).
    Group,
}

/// Deterministic pseudo-random numbers in [0, 1) (xorshift64*: fast, good enough for
/// generated test geometry), the same sequence on every call.
fn unit_random() -> impl FnMut() -> f64 {
    let mut state: u64 = 0x9E37_79B9_7F4A_7C15;
    move || {
        state ^= state >> 12;
        state ^= state << 25;
        state ^= state >> 27;
        (state.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// Writes `n` particles: `Transform { translation .. children Shape { appearance Appearance {
/// material Material { diffuseColor .. } } geometry Sphere { radius .. } } }`, with
/// deterministic pseudo-random positions, colours and radii.
pub fn write_particles(out: &mut impl Write, n: usize, layout: Layout) -> std::io::Result<()> {
    writeln!(out, "#VRML V2.0 utf8")?;
    if layout == Layout::Group {
        writeln!(out, "Group {{ children [")?;
    }
    let mut next = unit_random();
    let radius = 0.6 * (n.max(1) as f64).powf(-1.0 / 3.0);
    for _ in 0..n {
        let (x, y, z) = (2.0 * next() - 1.0, 2.0 * next() - 1.0, 2.0 * next() - 1.0);
        let (r, g, b) = (next(), next(), next());
        let rad = radius * (0.5 + next());
        writeln!(
            out,
            "Transform {{ translation {x:.6} {y:.6} {z:.6} children Shape {{ appearance Appearance {{ material Material {{ diffuseColor {r:.3} {g:.3} {b:.3} }} }} geometry Sphere {{ radius {rad:.5} }} }} }}"
        )?;
    }
    if layout == Layout::Group {
        writeln!(out, "] }}")?;
    }
    Ok(())
}

/// How [`write_table`] writes colours.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TableColours {
    /// 0-255 integers: few distinct colours, as a palette gives.
    Bytes,
    /// 0-1 with 6 decimals: a colour of its own per particle, as a colour map gives.
    Continuous,
}

/// Writes `n` rows `x,y,z,radius,red,green,blue`: positions in [-1,1]^3 with 6 decimals, radii
/// near `0.6 n^(-1/3)`, colours as `colours` says (deterministic pseudo-random values).
pub fn write_table(out: &mut impl Write, n: usize, colours: TableColours) -> std::io::Result<()> {
    writeln!(out, "x,y,z,radius,red,green,blue")?;
    let mut next = unit_random();
    let radius = 0.6 * (n.max(1) as f64).powf(-1.0 / 3.0);
    for _ in 0..n {
        let (x, y, z) = (2.0 * next() - 1.0, 2.0 * next() - 1.0, 2.0 * next() - 1.0);
        let rad = radius * (0.5 + next());
        let (r, g, b) = (next(), next(), next());
        match colours {
            TableColours::Bytes => {
                let byte = |c: f64| (c * 256.0) as u8;
                let (r, g, b) = (byte(r), byte(g), byte(b));
                writeln!(out, "{x:.6},{y:.6},{z:.6},{rad:.5},{r},{g},{b}")?;
            }
            TableColours::Continuous => {
                writeln!(out, "{x:.6},{y:.6},{z:.6},{rad:.5},{r:.6},{g:.6},{b:.6}")?;
            }
        }
    }
    Ok(())
}

/// `bench trace`'s scene with `n` spheres (the same as `benches/embree/`, so the two can be
/// run side by side): centres uniform in `[-1,1]^3` from SplitMix64 seeded with 1 (x, y, z
/// drawn in that order per sphere, `u = (next >> 11) * 2^-53`, centre `2u - 1`), radius
/// `0.6 N^(-1/3)`; camera at (0,0,4) looking down -z with fieldOfView 0.785398; a PointLight
/// at (3,3,3) and a DirectionalLight along (-1,-1,-1), headlight off.
#[allow(
    clippy::approx_constant,
    reason = "fieldOfView 0.785398 is the benchmark's stated value, as the Embree side uses it"
)]
pub fn random_spheres(n: usize) -> Scene {
    let mut state: u64 = 1;
    let mut next = || {
        state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        (mix(state) >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    };
    let radius = 0.6 * (n.max(1) as f64).powf(-1.0 / 3.0);
    let mut scene = Scene {
        headlight: false,
        ..Scene::default()
    };
    scene.materials.add(&Material::unlit());
    scene.spheres.reserve_exact(n);
    for _ in 0..n {
        let (x, y, z) = (next(), next(), next());
        let center = DVec3::new(2.0 * x - 1.0, 2.0 * y - 1.0, 2.0 * z - 1.0);
        scene.add_sphere(center, radius, &Material::default());
    }
    scene.lights.push(Light::Point(PointLight {
        location: DVec3::new(3.0, 3.0, 3.0),
        radius: f64::INFINITY,
        ..PointLight::default()
    }));
    scene.lights.push(Light::Directional(DirectionalLight {
        direction: DVec3::new(-1.0, -1.0, -1.0).normalize(),
        ..DirectionalLight::default()
    }));
    scene.viewpoints.push(Viewpoint {
        name: None,
        description: "bench".into(),
        position: DVec3::new(0.0, 0.0, 4.0),
        orientation: DQuat::IDENTITY,
        field_of_view: 0.785398,
        origin: Origin::default(),
    });
    scene
}

/// `bench gas`'s lit gas scene with `n` gas spheres ([`gas_cloud`] with lights).
pub fn lit_gas(n: usize) -> Scene {
    gas_cloud(n, true)
}

/// `n` gas spheres: centres uniform in `[-1,1]^3` (SplitMix64 seeded with 7), radii
/// `0.9 N^(-1/3)` times a factor in [0.6, 1.4), transparency in [0.3, 0.9), emission a warm
/// colour scaled by 0.3, albedo 0.8; with `lit`, two opaque spheres, a PointLight at
/// (0.3, 0.5, 0.2) inside the cloud and a DirectionalLight along (-1, -0.6, -0.4); camera at
/// (0, 0, 4.5) looking down -z, fieldOfView 0.7; headlight off. Without `lit`, no lights and
/// no opaque spheres (only emission and absorption: the `emission` scene of `gtsphere
/// bench`).
pub fn gas_cloud(n: usize, lit: bool) -> Scene {
    gas_cloud_with(n, lit, |_| Profile::Constant)
}

/// [`gas_cloud`] with density profiles (docs/model.md section 6): gas sphere `i` has `profile(i)`
/// and otherwise the same values (the same `transparency`, so the same diameter
/// transmittance).
pub fn gas_cloud_with(n: usize, lit: bool, profile: impl Fn(usize) -> Profile) -> Scene {
    let mut state: u64 = 7;
    let mut next = || {
        state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        (mix(state) >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    };
    let mut scene = Scene {
        headlight: false,
        background: DVec3::new(0.02, 0.02, 0.03),
        ..Scene::default()
    };
    scene.materials.add(&Material::unlit());
    let opaque = Material {
        diffuse: DVec3::new(0.8, 0.8, 0.8),
        specular: DVec3::splat(0.3),
        ..Material::default()
    };
    scene.materials.add(&opaque);
    let base = 0.9 * (n.max(1) as f64).powf(-1.0 / 3.0);
    for i in 0..n {
        let c = DVec3::new(next(), next(), next()) * 2.0 - 1.0;
        let radius = base * (0.6 + 0.8 * next());
        let warm = DVec3::new(1.0, 0.55 + 0.3 * next(), 0.2 + 0.3 * next());
        let gas = Material {
            diffuse: DVec3::splat(0.8),
            emissive: warm * 0.3,
            specular: DVec3::ZERO,
            shininess: 0.2,
            ambient_intensity: 0.2,
            transparency: 0.3 + 0.6 * next(),
            profile: profile(i),
            ..Material::default()
        };
        scene.add_sphere(c, radius, &gas);
    }
    if !lit {
        scene.viewpoints.push(bench_view());
        return scene;
    }
    for (c, r) in [
        (DVec3::new(-0.4, -0.3, 0.1), 0.3),
        (DVec3::new(0.5, 0.2, -0.5), 0.25),
    ] {
        scene.add_sphere(c, r, &opaque);
    }
    scene.lights.push(Light::Point(PointLight {
        location: DVec3::new(0.3, 0.5, 0.2),
        color: DVec3::new(1.0, 0.9, 0.8),
        ..PointLight::default()
    }));
    scene.lights.push(Light::Directional(DirectionalLight {
        direction: DVec3::new(-1.0, -0.6, -0.4).normalize(),
        color: DVec3::new(0.7, 0.8, 1.0),
        ambient_intensity: 0.1,
        ..DirectionalLight::default()
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

/// The two clouds of the scaling table.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Cloud {
    /// Optical depth 4 along a diameter (transparency exp(-4)).
    Thick,
    /// Transparency 0.9 (optical depth 0.105 along a diameter).
    Thin,
}

impl Cloud {
    /// Its name, `thick` or `thin`, as the scaling benchmark prints it and names its files.
    pub fn name(self) -> &'static str {
        match self {
            Cloud::Thick => "thick",
            Cloud::Thin => "thin",
        }
    }
    /// Its spheres' transparency: the transmittance along a diameter.
    pub fn transparency(self) -> f64 {
        match self {
            Cloud::Thick => (-4.0f64).exp(),
            Cloud::Thin => 0.9,
        }
    }
}

/// Albedos of the clouds: 16 colours spread over hue and brightness (linear RGB in
/// [0.2, 0.95]), so that every channel's scattering differs from sphere to sphere.
fn palette(k: usize) -> DVec3 {
    let f = |x: f64| 0.2 + 0.75 * x.fract();
    let k = k as f64;
    DVec3::new(
        f(k * 0.618_034 + 0.1),
        f(k * 0.381_966 + 0.45),
        f(k * 0.723_607 + 0.8),
    )
}

/// Colours of the clouds.
pub const CLOUD_COLOURS: usize = 16;

/// cloud-N: `bench trace`'s N centres (uniform in `[-1,1]^3`, SplitMix64 seeded with 1, so
/// also benches/embree's), radius `0.6 N^(-1/3)`, every sphere gas of transparency
/// [`Cloud::transparency`] and emission 0, albedo (diffuseColor) one of 16 colours picked by
/// a hash of the sphere's index; `PointLight { location 3 3 3 intensity 0.8 }`,
/// `DirectionalLight { direction -1 -1 -1 intensity 0.5 }`, headlight off, `Viewpoint {
/// position 0 0 4 fieldOfView 0.785398 }`, background black.
pub fn cloud(n: usize, kind: Cloud) -> Scene {
    let mut scene = random_spheres(n);
    scene.materials = MaterialTable::new();
    let paints: Vec<Paint> = (0..CLOUD_COLOURS)
        .map(|k| {
            scene.materials.add(&Material {
                diffuse: palette(k),
                emissive: DVec3::ZERO,
                specular: DVec3::ZERO,
                transparency: kind.transparency(),
                ..Material::default()
            })
        })
        .collect();
    for (i, s) in scene.spheres.iter_mut().enumerate() {
        let p = paints[(mix(i as u64 ^ 0xC10D) % CLOUD_COLOURS as u64) as usize];
        (s.material, s.color) = (p.material, p.color);
    }
    scene.lights = vec![
        // The VRML default radius 100: every sphere is within 6 of the light.
        Light::Point(PointLight {
            location: DVec3::new(3.0, 3.0, 3.0),
            intensity: 0.8,
            ..PointLight::default()
        }),
        Light::Directional(DirectionalLight {
            direction: DVec3::new(-1.0, -1.0, -1.0).normalize(),
            intensity: 0.5,
            ..DirectionalLight::default()
        }),
    ];
    scene
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::vrml::{load_str, LoadOptions};

    #[test]
    fn a_written_cloud_reads_back_as_the_same_scene() {
        for kind in [Cloud::Thick, Cloud::Thin] {
            let a = cloud(300, kind);
            let mut text = Vec::new();
            crate::vrml::write::write_scene(&a, &mut text).unwrap();
            let text = String::from_utf8(text).unwrap();
            let (b, report) = load_str("cloud.wrl", &text, &LoadOptions::default()).unwrap();
            assert!(report.warnings.is_empty());
            assert_eq!(a.spheres.len(), b.spheres.len());
            for (s, t) in a.spheres.iter().zip(&b.spheres) {
                assert_eq!((s.center, s.radius), (t.center, t.radius));
                assert_eq!(a.material_of(s), b.material_of(t));
            }
            assert_eq!(
                (a.headlight, a.background, a.viewpoints[0].position),
                (b.headlight, b.background, b.viewpoints[0].position)
            );
            assert_eq!(a.viewpoints[0].field_of_view, b.viewpoints[0].field_of_view);
            assert_eq!(a.lights.len(), b.lights.len());
            for (l, m) in a.lights.iter().zip(&b.lights) {
                match (l, m) {
                    (Light::Point(p), Light::Point(q)) => assert_eq!(
                        PointLight {
                            origin: Origin::default(),
                            ..*q
                        },
                        *p
                    ),
                    (Light::Directional(p), Light::Directional(q)) => {
                        // A top-level light lights every sphere, however the range is spelt.
                        assert!(q.scope.covers_all(b.spheres.len()));
                        assert_eq!(
                            (p.direction, p.color, p.intensity, p.ambient_intensity, p.on),
                            (q.direction, q.color, q.intensity, q.ambient_intensity, q.on)
                        );
                    }
                    _ => panic!("lights in another order: {l:?} {m:?}"),
                }
            }
        }
    }

    #[test]
    fn clouds_are_as_described() {
        let n = 1000;
        let thick = cloud(n, Cloud::Thick);
        let trace = random_spheres(n);
        let r = 0.6 * (n as f64).powf(-1.0 / 3.0);
        for (s, t) in thick.spheres.iter().zip(&trace.spheres) {
            assert_eq!((s.center, s.radius), (t.center, r));
            let m = thick.material_of(s);
            // Optical depth 4 along a diameter.
            assert!((m.sigma(s.radius) * 2.0 * s.radius - 4.0).abs() < 1e-12);
        }
        let used: std::collections::HashSet<crate::scene::Color> =
            thick.spheres.iter().map(|s| s.color).collect();
        assert_eq!(used.len(), CLOUD_COLOURS, "every colour is used");
        let thin = cloud(n, Cloud::Thin);
        assert!(thin
            .materials
            .records()
            .iter()
            .all(|m| m.transparency == 0.9));
    }
}
