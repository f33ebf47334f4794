//! `gtsphere._native`: the Python bindings. Each Python call converts its arguments, calls
//! the library (`gtsphere`) with the GIL released, and converts the result; the library's
//! errors become Python exceptions here ([`to_py`]). The pure-Python package `gtsphere`
//! (gtsphere/__init__.py) re-exports these names.

mod arrays;
mod camera;
mod files;
mod occlusion;
mod render;
mod scene;
mod work;

use pyo3::create_exception;
use pyo3::exceptions::{PyException, PyFileNotFoundError, PyOSError, PyValueError};
use pyo3::prelude::*;

// Module `gtsphere` (where they are re-exported), so that pickle finds them: an error
// raised in a worker process reaches its parent as itself.
create_exception!(
    gtsphere,
    Error,
    PyException,
    "Base class of gtsphere's own errors."
);
create_exception!(
    gtsphere,
    ParseError,
    Error,
    "A scene file that cannot be read: the message starts with file:line:col."
);
create_exception!(
    gtsphere,
    SceneWarning,
    pyo3::exceptions::PyUserWarning,
    "A warning about a scene file (file:line:col: what was found and what was done)."
);

/// A library error as a Python exception: bad values are `ValueError`, files that are
/// missing or unreadable `OSError`, scene files with positioned problems `ParseError`.
pub fn to_py(e: gtsphere::Error) -> PyErr {
    use gtsphere::Error as E;
    match e {
        E::Diag(_) | E::Diags(_) => ParseError::new_err(e.to_string()),
        // OSError(errno, strerror, filename): Python then sets `errno` and `filename`.
        E::Io {
            ref path,
            ref source,
        } => {
            // The OS's error number; ENOENT for a file found missing without one; None
            // (Python's own choice for such errors) otherwise.
            let not_found = source.kind() == std::io::ErrorKind::NotFound;
            let errno = source
                .raw_os_error()
                .or(not_found.then_some(2 /* ENOENT */));
            let args = (errno, source.to_string(), path.clone());
            if not_found {
                PyFileNotFoundError::new_err(args)
            } else {
                PyOSError::new_err(args)
            }
        }
        E::Array { .. } | E::Invalid(_) => PyValueError::new_err(e.to_string()),
        E::Cancelled => pyo3::exceptions::PyKeyboardInterrupt::new_err("render cancelled"),
        E::Image { .. } | E::Internal(_) | E::Other(_) => Error::new_err(e.to_string()),
    }
}

#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("Error", py.get_type::<Error>())?;
    m.add("ParseError", py.get_type::<ParseError>())?;
    m.add("SceneWarning", py.get_type::<SceneWarning>())?;
    m.add_class::<scene::Scene>()?;
    m.add_class::<camera::Camera>()?;
    m.add_class::<render::Film>()?;
    m.add_function(wrap_pyfunction!(scene::load, m)?)?;
    m.add_function(wrap_pyfunction!(render::render, m)?)?;
    m.add_function(wrap_pyfunction!(occlusion::occlusion, m)?)?;
    m.add_function(wrap_pyfunction!(files::save, m)?)?;
    m.add_function(wrap_pyfunction!(files::compare, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
