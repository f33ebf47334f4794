//! The finished picture in memory: f64 RGB, coverage and the extra channels, with the work
//! counters of the render. File writers take it ([`crate::output::write_film`]) or the f32
//! [`Image`] it rounds to ([`Film::image`]).

use super::{Aovs, Counters};
use crate::output::{Image, Layer};
use crate::Error;

/// A rendered picture (or the region of one that was asked for), row 0 at the top, pixel
/// `(x, y)` at index `y * width + x`. The extra channels are `Some` only when asked for in
/// [`super::Aovs`].
#[derive(Clone, Debug, PartialEq)]
pub struct Film {
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    /// Linear RGB, the mean of each pixel's samples.
    pub rgb: Vec<[f64; 3]>,
    /// Coverage in `[0, 1]`: the fraction of samples that met anything.
    pub alpha: Vec<f64>,
    /// The pixel's estimated absolute error (exact: the mean of its samples' quadrature error
    /// bounds; mc: the standard error of the mean; 0 where the result is exact).
    pub error: Option<Vec<f64>>,
    /// Distance along the centre ray to the first opaque hit, +inf on a miss.
    pub depth: Option<Vec<f64>>,
    /// World unit normal at that hit, 0 on a miss.
    pub normal: Option<Vec<[f64; 3]>>,
    /// What the centre ray hit: spheres numbered in file order, then the other surfaces;
    /// -1 on a miss.
    pub id: Option<Vec<i64>>,
    /// Exact ambient occlusion at the centre ray's first opaque hit (NaN on a miss), if
    /// asked for ([`Aovs::ao`](super::Aovs::ao)).
    pub ao: Option<Vec<f64>>,
    /// The work the render did, summed over its tiles.
    pub counters: Counters,
    /// The largest per-pixel error estimate.
    pub max_error: f64,
    /// Wall time of the tile loop, plus building the lights' grids for it (`View::grid_time`).
    pub seconds: f64,
    /// Of which building the lights' grids.
    pub grid_seconds: f64,
}

/// Bytes a film holds per pixel: RGB, alpha and the extra channels `aovs` asks for.
pub(crate) fn bytes_per_pixel(aovs: Aovs) -> u64 {
    let size = |on: bool, n: usize| if on { n as u64 } else { 0 };
    size(true, size_of::<[f64; 3]>() + size_of::<f64>())
        + size(aovs.error, size_of::<f64>())
        + size(aovs.depth, size_of::<f64>())
        + size(aovs.normal, size_of::<[f64; 3]>())
        + size(aovs.id, size_of::<i64>())
        + size(aovs.ao, size_of::<f64>())
}

/// `n` zeros, or an error when the memory for them cannot be had.
fn zeros<T: Clone + Default>(n: usize) -> Result<Vec<T>, Error> {
    let mut v = Vec::new();
    v.try_reserve_exact(n).map_err(|_| {
        Error::Invalid(format!(
            "cannot allocate {n} pixels of {} bytes for the film",
            size_of::<T>()
        ))
    })?;
    v.resize(n, T::default());
    Ok(v)
}

impl Film {
    /// A black `width x height` film with the channels `aovs` asks for, its counters and
    /// times zero; an error (no abort) when the memory cannot be had.
    pub(crate) fn zeroed(width: usize, height: usize, aovs: Aovs) -> Result<Film, Error> {
        let n = width
            .checked_mul(height)
            .ok_or_else(|| Error::Invalid(format!("a {width}x{height} film is too large")))?;
        Ok(Film {
            width,
            height,
            rgb: zeros(n)?,
            alpha: zeros(n)?,
            error: aovs.error.then(|| zeros(n)).transpose()?,
            depth: aovs.depth.then(|| zeros(n)).transpose()?,
            normal: aovs.normal.then(|| zeros(n)).transpose()?,
            id: aovs.id.then(|| zeros(n)).transpose()?,
            ao: aovs.ao.then(|| zeros(n)).transpose()?,
            counters: Counters::default(),
            max_error: 0.0,
            seconds: 0.0,
            grid_seconds: 0.0,
        })
    }

    /// The picture in f32, with the extra channels as the EXR layers `depth`, `normal.X`,
    /// `normal.Y`, `normal.Z`, `id`, `ao` and `error` (in that order).
    pub fn image(&self) -> Image {
        let f32s = |v: &[f64]| v.iter().map(|&x| x as f32).collect::<Vec<f32>>();
        let mut layers = Vec::new();
        if let Some(d) = &self.depth {
            layers.push(Layer {
                name: "depth".into(),
                data: f32s(d),
            });
        }
        if let Some(n) = &self.normal {
            for (k, axis) in ["X", "Y", "Z"].iter().enumerate() {
                layers.push(Layer {
                    name: format!("normal.{axis}"),
                    data: n.iter().map(|v| v[k] as f32).collect(),
                });
            }
        }
        if let Some(id) = &self.id {
            layers.push(Layer {
                name: "id".into(),
                data: id.iter().map(|&i| i as f32).collect(),
            });
        }
        if let Some(a) = &self.ao {
            layers.push(Layer {
                name: "ao".into(),
                data: f32s(a),
            });
        }
        if let Some(e) = &self.error {
            layers.push(Layer {
                name: "error".into(),
                data: f32s(e),
            });
        }
        Image {
            width: self.width,
            height: self.height,
            rgb: self.rgb.iter().map(|p| p.map(|v| v as f32)).collect(),
            alpha: f32s(&self.alpha),
            layers,
        }
    }
}
