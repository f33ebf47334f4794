//! Arguments as arrays: any array-like becomes a C-contiguous float64 numpy array (numpy's
//! `asarray` copies only when the dtype or layout differs), whose shape is then checked.
//! Results as arrays: a numpy array takes the library's vector.

use numpy::{PyArray1, PyArrayDyn, PyArrayMethods, PyReadonlyArrayDyn, PyUntypedArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// `numpy.asarray(obj, dtype=float64, order="C")`, read-only.
pub fn float64<'py>(
    py: Python<'py>,
    name: &str,
    obj: &Bound<'py, PyAny>,
) -> PyResult<PyReadonlyArrayDyn<'py, f64>> {
    let np = py.import("numpy")?;
    let kw = PyDict::new(py);
    kw.set_item("dtype", np.getattr("float64")?)?;
    kw.set_item("order", "C")?;
    let arr = np
        .call_method("asarray", (obj,), Some(&kw))
        .map_err(|e| PyValueError::new_err(format!("{name} must be an array of numbers: {e}")))?;
    let arr = arr
        .cast_into::<PyArrayDyn<f64>>()
        .map_err(|_| PyValueError::new_err(format!("{name} must be an array of numbers")))?;
    Ok(arr.readonly())
}

/// The shape as a string like `(5, 2)`.
pub fn shape_of(a: &PyReadonlyArrayDyn<'_, f64>) -> String {
    let s = a.shape();
    match s.len() {
        1 => format!("({},)", s[0]),
        _ => format!(
            "({})",
            s.iter()
                .map(|d| d.to_string())
                .collect::<Vec<_>>()
                .join(", ")
        ),
    }
}

/// An `(n, 3)` array (or, for `n == 1` allowed, a single triple) as a flat slice.
pub fn rows3<'a>(name: &str, a: &'a PyReadonlyArrayDyn<'_, f64>) -> PyResult<&'a [f64]> {
    let s = a.shape();
    if s.len() != 2 || s[1] != 3 {
        return Err(PyValueError::new_err(format!(
            "{name} must have shape (N, 3), got {}",
            shape_of(a)
        )));
    }
    a.as_slice()
        .map_err(|e| PyValueError::new_err(format!("{name}: {e}")))
}

/// A one-dimensional array as a slice.
pub fn flat<'a>(name: &str, a: &'a PyReadonlyArrayDyn<'_, f64>) -> PyResult<&'a [f64]> {
    if a.ndim() != 1 {
        return Err(PyValueError::new_err(format!(
            "{name} must have shape (N,), got {}",
            shape_of(a)
        )));
    }
    a.as_slice()
        .map_err(|e| PyValueError::new_err(format!("{name}: {e}")))
}

/// Three numbers (a tuple, list or array) as a vector, for positions, colours, directions.
pub fn vec3(name: &str, obj: &Bound<'_, PyAny>) -> PyResult<glam::DVec3> {
    let v: Vec<f64> = obj
        .extract()
        .map_err(|_| PyValueError::new_err(format!("{name} must be three numbers")))?;
    match v.as_slice() {
        &[x, y, z] => Ok(glam::DVec3::new(x, y, z)),
        _ => Err(PyValueError::new_err(format!(
            "{name} must be three numbers, got {}",
            v.len()
        ))),
    }
}

/// A numpy array of `data` with `shape`, taking the vector (no copy).
pub fn array<'py, T: numpy::Element>(
    py: Python<'py>,
    data: Vec<T>,
    shape: &[usize],
) -> PyResult<Py<PyAny>> {
    let a = PyArray1::from_vec(py, data);
    Ok(a.reshape(shape)?.into_any().unbind())
}
