//! `gtsphere.save` and `gtsphere.compare`: pictures to files, and the metrics of
//! `gtsphere compare`.

use std::path::PathBuf;

use gtsphere::compare::{metrics_of, Metrics};
use gtsphere::output::{format_for, read_image, write_film, write_image, write_npy, Format, Image};
use numpy::{PyArrayDyn, PyUntypedArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::arrays::{float64, shape_of};
use crate::render::Film;
use crate::to_py;

/// An RGB picture from an array of shape (H, W, 3), (H, W, 4) (RGBA) or (H, W) (grey),
/// in f64, with its alpha (1 where none is given).
struct Picture {
    width: usize,
    height: usize,
    rgb: Vec<[f64; 3]>,
    alpha: Vec<f64>,
}

fn picture(py: Python<'_>, name: &str, obj: &Bound<'_, PyAny>) -> PyResult<Picture> {
    let a = float64(py, name, obj)?;
    let s = a.shape().to_vec();
    let data = a
        .as_slice()
        .map_err(|e| PyValueError::new_err(format!("{name}: {e}")))?;
    let (h, w, c) = match *s.as_slice() {
        [h, w] => (h, w, 1),
        [h, w, c] if c == 3 || c == 4 => (h, w, c),
        _ => {
            return Err(PyValueError::new_err(format!(
                "{name} must have shape (H, W, 3), (H, W, 4) or (H, W), got {}",
                shape_of(&a)
            )))
        }
    };
    if h == 0 || w == 0 {
        return Err(PyValueError::new_err(format!("{name} is empty")));
    }
    let px = |k: usize| &data[k * c..(k + 1) * c];
    Ok(Picture {
        width: w,
        height: h,
        rgb: (0..h * w)
            .map(|k| match px(k) {
                &[v] => [v; 3],
                p => [p[0], p[1], p[2]],
            })
            .collect(),
        alpha: (0..h * w)
            .map(|k| if c == 4 { px(k)[3] } else { 1.0 })
            .collect(),
    })
}

/// Writes a Film or an array to `path`, by extension: .exr (linear float RGBA; a Film's
/// depth / normal / id / error channels too), .png (8-bit sRGB), .pfm (linear float RGB)
/// or .npy (float64 H x W x 3, every digit). An array may be (H, W, 3), (H, W, 4) RGBA or
/// (H, W) grey. The file appears whole or not at all (written under a temporary name, then
/// renamed).
#[pyfunction]
pub fn save(py: Python<'_>, image: &Bound<'_, PyAny>, path: PathBuf) -> PyResult<()> {
    if let Ok(film) = image.cast::<Film>() {
        let film = film.get().to_film(py)?;
        return py.detach(|| write_film(&path, &film)).map_err(to_py);
    }
    let p = picture(py, "image", image)?;
    let format = format_for(&path).map_err(to_py)?;
    py.detach(|| match format {
        Format::Npy => write_npy(&path, p.width, p.height, &p.rgb),
        _ => write_image(
            &path,
            &Image {
                width: p.width,
                height: p.height,
                rgb: p.rgb.iter().map(|c| c.map(|v| v as f32)).collect(),
                alpha: p.alpha.iter().map(|&v| v as f32).collect(),
                layers: Vec::new(),
            },
        ),
    })
    .map_err(to_py)
}

/// A Film, an array or a picture file, as (width, height, f64 RGB).
fn pixels(
    py: Python<'_>,
    name: &str,
    obj: &Bound<'_, PyAny>,
) -> PyResult<(usize, usize, Vec<[f64; 3]>)> {
    if let Ok(film) = obj.cast::<Film>() {
        let f = film.get().to_film(py)?;
        return Ok((f.width, f.height, f.rgb));
    }
    if let Ok(path) = obj.extract::<PathBuf>() {
        if !obj.is_instance_of::<PyArrayDyn<f64>>() {
            let img = py.detach(|| read_image(&path)).map_err(to_py)?;
            let rgb = img.rgb.iter().map(|c| c.map(f64::from)).collect();
            return Ok((img.width, img.height, rgb));
        }
    }
    let p = picture(py, name, obj)?;
    Ok((p.width, p.height, p.rgb))
}

/// Error metrics of `image` against `reference`, the numbers `gtsphere compare` prints:
/// a dict with rmse, relative_rmse, psnr (dB), max_abs and max_at ((x, y) of the largest
/// difference). Each argument is a Film, an array ((H, W, 3), (H, W, 4) or (H, W)) or the
/// path of a picture file (.exr, .pfm, .png, .npy), read as `gtsphere compare` reads it.
#[pyfunction]
pub fn compare<'py>(
    py: Python<'py>,
    image: &Bound<'py, PyAny>,
    reference: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyDict>> {
    let (aw, ah, a) = pixels(py, "image", image)?;
    let (bw, bh, b) = pixels(py, "reference", reference)?;
    let m: Metrics = metrics_of((aw, ah), &a, (bw, bh), &b).map_err(PyValueError::new_err)?;
    let d = PyDict::new(py);
    d.set_item("rmse", m.rmse)?;
    d.set_item("relative_rmse", m.relative_rmse)?;
    d.set_item("psnr", m.psnr)?;
    d.set_item("max_abs", m.max_abs)?;
    d.set_item("max_at", m.max_at)?;
    Ok(d)
}
