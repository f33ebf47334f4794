//! Rendering: the scene is prepared once (BVH, camera, lights), then image tiles are traced in
//! parallel by the chosen integrator and averaged into a film.

pub mod breakpoints;
pub mod camera;
pub mod gas;
pub mod integrators;
pub mod light_pieces;
pub mod lighting;
pub mod lights;
pub mod quadrature;
pub mod sampler;
pub mod segments;
pub mod shadow_volume;
pub mod surfaces;
pub mod tiles;
pub mod visibility;

use std::time::{Duration, Instant};

use glam::DVec3;

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
    /// The pixel's estimated absolute error: the mean of its samples' quadrature error
    /// estimates (exact), or the standard error of its samples' mean (mc); 0 where exact.
    pub error: bool,
}

impl Aovs {
    /// Whether the centre-ray channels are wanted.
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
    /// Every sphere becomes gas of this extinction (`--as-gas`).
    pub as_gas: Option<f64>,
    /// How camera rays are integrated.
    pub integrator: Integrator,
    /// Target error of the exact integrator, relative to the pixel's value (with an absolute
    /// floor of `tol * 1e-3`).
    pub tol: f64,
    /// Render only the pixels `x0..x1, y0..y1` of the `width x height` image (`--region`,
    /// `--tile`); the result is the same as those pixels of the whole render, bit for bit.
    pub region: Option<(u32, u32, u32, u32)>,
    /// Also return the pixels in f64 (`Rendered::rgb64`, 24 bytes a pixel more), for
    /// measuring errors below f32 rounding. Default false.
    pub film_f64: bool,
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
            as_gas: None,
            integrator: Integrator::Exact,
            tol: 1e-4,
            region: None,
            film_f64: false,
        }
    }
}

/// The camera-ray integrators (MODEL.md sections 3 and 5). Only `Exact` is exact; the others
/// are named approximations for comparison and are never chosen silently.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Integrator {
    /// Closed-form emission and absorption, adaptive quadrature of single scattering between
    /// the points where the integrand has kinks, to `tol`.
    Exact,
    /// Fixed-step ray marching with midpoint samples (step in world units).
    March { step: f64 },
    /// Unbiased Monte Carlo: emission and transmittance as expected values, single scattering
    /// from one sampled collision point per gas segment, `spp` samples per pixel.
    Mc,
}

/// Work counters (STYLE habit 13), summed over tiles.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Counters {
    pub camera_rays: u64,
    pub shadow_rays: u64,
    /// Integrand evaluations of the exact integrator's quadrature.
    pub quadrature_nodes: u64,
    /// Shadowing spheres gathered for the exact integrator's segments (summed over every
    /// segment and light: the spheres whose shadow boundaries and chords it had to consider).
    pub shadow_candidates: u64,
}

impl std::ops::AddAssign for Counters {
    fn add_assign(&mut self, o: Counters) {
        self.camera_rays += o.camera_rays;
        self.shadow_rays += o.shadow_rays;
        self.quadrature_nodes += o.quadrature_nodes;
        self.shadow_candidates += o.shadow_candidates;
    }
}

/// A scene ready to trace.
pub struct Prepared {
    pub bvh: SphereBvh,
    /// The opaque surfaces other than spheres.
    pub surfaces: surfaces::Surfaces,
    /// Spheres in the scene (the `id` channel numbers surfaces after them).
    pub spheres: usize,
    pub materials: Vec<Material>,
    pub lights: Vec<LightSource>,
    pub camera: CameraSetup,
    pub background: DVec3,
    /// Gas spheres present.
    pub gas_spheres: usize,
    /// The `Integrator` and `tol` of the options.
    pub integrator: Integrator,
    pub tol: f64,
    /// The median sphere radius (sets the depth of the first shadow band, `light_pieces`).
    pub typical_radius: f64,
    /// An upper bound on the radiance anything in the scene can send along a ray (largest RGB
    /// channel): emission plus single scattering of any gas, any lit surface, the background.
    /// Behind a transmittance `T`, what is left of a camera ray adds at most `T * rest_bound`.
    pub rest_bound: f64,
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
    if let Some((x0, y0, x1, y1)) = opts.region {
        if !(x0 < x1 && y0 < y1 && x1 <= opts.width && y1 <= opts.height) {
            return Err(format!(
                "the region {x0},{y0},{x1},{y1} is empty or outside the {}x{} image",
                opts.width, opts.height
            ));
        }
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
        surfaces,
        materials,
        background,
        ..
    } = scene;
    // Gas (MODEL.md section 1): sigma = -ln(transparency) / (2 r), or --as-gas SIGMA for every
    // sphere. An ellipsoid has no single diameter; it uses its volume-equivalent radius
    // (the cube root of the product of its semi-axes), so its mean transmittance matches.
    let radius_of = |s: &crate::scene::Sphere| match s.ellipsoid {
        None => s.radius,
        Some(e) => ellipsoids[e.index()].matrix3.determinant().abs().cbrt(),
    };
    let sigma_of = |s: &crate::scene::Sphere| -> Option<f64> {
        match opts.as_gas {
            Some(sigma) => Some(sigma),
            None => {
                let m = &materials[s.material as usize];
                m.is_gas().then(|| m.sigma(radius_of(s)))
            }
        }
    };
    let gas_spheres = spheres.iter().filter(|s| sigma_of(s).is_some()).count();
    // into_iter().map().collect() reuses the spheres' allocation (a Prim is no larger than a
    // Sphere), so the million-sphere case does not hold both lists at once.
    let prims: Vec<Prim> = spheres
        .into_iter()
        .enumerate()
        .map(|(i, s)| {
            let sigma = sigma_of(&s);
            Prim {
                center: s.center,
                radius: s.radius,
                material: s.material,
                sphere: i as u32,
                ellipsoid: s.ellipsoid,
                gas: sigma.is_some(),
                sigma: sigma.unwrap_or(0.0),
            }
        })
        .collect();
    let typical_radius = median_radius(&prims);
    let surface_colors = surface_color_bound(&surfaces);
    let rest_bound = rest_bound(&materials, &lights, background, surface_colors);
    let sphere_count = prims.len();
    let bvh = SphereBvh::build(prims, &ellipsoids);
    let surfaces = surfaces::Surfaces::build(surfaces);
    Ok(Prepared {
        bvh,
        surfaces,
        spheres: sphere_count,
        materials,
        lights,
        camera,
        background,
        gas_spheres,
        integrator: opts.integrator,
        tol: opts.tol,
        typical_radius,
        rest_bound,
        prepare_time: start.elapsed(),
    })
}

/// The largest channel of any Color a triangle carries (it replaces a diffuse colour).
fn surface_color_bound(surfaces: &[crate::scene::Surface]) -> f64 {
    surfaces
        .iter()
        .filter_map(|s| match &s.shape {
            crate::scene::SurfaceShape::Triangle(t) => t.color,
            _ => None,
        })
        .flat_map(|c| c.map(|v| v.max_element()))
        .fold(0.0, f64::max)
}

/// The median radius of (up to about a thousand evenly spread) primitives; 0 for none.
fn median_radius(prims: &[Prim]) -> f64 {
    if prims.is_empty() {
        return 0.0;
    }
    let step = prims.len().div_ceil(1001);
    let mut r: Vec<f64> = prims.iter().step_by(step).map(|p| p.radius).collect();
    let mid = r.len() / 2;
    *r.select_nth_unstable_by(mid, f64::total_cmp).1
}

/// [`Prepared::rest_bound`]: the largest of the background, any material's surface radiance
/// (emission, ambient and direct terms of every light at full strength, or 1 when unlit) and
/// any material's gas source `C + p a sum_i C_i I_i` (attenuation and visibility are at most
/// 1), each channel bounded by its largest.
fn rest_bound(
    materials: &[Material],
    lights: &[LightSource],
    background: DVec3,
    surface_colors: f64,
) -> f64 {
    let direct: f64 = lights.iter().map(|l| l.direct.max_element()).sum();
    let ambient: f64 = lights.iter().map(|l| l.ambient.max_element()).sum();
    let mut bound = background.max_element();
    for m in materials {
        let (e, a, s) = (
            m.emissive.max_element(),
            m.diffuse.max_element().max(surface_colors),
            m.specular.max_element(),
        );
        let gas = e + integrators::PHASE * a * direct;
        let surface = if m.unlit {
            a
        } else {
            e + ambient * m.ambient_intensity * a + direct * (a + s)
        };
        bound = bound.max(gas).max(surface);
    }
    bound
}
