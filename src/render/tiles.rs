//! The tile loop: rayon over square tiles, each pixel computed entirely inside one task and
//! its samples summed in a fixed order, so the image is the same bit for bit whatever the
//! thread count.

use std::time::Instant;

use glam::DVec3;
use rayon::prelude::*;

use super::integrators::{self, surface, Scratch};
use super::sampler::{offsets, Rng};
use super::Integrator;
use super::{Counters, Prepared, RenderOptions};
use crate::output::{Image, Layer};

const TILE: u32 = 16;

/// A finished render.
pub struct Rendered {
    pub image: Image,
    pub counters: Counters,
    /// The largest per-pixel error estimate.
    pub max_error: f64,
    /// Wall time of the tile loop.
    pub seconds: f64,
    /// The pixels' RGB in f64 before rounding to the f32 image, row by row; empty unless
    /// `RenderOptions::film_f64` (error measurements below f32 rounding, `gtsphere bench`).
    pub rgb64: Vec<[f64; 3]>,
}

/// A finished pixel: RGB and alpha, then (only when AOVs are asked for) depth, normal, id.
#[derive(Clone, Copy, Default)]
struct PixelOut {
    /// The f64 mean (rounded to f32 only when the image is assembled).
    rgb: [f64; 3],
    alpha: f32,
    error: f32,
    aov: Option<[f32; 5]>,
}

/// Told how the tile loop goes (the command line draws a progress bar); `()` is told nothing.
pub trait Progress: Sync {
    /// Before the first tile: how many tiles there are.
    fn start(&self, _tiles: u64) {}
    /// A tile is done (called from the worker threads, in any order).
    fn tile_done(&self) {}
    /// After the last tile.
    fn finish(&self) {}
}

impl Progress for () {}

fn render_pixel(
    prep: &Prepared,
    opts: &RenderOptions,
    i: u32,
    j: u32,
    samples: &mut Vec<(f64, f64)>,
    scratch: &mut Scratch,
    counters: &mut Counters,
) -> PixelOut {
    let (w, h) = (f64::from(opts.width), f64::from(opts.height));
    let pixel = u64::from(j) * u64::from(opts.width) + u64::from(i);
    offsets(opts.sampler, opts.spp, opts.seed, pixel, samples);
    if opts.sampler == super::SamplerKind::Center
        && prep.integrator == Integrator::Mc
        && prep.gas_spheres > 0
    {
        // Monte Carlo at the pixel centre: `spp` paths through the same point.
        samples.resize(opts.spp.max(1) as usize, (0.5, 0.5));
    }
    let cam = &prep.camera.camera;
    let mut sum = DVec3::ZERO;
    // Welford's running mean and sum of squared deviations (the one-pass `sum x^2 - n mean^2`
    // cancels, reporting ~sqrt(eps) |mean| where the samples agree to the last bit).
    let (mut run_mean, mut m2) = (DVec3::ZERO, DVec3::ZERO);
    let mut err = 0.0;
    let mut covered = 0u32;
    // The Monte Carlo integrator's own random numbers: a stream per pixel, apart from the
    // sample positions' stream.
    let mut rng = Rng::new(opts.seed ^ 0x6D63_5F70_6174_6873, pixel);
    for (k, &(sx, sy)) in samples.iter().enumerate() {
        let (o, d) = cam.ray((f64::from(i) + sx) / w, (f64::from(j) + sy) / h);
        let e = integrators::radiance(prep, o, d, &mut rng, scratch, counters);
        sum += e.value;
        err += e.error;
        covered += u32::from(e.covered);
        let delta = e.value - run_mean;
        run_mean += delta / (k + 1) as f64;
        m2 += delta * (e.value - run_mean);
    }
    let n = samples.len() as f64;
    let mean = sum / n;
    let error = if prep.integrator == Integrator::Mc && prep.gas_spheres > 0 {
        // Standard error of the mean, worst channel.
        if n > 1.0 {
            (m2.max(DVec3::ZERO) / (n * (n - 1.0))).max_element().sqrt()
        } else {
            f64::INFINITY
        }
    } else {
        err / n
    };
    let mut out = PixelOut {
        rgb: mean.to_array(),
        alpha: (f64::from(covered) / n) as f32,
        error: error as f32,
        aov: None,
    };
    if opts.aovs.any() {
        let (o, d) = cam.ray((f64::from(i) + 0.5) / w, (f64::from(j) + 0.5) / h);
        out.aov = Some(match surface::first_hit(prep, o, d, 0.0) {
            Some(hit) => {
                let sp = surface::surface_point(prep, o, d, hit);
                let n = sp.n.as_vec3();
                // Spheres are numbered first, then the other surfaces.
                let id = match hit.on {
                    surface::Opaque::Sphere(_) => f64::from(sp.scene_index(prep)),
                    surface::Opaque::Surface(i) => (prep.spheres + i as usize) as f64,
                };
                [hit.t as f32, n.x, n.y, n.z, id as f32]
            }
            None => [f32::INFINITY, 0.0, 0.0, 0.0, -1.0],
        });
    }
    out
}

/// Renders the prepared scene. Run inside a rayon pool to choose the thread count.
pub fn render(prep: &Prepared, opts: &RenderOptions) -> Rendered {
    render_with_progress(prep, opts, &())
}

/// [`render`], telling `progress` of each finished tile.
pub fn render_with_progress(
    prep: &Prepared,
    opts: &RenderOptions,
    progress: &dyn Progress,
) -> Rendered {
    let start = Instant::now();
    // The pixels to render: the region asked for, or the whole image. Each pixel depends
    // only on its own position, so a region equals the same pixels of a whole render.
    let (rx0, ry0, rx1, ry1) = opts.region.unwrap_or((0, 0, opts.width, opts.height));
    let (w, h) = (rx1 - rx0, ry1 - ry0);
    let (tx, ty) = (w.div_ceil(TILE), h.div_ceil(TILE));
    progress.start(u64::from(tx * ty));
    let tiles: Vec<(Vec<PixelOut>, Counters)> = (0..tx * ty)
        .into_par_iter()
        .map(|t| {
            let (x0, y0) = ((t % tx) * TILE, (t / tx) * TILE);
            let (x1, y1) = ((x0 + TILE).min(w), (y0 + TILE).min(h));
            let (x0, y0, x1, y1) = (x0 + rx0, y0 + ry0, x1 + rx0, y1 + ry0);
            let mut counters = Counters::default();
            let mut samples = Vec::with_capacity(opts.spp as usize);
            let mut scratch = Scratch::default();
            let mut px = Vec::with_capacity(((x1 - x0) * (y1 - y0)) as usize);
            for j in y0..y1 {
                for i in x0..x1 {
                    px.push(render_pixel(
                        prep,
                        opts,
                        i,
                        j,
                        &mut samples,
                        &mut scratch,
                        &mut counters,
                    ));
                }
            }
            progress.tile_done();
            (px, counters)
        })
        .collect();
    progress.finish();

    let n = (w as usize) * (h as usize);
    let mut image = Image {
        width: w as usize,
        height: h as usize,
        rgb: vec![[0.0; 3]; n],
        alpha: vec![0.0; n],
        layers: Vec::new(),
    };
    let mut depth = vec![0f32; if opts.aovs.depth { n } else { 0 }];
    let mut normal = vec![[0f32; 3]; if opts.aovs.normal { n } else { 0 }];
    let mut id = vec![0f32; if opts.aovs.id { n } else { 0 }];
    let mut error = vec![0f32; if opts.aovs.error { n } else { 0 }];
    let mut rgb64 = vec![[0f64; 3]; if opts.film_f64 { n } else { 0 }];
    let mut max_error = 0f64;
    let mut counters = Counters::default();
    for (t, (px, c)) in tiles.into_iter().enumerate() {
        counters += c;
        let t = t as u32;
        let (x0, y0) = ((t % tx) * TILE, (t / tx) * TILE);
        let x1 = (x0 + TILE).min(w);
        for (k, p) in px.into_iter().enumerate() {
            let (i, j) = (x0 + k as u32 % (x1 - x0), y0 + k as u32 / (x1 - x0));
            let at = (j as usize) * (w as usize) + i as usize;
            image.rgb[at] = p.rgb.map(|v| v as f32);
            image.alpha[at] = p.alpha;
            if opts.film_f64 {
                rgb64[at] = p.rgb;
            }
            max_error = max_error.max(f64::from(p.error));
            if opts.aovs.error {
                error[at] = p.error;
            }
            if let Some(a) = p.aov {
                if opts.aovs.depth {
                    depth[at] = a[0];
                }
                if opts.aovs.normal {
                    normal[at] = [a[1], a[2], a[3]];
                }
                if opts.aovs.id {
                    id[at] = a[4];
                }
            }
        }
    }
    if opts.aovs.depth {
        image.layers.push(Layer {
            name: "depth".into(),
            data: depth,
        });
    }
    if opts.aovs.normal {
        for (k, axis) in ["X", "Y", "Z"].iter().enumerate() {
            image.layers.push(Layer {
                name: format!("normal.{axis}"),
                data: normal.iter().map(|v| v[k]).collect(),
            });
        }
    }
    if opts.aovs.id {
        image.layers.push(Layer {
            name: "id".into(),
            data: id,
        });
    }
    if opts.aovs.error {
        image.layers.push(Layer {
            name: "error".into(),
            data: error,
        });
    }
    Rendered {
        image,
        counters,
        max_error,
        seconds: start.elapsed().as_secs_f64(),
        rgb64,
    }
}
