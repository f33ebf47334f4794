//! One render's view of a prepared scene ([`View`]): the camera's rays at the image size, the
//! lights the integrators use, the integrator and its tolerance, a bound on the radiance
//! anything can send, and for gas scenes each light's grid.

use std::time::{Duration, Instant};

use glam::DVec3;

use super::{
    integrators, invalid, light_grid, lights, Camera, ImagePlane, Integrator, Prepared,
    RenderOptions,
};
use crate::scene::MaterialTable;
use crate::Error;

/// One render's view of a [`Prepared`] scene: the camera's rays at the image size, the lights
/// the integrators use (switched-off lights dropped, the headlight along this camera), the
/// integrator and its tolerance. Dereferences to the prepared scene.
pub struct View<'a> {
    /// The prepared scene.
    pub(crate) prep: &'a Prepared,
    /// The camera at this image size.
    pub(crate) camera: ImagePlane,
    /// The lights that are on, the headlight among them when there is one.
    pub(crate) lights: Vec<lights::LightSource>,
    /// How camera rays are integrated.
    pub(crate) integrator: Integrator,
    /// Target relative error of the exact integrator, as [`RenderOptions::tol`].
    pub(crate) tol: f64,
    /// An upper bound on the radiance anything in the scene can send along a ray (largest RGB
    /// channel): emission plus single scattering of any gas, any lit surface, the background.
    /// Behind a transmittance `T`, what is left of a camera ray adds at most `T * rest_bound`.
    pub(crate) rest_bound: f64,
    /// Per light, the scene as it sees it, for the exact integrator's shadow searches in
    /// scenes with gas (`None` otherwise).
    pub(crate) grids: Vec<Option<light_grid::LightGrid>>,
    /// The voxel AO method's density grid, built for this render (`None` otherwise).
    pub(crate) ao_grid: Option<super::ao::methods::voxel::Grid>,
    /// Wall time of building `grids` and `ao_grid`.
    pub(crate) grid_time: Duration,
}

impl View<'_> {
    /// The voxel AO method's density grid, when this render uses it.
    pub fn ao_grid(&self) -> Option<&super::ao::methods::voxel::Grid> {
        self.ao_grid.as_ref()
    }

    /// The lights the integrators use: those that are on, the headlight among them.
    pub fn light_count(&self) -> usize {
        self.lights.len()
    }

    /// Whether the lights' grids were built (scenes with gas, the exact integrator), with
    /// their wall time and heap bytes.
    pub fn grids(&self) -> Option<(Duration, usize)> {
        let mut built = self.grids.iter().flatten().peekable();
        built.peek()?;
        Some((self.grid_time, built.map(|g| g.heap_bytes()).sum()))
    }
}

impl std::ops::Deref for View<'_> {
    type Target = Prepared;
    fn deref(&self) -> &Prepared {
        self.prep
    }
}

impl Prepared {
    /// The view of this scene that `render` traces: `camera` at the options' image size.
    /// The lights, which may have changed since `prepare` validated them, are checked again
    /// ([`Light::problem`](crate::scene::Light::problem)).
    pub fn view(&self, camera: &Camera, opts: &RenderOptions) -> Result<View<'_>, Error> {
        opts.validate()?;
        camera.lens.validate()?;
        if matches!(opts.integrator, Integrator::Ao(_)) || opts.aovs.ao {
            if let Some(why) = super::ao::unsupported(self) {
                return Err(invalid(why));
            }
        }
        for (i, l) in self.lights.iter().enumerate() {
            if let Some(m) = l.problem() {
                return Err(invalid(format!("lights[{i}]: {m}")));
            }
        }
        let headlight = match (self.headlight, opts.headlight_shadows) {
            (false, _) => lights::Headlight::Off,
            (true, false) => lights::Headlight::Carried,
            (true, true) => lights::Headlight::Shadowed,
        };
        let lights = lights::collect(
            &self.lights,
            headlight,
            self.spheres,
            self.surfaces.items.len(),
            camera.forward,
        );
        let rest_bound = rest_bound(
            &self.materials,
            &self.record_colors,
            &lights,
            self.background,
            self.surface_colors,
        );
        let start = Instant::now();
        let ao_grid = super::ao::methods::prepare_view(self, &opts.integrator).map_err(invalid)?;
        let grids = lights
            .iter()
            .map(|l| {
                let wanted = opts.integrator == Integrator::Exact
                    && self.gas_spheres > 0
                    && l.direct != DVec3::ZERO
                    && !l.carried;
                wanted
                    .then(|| light_grid::LightGrid::build(&l.kind, self.bvh.packed()))
                    .flatten()
            })
            .collect();
        Ok(View {
            prep: self,
            camera: camera.image_plane(opts.width, opts.height),
            grids,
            ao_grid,
            grid_time: start.elapsed(),
            lights,
            integrator: opts.integrator,
            tol: opts.tol,
            rest_bound,
        })
    }
}

/// [`Prepared::rest_bound`]: the largest of the background, any used material's surface
/// radiance (emission, ambient and direct terms of every light at full strength, or its
/// colour when unlit) and any used material's gas source `C + p a sum_i C_i I_i` (attenuation
/// and visibility are at most 1), each channel bounded by its largest.
fn rest_bound(
    materials: &MaterialTable,
    record_colors: &[f64],
    lights: &[lights::LightSource],
    background: DVec3,
    surface_colors: f64,
) -> f64 {
    let direct: f64 = lights.iter().map(|l| l.direct.max_element()).sum();
    let ambient: f64 = lights.iter().map(|l| l.ambient.max_element()).sum();
    let mut bound = background.max_element();
    for (m, &diffuse) in materials.records().iter().zip(record_colors) {
        if diffuse == f64::NEG_INFINITY {
            continue;
        }
        let (e, a, s) = (
            m.emissive.max_element(),
            diffuse.max(surface_colors),
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
