//! `gtsphere.render` and `gtsphere.Film`: a render on worker threads with the GIL released,
//! while the calling thread watches for Ctrl-C and reports progress ([`crate::work`]).

use gtsphere::render::ao::methods::{MAX_DIRECTIONS, MAX_SAMPLES};
use gtsphere::render::ao::{AoMethod, AoSettings, Weighting};
use gtsphere::render::{self as lib, Aovs, Integrator, RenderOptions, SamplerKind};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::arrays::array;
use crate::camera::Camera;
use crate::scene::Scene;
use crate::to_py;

/// A rendered picture as numpy arrays, row 0 at the top.
#[pyclass(module = "gtsphere", frozen)]
pub struct Film {
    /// (H, W, 3) float64 linear RGB.
    #[pyo3(get)]
    rgb: Py<PyAny>,
    /// (H, W) float64 coverage in [0, 1].
    #[pyo3(get)]
    alpha: Py<PyAny>,
    /// (H, W) float64 estimated absolute error of each pixel (exact: the quadrature's error
    /// bound; mc: the standard error of the mean; 0 where the value is exact).
    #[pyo3(get)]
    error: Py<PyAny>,
    /// (H, W) float64 distance to the first opaque hit through the pixel centre (inf on a
    /// miss), or None unless "depth" was in aovs.
    #[pyo3(get)]
    depth: Py<PyAny>,
    /// (H, W, 3) float64 world unit normal there (0 on a miss), or None unless "normal" was
    /// in aovs.
    #[pyo3(get)]
    normal: Py<PyAny>,
    /// (H, W) float64 exact ambient occlusion at the centre ray's first hit, with ao_reach
    /// and ao_weighting (NaN on a miss), or None unless "ao" was in aovs.
    #[pyo3(get)]
    ao: Py<PyAny>,
    /// (H, W) int64 index of what the centre ray hit (spheres in order, then the other
    /// surfaces; -1 on a miss), or None unless "id" was in aovs.
    #[pyo3(get)]
    id: Py<PyAny>,
    /// The largest per-pixel error estimate.
    #[pyo3(get)]
    max_error: f64,
    /// Wall time of the render (seconds).
    #[pyo3(get)]
    seconds: f64,
    /// Work counters: camera_rays, shadow_rays, quadrature_nodes, shadow_candidates.
    #[pyo3(get)]
    counters: Py<PyAny>,
    width: usize,
    height: usize,
    stats: gtsphere::render::Counters,
}

#[pymethods]
impl Film {
    /// Image width in pixels.
    #[getter]
    fn width(&self) -> usize {
        self.width
    }

    /// Image height in pixels.
    #[getter]
    fn height(&self) -> usize {
        self.height
    }

    fn __repr__(&self) -> String {
        format!(
            "<gtsphere.Film {}x{}, max error {:e}, {:.3} s>",
            self.width, self.height, self.max_error, self.seconds
        )
    }

    /// The picture as PNG bytes (8-bit sRGB, as `save(film, "x.png")` writes it): a
    /// notebook shows a Film as its picture.
    fn _repr_png_<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, pyo3::types::PyBytes>> {
        let film = self.to_film(py)?;
        let bytes = py
            .detach(|| gtsphere::output::png_bytes(&film.image()))
            .map_err(to_py)?;
        Ok(pyo3::types::PyBytes::new(py, &bytes))
    }
}

impl Film {
    /// The numpy arrays take the film's buffers (no copy); what save() needs is read back
    /// from them ([`Film::to_film`]).
    fn new(py: Python<'_>, film: lib::Film) -> PyResult<Film> {
        let (h, w) = (film.height, film.width);
        let none = || py.None();
        let c = PyDict::new(py);
        c.set_item("camera_rays", film.counters.camera_rays)?;
        c.set_item("shadow_rays", film.counters.shadow_rays)?;
        c.set_item("quadrature_nodes", film.counters.quadrature_nodes)?;
        c.set_item("shadow_candidates", film.counters.shadow_candidates)?;
        let lib::Film {
            width,
            height,
            rgb,
            alpha,
            error,
            depth,
            normal,
            id,
            ao,
            counters,
            max_error,
            seconds,
            ..
        } = film;
        Ok(Film {
            rgb: array(py, rgb.into_flattened(), &[h, w, 3])?,
            alpha: array(py, alpha, &[h, w])?,
            error: array(py, error.unwrap_or_else(|| vec![0.0; h * w]), &[h, w])?,
            depth: match depth {
                Some(d) => array(py, d, &[h, w])?,
                None => none(),
            },
            normal: match normal {
                Some(n) => array(py, n.into_flattened(), &[h, w, 3])?,
                None => none(),
            },
            id: match id {
                Some(i) => array(py, i, &[h, w])?,
                None => none(),
            },
            ao: match ao {
                Some(a) => array(py, a, &[h, w])?,
                None => none(),
            },
            max_error,
            seconds,
            counters: c.into_any().unbind(),
            width,
            height,
            stats: counters,
        })
    }

    /// The film as the library's writers take it, read from the arrays (as they are now, if
    /// the caller changed them).
    pub fn to_film(&self, py: Python<'_>) -> PyResult<lib::Film> {
        let n = self.width * self.height;
        let f64s = |name: &str, obj: &Py<PyAny>, per: usize| -> PyResult<Option<Vec<f64>>> {
            let obj = obj.bind(py);
            if obj.is_none() {
                return Ok(None);
            }
            let a = crate::arrays::float64(py, name, obj)?;
            let v = a
                .as_slice()
                .map_err(|e| PyValueError::new_err(e.to_string()))?;
            if v.len() != n * per {
                return Err(PyValueError::new_err(format!(
                    "film.{name} has {} values, not {} (was it resized?)",
                    v.len(),
                    n * per
                )));
            }
            Ok(Some(v.to_vec()))
        };
        let triples = |v: Vec<f64>| v.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
        Ok(lib::Film {
            width: self.width,
            height: self.height,
            rgb: triples(f64s("rgb", &self.rgb, 3)?.unwrap_or_default()),
            alpha: f64s("alpha", &self.alpha, 1)?.unwrap_or_default(),
            error: f64s("error", &self.error, 1)?,
            depth: f64s("depth", &self.depth, 1)?,
            normal: f64s("normal", &self.normal, 3)?.map(triples),
            id: f64s("id", &self.id, 1)?.map(|v| v.into_iter().map(|x| x as i64).collect()),
            ao: f64s("ao", &self.ao, 1)?,
            counters: self.stats,
            max_error: self.max_error,
            seconds: self.seconds,
            grid_seconds: 0.0,
        })
    }
}

fn integrator_of(name: &str, step: Option<f64>, ao: AoSettings) -> PyResult<Integrator> {
    match (name, step) {
        ("exact", None) => Ok(Integrator::Exact),
        ("mc", None) => Ok(Integrator::Mc),
        ("ao", None) => Ok(Integrator::Ao(ao)),
        ("march", Some(step)) => Ok(Integrator::March { step }),
        ("march", None) => Err(PyValueError::new_err(
            "integrator \"march\" needs step= (world units)",
        )),
        ("exact" | "mc" | "ao", Some(_)) => Err(PyValueError::new_err(
            "step= is only for integrator=\"march\"",
        )),
        (other, _) => Err(PyValueError::new_err(format!(
            "integrator = {other:?}: must be \"exact\", \"march\", \"mc\" or \"ao\""
        ))),
    }
}

/// The `ao_reach` keyword: a distance in world units, None for any distance.
pub fn reach_of(reach: Option<f64>) -> PyResult<f64> {
    let reach = reach.unwrap_or(f64::INFINITY);
    if reach.is_nan() || reach <= 0.0 {
        return Err(PyValueError::new_err(format!(
            "ao_reach = {reach:?}: must be a positive distance (or None: any distance)"
        )));
    }
    Ok(reach)
}

/// The `ao_weighting` keyword.
pub fn weighting_of(weighting: &str) -> PyResult<Weighting> {
    match weighting {
        "cosine" => Ok(Weighting::Cosine),
        "uniform" => Ok(Weighting::Uniform),
        other => Err(PyValueError::new_err(format!(
            "ao_weighting = {other:?}: must be \"cosine\" or \"uniform\""
        ))),
    }
}

/// The AO settings of `render`'s keywords (checked whatever the integrator, so that a typo
/// is not silently ignored).
fn ao_of(
    reach: Option<f64>,
    weighting: &str,
    colours: bool,
    (method, samples, directions): (&str, u32, u32),
) -> PyResult<AoSettings> {
    let reach = reach_of(reach)?;
    let weighting = weighting_of(weighting)?;
    let method = match method {
        "exact" => AoMethod::Exact,
        "mc" if (1..=MAX_SAMPLES).contains(&samples) => AoMethod::Mc { samples },
        "mc" => {
            return Err(PyValueError::new_err(format!(
                "ao_samples = {samples}: must be between 1 and {MAX_SAMPLES}"
            )))
        }
        "directions" if (1..=MAX_DIRECTIONS).contains(&directions) => {
            AoMethod::Directions { count: directions }
        }
        "directions" => {
            return Err(PyValueError::new_err(format!(
                "ao_directions = {directions}: must be between 1 and {MAX_DIRECTIONS}"
            )))
        }
        "sum" => AoMethod::Sum,
        "voxel" => AoMethod::VOXEL,
        other => {
            return Err(PyValueError::new_err(format!(
                "ao_method = {other:?}: must be \"exact\", \"mc\", \"directions\", \"sum\" or \"voxel\""
            )))
        }
    };
    Ok(AoSettings {
        reach,
        weighting,
        colours,
        method,
    })
}

fn aovs_of(names: Vec<String>) -> PyResult<Aovs> {
    let mut a = Aovs {
        error: true,
        ..Aovs::default()
    };
    for n in names {
        match n.as_str() {
            "depth" => a.depth = true,
            "normal" => a.normal = true,
            "id" => a.id = true,
            "error" => a.error = true,
            "ao" => a.ao = true,
            other => {
                return Err(PyValueError::new_err(format!(
                    "aovs: unknown channel {other:?}; choose from \"depth\", \"normal\", \"id\", \"ao\", \"error\""
                )))
            }
        }
    }
    Ok(a)
}

/// Renders `scene` seen by `camera` (None: Camera.from_scene(scene)) at width x height and
/// returns a Film: rgb (H, W, 3), alpha, error, and depth / normal / id when asked for.
///
/// spp: samples per pixel. integrator: "exact" (closed form and adaptive quadrature to
/// `tol`, relative to the pixel's value), "march" (fixed steps of `step` world units, an
/// approximation), "mc" (unbiased Monte Carlo, `spp` paths) or "ao" (ambient occlusion as
/// the picture, exact for opaque spheres, triangles and boxes, within `tol` among
/// cylinders and cones: the unoccluded fraction at
/// each visible point, about a triangle's or box's face normal on the viewer's side, within
/// `ao_reach` world units, None for any distance, weighted "cosine" or "uniform" by
/// `ao_weighting`, on white or, with `ao_colours`, times the diffuse colours; `ao_method`
/// names an approximation of spheres to compare with it: "mc" with `ao_samples` rays,
/// "directions" with `ao_directions`, "sum" or "voxel", see docs/ao-methods.md). seed: the
/// sample pattern's
/// seed. threads: worker threads (None: every core; more than four per core are lowered to
/// that, with a RuntimeWarning). aovs: any of "depth", "normal", "id"
/// ("error" is always returned). sampler: "stratified" or "center" (one sample at each
/// pixel centre). progress: called as progress(tiles_done, tiles_total) from this thread
/// every 50 ms when more tiles are done, last with tiles_done == tiles_total; an exception
/// it raises stops the render. headlight_shadows: render the headlight as a strict
/// directional light along the view that casts shadows (by default it is carried by the
/// viewer and casts none, as in VRML browsers).
///
/// A size, spp or set of aovs whose buffers would not fit in the memory available raises
/// ValueError before anything is allocated. The GIL is released while rendering; Ctrl-C
/// (KeyboardInterrupt) stops the render within a pixel's time and leaves the scene usable.
/// The pixels are the same for any thread count.
#[pyfunction]
#[pyo3(
    signature = (scene, camera, width, height, *, spp=16, integrator="exact", tol=1e-4, seed=0, threads=None, aovs=Vec::new(), sampler="stratified", step=None, progress=None, headlight_shadows=false, ao_reach=None, ao_weighting="cosine", ao_colours=false, ao_method="exact", ao_samples=16, ao_directions=64),
    text_signature = "(scene, camera, width, height, *, spp=16, integrator='exact', tol=1e-4, seed=0, threads=None, aovs=(), sampler='stratified', step=None, progress=None, headlight_shadows=False, ao_reach=None, ao_weighting='cosine', ao_colours=False, ao_method='exact', ao_samples=16, ao_directions=64)"
)]
#[allow(clippy::too_many_arguments)]
pub fn render(
    py: Python<'_>,
    scene: PyRef<'_, Scene>,
    camera: Option<&Camera>,
    width: u32,
    height: u32,
    spp: u32,
    integrator: &str,
    tol: f64,
    seed: u64,
    threads: Option<usize>,
    aovs: Vec<String>,
    sampler: &str,
    step: Option<f64>,
    progress: Option<Py<PyAny>>,
    headlight_shadows: bool,
    ao_reach: Option<f64>,
    ao_weighting: &str,
    ao_colours: bool,
    ao_method: &str,
    ao_samples: u32,
    ao_directions: u32,
) -> PyResult<Film> {
    let ao = ao_of(
        ao_reach,
        ao_weighting,
        ao_colours,
        (ao_method, ao_samples, ao_directions),
    )?;
    let opts = RenderOptions {
        width,
        height,
        spp,
        seed,
        sampler: match sampler {
            "stratified" => SamplerKind::Stratified,
            "center" => SamplerKind::Center,
            other => {
                return Err(PyValueError::new_err(format!(
                    "sampler = {other:?}: must be \"stratified\" or \"center\""
                )))
            }
        },
        aovs: aovs_of(aovs)?,
        integrator: integrator_of(integrator, step, ao)?,
        tol,
        region: None,
        headlight_shadows,
        ao,
    };
    let pool = crate::work::pool(py, threads)?;
    // The render shares the prepared scene, not the Python object: a change to the scene
    // meanwhile (from another thread) meets Scene::prepared_mut's error, which says why,
    // rather than pyo3's "Already borrowed".
    let prepared = scene.prepared.clone();
    drop(scene);
    let camera = match camera {
        Some(c) => c.inner,
        None => prepared.default_camera(width, height).map_err(to_py)?,
    };
    // Validates the options and the camera before the render starts; the lights' grids are
    // built here, on the pool and without the GIL.
    let view = py
        .detach(|| pool.install(|| prepared.view(&camera, &opts)))
        .map_err(to_py)?;
    let film = crate::work::watched(py, &pool, progress.as_ref(), "the render", |watch| {
        lib::render_view(&view, &opts, watch)
    })?
    .map_err(to_py)?;
    Film::new(py, film)
}
