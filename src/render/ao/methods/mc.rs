//! Monte Carlo ambient occlusion: `N` random directions per shading point, each traced
//! against the other opaque spheres within the reach; the unoccluded fraction is the share of
//! rays that meet nothing.
//!
//! This is what ray tracers do:
//! - OSPRay's `ao` renderer: `aoSamples` rays per sample (default 1), `aoDistance` the
//!   longest occluding distance (default 10^20), `aoIntensity` a strength (default 1);
//!   cosine-weighted directions from a Halton sequence (bases 5 and 7) rotated per pixel
//!   (`modules/cpu/render/util.ispc`, `computeAO`; <https://www.ospray.org/documentation.html>,
//!   "Ambient Occlusion Renderer").
//! - Tachyon (VMD's ray tracer): a number of samples per hit, uniform directions of the
//!   hemisphere each weighted by its cosine, at any distance (J. E. Stone, Tachyon
//!   `src/shade.c`, `shade_ambient_occlusion`); its GPU versions in VMD add the longest
//!   occluding distance `ao_maxdist` (Stone et al., "Interactive Ray Tracing Techniques for
//!   High-Fidelity Scientific Visualization", Ray Tracing Gems, 2019, chapter 27).
//! - Blender's Cycles: the Ambient Occlusion node's Samples and Distance
//!   (<https://docs.blender.org/manual/en/latest/render/shader_nodes/input/ao.html>).
//!
//! Here the directions are independent: cosine-weighted about the normal (uniform over the
//! hemisphere with the uniform weighting), so that each ray is unblocked with probability
//! the unoccluded fraction itself and the count is binomial. The estimate `k / N` is
//! unbiased, and its standard error is reported as `sqrt(p (1 - p) / N)` with
//! `p = (k + 1) / (N + 2)` (Laplace's rule of succession): the binomial standard error, kept
//! above 0 when every ray agrees, since `N` rays that all meet nothing do not make a point
//! exactly unoccluded. The random numbers come from the pixel's own stream (seeded by the
//! render's seed and the pixel), so a render is the same on any thread count.
//! `aoIntensity`-like strengths are left out: 1 is the only value that estimates AO.

use glam::DVec3;

use super::Weighting;
use crate::accel::SphereBvh;
use crate::render::sampler::Rng;

/// The unoccluded fraction at `x` (unit normal `n`, on the BVH's primitive `own`) from
/// `samples` random rays within `reach`, directions drawn as `w` weights them, and its
/// standard error (see the module comment).
pub fn unoccluded(
    bvh: &SphereBvh,
    (x, n, own): (DVec3, DVec3, Option<u32>),
    (reach, w): (f64, Weighting),
    samples: u32,
    rng: &mut Rng,
) -> (f64, f64) {
    let (e1, e2) = n.any_orthonormal_pair();
    let mut open = 0u32;
    for _ in 0..samples {
        let (u, v) = (rng.next_f64(), rng.next_f64());
        // `z = n . d`: cosine-weighted, the disk's uniform point lifted onto the hemisphere
        // (z² uniform); uniform, z itself uniform. Both in (0, 1].
        let (z, r) = match w {
            Weighting::Cosine => ((1.0 - u).sqrt(), u.sqrt()),
            Weighting::Uniform => (1.0 - u, (u * (2.0 - u)).sqrt()),
        };
        let (s, c) = (std::f64::consts::TAU * v).sin_cos();
        let d = (e1 * c + e2 * s) * r + n * z;
        open += u32::from(!blocked(bvh, x, d, own, reach));
    }
    let (k, m) = (f64::from(open), f64::from(samples));
    let p = (k + 1.0) / (m + 2.0);
    (k / m, (p * (1.0 - p) / m).sqrt())
}

/// Whether the ray from `x` along `d` meets an opaque sphere other than `own` at a distance
/// of at most `reach`. A point inside a sphere is blocked in every direction, as the exact
/// method has it.
pub fn blocked(bvh: &SphereBvh, x: DVec3, d: DVec3, own: Option<u32>, reach: f64) -> bool {
    bvh.any_except(x, d, 0.0, reach, own, |_, p, (t0, t1)| {
        !p.is_gas() && t1 > 0.0 && t0 <= reach
    })
}
