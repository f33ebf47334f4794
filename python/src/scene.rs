//! `gtsphere.Scene` and `gtsphere.load`: a scene read from a file or built from arrays, and
//! prepared (its BVH built) at once, so that every render of it shares one BVH.

use std::path::PathBuf;
use std::sync::Arc;

use glam::DVec3;
use gtsphere::render::{prepare, PrepareOptions, Prepared};
use gtsphere::scene::{DirectionalLight, Light, PointLight, Radii, SphereArrays};
use gtsphere::vrml::{load_path, LoadOptions};
use numpy::PyUntypedArrayMethods;
use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;

use crate::arrays::{array, flat, float64, rows3, vec3};
use crate::to_py;

/// A scene ready to render: spheres (and, from a file, the other surfaces), materials,
/// lights and Viewpoints, with its BVH built once. Make one with `gtsphere.load(path)` or
/// `Scene.from_arrays(centers, radii, ...)`; lights may be added and the headlight and
/// background changed at any time between renders.
#[pyclass(module = "gtsphere")]
pub struct Scene {
    pub prepared: Arc<Prepared>,
    warnings: Vec<String>,
}

impl Scene {
    fn new(prepared: Prepared, warnings: Vec<String>) -> Scene {
        Scene {
            prepared: Arc::new(prepared),
            warnings,
        }
    }

    fn prepared_mut(&mut self) -> PyResult<&mut Prepared> {
        Arc::get_mut(&mut self.prepared).ok_or_else(|| {
            PyRuntimeError::new_err("the scene is being rendered; change it after the render")
        })
    }
}

fn unit_interval(name: &str, v: f64) -> PyResult<f64> {
    if (0.0..=1.0).contains(&v) {
        Ok(v)
    } else {
        Err(PyValueError::new_err(format!(
            "{name} = {v:?}: must be in [0, 1]"
        )))
    }
}

fn colour(name: &str, obj: &Bound<'_, PyAny>) -> PyResult<DVec3> {
    let c = vec3(name, obj)?;
    if c.cmpge(DVec3::ZERO).all() && c.cmple(DVec3::ONE).all() {
        Ok(c)
    } else {
        Err(PyValueError::new_err(format!(
            "{name} = ({:?}, {:?}, {:?}): colour channels must be in [0, 1]",
            c.x, c.y, c.z
        )))
    }
}

fn non_negative(name: &str, v: f64) -> PyResult<f64> {
    if v >= 0.0 && v.is_finite() {
        Ok(v)
    } else {
        Err(PyValueError::new_err(format!(
            "{name} = {v:?}: must be finite and non-negative"
        )))
    }
}

#[pymethods]
impl Scene {
    /// Spheres from arrays, in order (sphere i has id i).
    ///
    /// centers: (N, 3) positions. radii: one number for all, or (N,) radii, each positive.
    /// colors: (N, 3) diffuse RGB in [0, 1]; default VRML's grey 0.8.
    /// transparency: (N,) in [0, 1]; 0 is opaque, t > 0 makes the sphere gas whose diameter
    /// transmits t (glowing its emissive colour, scattering its colour as albedo).
    /// emissive: (N, 3) emissive RGB in [0, 1]; default black.
    /// headlight: a white directional light along each camera's view, as VRML's default.
    /// background: RGB seen where rays meet nothing.
    /// profile: the gas spheres' density profile, "constant" (default), "linear",
    /// "quadratic" or "gaussian" (with profile_width, in (0, 1] of the radius, default 1/3);
    /// transparency stays the transmittance along a diameter (docs/model.md section 6).
    ///
    /// Arrays are read in place when they are C-contiguous float64 (otherwise numpy converts
    /// them once). A bad value raises ValueError naming the array, index and value, e.g.
    /// "radii[17] = -1.0: radius must be positive and finite".
    #[staticmethod]
    #[pyo3(signature = (centers, radii, colors=None, transparency=None, emissive=None, *, headlight=true, background=None, profile=None, profile_width=None))]
    #[allow(clippy::too_many_arguments)]
    fn from_arrays(
        py: Python<'_>,
        centers: &Bound<'_, PyAny>,
        radii: &Bound<'_, PyAny>,
        colors: Option<&Bound<'_, PyAny>>,
        transparency: Option<&Bound<'_, PyAny>>,
        emissive: Option<&Bound<'_, PyAny>>,
        headlight: bool,
        background: Option<&Bound<'_, PyAny>>,
        profile: Option<&str>,
        profile_width: Option<f64>,
    ) -> PyResult<Scene> {
        let prepare_opts = profile_options(profile, profile_width)?;
        let background = match background {
            Some(b) => colour("background", b)?,
            None => DVec3::ZERO,
        };
        let c = float64(py, "centers", centers)?;
        let r = float64(py, "radii", radii)?;
        let col = colors.map(|a| float64(py, "colors", a)).transpose()?;
        let tr = transparency
            .map(|a| float64(py, "transparency", a))
            .transpose()?;
        let em = emissive.map(|a| float64(py, "emissive", a)).transpose()?;
        let radii = if r.ndim() == 0 {
            Radii::One(*r.as_array().first().expect("a 0-d array has one value"))
        } else {
            Radii::Each(flat("radii", &r)?)
        };
        let arrays = SphereArrays {
            centers: rows3("centers", &c)?,
            radii,
            colors: col.as_ref().map(|a| rows3("colors", a)).transpose()?,
            transparency: tr.as_ref().map(|a| flat("transparency", a)).transpose()?,
            emissive: em.as_ref().map(|a| rows3("emissive", a)).transpose()?,
        };
        let prepared = py
            .detach(|| {
                let mut scene = gtsphere::scene::Scene::from_arrays(&arrays)?;
                scene.headlight = headlight;
                scene.background = background;
                prepare(scene, &prepare_opts)
            })
            .map_err(to_py)?;
        Ok(Scene::new(prepared, Vec::new()))
    }

    /// Adds a VRML PointLight (defaults as VRML97's): it lights points within `radius`,
    /// attenuated by 1 / max(a0 + a1 d + a2 d^2, 1), and casts hard shadows.
    #[pyo3(signature = (location, color=None, intensity=1.0, ambient_intensity=0.0, attenuation=None, radius=100.0))]
    fn add_point_light(
        &mut self,
        location: &Bound<'_, PyAny>,
        color: Option<&Bound<'_, PyAny>>,
        intensity: f64,
        ambient_intensity: f64,
        attenuation: Option<&Bound<'_, PyAny>>,
        radius: f64,
    ) -> PyResult<()> {
        let location = vec3("location", location)?;
        if !location.is_finite() {
            return Err(PyValueError::new_err("location must be finite"));
        }
        let attenuation = match attenuation {
            Some(a) => vec3("attenuation", a)?,
            None => DVec3::new(1.0, 0.0, 0.0),
        };
        if !(attenuation.is_finite() && attenuation.cmpge(DVec3::ZERO).all()) {
            return Err(PyValueError::new_err(
                "attenuation must be three finite non-negative numbers",
            ));
        }
        if radius.is_nan() || radius < 0.0 {
            return Err(PyValueError::new_err(format!(
                "radius = {radius:?}: must not be negative"
            )));
        }
        let light = PointLight {
            location,
            color: match color {
                Some(c) => colour("color", c)?,
                None => DVec3::ONE,
            },
            intensity: non_negative("intensity", intensity)?,
            ambient_intensity: unit_interval("ambient_intensity", ambient_intensity)?,
            attenuation,
            radius,
            ..PointLight::default()
        };
        self.prepared_mut()?.lights.push(Light::Point(light));
        Ok(())
    }

    /// Adds a VRML DirectionalLight travelling along `direction` (normalised here), lighting
    /// the whole scene and casting hard shadows.
    #[pyo3(signature = (direction=None, color=None, intensity=1.0, ambient_intensity=0.0))]
    fn add_directional_light(
        &mut self,
        direction: Option<&Bound<'_, PyAny>>,
        color: Option<&Bound<'_, PyAny>>,
        intensity: f64,
        ambient_intensity: f64,
    ) -> PyResult<()> {
        let direction = match direction {
            Some(d) => vec3("direction", d)?,
            None => DVec3::NEG_Z,
        };
        let unit = direction.normalize_or_zero();
        if unit == DVec3::ZERO || !unit.is_finite() {
            return Err(PyValueError::new_err(
                "direction must be a finite non-zero vector",
            ));
        }
        let light = DirectionalLight {
            direction: unit,
            color: match color {
                Some(c) => colour("color", c)?,
                None => DVec3::ONE,
            },
            intensity: non_negative("intensity", intensity)?,
            ambient_intensity: unit_interval("ambient_intensity", ambient_intensity)?,
            ..DirectionalLight::default()
        };
        self.prepared_mut()?.lights.push(Light::Directional(light));
        Ok(())
    }

    /// Whether a white DirectionalLight along each camera's view is added (VRML's
    /// NavigationInfo.headlight; True unless the file or from_arrays said otherwise).
    #[getter]
    fn get_headlight(&self) -> bool {
        self.prepared.headlight
    }

    #[setter]
    fn set_headlight(&mut self, on: bool) -> PyResult<()> {
        self.prepared_mut()?.headlight = on;
        Ok(())
    }

    /// The background colour (RGB) seen where rays meet nothing.
    #[getter]
    fn get_background(&self) -> (f64, f64, f64) {
        let b = self.prepared.background;
        (b.x, b.y, b.z)
    }

    #[setter]
    fn set_background(&mut self, rgb: &Bound<'_, PyAny>) -> PyResult<()> {
        let b = colour("background", rgb)?;
        self.prepared_mut()?.background = b;
        Ok(())
    }

    /// ((xmin, ymin, zmin), (xmax, ymax, zmax)) of everything in the scene, or None if empty.
    #[getter]
    #[allow(clippy::type_complexity)]
    fn bounds(&self) -> Option<((f64, f64, f64), (f64, f64, f64))> {
        self.prepared.bounds.map(|b| {
            (
                (b.min[0], b.min[1], b.min[2]),
                (b.max[0], b.max[1], b.max[2]),
            )
        })
    }

    /// Number of spheres (opaque and gas).
    #[getter]
    fn spheres(&self) -> usize {
        self.prepared.spheres
    }

    /// The spheres as arrays, `(centers, radii)`: (N, 3) and (N,) float64, in the scene's
    /// order (row i of from_arrays' arrays, or the file's i-th sphere; the rows of
    /// occlusion's results), coincident copies included. An ellipsoid gives its centre and
    /// the radius of a sphere holding it.
    fn sphere_arrays(&self, py: Python<'_>) -> PyResult<(Py<PyAny>, Py<PyAny>)> {
        let prepared = self.prepared.clone();
        let spheres = py.detach(|| prepared.scene_spheres());
        let n = spheres.len();
        let centers = spheres.iter().flat_map(|(c, _)| c.to_array()).collect();
        let radii = spheres.iter().map(|&(_, r)| r).collect();
        Ok((array(py, centers, &[n, 3])?, array(py, radii, &[n])?))
    }

    /// Number of gas spheres.
    #[getter]
    fn gas_spheres(&self) -> usize {
        self.prepared.gas_spheres
    }

    /// Number of lights (the headlight not included).
    #[getter]
    fn lights(&self) -> usize {
        self.prepared.lights.len()
    }

    /// The loader's warnings and notes (file:line:col: message), also issued as
    /// gtsphere.SceneWarning when the file was loaded.
    #[getter]
    fn warnings(&self) -> Vec<String> {
        self.warnings.clone()
    }

    fn __len__(&self) -> usize {
        self.prepared.spheres
    }

    fn __repr__(&self) -> String {
        let p = &self.prepared;
        format!(
            "<gtsphere.Scene: {} spheres ({} gas), {} other surfaces, {} lights{}>",
            p.spheres,
            p.gas_spheres,
            p.surface_count(),
            p.lights.len(),
            if p.headlight { " + headlight" } else { "" }
        )
    }
}

/// Reads a VRML97 scene (.wrl, or gzipped .wrz / .wrl.gz) and builds its BVH.
///
/// point_radius: radius of the spheres that PointSet points become (default: half the
/// median nearest-neighbour distance, said in a note). spheres_only: leave out everything
/// that is not a sphere. strict: every warning becomes an error. profile (and profile_width): every
/// gas sphere takes this density profile, as `render --profile` (default: each sphere's own,
/// from GasParticle PROTO instances). max_expansion: how far USE, PROTO and IS copies may
/// multiply the scene (to 4194304 nodes and values plus this many per byte of text, gzip data
/// to 8 times this its compressed size); past it, ParseError at the construct that went over.
///
/// Warnings are issued as gtsphere.SceneWarning (and kept in Scene.warnings). A file that
/// cannot be read raises gtsphere.ParseError whose message starts with file:line:col, or
/// OSError (FileNotFoundError) for a missing file.
// The default of `max_expansion` in the signature below (and in the stubs) is the library's.
const _: () = assert!(gtsphere::vrml::DEFAULT_MAX_EXPANSION == 16);

#[pyfunction]
#[allow(clippy::too_many_arguments)] // Python's keyword arguments, one each
#[pyo3(signature = (path, *, point_radius=None, spheres_only=false, strict=false, profile=None, profile_width=None, max_expansion=16))]
pub fn load(
    py: Python<'_>,
    path: PathBuf,
    point_radius: Option<f64>,
    spheres_only: bool,
    strict: bool,
    profile: Option<&str>,
    profile_width: Option<f64>,
    max_expansion: u64,
) -> PyResult<Scene> {
    let prepare_opts = profile_options(profile, profile_width)?;
    if let Some(r) = point_radius {
        if !(r > 0.0 && r.is_finite()) {
            return Err(PyValueError::new_err(format!(
                "point_radius = {r:?}: must be positive and finite"
            )));
        }
    }
    let opts = LoadOptions {
        strict,
        point_radius,
        spheres_only,
        max_expansion,
        ..LoadOptions::default()
    };
    let (prepared, warnings) = py
        .detach(|| {
            let (scene, report) = load_path(&path, &opts)?;
            let warnings: Vec<String> = report
                .warnings
                .iter()
                .chain(&report.notes)
                .map(|w| w.to_string())
                .collect();
            Ok::<_, gtsphere::Error>((prepare(scene, &prepare_opts)?, warnings))
        })
        .map_err(to_py)?;
    let warn = py.import("warnings")?;
    let category = py.get_type::<crate::SceneWarning>();
    for w in &warnings {
        warn.call_method1("warn", (w.as_str(), &category, 2))?;
    }
    Ok(Scene::new(prepared, warnings))
}

/// The `profile` and `profile_width` keywords (`render --profile NAME[:WIDTH]`): every gas sphere
/// takes that density profile (docs/model.md section 6). A bad name or width raises ValueError.
fn profile_options(profile: Option<&str>, width: Option<f64>) -> PyResult<PrepareOptions> {
    let profile = match (profile, width) {
        (None, None) => None,
        (None, Some(_)) => {
            return Err(PyValueError::new_err(
                "profile_width is the gaussian profile's: give profile=\"gaussian\" with it",
            ))
        }
        (Some(name), width) => Some(
            gtsphere::scene::Profile::parse(name, width)
                .map_err(|e| PyValueError::new_err(format!("profile: {e}")))?,
        ),
    };
    Ok(PrepareOptions {
        profile,
        ..PrepareOptions::default()
    })
}
