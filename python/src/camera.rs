//! `gtsphere.Camera`: where the eye is, where it looks and its lens, independent of the
//! image size.

use glam::DVec3;
use gtsphere::render::{self, CameraChoice, FovAcross, Lens, Projection};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

use crate::arrays::vec3;
use crate::scene::Scene;
use crate::to_py;

/// A camera: position, view direction, up vector and lens (perspective with a field of
/// view across the smaller image side, or orthographic with the world height of the
/// smaller side). Make one with Camera.look_at, Camera.frame or Camera.from_scene.
#[pyclass(module = "gtsphere", frozen)]
#[derive(Clone, Copy)]
pub struct Camera {
    pub inner: render::Camera,
}

fn lens(fov: f64, ortho_height: Option<f64>) -> Lens {
    match ortho_height {
        Some(height) => Lens::Orthographic { height },
        None => Lens::Perspective { fov },
    }
}

fn triple(v: DVec3) -> (f64, f64, f64) {
    (v.x, v.y, v.z)
}

#[pymethods]
impl Camera {
    /// At `eye` looking at `target`; `up` is made perpendicular to the view. `fov` is the
    /// perspective field of view (radians) across the smaller image side; give
    /// `ortho_height` (world units across the smaller side) for an orthographic camera.
    #[staticmethod]
    // The text signature spells out pi/4 (repr(math.pi / 4)), which pyo3 would show as `...`.
    #[pyo3(
        signature = (eye, target=None, up=None, fov=std::f64::consts::FRAC_PI_4, ortho_height=None),
        text_signature = "(eye, target=None, up=None, fov=0.7853981633974483, ortho_height=None)"
    )]
    fn look_at(
        eye: &Bound<'_, PyAny>,
        target: Option<&Bound<'_, PyAny>>,
        up: Option<&Bound<'_, PyAny>>,
        fov: f64,
        ortho_height: Option<f64>,
    ) -> PyResult<Camera> {
        let eye = vec3("eye", eye)?;
        let target = target.map(|t| vec3("target", t)).transpose()?;
        let up = up.map(|u| vec3("up", u)).transpose()?;
        let inner = render::Camera::look_at(
            eye,
            target.unwrap_or(DVec3::ZERO),
            up.unwrap_or(DVec3::Y),
            lens(fov, ortho_height),
        )
        .map_err(to_py)?;
        Ok(Camera { inner })
    }

    /// A camera looking along `direction` that sees the whole scene (its bounding ball,
    /// with `margin` of room) across the smaller image side: perspective with `fov`, or
    /// orthographic when `ortho` is true.
    #[staticmethod]
    #[pyo3(
        signature = (scene, direction=None, up=None, fov=std::f64::consts::FRAC_PI_4, ortho=false, margin=0.02),
        text_signature = "(scene, direction=None, up=None, fov=0.7853981633974483, ortho=False, margin=0.02)"
    )]
    fn frame(
        scene: &Scene,
        direction: Option<&Bound<'_, PyAny>>,
        up: Option<&Bound<'_, PyAny>>,
        fov: f64,
        ortho: bool,
        margin: f64,
    ) -> PyResult<Camera> {
        let direction = direction.map(|d| vec3("direction", d)).transpose()?;
        let up = up.map(|u| vec3("up", u)).transpose()?;
        let Some(ball) = scene.prepared.bounding_ball else {
            return Err(PyValueError::new_err(
                "the scene is empty: there is nothing to frame",
            ));
        };
        let inner = render::Camera::frame(
            ball,
            direction.unwrap_or(DVec3::NEG_Z),
            up.unwrap_or(DVec3::Y),
            if ortho {
                Lens::Orthographic { height: 1.0 }
            } else {
                Lens::Perspective { fov }
            },
            margin,
        )
        .map_err(to_py)?;
        Ok(Camera { inner })
    }

    /// The camera `gtsphere render` uses: the Viewpoint named `viewpoint` (DEF name or
    /// description), else the scene's first Viewpoint, else one looking down -z that frames
    /// the scene. `fov_across` is the image side a Viewpoint's fieldOfView spans: "smaller"
    /// (VRML97, the default), "width" (as PyMOL writes it) or "height", as `render
    /// --fov-across`; with "width" or "height" the angle depends on the image's shape, so
    /// give the image's `size=(width, height)`.
    #[staticmethod]
    #[pyo3(signature = (scene, viewpoint=None, *, fov_across="smaller", size=None))]
    fn from_scene(
        scene: &Scene,
        viewpoint: Option<String>,
        fov_across: &str,
        size: Option<(u32, u32)>,
    ) -> PyResult<Camera> {
        let choice = match viewpoint {
            Some(n) => CameraChoice::Named(n),
            None => CameraChoice::Auto,
        };
        let across = match fov_across {
            "smaller" => FovAcross::Smaller,
            "width" => FovAcross::Width,
            "height" => FovAcross::Height,
            other => {
                return Err(PyValueError::new_err(format!(
                    "fov_across = {other:?}: expected \"smaller\", \"width\" or \"height\""
                )))
            }
        };
        // The size matters for a fieldOfView across a side other than the smaller one (and
        // for an orthographic camera fitted to the scene, which this is not).
        let (width, height) = match (across, size) {
            (_, Some((w, h))) if w == 0 || h == 0 => {
                return Err(PyValueError::new_err(format!(
                    "size = ({w}, {h}): width and height must be positive"
                )))
            }
            (_, Some(wh)) => wh,
            (FovAcross::Smaller, None) => (1, 1),
            (_, None) => {
                return Err(PyValueError::new_err(format!(
                    "fov_across = {fov_across:?} needs the image's size=(width, height)"
                )))
            }
        };
        let (inner, _) = scene
            .prepared
            .camera(
                &choice,
                Projection::Perspective { fov_across: across },
                width,
                height,
            )
            .map_err(to_py)?;
        Ok(Camera { inner })
    }

    /// The eye position.
    #[getter]
    fn position(&self) -> (f64, f64, f64) {
        triple(self.inner.position)
    }

    /// The unit view direction.
    #[getter]
    fn forward(&self) -> (f64, f64, f64) {
        triple(self.inner.forward)
    }

    /// The unit up vector (perpendicular to forward).
    #[getter]
    fn up(&self) -> (f64, f64, f64) {
        triple(self.inner.up)
    }

    /// The unit vector to the right of the image.
    #[getter]
    fn right(&self) -> (f64, f64, f64) {
        triple(self.inner.right)
    }

    /// The perspective field of view (radians), or None for an orthographic camera.
    #[getter]
    fn fov(&self) -> Option<f64> {
        match self.inner.lens {
            Lens::Perspective { fov } => Some(fov),
            Lens::Orthographic { .. } => None,
        }
    }

    /// The orthographic height (world units across the smaller side), or None.
    #[getter]
    fn ortho_height(&self) -> Option<f64> {
        match self.inner.lens {
            Lens::Orthographic { height } => Some(height),
            Lens::Perspective { .. } => None,
        }
    }

    fn __repr__(&self) -> String {
        let c = &self.inner;
        format!(
            "<gtsphere.Camera at ({:?}, {:?}, {:?}) looking ({:?}, {:?}, {:?}), {}>",
            c.position.x,
            c.position.y,
            c.position.z,
            c.forward.x,
            c.forward.y,
            c.forward.z,
            match c.lens {
                Lens::Perspective { fov } => format!("fov {fov:?}"),
                Lens::Orthographic { height } => format!("orthographic height {height:?}"),
            }
        )
    }
}
