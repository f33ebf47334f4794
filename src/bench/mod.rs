//! What `gtsphere bench` and `cargo bench` take from the library beyond its API: the
//! generated benchmark [`scenes`], and `bench trace`'s camera and shadow ray passes timed
//! apart ([`ray_passes`]). Hidden from the documentation: a program has no use for them.

pub mod scenes;

use std::time::Instant;

use crate::render::integrators::surface::surface_point;
use crate::render::lights::towards;
use crate::render::packets::{BandHits, BAND};
use crate::render::visibility::{visible_after, Blockers};
use crate::render::{Prepared, RenderOptions};
use crate::Error;

/// What [`ray_passes`] traced and how long each pass took, on one thread.
#[derive(Clone, Copy, Debug, Default)]
pub struct RayPasses {
    /// Seconds spent finding every camera ray's first hit.
    pub camera_seconds: f64,
    /// Seconds spent tracing the shadow rays.
    pub shadow_seconds: f64,
    /// Camera rays that hit something.
    pub hits: u64,
    /// Shadow rays traced (one per hit and light that reaches the hit).
    pub shadow_rays: u64,
    /// Per light (the first two), the hits it lights: its shadow ray unblocked and N.L > 0.
    pub lit: [u64; 2],
}

/// The camera rays through each pixel of `prep`'s default camera at `opts`' size, then one
/// shadow ray per hit and light, on the calling thread, each pass timed apart.
///
/// A band of 16 rows at a time (so the hit list stays small). N.L <= 0 is traced too, as
/// the Embree reference does, so that the counts compare. As in the renderer, camera rays go
/// in 16x16 tiles, traced four by four pixels in a packet (Embree's harness traces one
/// `rtcIntersect1` at a time), and each light's shadow ray first tries the sphere that
/// blocked the previous one (an exact test; Embree has no such cache): neighbouring rays
/// share BVH nodes and spheres while they are still in cache.
pub fn ray_passes(prep: &Prepared, opts: &RenderOptions) -> Result<RayPasses, Error> {
    let (width, height) = (opts.width, opts.height);
    let view = prep.view(&prep.default_camera(width, height)?, opts)?;
    let mut out = RayPasses::default();
    let mut hits = Vec::new();
    let mut rows = BandHits::default();
    // Each light's last blocker, tried first, as the renderer does from pixel to pixel.
    let mut blockers = Blockers::default();
    for band in (0..height).step_by(16) {
        let t0 = Instant::now();
        hits.clear();
        for x0 in (0..width).step_by(16) {
            // As the renderer does (render/packets.rs): four rows at a time, their camera
            // rays traced four by four pixels in a packet, the hits then taken row by row
            // (the order the renderer shades them in, and so traces their shadow rays).
            for y in (band..(band + 16).min(height)).step_by(BAND as usize) {
                let (x1, y1) = ((x0 + 16).min(width), (y + BAND).min(height));
                rows.trace(&view, opts, (x0, x1), (y, y1));
                for p in 0..((x1 - x0) * (y1 - y)) as usize {
                    let (rays, found) = rows.of_pixel(p);
                    if let Some(h) = found[0] {
                        hits.push(surface_point(prep, rays[0].0, rays[0].1, h));
                    }
                }
            }
        }
        out.camera_seconds += t0.elapsed().as_secs_f64();
        out.hits += hits.len() as u64;
        let t1 = Instant::now();
        for sp in &hits {
            for (k, l) in view.lights.iter().enumerate() {
                if let Some((dir, dist, _)) = towards(l, sp.x) {
                    out.shadow_rays += 1;
                    let slot = blockers.slot(k);
                    let v = visible_after(prep, sp.x, dir, dist, Some(sp.on), slot);
                    if let Some(lit) = out.lit.get_mut(k) {
                        *lit += u64::from(v > 0.0 && sp.n.dot(dir) > 0.0);
                    }
                }
            }
        }
        out.shadow_seconds += t1.elapsed().as_secs_f64();
    }
    Ok(out)
}
