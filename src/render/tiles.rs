//! The tile loop: rayon over square tiles, each pixel computed entirely inside one task and
//! its samples summed in a fixed order, so the image is the same bit for bit whatever the
//! thread count.

use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use glam::DVec3;
use rayon::prelude::*;

use super::ao::AoScratch;
use super::integrators::{self, surface, Scratch};
use super::packets::{BandHits, BAND};
use super::sampler::{offsets, Rng};
use super::Integrator;
use super::{Camera, Counters, Film, Prepared, RenderOptions, View};
use crate::Error;

/// Pixels a side of a tile.
pub(crate) const TILE: u32 = 16;

/// Bytes the tile loop holds per pixel of the picture until the film is assembled: each
/// finished pixel, and its centre ray's hit when an extra channel needs it.
pub(crate) fn held_per_pixel(aovs: super::Aovs) -> u64 {
    let hit = if aovs.any() {
        size_of::<CentreHit>()
    } else {
        0
    };
    (size_of::<PixelOut>() + hit) as u64
}

/// Bytes one worker's buffers take while it traces a tile whose pixels hold `samples`
/// samples each, a band's camera rays taking `per_ray` bytes each; `None` on overflow.
pub(crate) fn worker_bytes(samples: u64, per_ray: u64) -> Option<u64> {
    // A pixel's sample positions, the stratified sampler's permutation and the band's
    // copy of the positions; the band's rays and hits.
    let positions = (2 * size_of::<(f64, f64)>() + size_of::<usize>()) as u64;
    let band = u64::from(TILE * BAND).checked_mul(per_ray)?;
    samples.checked_mul(positions.checked_add(band)?)
}

/// A finished pixel: RGB, alpha and the error estimate.
#[derive(Clone, Copy, Default)]
struct PixelOut {
    rgb: [f64; 3],
    alpha: f64,
    error: f64,
}

/// A finished tile: its pixels row by row, their centre rays' hits (when an extra channel
/// needs them) and its work counters.
type TileOut = (Vec<PixelOut>, Vec<CentreHit>, Counters);

/// What the ray through a pixel's centre hit first (traced only when depth, normal or id
/// are asked for).
#[derive(Clone, Copy, Default)]
struct CentreHit {
    depth: f64,
    normal: [f64; 3],
    id: i64,
    ao: f64,
}

/// Told how the tile loop goes (the command line draws a progress bar, Python calls back),
/// and asked whether to stop; `()` is told nothing and never cancels.
pub trait Progress: Sync {
    /// Before the first tile: how many tiles there are.
    fn start(&self, _tiles: u64) {}
    /// A tile is done (called from the worker threads, in any order).
    fn tile_done(&self) {}
    /// After the last tile.
    fn finish(&self) {}
    /// Whether to stop: asked before every pixel, from the worker threads, so it must be
    /// cheap. Once it says yes, `render` returns [`Error::Cancelled`] as soon as the pixels
    /// being traced are done.
    fn cancelled(&self) -> bool {
        false
    }
}

impl Progress for () {}

/// A cancellation flag to share with another thread (a signal handler, a UI): `render` with
/// it stops once [`Cancel::cancel`] was called.
#[derive(Debug, Default)]
pub struct Cancel(AtomicBool);

impl Cancel {
    /// Asks the render to stop: it returns [`Error::Cancelled`] once the pixels being
    /// traced are done.
    pub fn cancel(&self) {
        self.0.store(true, Ordering::Relaxed);
    }
    /// Whether [`Cancel::cancel`] was called.
    pub fn is_cancelled(&self) -> bool {
        self.0.load(Ordering::Relaxed)
    }
}

impl Progress for Cancel {
    fn cancelled(&self) -> bool {
        self.is_cancelled()
    }
}

fn render_pixel(
    view: &View,
    opts: &RenderOptions,
    (i, j): (u32, u32),
    samples: &mut Vec<(f64, f64)>,
    (scratch, ao_scratch): (&mut Scratch, &mut AoScratch),
    counters: &mut Counters,
    band: Option<(&BandHits, usize)>,
) -> PixelOut {
    let (w, h) = (f64::from(opts.width), f64::from(opts.height));
    let pixel = u64::from(j) * u64::from(opts.width) + u64::from(i);
    offsets(opts.sampler, opts.spp, opts.seed, pixel, samples);
    if opts.sampler == super::SamplerKind::Center
        && view.integrator == Integrator::Mc
        && view.gas_spheres > 0
    {
        // Monte Carlo at the pixel centre: `spp` paths through the same point.
        samples.resize(opts.spp.max(1) as usize, (0.5, 0.5));
    }
    let cam = &view.camera;
    let mut sum = DVec3::ZERO;
    // Welford's running mean and sum of squared deviations (the one-pass `sum x^2 - n mean^2`
    // cancels, reporting ~sqrt(eps) |mean| where the samples agree to the last bit).
    let (mut run_mean, mut m2) = (DVec3::ZERO, DVec3::ZERO);
    let (mut err, mut err2) = (0.0, 0.0);
    let mut covered = 0u32;
    // The Monte Carlo integrator's and the AO methods' own random numbers: a stream per pixel,
    // apart from the sample positions' stream.
    let mut rng = Rng::new(opts.seed ^ 0x6D63_5F70_6174_6873, pixel);
    for (k, &(sx, sy)) in samples.iter().enumerate() {
        let e = match band {
            // Traced already, in a packet (scenes without gas only).
            Some((band, at)) => {
                let (rays, hits) = band.of_pixel(at);
                let (o, d) = rays[k];
                match &view.integrator {
                    Integrator::Ao(ao) => super::ao::radiance_of_hit(
                        view,
                        ao,
                        (o, d),
                        hits[k],
                        ao_scratch,
                        &mut rng,
                        counters,
                    ),
                    _ => surface::radiance_of_hit(
                        view,
                        o,
                        d,
                        hits[k],
                        &mut scratch.blockers,
                        counters,
                    ),
                }
            }
            None => {
                let (o, d) = cam.ray((f64::from(i) + sx) / w, (f64::from(j) + sy) / h);
                match &view.integrator {
                    Integrator::Ao(ao) => {
                        let hit = surface::first_hit(view, o, d, 0.0);
                        let s = &mut *ao_scratch;
                        super::ao::radiance_of_hit(view, ao, (o, d), hit, s, &mut rng, counters)
                    }
                    _ => integrators::radiance(view, o, d, &mut rng, scratch, counters),
                }
            }
        };
        sum += e.value;
        err += e.error;
        err2 += e.error * e.error;
        covered += u32::from(e.covered);
        let delta = e.value - run_mean;
        run_mean += delta / (k + 1) as f64;
        m2 += delta * (e.value - run_mean);
    }
    let n = samples.len() as f64;
    let mean = sum / n;
    let error = if view.integrator == Integrator::Mc && view.gas_spheres > 0 {
        // Standard error of the mean, worst channel.
        if n > 1.0 {
            (m2.max(DVec3::ZERO) / (n * (n - 1.0))).max_element().sqrt()
        } else {
            f64::INFINITY
        }
    } else if matches!(view.integrator, Integrator::Ao(ao) if ao.method.is_random()) {
        // Standard errors of independent samples: the mean's is their root sum of squares / n.
        err2.sqrt() / n
    } else {
        err / n
    };
    PixelOut {
        rgb: mean.to_array(),
        alpha: f64::from(covered) / n,
        error,
    }
}

/// The first opaque hit of the ray through pixel `(i, j)`'s centre.
fn centre_hit(
    view: &View,
    opts: &RenderOptions,
    (i, j): (u32, u32),
    ao_scratch: &mut AoScratch,
) -> CentreHit {
    let (w, h) = (f64::from(opts.width), f64::from(opts.height));
    let (o, d) = view
        .camera
        .ray((f64::from(i) + 0.5) / w, (f64::from(j) + 0.5) / h);
    match surface::first_hit(view, o, d, 0.0) {
        Some(hit) => {
            let sp = surface::surface_point(view, o, d, hit);
            // Spheres are numbered first, then the other surfaces.
            let id = match hit.on {
                surface::Opaque::Sphere(_) => i64::from(sp.scene_index(view)),
                surface::Opaque::Surface(i) => (view.spheres + i as usize) as i64,
            };
            let ao = if opts.aovs.ao {
                let reach = (opts.ao.reach, opts.ao.weighting);
                // (The bound of its error, with Cylinders or Cones, is within `tol`.)
                super::ao::at_hit(view, &sp, reach, opts.tol, ao_scratch).0
            } else {
                0.0
            };
            CentreHit {
                depth: hit.t,
                normal: sp.n.to_array(),
                id,
                ao,
            }
        }
        None => CentreHit {
            depth: f64::INFINITY,
            normal: [0.0; 3],
            id: -1,
            ao: f64::NAN,
        },
    }
}

/// Renders `view` seen by `camera` as `opts` say, in rayon's current pool (run it inside
/// `ThreadPool::install` to choose the thread count), telling `progress` of each tile and
/// stopping with [`Error::Cancelled`] when it says so. The pixels are the same bit for bit
/// whatever the thread count and whatever else `prep` was rendered with.
pub fn render(
    prep: &Prepared,
    camera: &Camera,
    opts: &RenderOptions,
    progress: &dyn Progress,
) -> Result<Film, Error> {
    let view = prep.view(camera, opts)?;
    render_view(&view, opts, progress)
}

/// [`render`] of a view made by [`Prepared::view`] (with the same options).
///
/// Cancelled, it stops within a tile's time: the tiles being traced stop at their next
/// pixel, and a tile started after the cancel returns before it allocates anything.
pub fn render_view(
    view: &View,
    opts: &RenderOptions,
    progress: &dyn Progress,
) -> Result<Film, Error> {
    let start = Instant::now();
    // The pixels to render: the region asked for, or the whole image. Each pixel depends
    // only on its own position, so a region equals the same pixels of a whole render.
    let (rx0, ry0, rx1, ry1) = opts.region.unwrap_or((0, 0, opts.width, opts.height));
    let (w, h) = (rx1 - rx0, ry1 - ry0);
    // Tiles are counted in usize: (2^32 / 16)^2 overflows u32.
    let (tx, ty) = (w.div_ceil(TILE) as usize, h.div_ceil(TILE) as usize);
    let count = tx
        .checked_mul(ty)
        .ok_or_else(|| Error::Invalid(format!("a {w}x{h} image has too many tiles")))?;
    // The film first: an image too large for the memory fails here, before any tracing.
    let mut film = Film::zeroed(w as usize, h as usize, opts.aovs)?;
    progress.start(count as u64);
    // `None` for a tile cut short by a cancel: the collect then stops taking tiles.
    let tiles: Option<Vec<TileOut>> = (0..count)
        .into_par_iter()
        .map(|t| {
            if progress.cancelled() {
                return None;
            }
            let (x0, y0) = tile_origin(t, tx);
            let (x1, y1) = ((x0 + TILE).min(w), (y0 + TILE).min(h));
            let (x0, y0, x1, y1) = (x0 + rx0, y0 + ry0, x1 + rx0, y1 + ry0);
            let mut counters = Counters::default();
            let mut samples = Vec::with_capacity(opts.spp as usize);
            let mut scratch = Scratch::default();
            let mut ao_scratch = AoScratch::default();
            let mut px = Vec::with_capacity(((x1 - x0) * (y1 - y0)) as usize);
            let mut hits = Vec::new();
            // Without gas, every camera ray's first hit is all the tracing before shading:
            // a band's are traced first, four by four pixels in a packet.
            let packets = view.gas_spheres == 0;
            let mut band = BandHits::default();
            for b0 in (y0..y1).step_by(BAND as usize) {
                let b1 = (b0 + BAND).min(y1);
                if progress.cancelled() {
                    return None;
                }
                if packets {
                    band.trace(view, opts, (x0, x1), (b0, b1));
                }
                for j in b0..b1 {
                    for i in x0..x1 {
                        if progress.cancelled() {
                            return None;
                        }
                        let at = ((j - b0) * (x1 - x0) + (i - x0)) as usize;
                        px.push(render_pixel(
                            view,
                            opts,
                            (i, j),
                            &mut samples,
                            (&mut scratch, &mut ao_scratch),
                            &mut counters,
                            packets.then_some((&band, at)),
                        ));
                        if opts.aovs.any() {
                            hits.push(centre_hit(view, opts, (i, j), &mut ao_scratch));
                        }
                    }
                }
            }
            progress.tile_done();
            Some((px, hits, counters))
        })
        .collect();
    progress.finish();
    let tiles = match tiles {
        Some(tiles) if !progress.cancelled() => tiles,
        _ => return Err(Error::Cancelled),
    };

    for (t, (px, hits, c)) in tiles.into_iter().enumerate() {
        film.counters += c;
        let (x0, y0) = tile_origin(t, tx);
        let x1 = (x0 + TILE).min(w);
        for (k, p) in px.into_iter().enumerate() {
            let (i, j) = (x0 + k as u32 % (x1 - x0), y0 + k as u32 / (x1 - x0));
            let at = (j as usize) * (w as usize) + i as usize;
            film.rgb[at] = p.rgb;
            film.alpha[at] = p.alpha;
            film.max_error = film.max_error.max(p.error);
            if let Some(e) = &mut film.error {
                e[at] = p.error;
            }
            if let Some(a) = hits.get(k) {
                if let Some(d) = &mut film.depth {
                    d[at] = a.depth;
                }
                if let Some(nm) = &mut film.normal {
                    nm[at] = a.normal;
                }
                if let Some(id) = &mut film.id {
                    id[at] = a.id;
                }
                if let Some(ao) = &mut film.ao {
                    ao[at] = a.ao;
                }
            }
        }
    }
    // The lights' grids are built for this render (Prepared::view): their time is its too.
    film.grid_seconds = view.grid_time.as_secs_f64();
    film.seconds = start.elapsed().as_secs_f64() + film.grid_seconds;
    Ok(film)
}

/// The top left pixel of tile `t` (row-major, `tx` tiles a row), relative to the region.
fn tile_origin(t: usize, tx: usize) -> (u32, u32) {
    // Both fit: a region is at most 2^32 - 1 pixels a side.
    ((t % tx) as u32 * TILE, (t / tx) as u32 * TILE)
}
