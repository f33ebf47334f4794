//! `gtsphere.occlusion`: each sphere's mean unoccluded fraction over its surface, as
//! `gtsphere occlusion` writes it, on worker threads with the GIL released
//! ([`crate::work`]).

use gtsphere::render::particle_ao::{check_tol, particles_ao};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

use crate::arrays::array;
use crate::render::{reach_of, weighting_of};
use crate::scene::Scene;
use crate::to_py;

/// Each sphere's ambient occlusion: the mean over its surface of the unoccluded fraction
/// (docs/model.md section 11), integrated by adaptive cubature to `tol`, as the command
/// `gtsphere occlusion` computes it. Returns `(ao, error)`, two (N,) float64 arrays in the
/// scene's order (from_arrays' order, or the file's): the means, in [0, 1], and their
/// estimated absolute errors (at most `tol` unless a sphere's integral reached its cap of
/// points). A sphere repeated in one place takes the value of its first copy.
///
/// ao_reach: the distance within which a sphere occludes (world units; None: any distance).
/// ao_weighting: "cosine" (the light a diffuse surface receives from a uniform sky) or
/// "uniform" (the fraction of the hemisphere's solid angle). tol: the target absolute error
/// of each mean, between 0 and 1. threads: worker threads (None: every core; more than four
/// per core are lowered to that, with a RuntimeWarning). progress: called as
/// progress(spheres_done, spheres_total) from this thread every 50 ms when more are done,
/// last with spheres_done == spheres_total (coincident copies are done once and counted
/// once); an exception it raises stops the work.
///
/// AO is exact among opaque spheres, triangles and boxes, and to `tol` among closed
/// cylinders and cones: a scene with gas spheres (which occlude in AO pictures, not in this
/// table), ellipsoids or open cylinders or cones raises ValueError, as does a bad keyword (naming it). The GIL is released while
/// integrating; Ctrl-C (KeyboardInterrupt) stops the work within a sphere's time. The
/// values are the same for any thread count.
#[pyfunction]
#[pyo3(
    signature = (scene, *, ao_reach=None, ao_weighting="cosine", tol=1e-3, threads=None, progress=None),
    text_signature = "(scene, *, ao_reach=None, ao_weighting='cosine', tol=1e-3, threads=None, progress=None)"
)]
#[allow(clippy::type_complexity)]
pub fn occlusion(
    py: Python<'_>,
    scene: PyRef<'_, Scene>,
    ao_reach: Option<f64>,
    ao_weighting: &str,
    tol: f64,
    threads: Option<usize>,
    progress: Option<Py<PyAny>>,
) -> PyResult<(Py<PyAny>, Py<PyAny>)> {
    let reach = reach_of(ao_reach)?;
    let weighting = weighting_of(ao_weighting)?;
    check_tol(tol).map_err(PyValueError::new_err)?;
    let pool = crate::work::pool(py, threads)?;
    // The work shares the prepared scene, not the Python object (as render does).
    let prepared = scene.prepared.clone();
    drop(scene);
    let means = crate::work::watched(py, &pool, progress.as_ref(), "occlusion", |watch| {
        particles_ao(&prepared, (reach, weighting), tol, watch)
    })?
    .map_err(|e| match e {
        // The keywords were checked above: what is left is the scene's refusal.
        gtsphere::Error::Invalid(why) => PyValueError::new_err(format!("scene: {why}")),
        e => to_py(e),
    })?;
    let n = means.len();
    let (ao, error): (Vec<f64>, Vec<f64>) = means.iter().map(|a| (a.mean, a.error)).unzip();
    Ok((array(py, ao, &[n])?, array(py, error, &[n])?))
}
