//! Rendering: the scene is prepared once ([`prepare`]: BVHs, materials, lights), then each
//! picture ([`render()`]: a camera and [`RenderOptions`]) is traced in parallel tiles by the
//! chosen integrator and averaged into a [`Film`].

pub mod ao;
pub(crate) mod breakpoints;
pub(crate) mod camera;
mod copies;
pub(crate) mod density;
pub(crate) mod film;
pub(crate) mod gas;
pub(crate) mod integrators;
pub(crate) mod light_grid;
pub(crate) mod light_pieces;
pub(crate) mod lighting;
pub(crate) mod lights;
pub mod limits;
pub(crate) mod packets;
pub mod particle_ao;
pub(crate) mod profile;
pub(crate) mod quadrature;
pub(crate) mod sampler;
pub(crate) mod segments;
pub(crate) mod shadow_volume;
pub(crate) mod surfaces;
pub(crate) mod tiles;
pub(crate) mod view;
pub(crate) mod visibility;

use std::time::{Duration, Instant};

use glam::DVec3;

use crate::accel::{Packed, SphereBvh};
use crate::scene::{Bounds, EllipsoidId, Light, MaterialTable, Scene, Viewpoint};
use crate::Error;
pub use camera::{pymol_export, Camera, CameraChoice, FovAcross, ImagePlane, Lens, Projection};
pub use film::Film;
pub use sampler::SamplerKind;
pub use tiles::{render, render_view, Cancel, Progress};
pub use view::View;

/// Which per-pixel extra channels to keep in the [`Film`] (and write to EXR), from the ray
/// through the pixel's centre: `depth` (ray parameter of the first opaque hit, +inf on a
/// miss), `normal` (world unit normal, 0 on a miss), `id` (index of the sphere in file order,
/// then the other surfaces; -1 on a miss).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Aovs {
    /// Keep the `depth` channel.
    pub depth: bool,
    /// Keep the `normal` channel.
    pub normal: bool,
    /// Keep the `id` channel.
    pub id: bool,
    /// The pixel's estimated absolute error: the mean of its samples' quadrature error
    /// estimates (exact), or the standard error of its samples' mean (mc, AO by `mc`); 0
    /// where exact, and for the deterministic AO approximations, whose error is not estimated.
    pub error: bool,
    /// Exact ambient occlusion at the centre ray's first opaque hit (the model's section 11,
    /// with [`RenderOptions::ao`]'s reach and weighting; NaN on a miss), beside whatever the
    /// integrator draws.
    pub ao: bool,
}

impl Aovs {
    /// Whether the centre-ray channels are wanted.
    pub fn any(&self) -> bool {
        self.depth || self.normal || self.id || self.ao
    }
}

/// How one picture is rendered, validated by [`Prepared::view`] (the library's config, built
/// from CLI arguments or Python keywords). The camera is given beside it.
#[derive(Clone, Debug, PartialEq)]
pub struct RenderOptions {
    /// Image width in pixels, positive.
    pub width: u32,
    /// Image height in pixels, positive.
    pub height: u32,
    /// Samples per pixel (ignored by the centre sampler).
    pub spp: u32,
    /// Seed of the random numbers; with it, a pixel's samples are the same on any thread count.
    pub seed: u64,
    /// Where in each pixel the samples lie.
    pub sampler: SamplerKind,
    /// Which extra channels to keep beside the colour.
    pub aovs: Aovs,
    /// How camera rays are integrated.
    pub integrator: Integrator,
    /// Target error of the exact integrator, relative to the pixel's value (with an absolute
    /// floor of `tol * 1e-3`).
    pub tol: f64,
    /// Render only the pixels `x0..x1, y0..y1` of the `width x height` image (`--region`,
    /// `--tile`); the result is the same as those pixels of the whole render, bit for bit.
    pub region: Option<(u32, u32, u32, u32)>,
    /// The headlight as a strict DirectionalLight along the view, casting shadows
    /// (`--headlight-shadows`); by default it is carried by the viewer and casts none
    /// (docs/model.md section 1).
    pub headlight_shadows: bool,
    /// The reach and weighting of the `ao` channel ([`Aovs::ao`]; its method is always the
    /// exact one).
    pub ao: ao::AoSettings,
}

impl Default for RenderOptions {
    fn default() -> Self {
        RenderOptions {
            width: 800,
            height: 600,
            spp: 16,
            seed: 0,
            sampler: SamplerKind::Stratified,
            aovs: Aovs::default(),
            integrator: Integrator::Exact,
            tol: 1e-4,
            region: None,
            headlight_shadows: false,
            ao: ao::AoSettings::default(),
        }
    }
}

/// How a scene is prepared: what is fixed once the BVH is built.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PrepareOptions {
    /// Every sphere becomes gas of this extinction (`--as-gas`).
    pub as_gas: Option<f64>,
    /// Every gas sphere takes this density profile (`--profile`), whatever its material says.
    pub profile: Option<crate::scene::Profile>,
}

/// The camera-ray integrators (docs/model.md sections 3 and 5). Only `Exact` is exact; the others
/// are named approximations for comparison and are never chosen silently.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Integrator {
    /// Closed-form emission and absorption, adaptive quadrature of single scattering between
    /// the points where the integrand has kinks, to `tol`.
    Exact,
    /// Fixed-step ray marching with midpoint samples (step in world units).
    March {
        /// The step length, in world units, positive and finite.
        step: f64,
    },
    /// Unbiased Monte Carlo: emission and transmittance as expected values, single scattering
    /// from one sampled collision point per gas segment, `spp` samples per pixel.
    Mc,
    /// Ambient occlusion as the picture: the unoccluded fraction at each camera ray's first
    /// opaque hit, exact for opaque spheres (docs/model.md section 11) or by a named
    /// approximation ([`ao::AoMethod`]).
    Ao(ao::AoSettings),
}

/// Work counters, summed over tiles.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Counters {
    /// Camera rays traced.
    pub camera_rays: u64,
    /// Shadow rays traced.
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

/// A scene ready to trace from any camera: the BVHs, the materials and the lights. Built
/// once by [`prepare`]; [`render()`] takes it with a camera, so a turntable builds one BVH.
///
/// ```
/// use gtsphere::render::{self, Camera, Lens, PrepareOptions, RenderOptions};
/// use gtsphere::scene::{Radii, Scene, SphereArrays};
/// use glam::DVec3;
///
/// let centers = [0.0, 0.0, 0.0, 1.5, 0.0, 0.0];
/// let scene = Scene::from_arrays(&SphereArrays::new(&centers, Radii::One(0.5))).unwrap();
/// let prepared = render::prepare(scene, &PrepareOptions::default()).unwrap();
/// let opts = RenderOptions { width: 32, height: 24, spp: 1, ..RenderOptions::default() };
/// for k in 0..3 {
///     let a = k as f64 * 2.0 * std::f64::consts::PI / 3.0;
///     let eye = DVec3::new(0.75 + 5.0 * a.sin(), 0.0, 5.0 * a.cos());
///     let cam = Camera::look_at(eye, DVec3::new(0.75, 0.0, 0.0), DVec3::Y, Lens::default())
///         .unwrap();
///     let film = render::render(&prepared, &cam, &opts, &()).unwrap();
///     assert_eq!(film.rgb.len(), 32 * 24);
/// }
/// ```
pub struct Prepared {
    /// The BVH over the spheres and ellipsoids, opaque and gas.
    pub(crate) bvh: SphereBvh,
    /// The opaque surfaces other than spheres.
    pub(crate) surfaces: surfaces::Surfaces,
    /// Spheres in the scene (the `id` channel numbers surfaces after them).
    pub spheres: usize,
    /// Opaque spheres dropped as copies of one before them (see `render::copies`): (the
    /// copy's index in the scene, the index of the sphere kept in its place), in the scene's
    /// order.
    pub(crate) copies: Vec<(u32, u32)>,
    /// The scene's material records, indexed by each item's `material`
    /// ([`Sphere::material`](crate::scene::Sphere::material)).
    pub materials: MaterialTable,
    /// The scene's lights; they may be changed between renders (they are not in the BVH).
    pub lights: Vec<Light>,
    /// Whether a headlight (a white DirectionalLight along each camera's view) is added.
    pub headlight: bool,
    /// The scene's Viewpoints, for cameras chosen after the scene was prepared.
    pub viewpoints: Vec<Viewpoint>,
    /// World bounds of the scene, as `Scene::bounds`.
    pub bounds: Option<Bounds>,
    /// A ball holding the whole scene, as `Scene::bounding_ball` (framing cameras).
    pub bounding_ball: Option<(DVec3, f64)>,
    /// The colour of a ray that meets nothing, linear RGB.
    pub background: DVec3,
    /// Gas spheres present.
    pub gas_spheres: usize,
    /// The median sphere radius (sets the depth of the first shadow band, `light_pieces`).
    pub(crate) typical_radius: f64,
    /// The largest channel of any Color a triangle carries (for [`View::rest_bound`]).
    surface_colors: f64,
    /// Per material record, the largest channel of the diffuse colours of the items that use
    /// it (`-inf`: none does).
    record_colors: Vec<f64>,
    /// Wall time of `prepare` (BVH build included).
    pub prepare_time: Duration,
}

pub(crate) fn invalid(m: String) -> Error {
    Error::Invalid(m)
}

impl RenderOptions {
    /// Checks the sizes, region, sample count and integrator settings, and that the
    /// render's buffers fit in the memory available ([`RenderOptions::validate_on`] with
    /// the current rayon pool's threads).
    pub fn validate(&self) -> Result<(), Error> {
        self.validate_on(rayon::current_num_threads())
    }

    /// [`RenderOptions::validate`] for a render on `threads` worker threads: the memory its
    /// buffers need ([`RenderOptions::memory_bytes`]) is compared with what this machine has
    /// available ([`limits::available_memory`]; not compared where that is unknown).
    pub fn validate_on(&self, threads: usize) -> Result<(), Error> {
        if self.width == 0 || self.height == 0 {
            return Err(invalid(format!(
                "the image size {}x{} is empty",
                self.width, self.height
            )));
        }
        if let Some((x0, y0, x1, y1)) = self.region {
            if !(x0 < x1 && y0 < y1 && x1 <= self.width && y1 <= self.height) {
                return Err(invalid(format!(
                    "the region {x0},{y0},{x1},{y1} is empty or outside the {}x{} image",
                    self.width, self.height
                )));
            }
        }
        if self.spp == 0 {
            return Err(invalid("spp must be at least 1".into()));
        }
        if self.spp > limits::MAX_SPP {
            return Err(invalid(format!(
                "spp = {}: at most {} samples per pixel",
                self.spp,
                limits::MAX_SPP
            )));
        }
        // The tolerance is the exact integrator's; march and mc ignore it.
        if self.integrator == Integrator::Exact && !(self.tol > 0.0 && self.tol.is_finite()) {
            return Err(invalid(format!(
                "tol = {}: the tolerance must be positive and finite",
                self.tol
            )));
        }
        if let Integrator::March { step } = self.integrator {
            if !(step > 0.0 && step.is_finite()) {
                return Err(invalid(format!(
                    "step = {step}: the march step must be positive and finite"
                )));
            }
        }
        if let Integrator::Ao(ao) = self.integrator {
            ao::methods::check(&ao).map_err(invalid)?;
        }
        if self.aovs.ao {
            ao::check_reach(self.ao.reach).map_err(invalid)?;
        }
        self.check_memory(threads, limits::available_memory())
            .map_err(invalid)
    }
}

impl Prepared {
    /// Wall time of building the sphere BVH (part of [`Prepared::prepare_time`]).
    pub fn bvh_build_time(&self) -> Duration {
        self.bvh.build_time
    }

    /// Heap bytes of the sphere BVH and its primitives.
    pub fn bvh_bytes(&self) -> usize {
        self.bvh.heap_bytes()
    }

    /// The opaque surfaces other than spheres and ellipsoids.
    pub fn surface_count(&self) -> usize {
        self.surfaces.items.len()
    }

    /// Opaque spheres left out of the BVH as coincident copies of one before them (the
    /// same centre, radius, colour and material; it draws them).
    pub fn copies_dropped(&self) -> usize {
        self.copies.len()
    }

    /// One value per sphere of the scene, in the scene's order, from one per primitive of
    /// the BVH (leaf order): a sphere dropped as a copy takes the value of the one kept in
    /// its place. The work beyond the output is one pass over the copies.
    pub(crate) fn in_scene_order<T: Clone>(&self, per_prim: &[T]) -> Vec<T> {
        assert_eq!(per_prim.len(), self.bvh.len(), "one value per primitive");
        let Some(first) = per_prim.first() else {
            return Vec::new();
        };
        // Every sphere is a primitive or a copy of one, so each place is written below.
        let mut out = vec![first.clone(); self.spheres];
        for (q, v) in self.bvh.packed().iter().zip(per_prim) {
            out[q.sphere as usize] = v.clone();
        }
        // A kept sphere's place was written above; copies follow the scene's order.
        for &(copy, kept) in &self.copies {
            out[copy as usize] = out[kept as usize].clone();
        }
        out
    }

    /// The centre and radius (world units) of each sphere of the scene, in the scene's
    /// order, copies left out of the BVH included (for an ellipsoid, its bounding sphere).
    pub fn scene_spheres(&self) -> Vec<(DVec3, f64)> {
        let balls: Vec<(DVec3, f64)> = self
            .bvh
            .packed()
            .iter()
            .map(|q| (q.center, q.radius))
            .collect();
        self.in_scene_order(&balls)
    }

    /// The camera `render` uses by default: the first Viewpoint, or else one looking down -z
    /// that frames the scene ([`CameraChoice::Auto`], perspective).
    pub fn default_camera(&self, width: u32, height: u32) -> Result<Camera, Error> {
        Ok(self
            .camera(&CameraChoice::Auto, Projection::PERSPECTIVE, width, height)?
            .0)
    }

    /// The camera the command line would use: `choice` and `projection` applied to this
    /// scene's Viewpoints and bounds, with a sentence saying which camera it is.
    pub fn camera(
        &self,
        choice: &CameraChoice,
        projection: Projection,
        width: u32,
        height: u32,
    ) -> Result<(Camera, String), Error> {
        Camera::for_scene(
            &self.viewpoints,
            self.bounds
                .map(|b| (DVec3::from(b.min), DVec3::from(b.max))),
            self.bounding_ball,
            choice,
            projection,
            width,
            height,
        )
    }
}

/// Validates the scene ([`Scene::validate`]) and builds the BVHs. Consumes the scene: its
/// sphere list becomes the BVH's primitive list, so the spheres are not held twice.
pub fn prepare(scene: Scene, opts: &PrepareOptions) -> Result<Prepared, Error> {
    let start = Instant::now();
    scene.validate()?;
    if let Some(sigma) = opts.as_gas {
        if !(sigma >= 0.0 && sigma.is_finite()) {
            return Err(invalid(format!(
                "as_gas = {sigma}: the extinction must be finite and non-negative"
            )));
        }
    }
    let bounds = scene.bounds();
    let bounding_ball = bounds.map(|b| scene.bounding_ball_in(b));
    let Scene {
        spheres,
        ellipsoids,
        surfaces,
        materials,
        background,
        lights,
        headlight,
        viewpoints,
        ..
    } = scene;
    // Gas (docs/model.md section 1): a material with 0 < transparency, or every sphere with
    // --as-gas SIGMA. A sphere's record is looked up only when some record may be gas.
    let maybe_gas = opts.as_gas.is_some() || materials.may_have_gas();
    let is_gas = |s: &crate::scene::Sphere| {
        opts.as_gas.is_some() || (maybe_gas && materials.record(s.material).is_gas())
    };
    // Density profiles (docs/model.md section 6): --profile for every gas sphere, or each
    // material's own. Looked up per primitive only when some gas may be profiled.
    let profiled = match opts.profile {
        Some(p) => p != crate::scene::Profile::Constant,
        None => materials.may_have_profiled_gas(),
    };
    if materials.len() > crate::accel::bvh::MAX_MATERIALS {
        return Err(invalid(format!(
            "{} distinct materials: at most {} are supported",
            materials.len(),
            crate::accel::bvh::MAX_MATERIALS
        )));
    }
    // The ellipsoid of each sphere, kept only when there are any (the packed primitives keep
    // a flag; the BVH asks for the map by sphere index).
    let ellipsoid_of: Vec<Option<EllipsoidId>> = if spheres.iter().any(|s| s.ellipsoid.is_some()) {
        spheres.iter().map(|s| s.ellipsoid).collect()
    } else {
        Vec::new()
    };
    // Per material record, the largest diffuse colour channel of the items that use it
    // (`-inf`: none does), for `rest_bound`; the spheres' in the conversion's one pass.
    let mut record_colors = vec![f64::NEG_INFINITY; materials.len()];
    let mut note = |m: u32, c: crate::scene::Color| {
        let r = &mut record_colors[m as usize];
        *r = r.max(materials.diffuse(c).max_element());
    };
    for s in &surfaces {
        note(s.material, s.color);
    }
    let sphere_count = spheres.len();
    // into_iter().filter_map().collect() reuses the spheres' allocation (a packed primitive,
    // 48 bytes, is smaller than a 56-byte Sphere), so a large scene does not hold both lists.
    let mut copies = copies::Copies::default();
    let mut packed = spheres
        .into_iter()
        .enumerate()
        .filter_map(|(i, s)| {
            note(s.material, s.color);
            let gas = is_gas(&s);
            let q = Packed::new(
                s.center,
                s.radius,
                (s.material, s.color),
                i as u32,
                gas,
                s.ellipsoid.is_some(),
            );
            copies.first(&q).then_some(q)
        })
        .collect::<Vec<Packed>>();
    // The conversion left the spheres' larger allocation behind, its tail touched: give
    // the tail back (8 bytes a sphere).
    packed.shrink_to_fit();
    let gas_spheres = packed.iter().filter(|q| q.is_gas()).count();
    let typical_radius = median_radius(&packed);
    let surface_colors = surface_color_bound(&surfaces);
    let side = |q: &Packed| {
        let ellipsoid = ellipsoid_of.get(q.sphere as usize).copied().flatten();
        let profile = match opts.profile {
            Some(p) => p,
            None if profiled => materials.record(q.material()).profile,
            None => crate::scene::Profile::Constant,
        };
        // With a profile, the extinction at the centre (`--as-gas SIGMA` gives it as is).
        let sigma = match opts.as_gas {
            Some(sigma) => sigma,
            None => {
                let radius = match ellipsoid {
                    None => q.radius,
                    Some(e) => ellipsoids[e.index()].matrix3.determinant().abs().cbrt(),
                };
                let m = materials.record(q.material());
                if profile == crate::scene::Profile::Constant {
                    m.sigma(radius)
                } else {
                    profile::sigma0(m.transparency, radius, profile)
                }
            }
        };
        (ellipsoid, sigma, profile)
    };
    let bvh = SphereBvh::build_packed(packed, &ellipsoids, &side, profiled);
    drop(ellipsoid_of);
    let surfaces = surfaces::Surfaces::build(surfaces);
    Ok(Prepared {
        bvh,
        surfaces,
        spheres: sphere_count,
        copies: copies.dropped,
        materials,
        lights,
        headlight,
        viewpoints,
        bounds,
        bounding_ball,
        background,
        gas_spheres,
        typical_radius,
        surface_colors,
        record_colors,
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
fn median_radius(prims: &[Packed]) -> f64 {
    sampled_median(prims.iter().map(|p| p.radius))
}

/// The median of about 1001 of `values`, evenly spaced (0 without any).
pub(crate) fn sampled_median(values: impl ExactSizeIterator<Item = f64>) -> f64 {
    if values.len() == 0 {
        return 0.0;
    }
    let step = values.len().div_ceil(1001);
    let mut r: Vec<f64> = values.step_by(step).collect();
    let mid = r.len() / 2;
    *r.select_nth_unstable_by(mid, f64::total_cmp).1
}

#[cfg(test)]
mod tests;
