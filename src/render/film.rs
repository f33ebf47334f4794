//! The finished picture in memory: f64 RGB, coverage and the extra channels, with the work
//! counters of the render. File writers take it ([`crate::output::write_film`]) or the f32
//! [`Image`] it rounds to ([`Film::image`]).

use super::Counters;
use crate::output::{Image, Layer};

/// A rendered picture (or the region of one that was asked for), row 0 at the top, pixel
/// `(x, y)` at index `y * width + x`. The extra channels are `Some` only when asked for in
/// [`super::Aovs`].
#[derive(Clone, Debug, PartialEq)]
pub struct Film {
    pub width: usize,
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
    pub counters: Counters,
    /// The largest per-pixel error estimate.
    pub max_error: f64,
    /// Wall time of the tile loop, plus building the lights' grids for it (`View::grid_time`).
    pub seconds: f64,
    /// Of which building the lights' grids.
    pub grid_seconds: f64,
}

impl Film {
    /// The picture in f32, with the extra channels as the EXR layers `depth`, `normal.X`,
    /// `normal.Y`, `normal.Z`, `id` and `error` (in that order).
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
