//! Camera rays in packets: the first hits of a band of a tile's pixels, traced four by four
//! pixels at a time (`SphereBvh::closest_packet`), for the surface integrator to shade pixel
//! by pixel afterwards. The hits are those one ray at a time finds, so the pixels are the
//! same bit for bit; only the BVH's nodes are visited once for sixteen neighbouring rays.

use glam::DVec3;

use super::integrators::surface::{first_hits, OpaqueHit};
use super::sampler::offsets;
use super::{RenderOptions, View};
use crate::accel::{PacketStack, PACKET};

/// Rows of pixels in a band (and columns in a packet): a packet is four by four pixels.
pub const BAND: u32 = 4;
const _: () = assert!((BAND * BAND) as usize <= PACKET);

/// The first hits of every sample of a band's pixels, and the buffers that find them.
#[derive(Default)]
pub struct BandHits {
    /// Every sample's hit, pixel after pixel (row-major within the band).
    hits: Vec<Option<OpaqueHit>>,
    /// Where each pixel's hits start in `hits` (one more entry at the end).
    starts: Vec<usize>,
    rays: Vec<(DVec3, DVec3)>,
    samples: Vec<(f64, f64)>,
    stack: PacketStack,
}

/// Bytes a band holds per camera ray: the ray and its hit (the ray list may hold twice its
/// length while it grows).
pub(crate) fn bytes_per_sample() -> u64 {
    (2 * size_of::<(DVec3, DVec3)>() + size_of::<Option<OpaqueHit>>()) as u64
}

impl BandHits {
    /// Traces the camera rays of pixels `x0..x1` by `y0..y1` (at most [`BAND`] rows), each
    /// pixel's samples as the tile loop makes them.
    pub fn trace(&mut self, view: &View, opts: &RenderOptions, x: (u32, u32), y: (u32, u32)) {
        let ((x0, x1), (y0, y1)) = (x, y);
        debug_assert!(y1 - y0 <= BAND);
        let (w, h) = (f64::from(opts.width), f64::from(opts.height));
        self.rays.clear();
        self.starts.clear();
        for j in y0..y1 {
            for i in x0..x1 {
                let pixel = u64::from(j) * u64::from(opts.width) + u64::from(i);
                offsets(opts.sampler, opts.spp, opts.seed, pixel, &mut self.samples);
                self.starts.push(self.rays.len());
                for &(sx, sy) in &self.samples {
                    let ray = view
                        .camera
                        .ray((f64::from(i) + sx) / w, (f64::from(j) + sy) / h);
                    self.rays.push(ray);
                }
            }
        }
        self.starts.push(self.rays.len());
        self.hits.clear();
        self.hits.resize(self.rays.len(), None);
        let cols = (x1 - x0) as usize;
        let rows = (y1 - y0) as usize;
        for c0 in (0..cols).step_by(BAND as usize) {
            let block = || {
                (0..rows).flat_map(move |r| {
                    (c0..(c0 + BAND as usize).min(cols)).map(move |c| r * cols + c)
                })
            };
            let most = block()
                .map(|p| self.starts[p + 1] - self.starts[p])
                .max()
                .unwrap_or(0);
            // Sample `s` of each pixel of the block: neighbours, one packet.
            for s in 0..most {
                let mut rays = [(DVec3::ZERO, DVec3::X); PACKET];
                let mut at = [0usize; PACKET];
                let mut n = 0;
                for p in block() {
                    let k = self.starts[p] + s;
                    if k < self.starts[p + 1] {
                        rays[n] = self.rays[k];
                        at[n] = k;
                        n += 1;
                    }
                }
                let mut found = [None; PACKET];
                first_hits(view, &rays[..n], 0.0, &mut found, &mut self.stack);
                for (&k, &hit) in at[..n].iter().zip(&found) {
                    self.hits[k] = hit;
                }
            }
        }
    }

    /// The camera rays `(o, d)` of pixel `p` of the band (row-major) and their hits, one
    /// per sample.
    pub fn of_pixel(&self, p: usize) -> (&[(DVec3, DVec3)], &[Option<OpaqueHit>]) {
        let samples = self.starts[p]..self.starts[p + 1];
        (&self.rays[samples.clone()], &self.hits[samples])
    }
}
