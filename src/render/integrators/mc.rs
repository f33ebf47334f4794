//! Unbiased Monte Carlo (`--integrator mc`, a named approximation of docs/model.md section 3 for
//! comparison): one stochastic estimate per camera sample, whose spread over a pixel's samples
//! is the pixel's error estimate (the standard error of their mean, in `tiles`).
//!
//! The estimator keeps randomness only where it is needed, so that its sample variance shows
//! its real uncertainty:
//!
//! - **Transmittance and emission by expected value.** Along the camera ray the medium is
//!   piecewise constant (the segments of `gas_along`), so the emission term, the transmittance
//!   `T(0, t_s)` and the surface or background behind are the closed forms of
//!   `emission_absorption` (exact up to rounding, as in `exact`). They have zero variance
//!   because they have zero error. (A free-path estimator scores them as rare events: through
//!   thick gas it never sees the escapes, through thin gas it never sees a collision, and in
//!   both cases its samples all agree and its standard error claims certainty.)
//! - **Single scattering by one collision point in every segment.** In a segment `[t_a, t_b]`
//!   of extinction `sigma`, `t` is drawn with pdf `sigma exp(-sigma (t - t_a)) / F` on the
//!   segment, `F = 1 - exp(-sigma (t_b - t_a))`, by inverting the truncated exponential. The
//!   sample scores `T(0, t_a) (F / sigma) p sum_i (sum sigma_j a_j) E_i(x(t))`, with one shadow
//!   ray per light through `lights_at` (its visibility is the exact transmittance towards the
//!   light, itself an expected value). The pdf cancels the camera-side attenuation inside the
//!   segment exactly, so what varies from sample to sample is only the light arriving, `E_i`.
//!   No segment is ever left unsampled: a faint or hidden segment contributes to every sample,
//!   in proportion to its weight, and so does its variance.
//!
//! - **Profiled gas** (docs/model.md section 6): a segment with profiled members is not of constant
//!   extinction, so its collision point is drawn by inverting its closed-form optical depth
//!   (`profiled_sample`), with the same pdf `sigma_t(t) T(t_a, t) / F`; the emission of its
//!   members is then sampled there too when they differ in colour (otherwise it is the closed
//!   form `C F`).
//!
//! The result is unbiased and converges like `1 / sqrt(n)`; it is exact (zero variance) where
//! there is no scattering. What it cannot see is what no estimator of this kind sees: a light
//! feature narrower than about `1 / n` of a segment's sampling measure (the rim of a thin
//! shadow, say) until a sample lands on it.
//!
//! Cost per camera sample: one traversal for the segments, then one shadow ray per light for
//! each segment with scattering gas and `T(0, t_a) > 0`, i.e. `K L` shadow rays for a ray that
//! crosses `K` segments with `L` lights (the previous free-path estimator cast `L`). Through a
//! cloud of a million spheres `K` can reach thousands; this is what `exact` spends per
//! quadrature node, and `exact` evaluates at least 15 nodes per piece. Segments past the
//! point where `T(0, t_a)` underflows to 0 are skipped: their contribution is exactly 0 in f64.
//! (Russian roulette on small-weight segments would save shadow rays, but would bring back the
//! rare events this design removes.) Random numbers: one per sampled segment, from the pixel's
//! stream, so images are deterministic.

use glam::DVec3;

use super::{behind, gas_along, lights_at, scatter_at, scatter_for, Estimate, Scratch};
use crate::render::sampler::Rng;
use crate::render::segments::{emission_absorption, Member, Segment};

use crate::render::{Counters, View};

/// An unbiased Monte Carlo estimate of the radiance along the camera ray `o + t d`, its random
/// numbers drawn from `rng`.
pub fn radiance(
    view: &View,
    o: DVec3,
    d: DVec3,
    rng: &mut Rng,
    s: &mut Scratch,
    counters: &mut Counters,
) -> Estimate {
    let hit = gas_along(view, o, d, s, counters);
    let covered = hit.is_some() || !s.segments.is_empty();
    // The expected-value part: emission, transmittance and what lies behind, in closed form.
    let (emitted, transmittance) = emission_absorption(&s.segments);
    let mut value = emitted;
    if transmittance > 0.0 {
        value += transmittance * behind(view, o, d, hit, transmittance, counters);
    }
    if view.lights.is_empty() && s.segments.iter().all(|g| g.emitted().is_some()) {
        return Estimate {
            value,
            error: 0.0,
            covered,
        };
    }
    // The stochastic part: single scattering, one collision point per segment.
    let mut tau = 0.0f64;
    for seg in &s.segments {
        if seg.is_profiled() {
            let t_a = (-tau).exp();
            tau += seg.depth;
            if t_a == 0.0 {
                break;
            }
            value += t_a * profiled_sample(view, (o, d), seg, t_a, rng, s, counters);
            continue;
        }
        if seg.sigma <= 0.0 {
            continue;
        }
        let dt = seg.tb - seg.ta;
        let t_a = (-tau).exp();
        tau += seg.sigma * dt;
        if t_a == 0.0 {
            // T(0, t_a) underflowed: this and every later segment add exactly 0.
            break;
        }
        if seg.scatter == DVec3::ZERO {
            continue;
        }
        // F = 1 - exp(-sigma dt) by expm1, and t by ln_1p: at optical depths of 1e-12 the
        // naive forms lose every digit (F -> 0, t -> t_a) where these keep full precision.
        let f = -(-seg.sigma * dt).exp_m1();
        let xi = rng.next_f64();
        let t = (seg.ta - (-xi * f).ln_1p() / seg.sigma).clamp(seg.ta, seg.tb);
        // f / sigma -> dt as sigma dt -> 0, without cancellation.
        let weight = t_a * f / seg.sigma;
        let light = lights_at(
            view,
            o + t * d,
            |i| scatter_for(view, seg, &s.members, i),
            t_a * (-seg.sigma * (t - seg.ta)).exp(),
            counters,
        );
        value += weight * light;
    }
    Estimate {
        value,
        error: 0.0,
        covered,
    }
}

/// One collision in a segment with profiled members, by inverting its closed-form optical
/// depth: the collision's depth `tau* = -ln(1 - xi F)`, `F = 1 - exp(-depth)`, then the `t`
/// where `depth_to(t) = tau*`, so that `t` has pdf `sigma_t(t) T(ta, t) / F`. It scores
/// `(F / sigma_t(t))` times the source at `t`: the emission `sum sigma_j C_j` when the members
/// differ in colour (else it was added in closed form), and the scattering
/// `p sum_j sigma_j a_j sum_i E_i`. Relative to `T(0, ta)`, which is `t_a`.
fn profiled_sample(
    view: &View,
    (o, d): (DVec3, DVec3),
    seg: &Segment,
    t_a: f64,
    rng: &mut Rng,
    s: &Scratch,
    counters: &mut Counters,
) -> DVec3 {
    let emits = seg.emitted().is_none();
    let scatters = seg.albedo_max > 0.0 && !view.lights.is_empty();
    if !(emits || scatters) {
        return DVec3::ZERO;
    }
    let f = seg.opacity();
    if f <= 0.0 {
        return DVec3::ZERO;
    }
    let xi = rng.next_f64();
    let target = -(-xi * f).ln_1p();
    let t = invert_depth(seg, &s.profiled, target);
    let (sigma, emit) = seg.source_at(&s.profiled, t);
    // A point of zero density has probability 0; rounding at a rim can land on one (and NaN
    // fails the test too).
    if sigma.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
        return DVec3::ZERO;
    }
    let weight = f / sigma;
    let mut value = DVec3::ZERO;
    if emits {
        value += weight * emit;
    }
    if scatters {
        value += weight
            * lights_at(
                view,
                o + t * d,
                |i| scatter_at(view, seg, &s.members, &s.profiled, i, t),
                t_a * (-seg.depth_to(&s.profiled, t)).exp(),
                counters,
            );
    }
    value
}

/// The `t` in the segment where its optical depth from the start reaches `target` (in
/// `[0, depth]`): Newton's method on the closed form (whose derivative is the density),
/// kept inside a bisection bracket.
fn invert_depth(seg: &Segment, profiled: &[Member], target: f64) -> f64 {
    let (mut lo, mut hi) = (seg.ta, seg.tb);
    let mut t = seg.ta + (seg.tb - seg.ta) * (target / seg.depth).clamp(0.0, 1.0);
    for _ in 0..100 {
        let g = seg.depth_to(profiled, t) - target;
        if g.abs() <= 4.0 * f64::EPSILON * target {
            break;
        }
        if g > 0.0 {
            hi = t;
        } else {
            lo = t;
        }
        let (sigma, _) = seg.source_at(profiled, t);
        let next = t - g / sigma;
        t = if next > lo && next < hi {
            next
        } else {
            0.5 * (lo + hi)
        };
        if hi - lo <= 4.0 * f64::EPSILON * t.abs().max(hi.abs()) {
            break;
        }
    }
    t
}
