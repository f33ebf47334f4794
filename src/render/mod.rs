//! Rendering: the scene is prepared once (BVH, camera, lights), then image tiles are traced in
//! parallel by the chosen integrator and averaged into a film.

pub mod camera;
pub mod integrators;
pub mod lighting;
pub mod lights;
pub mod sampler;
pub mod tiles;
pub mod visibility;

use std::time::{Duration, Instant};

use glam::DVec3;

use crate::accel::bvh::GAS;
use crate::accel::{Prim, SphereBvh};
use crate::scene::{Material, Scene};
pub use camera::{CameraChoice, CameraSetup, Projection};
pub use lights::LightSource;
pub use sampler::SamplerKind;

/// Which per-pixel extra channels (EXR only) to produce, from the ray through the pixel's
/// centre: `depth` (ray parameter of the first opaque hit, +inf on a miss), `normal` (world
/// unit normal, 0 on a miss), `id` (index of the sphere in file order, -1 on a miss).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Aovs {
    pub depth: bool,
    pub normal: bool,
    pub id: bool,
}

impl Aovs {
    pub fn any(&self) -> bool {
        self.depth || self.normal || self.id
    }
}

/// Everything a render needs to know, validated (the library's config, built from CLI args).
#[derive(Clone, Debug, PartialEq)]
pub struct RenderOptions {
    pub width: u32,
    pub height: u32,
    /// Samples per pixel (ignored by the centre sampler).
    pub spp: u32,
    pub seed: u64,
    pub sampler: SamplerKind,
    pub camera: CameraChoice,
    pub projection: Projection,
    pub aovs: Aovs,
    /// Show a progress bar (only drawn when stderr is a terminal).
    pub progress: bool,
}

impl Default for RenderOptions {
    fn default() -> Self {
        RenderOptions {
            width: 800,
            height: 600,
            spp: 16,
            seed: 0,
            sampler: SamplerKind::Stratified,
            camera: CameraChoice::Auto,
            projection: Projection::Perspective,
            aovs: Aovs::default(),
            progress: false,
        }
    }
}

/// Work counters (STYLE habit 13), summed over tiles.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Counters {
    pub camera_rays: u64,
    pub shadow_rays: u64,
}

impl std::ops::AddAssign for Counters {
    fn add_assign(&mut self, o: Counters) {
        self.camera_rays += o.camera_rays;
        self.shadow_rays += o.shadow_rays;
    }
}

/// A scene ready to trace.
pub struct Prepared {
    pub bvh: SphereBvh,
    pub materials: Vec<Material>,
    pub lights: Vec<LightSource>,
    pub camera: CameraSetup,
    pub background: DVec3,
    /// Gas spheres present (not drawn by the surface integrator).
    pub gas_spheres: usize,
    /// Wall time of `prepare` (BVH build included).
    pub prepare_time: Duration,
}

/// Builds the BVH, camera and light list. Consumes the scene: its sphere list becomes the
/// BVH's primitive list, so the spheres are not held twice.
pub fn prepare(scene: Scene, opts: &RenderOptions) -> Result<Prepared, String> {
    let start = Instant::now();
    if opts.width == 0 || opts.height == 0 {
        return Err(format!(
            "the image size {}x{} is empty",
            opts.width, opts.height
        ));
    }
    let camera = camera::setup(
        &scene,
        &opts.camera,
        opts.projection,
        opts.width,
        opts.height,
    )?;
    let lights = lights::collect(&scene, camera.camera.forward);
    let Scene {
        spheres,
        ellipsoids,
        materials,
        background,
        ..
    } = scene;
    let gas_spheres = spheres
        .iter()
        .filter(|s| materials[s.material as usize].is_gas())
        .count();
    // into_iter().map().collect() reuses the spheres' allocation (a Prim is no larger than a
    // Sphere), so the million-sphere case does not hold both lists at once.
    let prims: Vec<Prim> = spheres
        .into_iter()
        .enumerate()
        .map(|(i, s)| Prim {
            center: s.center,
            radius: s.radius,
            material: s.material,
            sphere: i as u32,
            ellipsoid: s.ellipsoid,
            flags: if materials[s.material as usize].is_gas() {
                GAS
            } else {
                0
            },
        })
        .collect();
    let bvh = SphereBvh::build(prims, &ellipsoids);
    Ok(Prepared {
        bvh,
        materials,
        lights,
        camera,
        background,
        gas_spheres,
        prepare_time: start.elapsed(),
    })
}
